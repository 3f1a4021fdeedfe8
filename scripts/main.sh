#!/usr/bin/env bash
# Sets up, builds and runs FSS's main job on the bundled default input (CGAL's fandisk.off): the metrics
# of the input, one 256² virtual range scan from the iso view into a regular patch (written to
# build/out/fandisk_iso_patch.ply), and the metrics of that patch against the input.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$here/scripts/setup.sh"
"$here/scripts/build.sh" --target fss-remesh
build="${FSS_BUILD_DIR:-$here/build}"
mesh="$here/.cache/cgal-data/meshes/fandisk.off"
out="$build/out"
mkdir -p "$out"
echo "== input: $mesh"
"$build/bin/fss-remesh" info "$mesh"
echo
echo "== scan (iso view, 256x256)"
"$build/bin/fss-remesh" scan "$mesh" -o "$out/fandisk_iso_patch.ply" --view iso --resolution 256
echo
echo "== patch against the input"
"$build/bin/fss-remesh" info "$out/fandisk_iso_patch.ply" --ref "$mesh"
