#!/usr/bin/env bash
# `dynorb eval` on input found by the session-55 review (CTest: dynorb_cli_eval_bad_input): an
# output naming an input is refused before anything is written; a pipe is read as a file; a
# directory, a degenerate sim3 alignment and an RPE delta below the frame interval get one clear
# message; a non-UTF-8 path works with --json; one ground-truth pose plots without NaN.
# Usage: eval_bad_input_test.sh path/to/dynorb
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"

"$DYNORB" trajgen --out "$DIR" --seed 5 --duration-s 8 >/dev/null || fail "trajgen"
G="$DIR/groundtruth.txt"
E="$DIR/estimate.txt"
cp "$G" "$DIR/gt_copy.txt"
cp "$E" "$DIR/est_copy.txt"

# An output that names an input: the same string, another spelling, a link to it.
expect_clean_error "--json $G names the same file as --gt" eval --gt "$G" --est "$E" --json "$G"
expect_clean_error "names the same file as --est" eval --gt "$G" --est "$E" --json "$DIR/../$(basename "$DIR")/estimate.txt"
ln -s "$E" "$DIR/link.svg"
expect_clean_error "--plot $DIR/link.svg names the same file as --est" eval --gt "$G" --est "$E" --plot "$DIR/link.svg"
(cd "$DIR" && "$DYNORB" eval --gt groundtruth.txt --est estimate.txt --json ./groundtruth.txt >/dev/null 2>&1) &&
  fail "--json ./groundtruth.txt next to --gt groundtruth.txt accepted"
cmp -s "$G" "$DIR/gt_copy.txt" && cmp -s "$E" "$DIR/est_copy.txt" || fail "eval overwrote an input"
cp "$DIR/gt_copy.txt" "$G" && cp "$DIR/est_copy.txt" "$E"  # intact inputs for the checks below
ls -a "$DIR" | grep -q '\.tmp-' && fail "a refused eval left a temporary file"

# A pipe reads like a file; a directory and a missing file have their own messages.
"$DYNORB" eval --gt <(cat "$G") --est <(cat "$E") >/dev/null 2>&1 || fail "--gt/--est through a pipe"
mkdir -p "$DIR/folder"
expect_clean_error "$DIR/folder is a directory, not a file" eval --gt "$G" --est "$DIR/folder"
expect_clean_error "file not found: $DIR/missing.txt" eval --gt "$G" --est "$DIR/missing.txt"

# Numbers: decimal notation only; an underflow is a tiny value.
awk 'NR == 3 {$2 = "0x10"} {print}' "$E" >"$DIR/hex.txt"
expect_clean_error "hex.txt:3: not a number: '0x10'" eval --gt "$G" --est "$DIR/hex.txt"
awk '!/^#/ && !done {$2 = "1e-320"; done = 1} {print}' "$E" >"$DIR/tiny.txt"
"$DYNORB" eval --gt "$G" --est "$DIR/tiny.txt" >/dev/null 2>&1 || fail "1e-320 rejected"

# sim3 against a ground truth that does not move: no scale to find.
awk '!/^#/ {$2 = 1; $3 = 2; $4 = 3} {print}' "$G" >"$DIR/still.txt"
expect_clean_error "the ground-truth positions have no spread, or do not correlate with the estimate: no sim3 alignment" \
  eval --gt "$DIR/still.txt" --est "$E" --align sim3

# An RPE delta shorter than the frame interval (30 Hz): every pose would pair with itself. No
# RPE then, with the reason, and the ATE all the same.
out=$("$DYNORB" eval --gt "$G" --est "$E" --rpe-delta 0.005 2>&1) || fail "eval --rpe-delta 0.005: exit code $?"
grep -qF "RPE delta 0.005 s is shorter than the estimate's frame interval" <<<"$out" ||
  fail "eval --rpe-delta 0.005: no reason given: $out"
grep -q "ATE" <<<"$out" || fail "eval --rpe-delta 0.005: no ATE: $out"

# A file path that is not UTF-8 (Latin-1 e-acute) in the JSON.
LATIN1="$DIR/caf$(printf '\xe9').txt"
cp "$G" "$LATIN1"
"$DYNORB" eval --gt "$LATIN1" --est "$E" --json "$DIR/latin1.json" >/dev/null 2>&1 || fail "--json with a non-UTF-8 path"
/usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert j['inputs']['groundtruth'].endswith('caf\ufffd.txt')" \
  "$DIR/latin1.json" || fail "non-UTF-8 path in the JSON"

# One ground-truth pose (--align none): the figure has no NaN coordinate.
grep -v '^#' "$G" | sed -n 1p >"$DIR/one_gt.txt"
grep -v '^#' "$E" | sed -n 1p >"$DIR/one_est.txt"
"$DYNORB" eval --gt "$DIR/one_gt.txt" --est "$DIR/one_est.txt" --align none --max-diff 0.1 --plot "$DIR/one.svg" >/dev/null 2>&1 ||
  fail "eval with one ground-truth pose"
grep -qiE '(^|[^a-z])-?(nan|inf)([^a-z]|$)' "$DIR/one.svg" && fail "NaN in the one-pose figure"

finish "eval bad input checks"
