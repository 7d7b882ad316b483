#!/usr/bin/env bash
# A profile-guided build of photonlab (GCC): compile it instrumented, train it on the renders
# below, compile it again with their profile. Same images as the plain build, bit for bit; 0-10%
# faster (docs: explanation/performance.md). Installs what is missing first, as setup.sh does.
#   scripts/build_pgo.sh [BUILD_DIR]    (default build-pgo; BUILD_DIR/photonlab is the result)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh --no-build
dir="$(mkdir -p "${1:-build-pgo}" && cd "${1:-build-pgo}" && pwd)"
profile="$dir/pgo-profile"
rm -rf "$profile"  # a profile of older code would steer the new one wrongly

cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DPHOTONLAB_TESTS=OFF -DPHOTONLAB_PGO=generate \
  -DPHOTONLAB_PGO_DIR="$profile" >/dev/null
cmake --build "$dir" -j"$(nproc)" --target photonlab

# Training: the loops researchers wait on, small. Each integrator's hot code is shared by many
# scenes; code no render here reaches is compiled as without a profile (-fprofile-partial-training).
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
train() { "$dir/photonlab" render "$@" --width 128 -q -o "$tmp/train.exr"; }
train scenes/cornell-box.gltf --integrator path --spp 32
train scenes/cornell-spheres.gltf --integrator path --spp 32
train scenes/cornell-spheres.gltf --integrator path --spp 8 --spectral
train scenes/smallvcm-point.gltf --integrator bdpt --spp 8 --max-depth 10
train scenes/smallvcm-sun.gltf --integrator vcm --spp 8 --max-depth 10
train scenes/cornell-spheres.gltf --integrator sppm --passes 4 --photons-per-pass 200000
train scenes/glass-caustic.gltf --integrator photon --spp 4 --photons 200000 --caustic-photons 200000
echo "build_pgo: trained ($(ls "$profile" | wc -l) profiles)" >&2

cmake -S . -B "$dir" -DPHOTONLAB_PGO=use >/dev/null
cmake --build "$dir" -j"$(nproc)" --target photonlab
