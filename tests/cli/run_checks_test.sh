#!/usr/bin/env bash
# `dynorb run` on input that reads but cannot be right (CTest: dynorb_cli_run_checks): the run
# finishes, and its summary and stats.json carry a warning that says what to check; a good run
# has none. And which calibration a folder without camera.yaml gets.
# Usage: run_checks_test.sh path/to/dynorb
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"

"$DYNORB" synth --preset walking_xyz --frames 40 --people procedural --static-twin --out "$DIR/seq" >/dev/null 2>&1 ||
  { echo "FAIL: synth"; exit 1; }
SEQ="$DIR/seq"

# count_warnings stats.json -> number of entries of its "warnings" list
count_warnings() { /usr/bin/python3 -c 'import json, sys; print(len(json.load(open(sys.argv[1]))["warnings"]))' "$1"; }

# A good run: no warning.
out=$("$DYNORB" run --dataset "$SEQ" --out "$DIR/good" --quiet 2>&1) || fail "good run: exit code $?"
grep -q '^warning' <<<"$out" && fail "good run printed a warning: $out"
grep -q '"warnings": \[\]' "$DIR/good/stats.json" || fail "good run: stats.json has no empty \"warnings\" list"

# A run shorter than the 1 s RPE step has no RPE, and that is no reason for a warning.
out=$("$DYNORB" run --dataset "$SEQ" --out "$DIR/short" --frames 0:10 --quiet 2>&1) || fail "short run: exit code $?"
grep -q '^warning' <<<"$out" && fail "short run printed a warning: $out"

# The same sequence with DepthMapFactor 1 (raw 1/5000 m units read as metres).
sed 's/^DepthMapFactor:.*/DepthMapFactor: 1.0/' "$SEQ/camera.yaml" >"$DIR/factor1.yaml"
out=$("$DYNORB" run --dataset "$SEQ" --config "$DIR/factor1.yaml" --out "$DIR/factor1" --quiet 2>&1) ||
  fail "DepthMapFactor 1: exit code $?"
grep -q '^warning  .*m away (median over the first 30 frames).*check DepthMapFactor.*now 1)' <<<"$out" ||
  fail "DepthMapFactor 1: no depth-scale warning in the summary: $out"
[[ $(count_warnings "$DIR/factor1/stats.json") == 1 ]] || fail "DepthMapFactor 1: stats.json should list 1 warning"

# Ground truth on another clock: the run keeps its outputs, without ATE, and says why.
SHIFTED="$DIR/shifted"
cp -r "$SEQ" "$SHIFTED"
awk '/^#/ {print; next} {$1 = sprintf("%.6f", $1 + 1000); print}' "$SEQ/groundtruth.txt" >"$SHIFTED/groundtruth.txt"
out=$("$DYNORB" run --dataset "$SHIFTED" --out "$DIR/shifted_out" --quiet 2>&1) || fail "shifted ground truth: exit code $?"
grep -q "^warning  .*no ATE/RPE: groundtruth.txt has no pose within the run's frames" <<<"$out" ||
  fail "shifted ground truth: no warning in the summary: $out"
[[ -s "$DIR/shifted_out/trajectory.txt" ]] || fail "shifted ground truth: no trajectory.txt"
grep -q '"ate"' "$DIR/shifted_out/stats.json" && fail "shifted ground truth: stats.json has an ATE"

# A folder without camera.yaml named like a TUM sequence runs with that camera's built-in
# calibration (and says so); any other such folder is an error naming the rule.
TUM="$DIR/rgbd_dataset_freiburg3_copy"
cp -r "$SEQ" "$TUM" && rm "$TUM/camera.yaml"
err=$("$DYNORB" run --dataset "$TUM" --out "$DIR/tum" --quiet 2>&1 >/dev/null) || fail "TUM-named folder: exit code $?"
grep -qF "has no camera.yaml: using the TUM RGB-D freiburg3 calibration (config/tum_fr3.yaml" <<<"$err" ||
  fail "TUM-named folder: no note on stderr: $err"
grep -qF '"config": "built-in config/tum_fr3.yaml"' "$DIR/tum/stats.json" || fail "TUM-named folder: stats.json config"
grep -q '^Camera.fx: 535.4 ' "$DIR/tum/effective_config.yaml" || fail "TUM-named folder: not the freiburg3 fx"
OTHER="$DIR/other_sequence"
cp -r "$TUM" "$OTHER"
err=$("$DYNORB" run --dataset "$OTHER" --out "$DIR/other" --quiet 2>&1 >/dev/null)
code=$?
[[ $code == 2 ]] || fail "folder without camera.yaml: exit code $code"
grep -qF "has no camera.yaml (use e.g. --config config/tum_fr3.yaml; a folder named like a TUM sequence" <<<"$err" ||
  fail "folder without camera.yaml: message '$err'"
[[ ! -e "$DIR/other" ]] || fail "folder without camera.yaml: wrote output"

# --save-map: OUT/map.ply holds every landmark of the final map (stats.json "landmarks"), coloured
# from the images, with the ground-truth flag whose count stats.json reports; without the flag
# there is no map.ply.
[[ -e "$DIR/good/map.ply" ]] && fail "map.ply written without --save-map"
out=$("$DYNORB" run --dataset "$SEQ" --out "$DIR/map" --save-map --quiet 2>&1) || fail "--save-map: exit code $?"
grep -q 'map.ply}' <<<"$out" || fail "--save-map: the outputs line does not list map.ply: $out"
made=$(/usr/bin/python3 -c 'import json, sys; m = json.load(open(sys.argv[1]))["map_landmarks_on_dynamic_objects"]
print("%.1f %% of the landmarks made on dynamic objects (%d of %d)" % (100 * m["fraction"], m["made_on_dynamic_objects"], m["origin_known"]))' "$DIR/map/stats.json")
grep -qF "map vs masks      $made" <<<"$out" || fail "--save-map: no 'map vs masks' line '$made' in: $out"
/usr/bin/python3 - "$DIR/map" <<'PYEOF2' || fail "--save-map: map.ply does not match stats.json"
import json, struct, sys
d = sys.argv[1]
stats = json.load(open(d + "/stats.json"))
data = open(d + "/map.ply", "rb").read()
end = data.index(b"end_header\n") + len(b"end_header\n")
header = data[:end].decode().splitlines()
n = int([l for l in header if l.startswith("element vertex")][0].split()[2])
props = [l.split()[2] for l in header if l.startswith("property")]
assert props == ["x", "y", "z", "red", "green", "blue", "dynamic_object_id"], props
assert n == stats["landmarks"] == stats["map_landmarks_on_dynamic_objects"]["landmarks"] > 100, (n, stats["landmarks"])
stride = 16
assert len(data) - end == n * stride
rows = [data[end + i * stride:end + (i + 1) * stride] for i in range(n)]
m = stats["map_landmarks_on_dynamic_objects"]
ids = [r[15] for r in rows]
assert sum(i > 0 for i in ids) == m["made_on_dynamic_objects"], ids
assert {str(i): ids.count(i) for i in set(ids) if i} == m["by_object"], (m["by_object"], ids)
assert len({r[12:15] for r in rows}) > 20, "colours look constant"
zs = [struct.unpack("<f", r[8:12])[0] for r in rows]
assert all(abs(z) < 50 for z in zs)
PYEOF2
# A later run into the same folder without --save-map leaves no stale map.ply.
"$DYNORB" run --dataset "$SEQ" --out "$DIR/map" --frames 0:20 --quiet >/dev/null 2>&1 || fail "rerun without --save-map"
[[ -e "$DIR/map/map.ply" ]] && fail "a stale map.ply was left next to a run without --save-map"

# FAST mode's analysis schedule: every second frame analysed, the key in effect; bad values are
# one message, exit 2, no output.
cp "$SEQ/camera.yaml" "$DIR/every2.yaml"
printf 'fast:\n  analyse_every: 2\n' >>"$DIR/every2.yaml"
"$DYNORB" run --dataset "$SEQ" --mode fast --config "$DIR/every2.yaml" --out "$DIR/every2" --quiet >/dev/null 2>&1 ||
  fail "fast with analyse_every 2: exit code $?"
grep -q "analyse_every: 2" "$DIR/every2/effective_config.yaml" || fail "effective_config.yaml lacks fast.analyse_every"
for bad in 'analyse_every: 0|analyse_every must be in \[1, 8\]' \
           'analyse_every: 2\n  correspondences: descriptors|analyse_every > 1 needs correspondences: flow' \
           'analyse_every: 2\n  suspect_frames: 0|analyse_every > 1 needs use_region and suspect_frames > 0'; do
  cp "$SEQ/camera.yaml" "$DIR/bad_fast.yaml"
  printf "fast:\n  ${bad%%|*}\n" >>"$DIR/bad_fast.yaml"
  err=$("$DYNORB" run --dataset "$SEQ" --mode fast --config "$DIR/bad_fast.yaml" --out "$DIR/bad_fast" --quiet 2>&1 >/dev/null)
  code=$?
  [[ $code == 2 ]] || fail "fast ${bad%%|*}: exit code $code ($err)"
  grep -q -- "${bad#*|}" <<<"$err" || fail "fast ${bad%%|*}: message '$err'"
  [[ ! -e "$DIR/bad_fast" ]] || fail "fast ${bad%%|*}: wrote output"
done

finish "run checks"
