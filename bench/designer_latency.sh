#!/usr/bin/env bash
# The designer's drag latency table (BENCHMARKS.md): `e2e/latency.mjs` on the cup, the wine
# glass, the teacup and the five-sided panel at the e2e tests' viewport (1280 × 800) and at
# 1400 × 900, with `--disable-gpu` and with SwiftShader, shaded and with zebra stripes.
# usage: bash bench/designer_latency.sh PDESHAPE [MOVES]   (MOVES default 150)
# Needs the e2e directory's packages (`cd e2e && npm ci`) and Debian's chromium.
set -euo pipefail
if [ $# -lt 1 ]; then
  echo "usage: bash bench/designer_latency.sh PDESHAPE [MOVES]" >&2
  exit 2
fi
bin=$(realpath "$1")
moves=${2:-150}
cd "$(dirname "$0")/../e2e"
for viewport in 1280x800 1400x900; do
  for renderer in disable-gpu swiftshader; do
    for shading in shaded zebra; do
      echo "== $(date -u +%H:%M:%S) load $(cut -d' ' -f1 /proc/loadavg)"
      PDESHAPE_BIN="$bin" node latency.mjs "$moves" "$viewport" "$renderer" "$shading"
    done
  done
done
