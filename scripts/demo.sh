#!/usr/bin/env bash
# `make demo`: the main job on a built-in default. (Grows with the project; see README.md.)
set -euo pipefail
DYNORB=${1:-build/dev/bin/dynorb}
"$DYNORB" --help
