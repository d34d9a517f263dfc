#!/usr/bin/env bash
# Opens a `dynorb bench` report.html in headless Chromium (Debian package `chromium`) and checks
# that it loads, shows its tables and that every figure loaded (the report's script sets
# body data-images="loaded/total"); writes a screenshot. CTest: dynorb_bench_html, which runs
# after dynorb_bench_cli produced the report. Exit 77 (CTest: skipped) without chromium.
# Usage: html_check.sh REPORT_DIR SCREENSHOT.png
set -uo pipefail
REPORT=$(realpath "${1:?usage: html_check.sh REPORT_DIR SCREENSHOT.png}")/report.html
SHOT=$(realpath -m "${2:?screenshot path}")
BROWSER=$(command -v chromium || command -v chromium-browser || true)
if [[ -z "$BROWSER" ]]; then
  echo "SKIP: chromium is not installed (Debian: apt-get install chromium)"
  exit 77
fi
[[ -s "$REPORT" ]] || { echo "FAIL: $REPORT not found (run dynorb_bench_cli first)"; exit 1; }
PROFILE=$(mktemp -d)
trap 'rm -rf "$PROFILE"' EXIT
FLAGS=(--headless --no-sandbox --disable-gpu --disable-background-networking --disable-component-update
  --disable-sync --no-first-run --user-data-dir="$PROFILE" --virtual-time-budget=5000)
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

DOM=$(timeout 60 "$BROWSER" "${FLAGS[@]}" --dump-dom "file://$REPORT" 2>"$PROFILE/dump.err")
[[ $? == 0 ]] || fail "chromium --dump-dom failed: $(tail -3 "$PROFILE/dump.err")"
tables=$(grep -o '<table class="bench"' <<<"$DOM" | wc -l)
rows=$(grep -o '<tr>' <<<"$DOM" | wc -l)
images=$(grep -o '<img ' <<<"$DOM" | wc -l)
status=$(grep -o 'data-images="[0-9]*/[0-9]*"' <<<"$DOM" | head -1)
echo "report: $tables tables, $rows rows, $images images, $status"
((tables >= 6)) || fail "only $tables tables in the rendered page"
((images >= 2)) || fail "only $images images in the rendered page"
[[ $status =~ data-images=\"([0-9]+)/([0-9]+)\" ]] || fail "the page's load script did not run"
[[ ${BASH_REMATCH[1]:-x} == "${BASH_REMATCH[2]:-y}" ]] || fail "not every figure loaded: $status"
grep -q "figures loaded" <<<"$DOM" || fail "image status line missing"
grep -iE "Uncaught|SyntaxError|ERR_FILE_NOT_FOUND" "$PROFILE/dump.err" && fail "errors while loading"

timeout 60 "$BROWSER" "${FLAGS[@]}" --window-size=1280,2000 --screenshot="$SHOT" "file://$REPORT" \
  >/dev/null 2>"$PROFILE/shot.err" || fail "chromium --screenshot failed: $(tail -3 "$PROFILE/shot.err")"
[[ $(head -c 4 "$SHOT" 2>/dev/null | tail -c 3) == PNG ]] || fail "no screenshot PNG at $SHOT"
echo "screenshot: $SHOT"
((failures)) && exit 1
echo "report.html: loads in chromium, tables and figures present"
