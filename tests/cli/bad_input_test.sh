#!/usr/bin/env bash
# Bad input found by the session-54 review (CTest: dynorb_cli_bad_input): each case exits
# non-zero with one message naming what is wrong, and leaves no output behind; a UTF-8 byte order
# mark in a sequence's lists is read.
# Usage: bad_input_test.sh path/to/dynorb
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"

# Sizes that used to exhaust memory or write unreadable files.
expect_error "dynorb: error: --frames must be 0..1000000, got 2000000" synth --frames 2000000 --out "$DIR/s1"
[[ ! -e "$DIR/s1" ]] || fail "synth --frames 2000000 wrote $DIR/s1"
expect_error "dynorb: error: --scale must be <= 1000, got 1e+300" trajgen --scale 1e300 --out "$DIR/t1"
expect_error "fewer than 2 poses" trajgen --drop-fraction 0.999999 --out "$DIR/t2"
[[ ! -e "$DIR/t1" && ! -e "$DIR/t2" ]] || fail "a failed trajgen left its output folder"
expect_error "--seed: expects an integer below 2^64, got '99999999999999999999'" \
  trajgen --seed 99999999999999999999 --out "$DIR/t3"
expect_error "--seed: expects a non-negative integer, got '-1'" vocab --seed -1 --out "$DIR/v.yml"

# An output that is a directory: refused before any output is written.
mkdir -p "$DIR/t4/estimate.txt"
expect_error "cannot write $DIR/t4/estimate.txt: it exists and is not a file" trajgen --out "$DIR/t4"
[[ ! -e "$DIR/t4/groundtruth.txt" ]] || fail "trajgen wrote groundtruth.txt next to a directory estimate.txt"
"$DYNORB" trajgen --out "$DIR/pair" >/dev/null || fail "trajgen"
mkdir -p "$DIR/plot.png"
expect_error "cannot write $DIR/plot.png: it exists and is not a file" \
  eval --gt "$DIR/pair/groundtruth.txt" --est "$DIR/pair/estimate.txt" --json "$DIR/e.json" --plot "$DIR/plot.png"
[[ ! -e "$DIR/e.json" ]] || fail "eval wrote its JSON although the plot could not be written"

"$DYNORB" synth --preset walking_xyz --frames 12 --people procedural --out "$DIR/seq" >/dev/null 2>&1 ||
  { echo "FAIL: synth"; exit 1; }
mkdir -p "$DIR/run/stats.json"
expect_error "cannot write $DIR/run/stats.json: it exists and is not a file" run --dataset "$DIR/seq" --out "$DIR/run" --quiet
[[ ! -e "$DIR/run/trajectory.txt" ]] || fail "run wrote trajectory.txt although stats.json could not be written"

# A run that fails before writing (models, vocabulary) leaves no output folder (session 55).
mkdir -p "$DIR/no_models"
expect_error "no_models" run --dataset "$DIR/seq" --mode semantic --models "$DIR/no_models" --out "$DIR/deep/r1" --quiet
[[ ! -e "$DIR/deep" ]] || fail "a run whose models failed to load left $DIR/deep"
printf 'place_recognition:\n  vocabulary: %s\n' "$DIR/missing_vocabulary.yml" >"$DIR/vocab_overlay.yaml"
expect_error "missing_vocabulary.yml" run --dataset "$DIR/seq" --config-overlay "$DIR/vocab_overlay.yaml" \
  --out "$DIR/r2" --save-overlays "$DIR/r2_overlays" --quiet
[[ ! -e "$DIR/r2" && ! -e "$DIR/r2_overlays" ]] || fail "a run whose vocabulary failed to load left its folders"

# Lists that start with a byte order mark read as without it.
cp -r "$DIR/seq" "$DIR/bom"
for list in rgb.txt depth.txt groundtruth.txt; do
  { printf '\xef\xbb\xbf'; cat "$DIR/seq/$list"; } >"$DIR/bom/$list"
done
"$DYNORB" run --dataset "$DIR/bom" --out "$DIR/bom_out" --quiet >/dev/null 2>&1 || fail "run on lists with a byte order mark"
cmp -s "$DIR/bom_out/trajectory.txt" <("$DYNORB" run --dataset "$DIR/seq" --out "$DIR/plain_out" --quiet >/dev/null 2>&1 &&
  cat "$DIR/plain_out/trajectory.txt") || fail "a byte order mark changed the trajectory"

# results.json and published numbers of the wrong shape: named, no raw library message.
mkdir -p "$DIR/rep"
echo '{"format": "dynorb-bench-results/1", "suite": {"sequences": [], "modes": []}, "runs": []}' >"$DIR/rep/results.json"
expect_error "rep/results.json: expected 'seeds' (an array)" bench --report "$DIR/rep"
echo '{"systems": [5]}' >"$DIR/pub.json"
SUITES="$(dirname "${BASH_SOURCE[0]}")/../../bench/suites"
expect_error "pub.json: every entry of 'systems' must be an object" \
  bench --suite "$SUITES/quick.yaml" --out "$DIR/bq" --list --published "$DIR/pub.json"
[[ ! -e "$DIR/bq" ]] || fail "bench wrote $DIR/bq with a bad --published file"

finish "bad input checks"
