#!/usr/bin/env bash
# Runs the surface benchmark and its NumPy peer one after the other, on the same machine, for
# BENCHMARKS.md. Needs numpy and scipy (pip install -r bench/peers/requirements.txt); not part of
# the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== machine"; nproc; grep -m1 "model name" /proc/cpuinfo || true; date -u
echo "== pdeshape (cargo bench)"
cargo bench -p pdeshape --bench surface -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^solve_tessellate|time:"
echo "== NumPy peer"
python3 bench/peers/numpy_surface.py 60
echo "== pdeshape analysis (cargo bench)"
cargo bench -p pdeshape --bench analysis -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^analysis|time:"
echo "== optimisation of 5000 evaluations, 1 and 2 threads (cargo bench)"
cargo bench -p pdeshape --bench optimize 2>&1 | grep -E "^optimize_5000|time:"
echo "== vesicle reference minima (SciPy)"
python3 bench/peers/vesicle_reference.py
