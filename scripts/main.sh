#!/usr/bin/env bash
# Sets up, builds and runs FSS's main job on the bundled default input (CGAL's fandisk.off).
# Extra arguments are passed on to fss-remesh.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$here/scripts/setup.sh"
"$here/scripts/build.sh" --target fss-remesh
build="${FSS_BUILD_DIR:-$here/build}"
mesh="$here/.cache/cgal-data/meshes/fandisk.off"
"$build/bin/fss-remesh" info "$mesh" "$@"
