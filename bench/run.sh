#!/usr/bin/env bash
# Runs the surface benchmark and its NumPy peer one after the other, on the same machine, for
# BENCHMARKS.md. Needs numpy (pip install numpy); not part of the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== machine"; nproc; grep -m1 "model name" /proc/cpuinfo || true; date -u
echo "== pdeshape (cargo bench)"
cargo bench -p pdeshape --bench surface -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^solve_tessellate|time:"
echo "== NumPy peer"
python3 bench/peers/numpy_surface.py 60
echo "== splinepde (cargo bench)"
cargo bench -p pdeshape --bench splinepde -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^splinepde|time:|20x20"
