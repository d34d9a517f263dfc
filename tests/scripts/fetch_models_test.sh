#!/usr/bin/env bash
# scripts/fetch_models.sh offline (CTest: fetch_models_script), with `curl` faked by a stub first
# on PATH: unknown model names and a missing curl are refused before anything is created; a file
# with a wrong sha256 never stays at its final name (not after a failed download, not after a
# mismatching one) and no *.part file is left; each failure is one message and the exit code is
# non-zero; a good download is verified and kept.
# Usage: fetch_models_test.sh path/to/fetch_models.sh
set -uo pipefail
SCRIPT=$(realpath "${1:?usage: $(basename "$0") path/to/fetch_models.sh}")
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The stub curl logs its calls to $DIR/curl.log and, by $CURL_MODE: fail (exit 22 with curl's
# message), junk (writes a file with a wrong sum) or coco (writes the real coco.names, junk for
# any other URL).
BIN="$DIR/bin"
mkdir -p "$BIN"
cat > "$BIN/curl" <<'STUB'
#!/usr/bin/env bash
echo "$*" >> "$CURL_LOG"
out="" url=""
while [[ $# -gt 0 ]]; do [[ "$1" == -o ]] && out=$2; url=$1; shift; done
case "$CURL_MODE" in
  fail) echo "curl: (22) The requested URL returned error: 404" >&2; exit 22 ;;
  junk) echo junk > "$out" ;;
  coco) [[ "$url" == */coco.names ]] || { echo junk > "$out"; exit 0; }
    tr -s ' \n' '\n\n' <<<"person bicycle car motorbike aeroplane bus train truck boat traffic_light
    fire_hydrant stop_sign parking_meter bench bird cat dog horse sheep cow elephant bear zebra
    giraffe backpack umbrella handbag tie suitcase frisbee skis snowboard sports_ball kite
    baseball_bat baseball_glove skateboard surfboard tennis_racket bottle wine_glass cup fork knife
    spoon bowl banana apple sandwich orange broccoli carrot hot_dog pizza donut cake chair sofa
    pottedplant bed diningtable toilet tvmonitor laptop mouse remote keyboard cell_phone microwave
    oven toaster sink refrigerator book clock vase scissors teddy_bear hair_drier toothbrush" |
      sed '/^$/d' | tr '_' ' ' > "$out" ;;
esac
STUB
chmod +x "$BIN/curl"
export CURL_LOG="$DIR/curl.log" CURL_MODE=fail

# run MODE args...: runs the script with the stub curl; sets code, out (stdout), err (stderr).
run() {
  CURL_MODE=$1
  shift
  : > "$CURL_LOG"
  out=$(PATH="$BIN:$PATH" bash "$SCRIPT" "$@" 2>"$DIR/stderr")
  code=$?
  err=$(<"$DIR/stderr")
}
sum_ok() { echo "$1  $2" | sha256sum -c --status; }
no_parts() { [[ -z "$(find "$1" -name '*.part' 2>/dev/null)" ]] || fail "$2: left $(find "$1" -name '*.part')"; }
BODY_SHA=9e2ec912af5dff2a72300863864fc4da04e81999339d9fac5c7590ba8a3f4e11
COCO_SHA=634a1132eb33f8091d60f2c346ababe8b905ae08387037aed883953b7329af84

# Unknown names (a typo, a regex, an option-like word, a bad name after a good one, empty, two
# lines): exit 2, one message line listing the known names, nothing created, nothing fetched.
for args in "yolox.nano" "-e.*" "yolox_nano yolox_nano2" "yolo_fastest_1.1 .*" "''" \
  "$'yolox_nano\\nfoo'"; do
  eval "set -- $args"
  d="$DIR/unknown$RANDOM"
  run junk --dest "$d" "$@"
  [[ $code == 2 ]] || fail "unknown name ($args): exit code $code, expected 2"
  [[ "$err" == "unknown model "*" (known: yolo_fastest_1.1 yolo_fastest_1.1_xl"*")" ]] ||
    fail "unknown name ($args): message '$err'"
  [[ $(wc -l <<<"$err") == 1 ]] || fail "unknown name ($args): more than one message line: '$err'"
  [[ ! -e "$d" ]] || fail "unknown name ($args): created $d"
  [[ ! -s "$CURL_LOG" ]] || fail "unknown name ($args): called curl"
done

# --dest without a folder: one message (it was bash's "unbound variable").
err=$(bash "$SCRIPT" --dest 2>&1 >/dev/null)
code=$?
[[ $code == 2 && "$err" == "--dest needs a folder (e.g. --dest models)" ]] || fail "--dest alone: exit $code, message '$err'"

# No curl on PATH: one message up front, exit non-zero, nothing created.
NOCURL="$DIR/nocurl"
mkdir -p "$NOCURL"
for t in cat grep mkdir mv rm sed sha256sum; do ln -s "$(command -v "$t")" "$NOCURL/$t"; done
d="$DIR/nocurl_dest"
err=$(PATH="$NOCURL" "$(command -v bash)" "$SCRIPT" --dest "$d" yolox_nano 2>&1 >/dev/null)
code=$?
[[ $code != 0 ]] || fail "no curl: exit code 0"
[[ $(wc -l <<<"$err") == 1 && "$err" == *"needs curl"* ]] || fail "no curl: message '$err'"
[[ ! -e "$d" ]] || fail "no curl: created $d"

# A tampered file at its final name and a failing download: the tampered file is gone, no .part,
# exit 1, one FAILED line per file (with curl's reason) and a summary line.
d="$DIR/tampered"
mkdir -p "$d/yolox_nano"
echo tampered > "$d/yolox_nano/yolox_nano.onnx"
run fail --dest "$d" yolox_nano
[[ $code == 1 ]] || fail "failed download: exit code $code, expected 1"
[[ ! -e "$d/yolox_nano/yolox_nano.onnx" ]] || fail "failed download: tampered yolox_nano.onnx left at its final name"
no_parts "$d" "failed download"
[[ $(grep -c '^FAILED download .*(curl: (22) The requested URL returned error: 404)$' <<<"$err") == 2 ]] ||
  fail "failed download: expected 2 FAILED lines, got '$err'"
[[ $(wc -l <<<"$err") == 3 && "$(tail -1 <<<"$err")" == "2 file(s) failed; see above" ]] ||
  fail "failed download: messages '$err'"

# Downloads with a wrong sum: removed (no .part, nothing at the final names), one MISMATCH line each.
d="$DIR/mismatch"
mkdir -p "$d/yolox_nano"
echo tampered > "$d/yolox_nano/coco.names"
run junk --dest "$d" yolox_nano
[[ $code == 1 ]] || fail "mismatch: exit code $code, expected 1"
[[ -z "$(find "$d" -type f)" ]] || fail "mismatch: left $(find "$d" -type f)"
[[ $(grep -c '^SHA256 MISMATCH for ' <<<"$err") == 2 && $(wc -l <<<"$err") == 3 ]] ||
  fail "mismatch: messages '$err'"

# A good download replaces a tampered file; the others fail; a second run keeps the good file.
d="$DIR/good"
mkdir -p "$d/yolox_nano"
echo tampered > "$d/yolox_nano/coco.names"
run coco --dest "$d" yolox_nano
[[ $code == 1 ]] || fail "good download: exit code $code, expected 1 (yolox_nano.onnx is junk)"
sum_ok "$COCO_SHA" "$d/yolox_nano/coco.names" || fail "good download: coco.names not verified and kept"
grep -qxF "verified $d/yolox_nano/coco.names" <<<"$out" || fail "good download: no 'verified' line in '$out'"
[[ ! -e "$d/yolox_nano/yolox_nano.onnx" ]] || fail "good download: junk yolox_nano.onnx kept"
no_parts "$d" "good download"
run fail --dest "$d" yolox_nano
grep -qxF "ok       $d/yolox_nano/coco.names" <<<"$out" || fail "second run: coco.names not 'ok': '$out'"
[[ $(grep -c coco.names "$CURL_LOG") == 0 ]] || fail "second run: fetched coco.names again"

# The body model's class list is written by the script (no download): a tampered one is rewritten.
d="$DIR/body"
mkdir -p "$d/yolo_fastest_1.1_body"
echo person > "$d/yolo_fastest_1.1_body/body.names"
run fail --dest "$d" yolo_fastest_1.1_body
[[ $code == 1 ]] || fail "body: exit code $code, expected 1"
sum_ok "$BODY_SHA" "$d/yolo_fastest_1.1_body/body.names" || fail "body: body.names not rewritten"
for f in "$d"/yolo_fastest_1.1_body/*; do
  [[ "$f" == */body.names ]] || fail "body: left $f"
done
[[ $(grep -c '^FAILED download ' <<<"$err") == 3 ]] || fail "body: expected 3 FAILED lines, got '$err'"

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "all fetch_models.sh checks passed"
