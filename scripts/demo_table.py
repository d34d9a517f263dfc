#!/usr/bin/env python3
"""Prints the demo's comparison table from a `dynorb bench` output folder
(runs/<sequence>/<mode>/seed1/stats.json; a sequence ending in _twin is the static twin)."""
import json
import pathlib
import sys


def main(runs: pathlib.Path) -> int:
    rows = {}
    for stats_path in sorted(runs.glob("runs/*/*/seed1/stats.json")):
        mode = stats_path.parent.parent.name
        variant = "twin" if stats_path.parent.parent.parent.name.endswith("_twin") else "dynamic"
        rows[(mode, variant)] = json.loads(stats_path.read_text())
    if not rows:
        print("no runs completed")
        return 1
    twin = rows.get(("plain", "twin"))
    twin_ate = twin["ate"]["rmse_m"] if twin and "ate" in twin else None
    # Speed is compared with plain on the same sequence: plain on the dynamic one is slowed by the
    # people it tracks, so it is no yardstick for the twin's rows.
    plain_ms = {variant: rows.get(("plain", variant), {}).get("timing_ms", {}).get("frame_total", {}).get("mean")
                for variant in ("dynamic", "twin")}
    # Keypoint labels against the masks, objects moving at that frame (stats.json
    # dynamic_keypoints.moving_now): recall, precision by the keypoint's centre pixel, and
    # precision counting an object's outline corners (FAST circle on the object) as its own.
    header = f"{'mode':10} {'sequence':9} {'ATE RMSE [m]':>12} {'ratio to twin':>13} {'tracked':>8} " \
             f"{'ms/frame':>9} {'vs plain (same seq.)':>20} {'moving kp recall':>16} {'precision':>9} " \
             f"{'w/ outlines':>11} {'map on objects':>14}"
    print(header)
    print("-" * len(header))
    for (mode, variant), s in sorted(rows.items(), key=lambda kv: (kv[0][1] != "twin", kv[0][0])):
        ate = s.get("ate", {}).get("rmse_m")
        ms = s["timing_ms"]["frame_total"]["mean"]
        now = s.get("dynamic_keypoints", {}).get("moving_now", {})
        ratio = f"{ate / twin_ate:13.1f}" if ate is not None and twin_ate else f"{'-':>13}"
        speed = f"{ms / plain_ms[variant]:19.2f}x" if plain_ms[variant] else f"{'-':>20}"
        has_filter = mode != "plain" and now.get("true_positive", 0) + now.get("false_negative", 0) > 0
        # A ratio with nothing to divide by is null in stats.json (e.g. nothing removed): "-".
        def number(value, width):
            return f"{value:{width}.2f}" if has_filter and value is not None else f"{'-':>{width}}"
        recall = number(now.get("recall"), 16)
        precision = number(now.get("precision"), 9)
        outlines = number(now.get("support", {}).get("precision"), 11)
        ate_text = f"{ate:12.4f}" if ate is not None else f"{'-':>12}"
        # Share of the final map's landmarks made on a dynamic object (stats.json
        # map_landmarks_on_dynamic_objects; sequences with masks).
        on_map = s.get("map_landmarks_on_dynamic_objects", {}).get("fraction")
        map_text = f"{100 * on_map:13.1f}%" if on_map is not None else f"{'-':>14}"
        print(f"{mode:10} {variant:9} {ate_text} {ratio} {100 * s['tracked_fraction']:7.1f}% {ms:9.1f} {speed} "
              f"{recall} {precision} {outlines} {map_text}")
    return 0


if __name__ == "__main__":
    sys.exit(main(pathlib.Path(sys.argv[1])))
