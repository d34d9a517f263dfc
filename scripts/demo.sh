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

# The main job: a dynamic office sequence (people walking) and its static twin, rendered by
# `dynorb synth`, then SLAM with every available mode, scored against the exact ground truth.
DEMO_FRAMES=${DEMO_FRAMES:-300}
DEMO_PRESET=${DEMO_PRESET:-walking_xyz}

available_modes() {
  # plain is always there; the dynamic modes appear in `dynorb run --help` once built in.
  "$DYNORB" run --help | sed -n 's/.*--mode TEXT:{\(.*\)}.*/\1/p' | tr ',' ' '
}

demo_slam() {
  local data="$OUT_DIR/data" runs="$OUT_DIR/runs"
  mkdir -p "$data" "$runs"
  for variant in dynamic twin; do
    local seq="$data/${DEMO_PRESET}_${variant}"
    if [[ ! -f "$seq/groundtruth.txt" ]]; then
      log "rendering $DEMO_FRAMES frames of $DEMO_PRESET ($variant) -> $seq"
      local twin=()
      [[ $variant == twin ]] && twin=(--static-twin)
      rm -rf "$seq"
      "$DYNORB" synth --preset "$DEMO_PRESET" --seed 7 --frames "$DEMO_FRAMES" --out "$seq" "${twin[@]}"
    fi
  done
  local modes
  modes=$(available_modes)
  [[ -n $modes ]] || modes=plain
  log "SLAM runs (modes: $modes)"
  for mode in $modes; do
    for variant in dynamic twin; do
      # Dynamic modes on the static twin only matter for plain (the reference accuracy).
      [[ $variant == twin && $mode != plain ]] && continue
      local out="$runs/${mode}_${variant}"
      echo "-- $mode on $variant"
      if ! "$DYNORB" run --dataset "$data/${DEMO_PRESET}_${variant}" --out "$out" --mode "$mode" --quiet >"$out.log" 2>&1; then
        echo "   skipped: $(tail -1 "$out.log")"
        continue
      fi
      DEMO_OUTPUTS+=("$out/stats.json")
    done
  done
  log "results ($DEMO_PRESET, $DEMO_FRAMES frames; ATE = TUM absolute trajectory error, SE(3)-aligned)"
  python3 "$(dirname "$0")/demo_table.py" "$runs"
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
