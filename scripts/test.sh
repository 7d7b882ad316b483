#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (Catch2 through ctest, then pytest for
# the Python scripts). This is the README's second command.
#   --sanitizers   then builds again with AddressSanitizer + UndefinedBehaviorSanitizer into
#                  build-sanitize/ and runs the Catch2 tests there too (what .ci/run does),
#                  all but those tagged [long] (ctest label "long": the longest convergence
#                  checks under the sanitizers, on code paths shorter tests also take).
#                  -O1 -g1: half the build time of -O2 -g, and stack traces keep their lines.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 600
if compgen -G "tests/test_*.py" >/dev/null; then
  /usr/bin/python3 -m pytest -q -p no:cacheprovider tests
fi
if [ "${1:-}" = "--sanitizers" ]; then
  cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DPHOTONLAB_SANITIZE=ON >/dev/null
  cmake --build build-sanitize -j"$(nproc)"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" --timeout 900 -LE long
fi
