#!/usr/bin/env bash
# Are two photonlab builds' images bit-identical? Renders every shipped scene with every
# integrator the new build registers (`photonlab integrators`) that the old one can render, at
# 40 pixels wide, and compares them pixel for pixel
# (`photonlab compare` gives rmse 0 only for identical images). For refactors: docs/pages/explanation/architecture.md.
#   scripts/compare_builds.sh OLD_BINARY NEW_BINARY [extra render options, e.g. --spectral]
set -euo pipefail
if [ $# -lt 2 ]; then echo "usage: $0 OLD NEW [render options]" >&2; exit 2; fi
old=$1 new=$2
shift 2
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
differ=0 compared=0
# SCENES="a.gltf b.gltf" compares other files (a variant with the material a change touches).
for scene in ${SCENES:-"$root"/scenes/*.gltf}; do
  name=$(basename "$scene" .gltf)
  for integrator in $("$new" integrators | sed -n 's/^\([a-z_]*\): .*/\1/p'); do
    case $integrator in
      photon) args="--spp 3 --photons 20000 --caustic-photons 20000" ;;
      ppm | sppm | pppm) args="--passes 3 --photons-per-pass 20000" ;;
      radiosity) args="--spp 3 --patches 300" ;;
      *) args="--spp 3" ;;
    esac
    # An integrator the old build does not have, or cannot render here (radiosity refuses a
    # sky and spectral mode), is skipped.
    if ! "$old" render "$scene" --integrator "$integrator" --width 40 $args -q -o "$tmp/a.exr" "$@" 2>/dev/null; then
      continue
    fi
    "$new" render "$scene" --integrator "$integrator" --width 40 $args -q -o "$tmp/b.exr" "$@"
    compared=$((compared + 1))
    if ! "$new" compare "$tmp/b.exr" "$tmp/a.exr" | grep -q '"rmse": 0,'; then
      echo "DIFFERENT: $name $integrator"
      differ=1
    fi
  done
done
echo "$compared renders compared: $([ $differ = 0 ] && echo "all bit-identical" || echo "some differ")"
exit $differ
