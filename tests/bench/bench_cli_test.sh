#!/usr/bin/env bash
# End-to-end check of `dynorb bench` (CTest: dynorb_bench_cli):
#  1. bad suites (unknown mode, missing dataset, unknown preset/key) fail with exit 2, one
#     "dynorb: error:" line naming suite:line, before any run starts (nothing written);
#  2. report.md/html from the stored tests/bench/data/results.json (numbers checked);
#  3. a tiny synthetic suite: runs, plots, results.json; resume after more repeats, after a lost
#     stats.json and after a real interruption (SIGTERM mid-run).
# Usage: bench_cli_test.sh path/to/dynorb SOURCE_DIR [ARTIFACT_DIR]  (the report of step 3 is
# copied to ARTIFACT_DIR for the headless-browser test).
set -uo pipefail
DYNORB=$(realpath "${1:?usage: bench_cli_test.sh path/to/dynorb SOURCE_DIR [ARTIFACT_DIR]}")
SRC=$(realpath "${2:?source dir}")
ARTIFACTS=${3:-}
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# --- 1. bad suites -------------------------------------------------------------------------
check_error() {  # name expected-substring suite-text [extra args]
  local name=$1 expected=$2 text=$3
  shift 3
  printf '%s' "$text" >"$DIR/$name.yaml"
  local err code
  err=$("$DYNORB" bench --suite "$DIR/$name.yaml" --out "$DIR/out_$name" --quiet "$@" 2>&1 >/dev/null)
  code=$?
  [[ $code == 2 ]] || fail "$name: exit code $code ($err)"
  grep -qF -- "$expected" <<<"$err" || fail "$name: message '$err' lacks '$expected'"
  [[ $(wc -l <<<"$err") == 1 ]] || fail "$name: more than one line: $err"
  [[ ! -e "$DIR/out_$name" ]] || fail "$name: wrote $DIR/out_$name before failing"
}
SYN='sequences:
  - {name: syn, synthetic: {preset: walking_xyz, frames: 10}}
'
check_error unknown_mode "unknown_mode.yaml:5: unknown mode 'mystery' (modes of this dynorb build: plain" \
  "${SYN}modes:
  - plain
  - mystery
"
check_error missing_dataset "missing_dataset.yaml:2: dataset of sequence 'fr3' not found" \
  'sequences:
  - {name: fr3, path: no_such_folder}
modes: [plain]
'
check_error missing_dataset_root "--skip-missing" \
  'sequences:
  - {name: fr3, path: no_such_folder}
modes: [plain]
' --dataset-root "$DIR"
check_error all_skipped "no sequence to run" \
  'sequences:
  - {name: fr3, path: no_such_folder}
modes: [plain]
' --skip-missing
check_error unknown_preset "unknown_preset.yaml:2: unknown synthetic preset 'running'" \
  'sequences:
  - {name: syn, synthetic: {preset: running}}
modes: [plain]
'
check_error unknown_key "unknown_key.yaml:4: unknown key 'repeat' in the suite" \
  "${SYN}modes: [plain]
repeat: 3
"
check_error missing_config "missing_config.yaml:4: config file of mode 'plain-nope' not found" \
  "${SYN}modes:
  - {name: plain, config: nope.yaml}
"
check_error missing_overlay "missing_overlay.yaml:4: overlay file of mode 'plain-nope' not found" \
  "${SYN}modes:
  - {name: plain, overlay: nope.yaml}
"
err=$("$DYNORB" bench --suite "$DIR/no_such_suite.yaml" --out "$DIR/o" 2>&1 >/dev/null)
[[ $? == 2 ]] && grep -qF "suite file not found" <<<"$err" || fail "missing suite file: $err"

# --- 2. report from a stored results.json ----------------------------------------------------
mkdir -p "$DIR/stored"
cp "$SRC/tests/bench/data/results.json" "$DIR/stored/"
"$DYNORB" bench --report "$DIR/stored" --published "$SRC/bench/published_results.json" >/dev/null || fail "--report"
MD="$DIR/stored/report.md"
for needle in "| syn_walking_xyz | 0.0500 [0.0400-0.0600] | 0.0130 [0.0120-0.0140] |" \
  "## Robustness ratio ATE(dynamic) / ATE(static twin)" "| syn_walking_xyz | 3.50 [3.00-4.00] | 1.10 [1.00-1.20] |" \
  "| syn_walking_xyz | 1.00x [1.00-1.00] | 1.50x [1.50-1.50] |" "| syn_walking_xyz | fast | 85.0 [80.0-90.0] | 65.0 [60.0-70.0] | 40.0 [30.0-50.0] | 95.0 [94.0-96.0] | 83.0 [78.0-88.0] | 95.0 [93.0-97.0] | 20.0 [20.0-20.0] |" \
  "| dynorb plain | 0.300 | this run |" "| DynaSLAM (RGB-D) | 0.0150 |" "| DS-SLAM | 0.0247 |" "(not verified)" \
  "runs: 9 ok, 1 failed" "| fr3_walking_xyz | fast |" "| fr3_walking_xyz | - | - |" \
  "| syn_walking_xyz | 0.0250 [0.0200-0.0300] | 0.0065 [0.0060-0.0070] |" \
  "## CPU time per frame [ms]" "| syn_walking_xyz | 40.0 [40.0-40.0] | 56.0 [52.0-60.0] |" \
  "## CPU ratio to plain" "| syn_walking_xyz | 1.00x [1.00-1.00] | 1.40x [1.30-1.50] |" \
  "## Summary per mode" "| plain | 2 of 2 | 0.0500 | 3.50 [3.00-4.00] | 0 of 2 | 21.0 [20.0-22.0] | 1.00x [1.00-1.00] | - |" \
  "| fast | 2 of 2 | 0.0130 | 1.10 [1.00-1.20] | 2 of 2 | 31.5 [30.0-33.0] | 1.50x [1.50-1.50] | - |"; do
  grep -qF -- "$needle" "$MD" || fail "report.md lacks '$needle'"
done
# The summary is the report's first table.
[[ $(grep -m1 -n '^## ' "$MD") == *"## Summary per mode" ]] || fail "report.md does not open with the summary"
HTML="$DIR/stored/report.html"
[[ $(grep -c "<table" "$HTML") -ge 8 ]] || fail "report.html: fewer than 8 tables"
grep -qF "report test fixture &lt;&amp;&gt;" "$HTML" || fail "report.html: text not escaped"
# Two dynamic sequences: the pooled robustness rows. syn_walking_rpy = syn_walking_xyz with half
# the dynamic ATE: plain ratios 3, 4, 1.5, 2 (median 2.5), fast 1, 1.2, 0.5, 0.6 (median 0.8).
mkdir -p "$DIR/pooled"
/usr/bin/python3 - "$SRC/tests/bench/data/results.json" "$DIR/pooled/results.json" <<'EOF' || fail "pooled fixture"
import copy, json, sys
r = json.load(open(sys.argv[1]))
for s in list(r["suite"]["sequences"]):
    if s["name"].startswith("syn_walking_xyz"):
        t = copy.deepcopy(s)
        t["name"] = s["name"].replace("xyz", "rpy")
        if t["twin_of"]: t["twin_of"] = "syn_walking_rpy"
        r["suite"]["sequences"].append(t)
for run in list(r["runs"]):
    if run["sequence"].startswith("syn_walking_xyz"):
        t = copy.deepcopy(run)
        t["sequence"] = run["sequence"].replace("xyz", "rpy")
        if t["sequence"] == "syn_walking_rpy" and "stats" in t:
            t["stats"]["ate"]["rmse_m"] *= 0.5
        r["runs"].append(t)
# Map statistics on syn_walking_rpy's plain runs: 30 and 10 of 100 landmarks on movers (a key
# that is no mask id is left out of the per-object split).
for run in r["runs"]:
    if run["sequence"] == "syn_walking_rpy" and run["mode"] == "plain":
        first = run["seed"] == 1
        run["stats"]["map_landmarks_on_dynamic_objects"] = {
            "made_on_dynamic_objects": 30 if first else 10, "origin_known": 100,
            "by_object": {"1": 20, "4": 10, "4x": 7} if first else {"1": 10}}
# One run's own plausibility warning (stats.json "warnings") reaches the report's summary.
warned = next(run for run in r["runs"] if run["sequence"] == "syn_walking_rpy" and "stats" in run)
warned["stats"]["warnings"] = ["the depth images read as 1.25e+04 m away"]
json.dump(r, open(sys.argv[2], "w"))
EOF
"$DYNORB" bench --report "$DIR/pooled" >/dev/null || fail "--report pooled"
for needle in "| syn_walking_rpy | 1.75 [1.50-2.00] | 0.55 [0.50-0.60] |" \
  "| all sequences and seeds | 2.50 [1.50-4.00] | 0.80 [0.50-1.20] |" "| ratio <= 1.3 | 0 of 4 | 4 of 4 |" \
  "| plain | 4 of 4 | 0.0375 | 2.50 [1.50-4.00] | 0 of 4 | 21.0 [20.0-22.0] | 1.00x [1.00-1.00] | 20.00 (1: 15.00, 4: 5.00) |"; do
  grep -qF -- "$needle" "$DIR/pooled/report.md" || fail "pooled report.md lacks '$needle'"
done
grep -qF "all sequences and seeds" "$MD" && fail "one dynamic sequence must not get a pooled row"
grep -qF "recall per moving object" "$MD" && fail "a report without by_object stats has a per-object table"
# Recall per moving object: the fast runs of the fixture with per-object counts (seed 1: person 90 %,
# box 50 %; seed 2: person 96 %, no box); plain rows are left out.
mkdir -p "$DIR/objects"
/usr/bin/python3 - "$SRC/tests/bench/data/results.json" "$DIR/objects/results.json" <<'EOF' || fail "per-object fixture"
import json, sys
r = json.load(open(sys.argv[1]))
recalls = {1: {"1": 0.90, "4": 0.50}, 2: {"1": 0.96}}
for run in r["runs"]:
    if run["sequence"] == "syn_walking_xyz" and "stats" in run:
        now = run["stats"]["dynamic_keypoints"].setdefault("moving_now", {})
        now["by_object"] = {k: {"recall": v} for k, v in recalls[run["seed"]].items()} if run["mode"] == "fast" else {}
json.dump(r, open(sys.argv[2], "w"))
EOF
"$DYNORB" bench --report "$DIR/objects" >/dev/null || fail "--report objects"
for needle in "## Dynamic keypoints: recall per moving object [%]" "| sequence | mode | object 1 | object 4 |" \
  "| syn_walking_xyz | fast | 93.0 [90.0-96.0] | 50.0 |"; do
  grep -qF -- "$needle" "$DIR/objects/report.md" || fail "objects report.md lacks '$needle'"
done
sed -n '/recall per moving object/,/^## Figures/p' "$DIR/objects/report.md" | grep -qF "| syn_walking_xyz | plain |" &&
  fail "the per-object table has a plain row"
[[ $(grep -c '^- warning: syn_walking_rpy / .* seed [0-9]*: the depth images read as 1.25e+04 m away$' \
  "$DIR/pooled/report.md") == 1 ]] || fail "pooled report.md: the run's warning is not listed once"
grep -q '^- warning:' "$MD" && fail "report.md lists a warning no run had"

echo '{"format": "something else"}' >"$DIR/stored/results.json"
err=$("$DYNORB" bench --report "$DIR/stored" 2>&1 >/dev/null)
[[ $? == 2 ]] && grep -qF "not a dynorb bench results.json" <<<"$err" || fail "bad results.json: $err"
# Valid JSON of the wrong shape: the file is named (nlohmann's message alone did not).
echo '{"format": "dynorb-bench-results/1", "suite": {}, "runs": "none"}' >"$DIR/stored/results.json"
err=$("$DYNORB" bench --report "$DIR/stored" 2>&1 >/dev/null)
[[ $? == 2 ]] && grep -qF "stored/results.json: expected 'runs' (an array)" <<<"$err" ||
  fail "results.json of the wrong shape: $err"

# --- 3. a real (tiny) suite, resume -------------------------------------------------------------
cat >"$DIR/tiny.yaml" <<'EOF'
name: tiny
repeats: 1
preload: true
front_end_threads: 2
save_map: true
sequences:
  - {name: syn, synthetic: {preset: walking_xyz, seed: 3, frames: 14, static_twin: true}}
modes:
  - plain
  - {name: mystery, optional: true}
EOF
OUT="$DIR/bench"
run_bench() { "$DYNORB" bench --suite "$DIR/tiny.yaml" --out "$OUT" --people "${BENCH_PEOPLE:-procedural}" --quiet "$@"; }
run_bench >"$DIR/run1.txt" 2>"$DIR/run1.err" || fail "tiny run 1: $(cat "$DIR/run1.err")"
grep -qF "mode 'mystery' is not registered" "$DIR/run1.err" || fail "no warning for the optional mode"
grep -qF "runs: 2 (0 resumed, 0 failed)" "$DIR/run1.txt" || fail "run 1 summary: $(cat "$DIR/run1.txt")"
for f in results.json report.md report.html plots/syn__plain.png plots/syn__plain.svg plots/syn_twin__plain.png \
  plots/syn__plain_keypoints.png runs/syn/plain/seed1/stats.json runs/syn_twin/plain/seed1/trajectory.txt \
  runs/syn/plain/seed1/map.ply runs/syn_twin/plain/seed1/map.ply plots/syn__plain_map.png \
  cache/walking_xyz_s3_f14/rgb.txt cache/walking_xyz_s3_f14_twin/rgb.txt; do
  [[ -s "$OUT/$f" ]] || fail "run 1 did not write $f"
done
[[ ! -e "$OUT/runs/syn/plain/seed1/overlays" ]] || fail "overlay frames left behind"
/usr/bin/python3 - "$OUT/results.json" <<'EOF' || fail "results.json content"
import json, sys
r = json.load(open(sys.argv[1]))
assert len(r["runs"]) == 2, r["runs"]
for run in r["runs"]:
    s = run["stats"]
    assert run["status"] == "ok" and s["frames"] == 14, run
    assert s["ate"]["rmse_m"] >= 0 and "frame_total" in s["timing_ms"]
    assert s["preload"] is True and s["preload_seconds"] > 0, s.get("preload")  # the suite's preload: true
assert r["suite"]["preload"] is True and r["suite"]["save_map"] is True
for run in r["runs"]:  # the map's landmarks against the masks (the twin's masks are empty)
    m = run["stats"]["map_landmarks_on_dynamic_objects"]
    assert m["landmarks"] == run["stats"]["landmarks"] and 0 <= m["made_on_dynamic_objects"] <= m["origin_known"], m
    assert run["sequence"] != "syn_twin" or m["made_on_dynamic_objects"] == 0, m
assert "dynamic_keypoints" in r["runs"][0]["stats"]
EOF
/usr/bin/python3 - "$OUT/runs/syn/plain/seed1/frames.csv" "$OUT/runs/syn/plain/seed1/stats.json" <<'EOF' || fail "frames.csv content"
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
s = json.load(open(sys.argv[2]))
assert len(rows) == 14, len(rows)
assert [int(r["frame"]) for r in rows] == list(range(14))
assert sum(int(r["new_keyframe"]) for r in rows) == s["keyframes_inserted"], rows
assert sum(r["state"] == "ok" for r in rows) == s["tracked_frames"]
assert all(float(r["total_ms"]) > 0 and int(r["keypoints"]) > 0 for r in rows)
assert all(r["judged"] == "1" for r in rows), rows  # plain mode has no filter: every frame counts
assert all(r["analysed"] == "1" for r in rows) and s["filter_analysed_frames"] == 14, s["filter_analysed_frames"]
# Pose inliers and new landmarks on moving objects (synthetic masks): counted per frame, summed in stats.json.
on = [int(r["inliers_on_movers"]) for r in rows]
assert all(0 <= o <= int(r["inliers"]) for o, r in zip(on, rows)), on
m = s["inliers_on_moving_objects"]
assert m["per_frame"]["count"] == s["tracked_frames"], m
assert abs(m["per_frame"]["mean"] * m["per_frame"]["count"] - sum(on)) < 1e-6, (m, on)
assert m["frames_with_any"] == sum(o > 0 for o in on) and m["support_per_frame"]["mean"] >= m["per_frame"]["mean"]
l = s["landmarks_created_on_moving_objects"]
assert l["created"] >= l["support_on_moving_objects"] >= l["on_moving_objects"] >= 0, l
assert sum(int(r["new_landmarks_on_movers"]) for r in rows) == l["on_moving_objects"], l
assert l["created"] >= s["landmarks"] * 0 + 100, l  # the first keyframe alone seeds hundreds
EOF
grep -qF "## Robustness ratio" "$OUT/report.md" || fail "tiny report has no robustness table"
grep -qF "## Map landmarks made on dynamic objects [%]" "$OUT/report.md" || fail "tiny report has no map table"
grep -qF "plots/syn__plain_map.png" "$OUT/report.md" || fail "tiny report does not show the map picture"
grep -qF "## Map landmarks made on dynamic objects" "$MD" && fail "a report without map stats has a map table"
grep -qF "run mode sequential, pipeline on (depth 4)," "$OUT/report.md" || fail "tiny report does not say the runs were pipelined"
grep -qF "pipeline on (depth 4), 2 front-end threads, frames preloaded (live-camera timing)," "$OUT/report.md" ||
  fail "tiny report does not say the frames were preloaded on 2 front-end threads"
grep -qF '"front_end_threads": 2' "$OUT/runs/syn/plain/seed1/stats.json" ||
  fail "the tiny suite's runs did not use 2 front-end threads"
# Keypoint labels of a dynamic mode against the masks: all objects, objects moving at that frame
# (objects.txt), and per cue; the counts must add up.
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --out "$DIR/fastrun" --quiet >"$DIR/fastrun.txt" 2>&1 ||
  fail "fast run on the cached sequence"
# The printed summary gives the keypoint labels of stats.json (both truths); a plain run prints none.
/usr/bin/python3 - "$DIR/fastrun/stats.json" "$DIR/fastrun.txt" <<'EOF' || fail "summary line of the keypoint labels"
import json, sys
now = json.load(open(sys.argv[1]))["dynamic_keypoints"]["moving_now"]
line = "moving keypoints  precision %.3f, recall %.3f (centre on the mask); outline corners counted: %.3f, %.3f" % (
    now["precision"], now["recall"], now["support"]["precision"], now["support"]["recall"])
assert now["true_positive"] + now["false_positive"] > 0, now
assert line in open(sys.argv[2]).read().splitlines(), (line, open(sys.argv[2]).read())
# Per object id: the keypoints on each moving object, removed and kept, add up to the totals.
by = now["by_object"]
assert by and all(k.isdigit() and 1 <= int(k) <= 255 for k in by), by
assert sum(o["true_positive"] for o in by.values()) == now["true_positive"], by
assert sum(o["false_negative"] for o in by.values()) == now["false_negative"], by
assert all(abs(o["recall"] - o["true_positive"] / (o["true_positive"] + o["false_negative"])) < 1e-12 for o in by.values())
EOF
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --out "$DIR/plainrun" --quiet >"$DIR/plainrun.txt" 2>&1 ||
  fail "plain run on the cached sequence"
grep -q "ATE RMSE" "$DIR/plainrun.txt" || fail "plain run summary: $(cat "$DIR/plainrun.txt")"
grep -q "moving keypoints" "$DIR/plainrun.txt" && fail "a plain run printed keypoint labels"
# make demo's table (scripts/demo_table.py) over a bench-like layout of these runs: the labels of
# objects moving at the frame, for the filtering mode only.
for run in syn/fast:fastrun syn/plain:plainrun syn_twin/plain:bench/runs/syn_twin/plain/seed1; do
  mkdir -p "$DIR/demo/runs/${run%%:*}/seed1" && cp "$DIR/${run#*:}/stats.json" "$DIR/demo/runs/${run%%:*}/seed1/"
done
/usr/bin/python3 "$SRC/scripts/demo_table.py" "$DIR/demo" >"$DIR/demo_table.txt" || fail "demo_table.py: $(cat "$DIR/demo_table.txt")"
/usr/bin/python3 - "$DIR/fastrun/stats.json" "$DIR/demo_table.txt" <<'EOF' || fail "demo table: $(cat "$DIR/demo_table.txt")"
import json, sys
fast = json.load(open(sys.argv[1]))
now = fast["dynamic_keypoints"]["moving_now"]
rows = {tuple(l.split()[:2]): l.split() for l in open(sys.argv[2]).read().splitlines()[2:]}
assert rows[("fast", "dynamic")][-4:-1] == ["%.2f" % now["recall"], "%.2f" % now["precision"], "%.2f" % now["support"]["precision"]], rows
assert rows[("plain", "dynamic")][-4:-1] == ["-", "-", "-"] and rows[("plain", "twin")][-4:-1] == ["-", "-", "-"], rows
# The last column: the share of the final map's landmarks made on dynamic objects.
assert rows[("fast", "dynamic")][-1] == "%.1f%%" % (100 * fast["map_landmarks_on_dynamic_objects"]["fraction"]), rows
assert rows[("plain", "twin")][-1] == "0.0%", rows
# Speed is compared with plain on the same sequence: both plain rows are 1.00x.
assert "1.00x" in rows[("plain", "twin")] and "1.00x" in rows[("plain", "dynamic")], rows
EOF
# Overlays of every 5th frame only (frames 0, 5, 10 of 14); the filter draws nothing on the others.
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --out "$DIR/fastov" --quiet \
  --save-overlays "$DIR/fastov/overlays" --overlay-every 5 >/dev/null 2>&1 || fail "fast run with overlays"
[[ "$(ls "$DIR/fastov/overlays" | tr '\n' ' ')" == "000000.png 000005.png 000010.png " ]] ||
  fail "--overlay-every 5 wrote: $(ls "$DIR/fastov/overlays" | tr '\n' ' ')"
/usr/bin/python3 - "$DIR/fastov/stats.json" "$DIR/fastrun/stats.json" <<'EOF' || fail "overlays changed the result"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
assert a["ate"] == b["ate"] and a["dynamic_keypoints"] == b["dynamic_keypoints"], "overlays changed the labels"
overlay = a["timing_ms"]["filter_stages"]["overlay"]
assert overlay["median"] == 0 and overlay["max"] > 0, overlay  # drawn on 3 of 14 frames only
assert overlay["frames_run"] == 3 and a["timing_ms"]["filter_stages"]["flow"]["frames_run"] >= 10, a["timing_ms"]["filter_stages"]
EOF
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --out "$DIR/fastov0" --quiet \
  --save-overlays "$DIR/fastov0/overlays" --overlay-every 0 >/dev/null 2>&1 && fail "--overlay-every 0 accepted"
# Pipelining (the default) is deterministic; --no-pipeline runs one frame at a time.
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --out "$DIR/fastrun2" --quiet >/dev/null 2>&1 ||
  fail "second fast run"
cmp -s "$DIR/fastrun/trajectory.txt" "$DIR/fastrun2/trajectory.txt" || fail "pipelined fast runs differ"
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --out "$DIR/fastnp" --quiet --no-pipeline \
  >/dev/null 2>&1 || fail "fast run --no-pipeline"
/usr/bin/python3 - "$DIR/fastrun/stats.json" "$DIR/fastnp/stats.json" <<'EOF' || fail "pipeline flag"
import json, sys
piped, single = (json.load(open(f)) for f in sys.argv[1:3])
assert piped["pipeline"] is True and single["pipeline"] is False, (piped["pipeline"], single["pipeline"])
assert piped["pipeline_depth"] == 4 and single["pipeline_depth"] == 0, (piped["pipeline_depth"], single["pipeline_depth"])
for s in (piped, single):
    t = s["timing_ms"]
    assert t["frame_latency"]["count"] == s["frames"] and t["frame_latency"]["mean"] > 0, t["frame_latency"]
# Without pipelining the caller waits for the whole frame: total = latency (to timer resolution).
t = single["timing_ms"]
assert abs(t["frame_total"]["mean"] - t["frame_latency"]["mean"]) < 0.05 * t["frame_latency"]["mean"], t
EOF
# --preload: every frame decoded before the clock starts; the same trajectory, and stats.json says so.
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --out "$DIR/fastpre" --quiet --preload \
  >/dev/null 2>&1 || fail "fast run --preload"
cmp -s "$DIR/fastrun/trajectory.txt" "$DIR/fastpre/trajectory.txt" || fail "--preload changed the trajectory"
/usr/bin/python3 - "$DIR/fastrun/stats.json" "$DIR/fastpre/stats.json" <<'EOF' || fail "preload flag in stats.json"
import json, sys
streamed, preloaded = (json.load(open(f)) for f in sys.argv[1:3])
assert streamed["preload"] is False and "preload_seconds" not in streamed, streamed.get("preload")
assert preloaded["preload"] is True and preloaded["preload_seconds"] > 0, preloaded.get("preload_seconds")
assert preloaded["frames"] == streamed["frames"] == 14
# With --preload the mask statistics are computed after the timed loop: the same numbers.
for key in ("dynamic_keypoints", "inliers_on_moving_objects", "landmarks_created_on_moving_objects"):
    assert preloaded[key] == streamed[key], key
for s in (streamed, preloaded):
    assert s["cpu_seconds"] > 0 and abs(s["cpu_ms_per_frame"] - 1000 * s["cpu_seconds"] / 14) < 1e-6, s["cpu_seconds"]
EOF
cmp -s <(cut -d, -f1-11,20- "$DIR/fastrun/frames.csv") <(cut -d, -f1-11,20- "$DIR/fastpre/frames.csv") ||
  fail "--preload changed frames.csv beyond its timing columns"
# Landmark dynamic votes (tracking.dynamic_votes_to_erase, off by default): with one vote a FAST
# run erases landmarks seen next to moving keypoints and judges each by where it was made.
printf 'tracking:\n  dynamic_votes_to_erase: 1\n' >"$DIR/votes.yaml"
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --config-overlay "$DIR/votes.yaml" --out "$DIR/fastvotes" \
  --quiet >/dev/null 2>&1 || fail "fast run with dynamic votes"
/usr/bin/python3 - "$DIR/fastrun/stats.json" "$DIR/fastvotes/stats.json" <<'EOF' || fail "landmark dynamic votes"
import json, sys
default, votes = (json.load(open(f))["landmarks_erased_as_dynamic"] for f in sys.argv[1:3])
assert default["erased"] == default["votes"] == default["made_on_dynamic_objects"] == 0, default
assert votes["votes"] >= votes["erased"] > 0, votes
assert votes["erased"] >= votes["origin_known"] >= votes["made_on_dynamic_objects"] >= 0, votes
EOF
# --config-overlay: more YAML over the config (later files win); effective_config.yaml and
# stats.json show it. A missing or bad overlay: one error line naming it, no outputs.
printf 'fast:\n  correspondences: descriptors\n' >"$DIR/bf.yaml"
printf 'fast:\n  correspondences: telepathy\n' >"$DIR/bad_overlay.yaml"
"$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --config-overlay "$DIR/bf.yaml" --out "$DIR/fastbf" \
  --quiet >/dev/null 2>&1 || fail "fast run with an overlay"
grep -qE '^ *correspondences: "?descriptors' "$DIR/fastbf/effective_config.yaml" || fail "overlay not in effective_config.yaml"
grep -qF "camera.yaml + $DIR/bf.yaml" "$DIR/fastbf/stats.json" || fail "stats.json config does not name the overlay"
grep -qE '^ *correspondences: "?flow' "$DIR/fastrun/effective_config.yaml" || fail "default run is not on flow"
grep -qE '^ *quiet_analyse_every: 2' "$DIR/fastrun/effective_config.yaml" || fail "fast mode's quiet schedule is not 2"
grep -qE '^ *residual_static_veto: true' "$DIR/fastrun/effective_config.yaml" || fail "fast mode's residual veto is not on"
for overlay in "$DIR/no_such_overlay.yaml" "$DIR/bad_overlay.yaml"; do
  err=$("$DYNORB" run --dataset "$OUT/cache/walking_xyz_s3_f14" --mode fast --config-overlay "$overlay" \
    --out "$DIR/fastbad" --quiet 2>&1 >/dev/null)
  [[ $? == 2 ]] || fail "bad overlay $overlay: exit code not 2 ($err)"
  grep -qF "$overlay" <<<"$err" || fail "bad overlay: message '$err' does not name $overlay"
  [[ ! -e "$DIR/fastbad/stats.json" ]] || fail "bad overlay: wrote stats.json"
done
# A frame whose size disagrees with the config: exit 2, one error line naming the image, no
# results; with --preload the first frame already fails, before the others are decoded (the
# copy's 4th colour image is corrupt: decoding everything first would report that instead).
SEQ14="$DIR/seq14"
cp -r "$OUT/cache/walking_xyz_s3_f14" "$SEQ14"
corrupt=$(grep -v '^#' "$SEQ14/rgb.txt" | sed -n 4p | awk '{print $2}')
head -c 100 "$OUT/cache/walking_xyz_s3_f14/$corrupt" >"$SEQ14/$corrupt"
sed 's/^Camera.width: .*/Camera.width: 320/' "$SEQ14/camera.yaml" >"$DIR/narrow.yaml"
for flag in --preload --no-pipeline; do
  err=$("$DYNORB" run --dataset "$SEQ14" --config "$DIR/narrow.yaml" --out "$DIR/narrow$flag" --quiet $flag 2>&1 >/dev/null)
  code=$?
  [[ $code == 2 ]] || fail "size mismatch $flag: exit code $code ($err)"
  grep -qF -- "image is 640x480 but $DIR/narrow.yaml says 320x480" <<<"$err" || fail "size mismatch $flag: '$err'"
  [[ $(wc -l <<<"$err") == 1 ]] || fail "size mismatch $flag: more than one line: $err"
  [[ ! -e "$DIR/narrow$flag/stats.json" && ! -e "$DIR/narrow$flag/trajectory.txt" ]] || fail "size mismatch $flag: wrote results"
done
/usr/bin/python3 - "$DIR/fastrun/frames.csv" <<'EOF' || fail "fast frames.csv: the first frame is not judged"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert rows[0]["judged"] == "0" and rows[0]["state"] == "not_initialized", rows[0]
assert rows[0]["filtered"] == rows[0]["keypoints"], rows[0]  # withheld
assert all(r["judged"] == "1" for r in rows[1:]) and rows[1]["state"] == "ok", rows[1]
stats = __import__("json").load(open(sys.argv[1].replace("frames.csv", "stats.json")))
assert stats["filter_analysed_frames"] == sum(r["analysed"] == "1" for r in rows), stats["filter_analysed_frames"]
assert rows[0]["analysed"] == "1" and rows[1]["analysed"] == "1", rows[:2]  # quiet analyses come first
EOF
/usr/bin/python3 - "$DIR/fastrun/stats.json" "$OUT/cache/walking_xyz_s3_f14" <<'EOF' || fail "keypoint label statistics"
import json, os, sys
d = json.load(open(sys.argv[1]))["dynamic_keypoints"]
now, cues = d["moving_now"], d["by_cue"]
total = lambda s: s["true_positive"] + s["false_positive"] + s["false_negative"] + s["true_negative"]
assert total(now) + now["ignored"] == total(d), (now, d)
assert now["true_positive"] + now["false_negative"] <= d["true_positive"] + d["false_negative"]
assert {"epipolar", "direction", "magnitude", "residual", "depth", "seed", "track", "region"} <= set(cues), cues
assert cues["seed"]["flagged"] <= now["true_positive"] + now["false_positive"], (cues["seed"], now)
for stats in (d, now):
    assert 0 <= stats["false_positive_within_3px"] <= stats["false_positive"], stats
    assert stats["precision_within_3px"] >= stats["precision"], stats
    # The scale-aware support truth is a superset of the pixel truth: as many removals or more are right.
    sup = stats["support"]
    assert sup["true_positive"] + sup["false_positive"] == stats["true_positive"] + stats["false_positive"], sup
    assert sup["true_positive"] >= stats["true_positive"] and sup["precision"] >= stats["precision"], sup
# Keypoints are ignored only when some object stands still (objects.txt moving = 0).
still = [l for l in open(os.path.join(sys.argv[2], "objects.txt")) if not l.startswith("#") and l.split()[2] == "0"]
assert still or now["ignored"] == 0, now
EOF
# The view-loss reference: the twin's images with the dynamic sequence's masks, mode semantic;
# the same trajectory as the recipe of docs/benchmark.md run by hand.
# The sequence's own config (here 800 features) is the base of the reference's config too.
sed 's/^ORBextractor.nFeatures: .*/ORBextractor.nFeatures: 800/' "$OUT/cache/walking_xyz_s3_f14/camera.yaml" >"$DIR/vl_camera.yaml"
cat >"$DIR/vl.yaml" <<'EOF2'
sequences:
  - {name: syn, config: vl_camera.yaml, synthetic: {preset: walking_xyz, seed: 3, frames: 14, static_twin: true, view_loss: true}}
modes: [plain]
EOF2
VL="$DIR/vl"
"$DYNORB" bench --suite "$DIR/vl.yaml" --out "$VL" --people procedural --quiet >"$DIR/vl.txt" 2>&1 ||
  fail "view-loss suite: $(cat "$DIR/vl.txt")"
grep -qF "runs: 3 (0 resumed, 0 failed)" "$DIR/vl.txt" || fail "view-loss summary: $(cat "$DIR/vl.txt")"
# The default front_end_threads (auto): two with a filter, one in plain mode, and the report says so.
grep -qF "pipeline on (depth 4), 2 front-end threads with a filter (1 in plain)," "$VL/report.md" ||
  fail "the view-loss report does not say how many front-end threads the runs used"
grep -qF '"front_end_threads": 2' "$VL/runs/syn_viewloss/view_loss/seed1/stats.json" ||
  fail "the view-loss (semantic) run did not use 2 front-end threads"
grep -qF '"front_end_threads": 1' "$VL/runs/syn/plain/seed1/stats.json" ||
  fail "the plain run did not use 1 front-end thread"
grep -q "^ORBextractor.nFeatures: 800" "$VL/cache/walking_xyz_s3_f14_viewloss.yaml" ||
  fail "the view-loss config does not start from the sequence's config"
cp "$DIR/vl_camera.yaml" "$DIR/vl_by_hand.yaml"
printf 'semantic:\n  source: masks\n  list: %s\n' "$VL/cache/walking_xyz_s3_f14/masks.txt" >>"$DIR/vl_by_hand.yaml"
"$DYNORB" run --dataset "$VL/cache/walking_xyz_s3_f14_twin" --mode semantic --config "$DIR/vl_by_hand.yaml" \
  --out "$DIR/vl_by_hand" --quiet >/dev/null 2>&1 || fail "view-loss run by hand"
cmp -s "$DIR/vl_by_hand/trajectory.txt" "$VL/runs/syn_viewloss/view_loss/seed1/trajectory.txt" ||
  fail "the bench's view-loss run differs from the recipe"
/usr/bin/python3 - "$VL/results.json" <<'EOF2' || fail "view-loss results.json"
import json, sys
r = json.load(open(sys.argv[1]))
runs = {(x["sequence"], x["mode"]): x for x in r["runs"]}
assert set(runs) == {("syn", "plain"), ("syn_twin", "plain"), ("syn_viewloss", "view_loss")}, set(runs)
ref = runs[("syn_viewloss", "view_loss")]["stats"]
assert ref["mode"] == "semantic" and ref["filtered_keypoints_per_frame"]["max"] > 0, ref["filtered_keypoints_per_frame"]
assert {"label": "view_loss", "name": "semantic", "config": "", "view_loss": True} in r["suite"]["modes"]
assert [s["view_loss_of"] for s in r["suite"]["sequences"]] == ["", "", "syn"], r["suite"]["sequences"]
# The masks are read on every frame (the people are in view on all 14): sessions 52-53 read them
# only on frames 0, 1 and 8 (--mode semantic's quiet schedule took the mask file for empty).
import csv, os
frames = os.path.join(os.path.dirname(sys.argv[1]), "runs/syn_viewloss/view_loss/seed1/frames.csv")
filtered = [int(row["filtered"]) for row in csv.DictReader(open(frames))]
assert len(filtered) == 14 and min(filtered) > 0, filtered
EOF2
/usr/bin/python3 - "$VL/results.json" "$VL/report.md" <<'EOF2' || fail "view-loss report.md"
import json, sys
r = json.load(open(sys.argv[1]))
ate = {(x["sequence"], x["mode"]): x["stats"]["ate"]["rmse_m"] for x in r["runs"]}
row = "| syn | %.2f | %.2f |" % (ate[("syn", "plain")] / ate[("syn_twin", "plain")],
                                ate[("syn_viewloss", "view_loss")] / ate[("syn_twin", "plain")])
md = open(sys.argv[2]).read()
robust = md.split("## Robustness ratio")[1].split("\n## ")[0]
assert "| sequence | plain | view_loss |" in robust and row in robust, (row, robust)
assert "| syn_viewloss | view_loss |" in md and "| syn_viewloss | plain |" not in md
assert "| syn | view_loss |" not in md
EOF2
check_error view_loss_without_plain "view_loss_without_plain.yaml:2: sequence 'syn': 'view_loss' needs the mode 'plain'" \
  'sequences:
  - {name: syn, synthetic: {preset: walking_xyz, frames: 10, view_loss: true}}
modes: [fast]
'
check_error view_loss_label "view_loss_label.yaml:5: mode label 'view_loss' is reserved" \
  'sequences:
  - {name: syn, synthetic: {preset: walking_xyz, frames: 10, view_loss: true}}
modes:
  - plain
  - {name: fast, label: view_loss}
'
# A cached sequence from another generator version is generated again, not reused.
sed -i 's/^synth_version: .*/synth_version: 0/' "$OUT/cache/walking_xyz_s3_f14/scene.yaml"
run_bench >"$DIR/run1v.txt" 2>&1 || fail "run 1v: $(cat "$DIR/run1v.txt")"
grep -q '^synth_version: 0' "$OUT/cache/walking_xyz_s3_f14/scene.yaml" && fail "a stale cached sequence was reused"
grep -q '^synth_version: [1-9]' "$OUT/cache/walking_xyz_s3_f14/scene.yaml" || fail "the regenerated scene.yaml has no version"
# A result written by another build is run again, not resumed.
/usr/bin/python3 - "$OUT/runs/syn_twin/plain/seed1/stats.json" <<'EOF' || fail "rewrite build_id"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["build_id"].startswith("fnv1a64:"), s["build_id"]
s["build_id"] = "fnv1a64:0000000000000000"
json.dump(s, open(sys.argv[1], "w"))
EOF
# Its pictures are drawn again (stamped old here); the resumed run's are left alone.
touch -d @1000000000 "$OUT"/plots/syn__plain* "$OUT"/plots/syn_twin__plain*
run_bench >"$DIR/run1b.txt" 2>&1 || fail "run 1b: $(cat "$DIR/run1b.txt")"
grep -qF "runs: 2 (1 resumed, 0 failed)" "$DIR/run1b.txt" || fail "older build resumed: $(cat "$DIR/run1b.txt")"
for f in syn_twin__plain.png syn_twin__plain.svg syn_twin__plain_map.png syn_twin__plain_keypoints.png; do
  [[ -s "$OUT/plots/$f" && $(stat -c %Y "$OUT/plots/$f") -gt 1000000000 ]] || fail "redone run: $f not drawn again"
done
for f in syn__plain.png syn__plain_map.png syn__plain_keypoints.png; do
  [[ $(stat -c %Y "$OUT/plots/$f") == 1000000000 ]] || fail "resumed run: $f drawn again"
done
! grep -qF 'fnv1a64:0000000000000000' "$OUT/runs/syn_twin/plain/seed1/stats.json" ||
  fail "the older build's stats.json was kept"
# An unreadable stats.json is run again too (no abort).
printf '{"build_id": 7, truncated' >"$OUT/runs/syn_twin/plain/seed1/stats.json"
run_bench >"$DIR/run1c.txt" 2>&1 || fail "run 1c: $(cat "$DIR/run1c.txt")"
grep -qF "runs: 2 (1 resumed, 0 failed)" "$DIR/run1c.txt" || fail "corrupt stats.json: $(cat "$DIR/run1c.txt")"
# Redone with --no-plots: its old pictures are gone (not shown beside the new results); the
# resumed run's stay.
printf 'broken' >"$OUT/runs/syn_twin/plain/seed1/stats.json"
run_bench --no-plots >"$DIR/run1d.txt" 2>&1 || fail "run 1d: $(cat "$DIR/run1d.txt")"
ls "$OUT"/plots/syn_twin__plain* >/dev/null 2>&1 && fail "a run redone with --no-plots kept its old pictures"
[[ -s "$OUT/plots/syn__plain_map.png" ]] || fail "--no-plots removed a resumed run's picture"
stamp=$(stat -c %Y.%s "$OUT/runs/syn/plain/seed1/stats.json")
sleep 1
run_bench --repeats 2 >"$DIR/run2.txt" 2>&1 || fail "run 2: $(cat "$DIR/run2.txt")"
grep -qF "runs: 4 (2 resumed, 0 failed)" "$DIR/run2.txt" || fail "run 2 summary: $(cat "$DIR/run2.txt")"
[[ $(stat -c %Y.%s "$OUT/runs/syn/plain/seed1/stats.json") == "$stamp" ]] || fail "seed 1 was run again"
# A run whose stats.json is missing (interrupted after its trajectory was written) is redone.
rm "$OUT/runs/syn_twin/plain/seed2/stats.json"
run_bench --repeats 2 >"$DIR/run3.txt" 2>&1 || fail "run 3"
grep -qF "runs: 4 (3 resumed, 0 failed)" "$DIR/run3.txt" || fail "run 3 summary: $(cat "$DIR/run3.txt")"
# A run whose map.ply is missing while the suite asks for maps is redone.
rm "$OUT/runs/syn/plain/seed2/map.ply"
run_bench --repeats 2 >"$DIR/run3m.txt" 2>&1 || fail "run 3m"
grep -qF "runs: 4 (3 resumed, 0 failed)" "$DIR/run3m.txt" || fail "run 3m summary: $(cat "$DIR/run3m.txt")"
[[ -s "$OUT/runs/syn/plain/seed2/map.ply" ]] || fail "the lost map.ply was not written again"
# A real interruption: SIGTERM while the seed-3 run of the first sequence is under way.
run_bench --repeats 3 >/dev/null 2>&1 &
pid=$!
for _ in $(seq 1 300); do
  [[ -d "$OUT/runs/syn/plain/seed3" ]] && break
  sleep 0.05
done
kill -TERM "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
ls -a "$OUT" "$OUT/runs/syn/plain/seed3" 2>/dev/null | grep -q '\.tmp-' && fail "interrupted run left a temporary file"
/usr/bin/python3 -c "import json,sys; json.load(open(sys.argv[1]))" "$OUT/results.json" || fail "results.json broken by the interruption"
run_bench --repeats 3 >"$DIR/run4.txt" 2>&1 || fail "run 4: $(cat "$DIR/run4.txt")"
grep -qE "runs: 6 \((4|5|6) resumed, 0 failed\)" "$DIR/run4.txt" || fail "run 4 summary: $(cat "$DIR/run4.txt")"
for s in 1 2 3; do
  [[ -s "$OUT/runs/syn/plain/seed$s/stats.json" && -s "$OUT/runs/syn_twin/plain/seed$s/stats.json" ]] || fail "seed $s missing"
done
# Session 55: a run is resumed only when it was made from the same request (here the suite's
# pipeline setting changed), and a cached sequence only when it shows the same people.
sed -i 's/^front_end_threads: 2$/front_end_threads: 2\npipeline: false/' "$DIR/tiny.yaml"
run_bench --repeats 1 >"$DIR/run5.txt" 2>&1 || fail "run 5: $(cat "$DIR/run5.txt")"
grep -qF "runs: 2 (0 resumed, 0 failed)" "$DIR/run5.txt" || fail "another request resumed: $(cat "$DIR/run5.txt")"
grep -q '"pipeline": false' "$OUT/runs/syn/plain/seed1/bench_request.json" || fail "bench_request.json"
# The same request spelled otherwise (the output folder with a trailing "/.", from another
# working directory) is the same request.
(cd "$DIR" && "$DYNORB" bench --suite tiny.yaml --out "$OUT/." --people procedural --quiet --repeats 1 >"$DIR/run5b.txt" 2>&1) ||
  fail "run 5b: $(cat "$DIR/run5b.txt")"
grep -qF "runs: 2 (2 resumed, 0 failed)" "$DIR/run5b.txt" || fail "another spelling of --out was not resumed: $(cat "$DIR/run5b.txt")"
PEOPLE="$SRC/../shared/data/people"
if [[ -d "$PEOPLE" ]]; then
  BENCH_PEOPLE=$PEOPLE run_bench --repeats 1 >"$DIR/run6.txt" 2>&1 || fail "run 6: $(cat "$DIR/run6.txt")"
  grep -qF "runs: 2 (0 resumed, 0 failed)" "$DIR/run6.txt" || fail "other people resumed: $(cat "$DIR/run6.txt")"
  grep -qF "people_dir: '$PEOPLE'" "$OUT/cache/walking_xyz_s3_f14/scene.yaml" ||
    fail "the cached sequence with procedural people was reused for --people $PEOPLE"
fi
# Refused before anything is written: a missing people folder, an overlay with an unknown key,
# a seed listed twice.
expect_bench_error() {
  local expected=$1 out=$2
  shift 2
  local err
  err=$("$DYNORB" bench --out "$out" --quiet "$@" 2>&1 >/dev/null) && fail "$*: exit code 0"
  grep -qF -- "$expected" <<<"$err" || fail "$*: message '$err', expected '$expected'"
  [[ ! -e "$out" ]] || fail "$*: wrote $out"
}
expect_bench_error "people directory not found: /nonexistent/people" "$DIR/bp" --suite "$DIR/tiny.yaml" --people /nonexistent/people
printf 'fast:\n  no_such_key: 3\n' >"$DIR/bad_overlay.yaml"
sed 's|^  - plain$|  - {name: fast, overlay: bad_overlay.yaml}|' "$DIR/tiny.yaml" >"$DIR/bad_overlay_suite.yaml"
expect_bench_error "no_such_key" "$DIR/bo" --suite "$DIR/bad_overlay_suite.yaml" --people procedural
# Every shipped suite plans (overlays holding a few keys over the sequence's camera config).
# (The real TUM sequences are not here: all skipped is that suite's only allowed complaint.)
for suite in "$SRC"/bench/suites/*.yaml; do
  err=$("$DYNORB" bench --suite "$suite" --out "$DIR/list" --list --skip-missing 2>&1 >/dev/null) ||
    grep -qF "no sequence to run (all skipped)" <<<"$err" || fail "shipped suite $(basename "$suite") refused: $err"
done
sed 's/^repeats: 1$/seeds: [4, 4]/' "$DIR/tiny.yaml" >"$DIR/dup_seeds.yaml"
expect_bench_error "seed 4 is listed twice" "$DIR/ds" --suite "$DIR/dup_seeds.yaml" --people procedural

if [[ -n "$ARTIFACTS" ]]; then
  rm -rf "$ARTIFACTS" && mkdir -p "$ARTIFACTS" && cp -r "$OUT/report.html" "$OUT/report.md" "$OUT/results.json" "$OUT/plots" "$ARTIFACTS/"
fi

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "bench CLI: all checks passed"
