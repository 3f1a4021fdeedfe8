#!/usr/bin/env bash
# Sets up, builds and runs FSS's main job on the bundled default input (CGAL's fandisk.off): replays the
# example session examples/fandisk.session.json (seven regular scans and two fishbone scans, recorded by
# examples/record_fandisk_session.cpp) head-less, writes the remeshed mesh, a JSON report (every metric
# against the input, per-scan timings and stitch reports) and a minimum-angle snapshot to build/out/.
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
echo "== replay of examples/fandisk.session.json"
"$build/bin/fss-remesh" run "$here/examples/fandisk.session.json" -o "$out/fandisk_remeshed.ply" \
  --report "$out/fandisk_report.json" --snapshot "$out/fandisk_remeshed.png"
