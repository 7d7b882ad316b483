#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default job: the Cornell box, path traced,
# written as linear EXR and sRGB PNG into results/quickstart/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
mkdir -p results/quickstart
./build/photonlab render scenes/cornell-box.gltf --integrator path --width 512 --spp 256 \
  -o results/quickstart/cornell-box.exr -o results/quickstart/cornell-box.png
echo "wrote results/quickstart/cornell-box.exr and results/quickstart/cornell-box.png"
