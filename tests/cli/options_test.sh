#!/usr/bin/env bash
# Numeric command-line options with bad values (CTest: dynorb_cli_options): each call exits
# non-zero with a message naming the option and what it expects, and writes nothing.
# Usage: options_test.sh path/to/dynorb
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"

# expect_error expected-first-line args...  (OUT stands for a fresh output folder)
expect_error() {
  local expected=$1
  shift
  local out="$DIR/out$failures$RANDOM" args=() err code
  for a in "$@"; do args+=("${a//OUT/$out}"); done
  err=$("$DYNORB" "${args[@]}" 2>&1 >/dev/null)
  code=$?
  [[ $code != 0 ]] || fail "$*: exit code 0"
  [[ "$(head -1 <<<"$err")" == "$expected" ]] || fail "$*: message '$(head -1 <<<"$err")', expected '$expected'"
  [[ ! -e "$out" ]] || fail "$*: wrote $out"
}

NO_DATA="$DIR/no_such_sequence"
expect_error "--seed: expects a non-negative integer, got '-1'" run --dataset "$NO_DATA" --out OUT --seed -1
expect_error "--seed: expects a non-negative integer, got '1e3'" run --dataset "$NO_DATA" --out OUT --seed 1e3
expect_error "--overlay-every: expects an integer >= 1, got '0'" run --dataset "$NO_DATA" --out OUT --overlay-every 0
expect_error "--overlay-every: expects an integer >= 1, got '2.5'" run --dataset "$NO_DATA" --out OUT --overlay-every 2.5
expect_error "--pipeline-depth: Value 17 not in range 1 to 16" run --dataset "$NO_DATA" --out OUT --pipeline-depth 17
expect_error "--seed: expects a non-negative integer, got '-3'" synth --out OUT --frames 1 --seed -3
expect_error "--num-people: Value 0 not in range 1 to 3" synth --out OUT --frames 1 --num-people 0
expect_error "--num-people: Value 4 not in range 1 to 3" synth --out OUT --frames 1 --num-people 4
expect_error "--seed: expects a non-negative integer, got '-2'" trajgen --out OUT --seed -2
# Good values pass the option checks (the run then fails on the missing dataset).
expect_error "dynorb: error: dataset folder not found: $NO_DATA" run --dataset "$NO_DATA" --out OUT --seed 18446744073709551615 --overlay-every 3

finish "option checks"
