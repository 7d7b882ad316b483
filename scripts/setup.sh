#!/usr/bin/env bash
# Idempotent set-up: installs what is missing (Debian 12 packages, including Python with numpy,
# matplotlib, OpenImageIO's bindings and pytest for scripts/, Chromium for the browser tests, and
# MkDocs with the Material theme for the documentation site),
# configures and builds into build/.
# Usage: scripts/setup.sh [--no-build]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

apt_packages=(
  build-essential cmake pkg-config
  libembree-dev libtbb-dev libnanoflann-dev libglm-dev
  libopenimageio-dev libtinygltf-dev nlohmann-json3-dev
  catch2 libtomlplusplus-dev libcli11-dev
  python3 python3-numpy python3-matplotlib python3-openimageio python3-pytest python3-distributed
  chromium mkdocs mkdocs-material
)

missing=()
for p in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The scripts run on Debian's own Python (/usr/bin/python3), where the packages above live.
/usr/bin/python3 -c "import numpy, matplotlib, OpenImageIO, pytest" ||
  { echo "setup: Debian's python3 lacks numpy/matplotlib/OpenImageIO/pytest" >&2; exit 1; }

[ "${1:-}" = "--no-build" ] && exit 0
cmake -S . -B build -DCMAKE_BUILD_TYPE="${CMAKE_BUILD_TYPE:-Release}" >/dev/null
cmake --build build -j"$(nproc)"
