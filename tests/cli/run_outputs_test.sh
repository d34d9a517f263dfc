#!/usr/bin/env bash
# What a run's outputs say, found by the session-55 review of the measurement code (CTest:
# dynorb_cli_run_outputs): frames.csv's frame is the sequence index the overlays are named by; a
# frame without a ground-truth mask is unknown (-1), not "nothing on movers"; a first frame
# withheld whole is not "filtered"; undefined ratios are null / n/a; writing overlays is timed
# apart from the run.
# Usage: run_outputs_test.sh path/to/dynorb
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"

"$DYNORB" synth --preset walking_xyz --frames 12 --people procedural --out "$DIR/seq" >/dev/null 2>&1 ||
  { echo "FAIL: synth"; exit 1; }
# Masks of every second frame only.
awk '/^#/ || (++n % 2 == 1)' "$DIR/seq/masks.txt" >"$DIR/masks.txt" && mv "$DIR/masks.txt" "$DIR/seq/masks.txt"
"$DYNORB" run --dataset "$DIR/seq" --mode fast --frames 3:11 --save-overlays "$DIR/ov" --out "$DIR/fast" \
  --quiet >"$DIR/fast.txt" 2>&1 || fail "fast run: $(cat "$DIR/fast.txt")"
[[ -s "$DIR/ov/000003.png" && -s "$DIR/ov/000010.png" ]] || fail "overlays not named by the sequence index"
grep -qF "RPE (1 s)         n/a" "$DIR/fast.txt" || fail "an 8-frame run printed an RPE: $(grep RPE "$DIR/fast.txt")"
/usr/bin/python3 - "$DIR/fast" "$DIR/seq" <<'PYEOF' || fail "fast run outputs"
import csv, json, sys
out, seq = sys.argv[1], sys.argv[2]
rows = list(csv.DictReader(open(out + "/frames.csv")))
stats = json.load(open(out + "/stats.json"))
assert [int(r["frame"]) for r in rows] == list(range(3, 11)), [r["frame"] for r in rows]
masked = set()
for line in open(seq + "/masks.txt"):
    if not line.startswith("#"):
        masked.add(round(float(line.split()[0]), 6))
unknown = [r for r in rows if round(float(r["timestamp"]), 6) not in masked]
assert 3 <= len(unknown) <= 5, len(unknown)
assert all(r["inliers_on_movers"] == "-1" and r["new_landmarks_on_movers"] == "-1" for r in unknown)
known = [r for r in rows if r not in unknown]
assert all(int(r["inliers_on_movers"]) >= 0 for r in known)
on = stats["inliers_on_moving_objects"]["per_frame"]
tracked_known = [r for r in known if r["state"] == "ok"]
assert on["count"] == len(tracked_known), (on["count"], len(tracked_known))
judged = [r for r in rows if r["judged"] == "1"]
assert stats["filtered_keypoints_per_frame"]["count"] == len(judged) == len(rows) - 1, stats["filtered_keypoints_per_frame"]
assert stats["rpe"]["pairs"] == 0 and stats["rpe"]["trans_rmse_m_per_s"] is None, stats["rpe"]
assert stats["overlay_write_seconds"] > 0, stats.get("overlay_write_seconds")
assert "by_cue_definition" in stats["dynamic_keypoints"]
PYEOF
# A plain run removes nothing: its precision is undefined (null), not 0.
"$DYNORB" run --dataset "$DIR/seq" --out "$DIR/plain" --quiet >/dev/null 2>&1 || fail "plain run"
/usr/bin/python3 - "$DIR/plain/stats.json" <<'PYEOF' || fail "plain run: precision of nothing removed"
import json, sys
d = json.load(open(sys.argv[1]))["dynamic_keypoints"]
assert d["true_positive"] + d["false_positive"] == 0, d
assert d["precision"] is None and d["mean_frame_precision"] is None, d
assert d["recall"] == 0.0, d["recall"]
PYEOF

# The demo's table (scripts/demo_table.py, `make demo`) takes null ratios: a semantic run with an
# empty box list removes nothing while movers are in view.
mkdir -p "$DIR/table/runs/seq/plain/seed1" "$DIR/table/runs/seq/semantic/seed1"
cp "$DIR/plain/stats.json" "$DIR/table/runs/seq/plain/seed1/"
: >"$DIR/boxes.txt"
printf 'semantic:\n  source: boxes\n  list: %s\n' "$DIR/boxes.txt" >"$DIR/no_boxes.yaml"
"$DYNORB" run --dataset "$DIR/seq" --mode semantic --config-overlay "$DIR/no_boxes.yaml" \
  --out "$DIR/table/runs/seq/semantic/seed1" --quiet >/dev/null 2>&1 || fail "semantic run with no boxes"
/usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/../../scripts/demo_table.py" "$DIR/table" >"$DIR/table.txt" 2>&1 ||
  fail "demo_table.py on null ratios: $(cat "$DIR/table.txt")"

finish "run output checks"
