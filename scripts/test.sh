#!/usr/bin/env bash
# Installs what is missing, builds, and runs the tests (Catch2 through ctest, then pytest for
# the Python scripts and the documentation). This is the README's second command.
#   (default)      all but the longest: the convergence checks labelled "long" in ctest (tagged
#                  [long]) and the pytest cases marked slow (the profile-guided build), which
#                  exercise code the other tests take too
#   --all          every test, those included (what .ci/run runs)
#   --sanitizers   then builds again with AddressSanitizer + UndefinedBehaviorSanitizer into
#                  build-sanitize/ and runs the Catch2 tests there too (what .ci/run does),
#                  all but those tagged [long] and [heavy] (ctest labels "long", "heavy": the
#                  longest convergence checks under the sanitizers, on code paths shorter tests
#                  also take, measured with gcov) and [latency] (real-time stop bounds, which
#                  the sanitizers' slowdown would break; every stop is also tested with an
#                  injected clock).
#                  -O1 -g1: half the build time of -O2 -g, and stack traces keep their lines
#                  (the test files without debug information: tests/CMakeLists.txt).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
all=0 sanitizers=0
for arg in "$@"; do
  case $arg in
    --all) all=1 ;;
    --sanitizers) sanitizers=1 ;;
    *) echo "usage: scripts/test.sh [--all] [--sanitizers]" >&2; exit 2 ;;
  esac
done
bash scripts/setup.sh
if [ $all = 1 ]; then
  ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 600
else
  ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 600 -LE long
fi
if compgen -G "tests/test_*.py" >/dev/null; then
  if [ $all = 1 ]; then
    /usr/bin/python3 -m pytest -q -p no:cacheprovider --durations=8 tests
  else
    /usr/bin/python3 -m pytest -q -p no:cacheprovider --durations=8 -m "not slow" tests
  fi
fi
if [ $sanitizers = 1 ]; then
  cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DPHOTONLAB_SANITIZE=ON >/dev/null
  cmake --build build-sanitize -j"$(nproc)"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" --timeout 900 -LE "long|heavy|latency"
fi
