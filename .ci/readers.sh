#!/usr/bin/env bash
# Mesh files read back by independent tools: trimesh (pip, pinned, in a venv), ADMesh (Debian)
# and the Khronos glTF validator (npm, locked). Installs what is missing, then runs
# .ci/readers/check.py against the release binary. Fails if a tool cannot be installed.
set -euo pipefail
cd "$(dirname "$0")/.."
here=.ci/readers
if ! command -v admesh >/dev/null; then
    apt-get update -qq
    apt-get install -y -qq admesh >/dev/null
fi
if [ ! -x "$here/.venv/bin/python" ]; then
    python3.11 -m venv "$here/.venv"
fi
"$here/.venv/bin/pip" install -q -r "$here/requirements.txt"
(cd "$here" && npm ci --silent --no-audit --no-fund)
# The binary as the test command builds it (the same features: nothing is rebuilt after it).
cargo test --workspace --release --no-run --quiet
bin="${CARGO_TARGET_DIR:-target}/release/pdeshape"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$here/.venv/bin/python" "$here/check.py" "$bin" "$out"
