#!/usr/bin/env bash
# End-to-end check of `dynorb trajgen` / `dynorb eval` (registered with CTest as dynorb_eval_cli):
# a good run writes table, JSON and plots; every kind of bad input exits with code 2, prints one
# "dynorb: error:" line and leaves no output file behind.
set -uo pipefail
DYNORB=${1:?usage: cli_test.sh path/to/dynorb}
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$DYNORB" trajgen --out "$DIR" --seed 3 --duration-s 10 >/dev/null || fail "trajgen"
G="$DIR/groundtruth.txt"
E="$DIR/estimate.txt"

out=$("$DYNORB" eval --gt "$G" --est "$E" --json "$DIR/r.json" --plot "$DIR/r.png") || fail "good run exit code"
for needle in "ATE [m]" "RPE trans [m/s]" "RPE rot [deg/s]" "coverage" "evaluate_rpe.py"; do
  grep -qF -- "$needle" <<<"$out" || fail "table lacks '$needle'"
done
/usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert j['ate_m']['count'] > 250" "$DIR/r.json" \
  || fail "json"
[[ $(head -c 4 "$DIR/r.png" | tail -c 3) == PNG ]] || fail "png signature"
"$DYNORB" eval --gt "$G" --est "$E" --plot "$DIR/r.svg" >/dev/null && grep -q "<svg" "$DIR/r.svg" || fail "svg"
"$DYNORB" eval --help | grep -q -- "--rpe-delta" || fail "--help"

# Bad inputs: exit 2, one error line, no output files.
printf '1.0 0 0 0 0 0 0 1\n2.0 0 0 x 0 0 0 1\n' >"$DIR/malformed.txt"
printf '1.0 0 0 0 0 0 0 1\n2.0 0 0 nan 0 0 0 1\n' >"$DIR/nan.txt"
printf '2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n' >"$DIR/nonmono.txt"
printf '1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n3.0 1 0 0 0 0 0 1\n' >"$DIR/nooverlap.txt"
sed -n '2,3p' "$E" >"$DIR/two.txt"
check_error() {
  local name=$1 expected=$2
  shift 2
  rm -f "$DIR/bad.json" "$DIR/bad.png"
  local err
  err=$("$DYNORB" eval "$@" --json "$DIR/bad.json" --plot "$DIR/bad.png" 2>&1 >/dev/null)
  local code=$?
  [[ $code == 2 ]] || fail "$name: exit code $code"
  grep -qF -- "$expected" <<<"$err" || fail "$name: message '$err' lacks '$expected'"
  [[ $(wc -l <<<"$err") == 1 ]] || fail "$name: more than one line: $err"
  [[ ! -e "$DIR/bad.json" && ! -e "$DIR/bad.png" ]] || fail "$name: left an output file"
  ls -a "$DIR" | grep -q '\.tmp-' && fail "$name: left a temporary file"
}
check_error missing "file not found" --gt "$DIR/missing.txt" --est "$E"
check_error malformed "malformed.txt:2" --gt "$G" --est "$DIR/malformed.txt"
check_error nan "nan.txt:2" --gt "$G" --est "$DIR/nan.txt"
check_error nonmono "nonmono.txt:2" --gt "$G" --est "$DIR/nonmono.txt"
check_error nooverlap "no estimate pose has a ground-truth pose" --gt "$G" --est "$DIR/nooverlap.txt"
check_error twopairs "needs at least 3" --gt "$G" --est "$DIR/two.txt"
check_error align "unknown alignment 'affine'" --gt "$G" --est "$E" --align affine
err=$("$DYNORB" eval --gt "$G" --est "$E" --plot "$DIR/bad.jpg" 2>&1 >/dev/null)
[[ $? == 2 && $err == *"--plot must name a .png or .svg"* && ! -e "$DIR/bad.jpg" ]] || fail "plot extension: $err"
err=$("$DYNORB" eval --gt "$G" --est "$E" --json "$DIR/no/such/dir/r.json" 2>&1 >/dev/null)
[[ $? == 2 && $err == *"does not exist"* ]] || fail "unwritable json path: $err"

# Low coverage is warned about.
awk 'NR < 100 || NR > 160' "$E" >"$DIR/gappy.txt"
"$DYNORB" eval --gt "$G" --est "$DIR/gappy.txt" | grep -q "^warning: coverage" || fail "coverage warning"

# The real fr3/walking_static ground truth repeats a stamp; --gt accepts it as TUM's tools do.
REAL_GT="$(dirname "$0")/../../../shared/data/tum/rgbd_dataset_freiburg3_walking_static/groundtruth.txt"
if [[ -f "$REAL_GT" ]]; then
  awk '$1 ~ /^#/ || !seen[$1]++' "$REAL_GT" >"$DIR/static_est.txt"  # an estimate must be strict
  "$DYNORB" eval --gt "$REAL_GT" --est "$DIR/static_est.txt" >/dev/null 2>&1 || fail "real walking_static ground truth rejected"
  err=$("$DYNORB" eval --gt "$REAL_GT" --est "$REAL_GT" 2>&1 >/dev/null)
  [[ $? == 2 && $err == *"duplicate timestamp"* ]] || fail "duplicate stamp in an estimate accepted: $err"
fi

if ((failures)); then
  echo "$failures check(s) failed"
  exit 1
fi
echo "all CLI checks passed"
