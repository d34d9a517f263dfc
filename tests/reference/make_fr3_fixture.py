#!/usr/bin/python3
"""Writes the real-data fixture of the reference check (run once; outputs are committed):

  data/fr3_walking_xyz_gt.txt   the first 12 s of the TUM fr3/walking_xyz motion-capture ground
                                truth, lines copied verbatim
  data/fr3_walking_xyz_est.txt  a perturbed "estimate" at the RGB frame stamps of the sequence:
                                nearest ground-truth pose + drift (5 mm/s, 0.2 deg/s about z) +
                                noise (1 cm, 0.3 deg), seen in another world frame, with ~3% of
                                the frames dropped and a 1.5 s tracking loss (5.0 s .. 6.5 s)

Usage: tests/reference/make_fr3_fixture.py [/path/to/shared/data/tum/rgbd_dataset_freiburg3_walking_xyz]
"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT = os.path.join(HERE, "..", "..", "..", "shared", "data", "tum", "rgbd_dataset_freiburg3_walking_xyz")
WINDOW_S = 12.0


def axis_angle(axis, angle):
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def matrix_to_quat(r):
    w = np.sqrt(max(0.0, 1.0 + np.trace(r))) / 2.0
    x = np.copysign(np.sqrt(max(0.0, 1.0 + r[0, 0] - r[1, 1] - r[2, 2])) / 2.0, r[2, 1] - r[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1.0 - r[0, 0] + r[1, 1] - r[2, 2])) / 2.0, r[0, 2] - r[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1.0 - r[0, 0] - r[1, 1] + r[2, 2])) / 2.0, r[1, 0] - r[0, 1])
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


def quat_to_matrix(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else DEFAULT
    gt_lines, gt = [], []
    with open(os.path.join(src, "groundtruth.txt")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            values = [float(v) for v in line.split()]
            if gt and values[0] > gt[0][0] + WINDOW_S:
                break
            gt_lines.append(line.strip())
            gt.append(values)
    gt = np.array(gt)
    rgb = []
    with open(os.path.join(src, "associations.txt")) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                rgb.append(float(line.split()[0]))
    rgb = np.array([t for t in rgb if gt[0, 0] - 0.01 <= t <= gt[-1, 0]])

    rng = np.random.default_rng(20240601)
    frame_r = axis_angle([0.3, -0.5, 0.8], 1.1)
    frame_t = np.array([0.7, -1.2, 0.4])
    drift_dir = np.array([0.6, 0.0, -0.8])
    t0 = gt[0, 0]
    out = ["# perturbed estimate for the dynorb reference check (tests/reference/make_fr3_fixture.py)",
           "# timestamp tx ty tz qx qy qz qw"]
    for t in rgb:
        elapsed = t - t0
        drop = rng.random() < 0.03
        noise_p = rng.normal(0.0, 0.01, 3)
        noise_r = rng.normal(0.0, np.radians(0.3), 3)
        if drop or 5.0 <= elapsed < 6.5:
            continue
        k = int(np.argmin(np.abs(gt[:, 0] - t)))
        r = quat_to_matrix(gt[k, 4:8])
        p = gt[k, 1:4] + 0.005 * elapsed * drift_dir + noise_p
        r = axis_angle([0, 0, 1], np.radians(0.2) * elapsed) @ r @ axis_angle(noise_r, np.linalg.norm(noise_r))
        p_est = frame_r @ p + frame_t
        q = matrix_to_quat(frame_r @ r)
        out.append("%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f" % (t, *p_est, *q))
    with open(os.path.join(HERE, "data", "fr3_walking_xyz_gt.txt"), "w") as f:
        f.write("# first %.0f s of TUM RGB-D rgbd_dataset_freiburg3_walking_xyz/groundtruth.txt\n" % WINDOW_S)
        f.write("# timestamp tx ty tz qx qy qz qw\n" + "\n".join(gt_lines) + "\n")
    with open(os.path.join(HERE, "data", "fr3_walking_xyz_est.txt"), "w") as f:
        f.write("\n".join(out) + "\n")
    print("ground truth %d poses, estimate %d poses" % (len(gt_lines), len(out) - 2))


if __name__ == "__main__":
    main()
