#!/usr/bin/env bash
# `make demo` (scripts/demo.sh path/to/dynorb): a short tour of dynorb on built-in data.
# Each step is a function; later features add their own step and call it from main.
set -euo pipefail

DYNORB=${1:-build/dev/bin/dynorb}
OUT_DIR=${DEMO_OUT_DIR:-out/demo}

log() { printf '\n== %s\n' "$*"; }

require_binary() {
  if [[ ! -x "$DYNORB" ]]; then
    echo "demo: dynorb binary not found at '$DYNORB' (build first: make build)" >&2
    exit 1
  fi
}

# Trajectory evaluation: synthetic ground truth + estimate -> ATE/RPE table, JSON and plot.
demo_eval() {
  local dir="$OUT_DIR/eval"
  log "trajectory evaluation (dynorb trajgen + dynorb eval) -> $dir"
  mkdir -p "$dir"
  "$DYNORB" trajgen --out "$dir" --seed 1 --duration-s 30 --rate-hz 30 --noise-m 0.01 --drift-m-per-s 0.002
  "$DYNORB" eval --gt "$dir/groundtruth.txt" --est "$dir/estimate.txt" --align se3 \
    --json "$dir/eval.json" --plot "$dir/eval.png"
  "$DYNORB" eval --gt "$dir/groundtruth.txt" --est "$dir/estimate.txt" --plot "$dir/eval.svg" >/dev/null
  DEMO_OUTPUTS+=("$dir/eval.json" "$dir/eval.png" "$dir/eval.svg")
}

# The main job: `dynorb bench` on bench/suites/demo.yaml — a synthetic office sequence with people
# walking through it and its static twin (rendered by `dynorb synth`), SLAM with every available
# mode, scored against the exact ground truth; tables in report.md/report.html.
DEMO_FRAMES=${DEMO_FRAMES:-300}

demo_slam() {
  local suite="$(dirname "$0")/../bench/suites/demo.yaml" out="$OUT_DIR/bench"
  if [[ $DEMO_FRAMES != 300 ]]; then  # a shorter demo: same suite, fewer frames
    mkdir -p "$OUT_DIR"
    sed "s/frames: 300/frames: $DEMO_FRAMES/" "$suite" >"$OUT_DIR/demo_suite.yaml"
    suite="$OUT_DIR/demo_suite.yaml"
  fi
  log "SLAM benchmark: $suite -> $out"
  "$DYNORB" bench --suite "$suite" --out "$out"
  log "results (ATE = TUM absolute trajectory error, SE(3)-aligned; ratio = ATE / ATE of the static twin)"
  echo "   (map on objects = share of the final map's landmarks made on the people and the moved objects)"
  python3 "$(dirname "$0")/demo_table.py" "$out"
  DEMO_OUTPUTS+=("$out/report.html" "$out/report.md" "$out/results.json"
    "$out/runs/<sequence>/<mode>/seed1/map.ply (each run's map: MeshLab, CloudCompare, Open3D)")
}

main() {
  require_binary
  DEMO_OUTPUTS=()
  demo_eval
  demo_slam
  log "outputs"
  printf '  %s\n' "${DEMO_OUTPUTS[@]}"
}

main "$@"
