#!/usr/bin/env bash
# Runs the surface benchmark and its NumPy peer one after the other, on the same machine, for
# BENCHMARKS.md. Needs the packages of bench/peers/requirements.txt; not part of the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== machine"; nproc; grep -m1 "model name" /proc/cpuinfo || true; date -u
echo "== pdeshape (cargo bench)"
cargo bench -p pdeshape --bench surface -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^solve_tessellate|time:"
echo "== NumPy peer"
python3 bench/peers/numpy_surface.py 60
echo "== pdeshape BFS splines and the section-6 blend (cargo bench)"
cargo bench -p pdeshape --bench bfs -- --warm-up-time 2 --measurement-time 10 2>&1 | grep -E "^bfs_|^blend_|time:"
echo "== scikit-fem peer (ElementQuadBFS; pip install scikit-fem)"
python3 bench/peers/skfem_bfs.py 32 64 128
