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
