#!/usr/bin/env bash
# README's first command: installs what is missing, builds, and runs the default experiment
# (experiments/quickstart.toml: path tracing vs SPPM vs PPPM on a caustic, about two minutes on
# 2 cores), then writes its report (plots, image comparison, index.html).
# Re-running it renders into results/quickstart-2/, -3, ... and reuses the cached reference.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
out="$(./build/photonlab run experiments/quickstart.toml)"
/usr/bin/python3 scripts/report.py "$out" >/dev/null
echo "report: $root/$out/index.html (plots: $out/convergence.png, $out/comparison.png; numbers: $out/metrics.csv)"
