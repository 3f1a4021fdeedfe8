#!/usr/bin/env bash
# Sets up, builds and runs all FSS tests (GUI tests under xvfb-run when there is no display).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$here/scripts/setup.sh"
"$here/scripts/build.sh"
build="${FSS_BUILD_DIR:-$here/build}"
run=()
if [[ -z "${DISPLAY:-}" ]]; then run=(xvfb-run -a -s "-screen 0 1280x1024x24"); fi
cd "$build"
"${run[@]}" ctest --output-on-failure --parallel "$(nproc)" --timeout 900 "$@"
