#!/usr/bin/env bash
# Installs every Debian package FSS needs and prepares the test data (CGAL's sample meshes).
# Quick and quiet when everything is already present. Uses sudo when not root.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

packages=(
  cmake ninja-build g++ pkg-config ccache lld
  libcgal-dev libeigen3-dev libgmp-dev libmpfr-dev nlohmann-json3-dev libssl-dev libtbb-dev libcli11-dev
  clang-format
  libvtk9-dev libglew-dev libegl-dev libgl-dev libgl1-mesa-dri libegl-mesa0 libgbm1
  qt6-base-dev qt6-base-dev-tools libqt6opengl6-dev qt6-tools-dev qt6-tools-dev-tools
  libgtest-dev libgmock-dev libbenchmark-dev
  libgmsh-dev python3-meshio
  libcgal-demo xvfb xauth
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} Debian package(s): ${missing[*]}"
  sudo=()
  if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Test data: CGAL's sample meshes ship inside libcgal-demo's documentation folder as data.tar.gz.
data_dir="$here/.cache/cgal-data"
if [[ ! -f "$data_dir/meshes/fandisk.off" ]]; then
  tarball=$(dpkg -L libcgal-demo libcgal-dev 2>/dev/null | grep -m1 '/data\.tar\.gz$' || true)
  [[ -n "$tarball" && -f "$tarball" ]] || { echo "setup: CGAL's data.tar.gz was not found (is libcgal-demo installed?)" >&2; exit 1; }
  mkdir -p "$data_dir"
  tar -xzf "$tarball" -C "$data_dir" --strip-components=1 data/meshes
  echo "setup: extracted CGAL sample meshes to $data_dir/meshes"
fi
