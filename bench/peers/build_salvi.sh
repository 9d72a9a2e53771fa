#!/usr/bin/env bash
# Builds the peer for n-sided fills from Péter Salvi's transfinite surface library (MIT) and its
# geometry library libgeom (MIT), at pinned commits, together with bench/peers/salvi_fill.cc.
#
# usage: bench/peers/build_salvi.sh OUTDIR
#
# OUTDIR/src/transfinite, OUTDIR/src/libgeom   the sources at the pinned commits
# OUTDIR/obj/                                   object files
# OUTDIR/salvi_fill                             the driver (see salvi_fill.cc and salvi_fill.py)
#
# Needs git, g++ (C++17) and Eigen 3 (Debian: `apt-get install libeigen3-dev`; or set
# EIGEN_INCLUDE to a directory holding Eigen/). The library's own CMake files want CMake 4.0
# and build its test and utility programs too; this script compiles the library's sources
# directly instead (the same list as src/transfinite/CMakeLists.txt, the same -std=c++17 -O3),
# so CMake is not needed. Shewchuk's Triangle is not used (it is not free software): without it
# the library's biharmonic patch meshes its domain with its own regular grid.
#
# TRANSFINITE_REPO and LIBGEOM_REPO override where the sources are cloned from (a URL or a
# local git directory holding the pinned commits). TWIST_STEP: see the end of this script.
set -euo pipefail

TRANSFINITE_COMMIT=2324dcb781844e98aca686441e156b820a993baa # 2026-03-02
# 2025-05-21, the commit transfinite's submodule points at
LIBGEOM_COMMIT=4373e32c3726f62773a418037a5675a3f9bde707
TRANSFINITE_REPO=${TRANSFINITE_REPO:-https://github.com/salvipeter/transfinite}
LIBGEOM_REPO=${LIBGEOM_REPO:-https://github.com/salvipeter/libgeom}

if [ $# -ne 1 ]; then
    echo "usage: $0 OUTDIR" >&2
    exit 2
fi
out=$(mkdir -p "$1" && cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)

checkout() { # repo commit dir
    if [ ! -d "$3/.git" ]; then
        git clone --quiet "$1" "$3"
    fi
    if ! git -C "$3" cat-file -e "$2^{commit}" 2>/dev/null; then
        git -C "$3" fetch --quiet origin "$2" || git -C "$3" fetch --quiet origin
    fi
    git -C "$3" -c advice.detachedHead=false checkout --quiet "$2"
}
mkdir -p "$out/src" "$out/obj"
checkout "$TRANSFINITE_REPO" "$TRANSFINITE_COMMIT" "$out/src/transfinite"
checkout "$LIBGEOM_REPO" "$LIBGEOM_COMMIT" "$out/src/libgeom"

eigen=${EIGEN_INCLUDE:-/usr/include/eigen3}
if [ ! -f "$eigen/Eigen/Sparse" ]; then
    echo "build_salvi.sh: Eigen 3 not found in $eigen" \
        "(apt-get install libeigen3-dev, or set EIGEN_INCLUDE)" >&2
    exit 1
fi

tf=$out/src/transfinite/src/transfinite
geom=$out/src/libgeom
flags=(-std=c++17 -O3 -DNDEBUG -fPIC -w -I"$geom" -I"$tf" -I"$eigen")

# The library's source list, from its CMakeLists.txt.
mapfile -t tf_sources < <(sed -n '/add_library(transfinite/,/)/p' "$tf/CMakeLists.txt" |
    grep -o '[A-Za-z0-9_-]*\.cc')
geom_sources=(vector.cc matrix2x2.cc matrix3x3.cc bspline.cc trimesh.cc)

jobs=()
for s in "${geom_sources[@]}"; do jobs+=("$geom/$s"); done
for s in "${tf_sources[@]}"; do jobs+=("$tf/$s"); done
compile() { # source -> obj/<dir>_<name>.o, only when newer
    local o="$OUT/obj/$(basename "$(dirname "$1")")_$(basename "${1%.cc}").o"
    if [ ! -f "$o" ] || [ "$1" -nt "$o" ]; then
        g++ "${FLAGS[@]}" -c "$1" -o "$o"
    fi
}
export -f compile
export OUT=$out
# Bash cannot export arrays: pass the flags as one string.
export FLAGS_STR="${flags[*]}"
printf '%s\n' "${jobs[@]}" |
    xargs -P "${JOBS:-2}" -I{} bash -c 'read -r -a FLAGS <<< "$FLAGS_STR"; compile "$1"' _ {}

g++ "${flags[@]}" -o "$out/salvi_fill" "$here/salvi_fill.cc" "$out"/obj/*.o

# TWIST_STEP=1e-6 also builds OUTDIR/salvi_fill_twist: the same driver with a copy of the
# library's surface.cc whose corner twists (one-sided differences of the ribbons' cross
# derivatives in Surface::updateCorner, step 1e-4) use that step instead. Only for checking
# where the corner-blended patches' G1 error comes from; the figures use the library as it is.
if [ -n "${TWIST_STEP:-}" ]; then
    grep -q 'static const double step = 1.0e-4;' "$tf/surface.cc" || {
        echo "build_salvi.sh: the twist step is no longer where this script expects it" >&2
        exit 1
    }
    mkdir -p "$out/twist"
    sed "s/static const double step = 1.0e-4;/static const double step = $TWIST_STEP;/" \
        "$tf/surface.cc" > "$out/twist/surface.cc"
    g++ "${flags[@]}" -c "$out/twist/surface.cc" -o "$out/twist/surface.o"
    g++ "${flags[@]}" -o "$out/salvi_fill_twist" "$here/salvi_fill.cc" \
        $(ls "$out"/obj/*.o | grep -v '/transfinite_surface\.o$') "$out/twist/surface.o"
    echo "built $out/salvi_fill_twist (corner twist step $TWIST_STEP)"
fi
echo "built $out/salvi_fill (transfinite $TRANSFINITE_COMMIT, libgeom $LIBGEOM_COMMIT)"
