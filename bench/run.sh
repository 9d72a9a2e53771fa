#!/usr/bin/env bash
# Runs every benchmark and its peer (NumPy, SciPy, libigl, scikit-fem) one after the other, on
# the same machine, for BENCHMARKS.md. Needs the packages of bench/peers/requirements.txt
# (pip install -r bench/peers/requirements.txt); not part of the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== machine"; nproc; grep -m1 "model name" /proc/cpuinfo || true; date -u
echo "== pdeshape (cargo bench)"
cargo bench -p pdeshape --bench surface -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^solve_tessellate|time:"
echo "== NumPy peer"
python3 bench/peers/numpy_surface.py 60
echo "== pdeshape dynamic curves (cargo bench; the CPU line is this thread's CPU time per run)"
cargo bench -p pdeshape --bench dynamic -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^J =|^dynamic|time:"
echo "== NumPy/SciPy peer of the dynamic scheme"
python3 bench/peers/numpy_dynamic.py 11
echo "== the same J = 2000, L = 30000 run given by formulas, whole pdeshape curve process (3 runs)"
cargo build --release -p pdeshape-cli
for i in 1 2 3; do
  /usr/bin/time -f "%e s wall, %U s user" "${CARGO_TARGET_DIR:-target}/release/pdeshape" curve bench/dynamic_section33_j2000.toml -o /tmp/dynamic_j2000.csv
done
echo "== B-spline grid: pdeshape (cargo bench)"
cargo bench -p pdeshape --bench spline -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^bspline|^X\[|time:"
echo "== B-spline grid: SciPy peer (BLAS threads as installed, then one thread)"
python3 bench/peers/scipy_bspline_grid.py 60
OPENBLAS_NUM_THREADS=1 python3 bench/peers/scipy_bspline_grid.py 60 | head -1
echo "== finite differences: 256 x 256 biharmonic patch (cargo bench), then libigl on the same grid"
cargo bench -p pdeshape --bench fd -- --warm-up-time 1 --measurement-time 10 2>&1 | grep -E "^fd |time:"
python3 bench/peers/libigl_biharmonic.py 256 5
python3 bench/peers/libigl_biharmonic.py 256 3 --periodic
echo "== pdeshape analysis (cargo bench)"
cargo bench -p pdeshape --bench analysis -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^analysis|time:"
echo "== pdeshape BFS splines and the section-6 blend (cargo bench)"
cargo bench -p pdeshape --bench bfs -- --warm-up-time 2 --measurement-time 10 2>&1 | grep -E "^bfs_|^blend_|time:"
echo "== scikit-fem peer (ElementQuadBFS; pip install scikit-fem)"
python3 bench/peers/skfem_bfs.py 32 64 128
echo "== optimisation of 5000 evaluations, 1 and 2 threads (cargo bench)"
cargo bench -p pdeshape --bench optimize 2>&1 | grep -E "^optimize_5000|time:"
echo "== vesicle reference minima (SciPy)"
python3 bench/peers/vesicle_reference.py
echo "== splinepde (cargo bench)"
cargo bench -p pdeshape --bench splinepde -- --warm-up-time 2 --measurement-time 8 2>&1 | grep -E "^splinepde|time:|20x20"
