#!/usr/bin/env bash
# Configures and builds FSS into ./build (Release with debug info, Ninja when available).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${FSS_BUILD_DIR:-$here/build}"
gen=()
if [[ ! -f "$build/CMakeCache.txt" ]] && command -v ninja >/dev/null; then gen=(-G Ninja); fi
cmake -S "$here" -B "$build" "${gen[@]}" -DCMAKE_BUILD_TYPE="${FSS_BUILD_TYPE:-RelWithDebInfo}" \
  -DFSS_DATA_DIR="$here/.cache/cgal-data" >/dev/null
cmake --build "$build" --parallel "$(nproc)" "$@"
