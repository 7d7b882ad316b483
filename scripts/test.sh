#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (Catch2 through ctest, then pytest for
# the Python scripts). This is the README's second command and what .ci/run calls.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 600
if compgen -G "tests/test_*.py" >/dev/null; then
  .venv/bin/python -m pytest -q tests
fi
