#!/usr/bin/python3
"""Independent numpy implementation of the TUM RGB-D benchmark trajectory metrics.

Written from the published definitions (Sturm et al., "A Benchmark for the Evaluation of RGB-D
SLAM Systems", IROS 2012, and the behaviour of its associate.py / evaluate_ate.py /
evaluate_rpe.py tools) to produce reference values for dynorb's C++ evaluator. It shares no code
with the C++: association enumerates candidates explicitly and accepts them greedily, alignment
is Horn's method via the SVD of the cross-covariance, RPE uses 4x4 matrices and numpy.linalg.inv,
coverage merges intervals.

Usage (Debian: /usr/bin/python3 with python3-numpy):
    tests/reference/tum_reference.py                  # print values for every case in cases.json
    tests/reference/tum_reference.py --write          # (re)write reference_values.json
See docs/evaluation.md, "Reference check".
"""
import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def read_tum(path):
    """Returns (stamps[n], positions[n,3], quaternions xyzw [n,4]) sorted by stamp."""
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            rows.append([float(v) for v in line.replace(",", " ").split()])
    data = np.array(rows, dtype=np.float64)
    order = np.argsort(data[:, 0], kind="stable")
    data = data[order]
    return data[:, 0], data[:, 1:4], data[:, 4:8]


def quat_to_matrix(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def pose_matrix(position, quaternion):
    m = np.eye(4)
    m[:3, :3] = quat_to_matrix(quaternion)
    m[:3, 3] = position
    return m


def associate(gt_stamps, est_stamps, offset, max_diff):
    """associate.py's rule: candidates |a - (b + offset)| < max_diff, sorted by (diff, a, b),
    accepted greedily when both unused; returned sorted by ground-truth stamp."""
    shifted = est_stamps + offset
    candidates = []
    lo = np.searchsorted(gt_stamps, shifted - max_diff, side="left")
    hi = np.searchsorted(gt_stamps, shifted + max_diff, side="right")
    for j in range(len(est_stamps)):
        for i in range(max(lo[j] - 1, 0), min(hi[j] + 1, len(gt_stamps))):
            a, b = gt_stamps[i], est_stamps[j]
            diff = abs(a - (b + offset))
            if diff < max_diff:
                candidates.append((diff, a, b, i, j))
    candidates.sort()
    used_gt, used_est, matches = set(), set(), []
    for diff, a, b, i, j in candidates:
        if i in used_gt or j in used_est:
            continue
        used_gt.add(i)
        used_est.add(j)
        matches.append((i, j))
    matches.sort()
    return matches


def horn_align(model, data, with_scale):
    """Least-squares data ~ s R model + t for 3xn arrays (Horn 1987 / Umeyama 1991, via SVD)."""
    mu_m = model.mean(axis=1, keepdims=True)
    mu_d = data.mean(axis=1, keepdims=True)
    m0, d0 = model - mu_m, data - mu_d
    cross = d0 @ m0.T / model.shape[1]  # cross-covariance, data x model
    u, sing, vt = np.linalg.svd(cross)
    sign = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2, 2] = -1.0
    rot = u @ sign @ vt
    scale = 1.0
    if with_scale:
        variance = (m0 * m0).sum() / model.shape[1]
        scale = np.trace(np.diag(sing) @ sign) / variance
    trans = mu_d - scale * rot @ mu_m
    return rot, trans, scale


def stats(values):
    v = np.asarray(values, dtype=np.float64)
    if len(v) == 0:
        return None
    return {"rmse": float(np.sqrt(np.dot(v, v) / len(v))), "mean": float(np.mean(v)),
            "median": float(np.median(v)), "std": float(np.std(v)), "min": float(np.min(v)),
            "max": float(np.max(v)), "count": int(len(v))}


def closest(sorted_values, t):
    """Index of the closest value; exact ties go to the earlier index."""
    k = int(np.searchsorted(sorted_values, t, side="left"))
    if k == 0:
        return 0
    if k == len(sorted_values):
        return len(sorted_values) - 1
    return k - 1 if abs(t - sorted_values[k - 1]) <= abs(sorted_values[k] - t) else k


def rotation_angle(r):
    return float(np.arccos(min(1.0, max(-1.0, (np.trace(r) - 1.0) / 2.0))))


def rpe(gt, est, delta, offset, scale):
    """evaluate_rpe.py --fixed_delta --delta_unit s --max_pairs 0."""
    gt_t, gt_p, gt_q = gt
    est_t, est_p, est_q = est
    gt_m = [pose_matrix(p, q) for p, q in zip(gt_p, gt_q)]
    est_m = [pose_matrix(p, q) for p, q in zip(est_p, est_q)]
    max_dt = 2.0 * float(np.median(np.diff(gt_t)))
    trans, rot, trans_paper = [], [], []
    n = len(est_t)
    for i in range(n):
        j = closest(est_t, est_t[i] + delta)
        if j == n - 1:
            continue
        gi = closest(gt_t, est_t[i] + offset)
        gj = closest(gt_t, est_t[j] + offset)
        if abs(gt_t[gi] - (est_t[i] + offset)) > max_dt or abs(gt_t[gj] - (est_t[j] + offset)) > max_dt:
            continue
        back_est = np.linalg.inv(est_m[j]) @ est_m[i]  # est_j^-1 est_i
        back_est[:3, 3] *= scale
        back_gt = np.linalg.inv(gt_m[gj]) @ gt_m[gi]
        error = np.linalg.inv(back_est) @ back_gt
        trans.append(float(np.linalg.norm(error[:3, 3])))
        rot.append(rotation_angle(error[:3, :3]) * 180.0 / np.pi)
        fwd_est = np.linalg.inv(est_m[i]) @ est_m[j]
        fwd_est[:3, 3] *= scale
        fwd_gt = np.linalg.inv(gt_m[gi]) @ gt_m[gj]
        paper = np.linalg.inv(fwd_gt) @ fwd_est
        trans_paper.append(float(np.linalg.norm(paper[:3, 3])))
    return {"gt_max_time_difference_s": max_dt, "trans_m": stats(trans), "rot_deg": stats(rot),
            "trans_paper_form_m": stats(trans_paper)}


def coverage(gt_t, centers, window):
    """Fraction of [gt_first, gt_last] within +-window of an associated estimate stamp."""
    begin, end = gt_t[0], gt_t[-1]
    intervals = sorted((max(begin, c - window), min(end, c + window)) for c in centers)
    merged = []
    for a, b in intervals:
        if b <= a:
            continue
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    covered = sum(b - a for a, b in merged)
    return {"fraction": covered / (end - begin), "covered_s": covered}


def evaluate(case):
    gt = read_tum(os.path.join(HERE, case["groundtruth"]))
    est = read_tum(os.path.join(HERE, case["estimate"]))
    o = case["options"]
    matches = associate(gt[0], est[0], o["offset_s"], o["max_diff_s"])
    gt_xyz = np.array([gt[1][i] for i, _ in matches]).T
    est_xyz = np.array([est[1][j] for _, j in matches]).T
    if o["align"] == "none":
        rot, trans, scale = np.eye(3), np.zeros((3, 1)), 1.0
    else:
        rot, trans, scale = horn_align(est_xyz, gt_xyz, o["align"] == "sim3")
    aligned = scale * rot @ est_xyz + trans
    errors = np.sqrt(((aligned - gt_xyz) ** 2).sum(axis=0))
    centers = [est[0][j] + o["offset_s"] for _, j in matches]
    return {"pairs": len(matches), "ate_m": stats(errors), "scale": float(scale),
            "rpe": rpe(gt, est, o["rpe_delta_s"], o["offset_s"], scale),
            "coverage": coverage(gt[0], centers, o["coverage_window_s"])}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--write", action="store_true", help="write reference_values.json")
    args = parser.parse_args()
    with open(os.path.join(HERE, "cases.json")) as f:
        cases = json.load(f)
    out = {"generator": "tests/reference/tum_reference.py", "numpy": np.__version__, "cases": []}
    for case in cases:
        result = evaluate(case)
        out["cases"].append(dict(case, expected=result))
        print("%-28s pairs %5d  ATE rmse %.6f m  RPE %.6f m / %.6f deg  coverage %.4f" % (
            case["name"], result["pairs"], result["ate_m"]["rmse"],
            result["rpe"]["trans_m"]["rmse"], result["rpe"]["rot_deg"]["rmse"], result["coverage"]["fraction"]))
    if args.write:
        with open(os.path.join(HERE, "reference_values.json"), "w") as f:
            json.dump(out, f, indent=1)
            f.write("\n")
        print("wrote", os.path.join(HERE, "reference_values.json"))


if __name__ == "__main__":
    sys.exit(main())
