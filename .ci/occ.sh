#!/usr/bin/env bash
# STEP and IGES files of every example checked by OpenCascade (cadquery-ocp, pinned in
# .ci/occ-requirements.txt, installed into a venv here). Fails when the bindings are missing.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${OCC_VENV:-.ci/.venv-occ}"
if [ ! -x "$venv/bin/python" ]; then
  python3.11 -m venv "$venv" || python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q -r .ci/occ-requirements.txt
# The binary as the test command builds it (the same features: nothing is rebuilt after it).
cargo test --workspace --release --no-run --quiet
bin="${CARGO_TARGET_DIR:-target}/release/pdeshape"
"$venv/bin/python" bench/peers/occ_check.py "$bin" examples
# The designer's STEP downloads read back by OpenCascade (headless Chromium, after .ci/e2e.sh
# has installed the browser and the driver).
occ_python="$(cd "$venv/bin" && pwd)/python"
(cd e2e && npm ci --no-audit --no-fund >/dev/null && OCC_PYTHON="$occ_python" npm run test:occ)
