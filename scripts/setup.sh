#!/usr/bin/env bash
# Idempotent set-up: installs what is missing (Debian 12 packages, then a project-local
# Python venv for the plotting scripts), configures and builds into build/.
# Usage: scripts/setup.sh [--no-build]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

apt_packages=(
  build-essential cmake pkg-config
  libembree-dev libtbb-dev libnanoflann-dev libglm-dev
  libopenimageio-dev libtinygltf-dev nlohmann-json3-dev
  catch2 libtomlplusplus-dev libcli11-dev
  python3 python3-venv
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

# Python for scripts/ (plots, comparisons, their pytest tests): a venv local to the project.
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
if ! .venv/bin/python -c "import numpy, pytest" 2>/dev/null; then
  .venv/bin/pip install -q numpy pytest
fi

[ "${1:-}" = "--no-build" ] && exit 0
cmake -S . -B build -DCMAKE_BUILD_TYPE="${CMAKE_BUILD_TYPE:-Release}" >/dev/null
cmake --build build -j"$(nproc)"
