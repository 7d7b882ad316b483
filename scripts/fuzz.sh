#!/usr/bin/env bash
# Fuzzes a parser with libFuzzer (clang, AddressSanitizer, UndefinedBehaviorSanitizer).
#   scripts/fuzz.sh gltf|experiment [SECONDS]     (default 600)
# Installs clang if missing, builds into build-fuzz/, seeds the corpus from the shipped scenes and
# experiments (scripts/make_fuzz_corpus.py), and runs for SECONDS. Crash inputs land in
# build-fuzz/crashes-TARGET/; turn each into a regression test (tests/fuzz/regressions/ and
# test_fuzz_regressions.cpp) after fixing it.
set -euo pipefail
target="${1:?usage: scripts/fuzz.sh gltf|experiment [SECONDS]}"
seconds="${2:-600}"
case "$target" in gltf|experiment) ;; *) echo "fuzz.sh: unknown target '$target' (gltf, experiment)" >&2; exit 2;; esac
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh --no-build
need=()
for p in clang-14 libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need+=("$p")
done
if ((${#need[@]})); then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
fi
if [ ! -f build-fuzz/CMakeCache.txt ]; then
  CXX=clang++-14 cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPHOTONLAB_FUZZ=ON -DPHOTONLAB_TESTS=OFF >/dev/null
fi
cmake --build build-fuzz -j"$(nproc)" --target "fuzz_$target"
/usr/bin/python3 scripts/make_fuzz_corpus.py build-fuzz/seeds
corpus="build-fuzz/corpus-$target"
crashes="$root/build-fuzz/crashes-$target"
mkdir -p "$corpus" "$crashes"
# The experiment configs name "../scenes/…": run from experiments/ so that those resolve.
cd "$([ "$target" = experiment ] && echo experiments || echo .)"
"$root/build-fuzz/tests/fuzz/fuzz_$target" "$root/$corpus" "$root/build-fuzz/seeds/$target" \
  -max_total_time="$seconds" -timeout=20 -rss_limit_mb=6144 -malloc_limit_mb=6144 \
  -artifact_prefix="$crashes/" -print_final_stats=1
