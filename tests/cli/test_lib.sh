# Shared set-up of the CLI tests (sourced): DYNORB (the executable, from $1), DIR (a temporary
# folder removed on exit), fail MESSAGE (counts a failure) and finish NAME (reports, sets the exit
# code). The sourcing script sets `-uo pipefail` itself.
DYNORB=$(realpath "${1:?usage: $(basename "$0") path/to/dynorb}")
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
finish() {
  if ((failures)); then
    echo "$failures failure(s)"
    exit 1
  fi
  echo "all $1 passed"
}
# run_dynorb command args...: runs `dynorb command args`; its stderr in $err, exit code in $code.
run_dynorb() {
  err=$("$DYNORB" "$@" 2>&1 >/dev/null)
  code=$?
}
# expect_error EXPECTED command args...: `dynorb command args` exits non-zero and its stderr
# contains EXPECTED.
expect_error() {
  local expected=$1 err code
  shift
  run_dynorb "$@"
  [[ $code != 0 ]] || fail "$*: exit code 0"
  grep -qF -- "$expected" <<<"$err" || fail "$*: message '$err', expected '$expected'"
}
# expect_clean_error EXPECTED command args...: as expect_error, and an input error's exit code 2
# with exactly one line.
expect_clean_error() {
  local expected=$1 err code
  shift
  run_dynorb "$@"
  [[ $code == 2 ]] || fail "$*: exit code $code"
  grep -qF -- "$expected" <<<"$err" || fail "$*: message '$err', expected '$expected'"
  [[ $(wc -l <<<"$err") == 1 ]] || fail "$*: more than one line: $err"
}
