#!/usr/bin/env bash
# Animations read back by independent tools: the Khronos glTF validator and trimesh, installed
# in .ci/readers/ by .ci/readers.sh (which .ci/run calls first). Fails if they are missing.
set -euo pipefail
cd "$(dirname "$0")/.."
readers=.ci/readers
py="${ANIM_PYTHON:-$readers/.venv/bin/python}"
validator="${ANIM_VALIDATOR:-$readers/validate_gltf.mjs}"
if [ ! -x "$py" ] || [ ! -f "$validator" ]; then
    echo "FAIL: $py or $validator missing: run .ci/readers.sh first" >&2
    exit 1
fi
# The binary as the test command builds it (the same features: nothing is rebuilt after it).
cargo test --workspace --release --no-run --quiet
bin="${CARGO_TARGET_DIR:-target}/release/pdeshape"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$py" .ci/anim/check.py "$bin" "$out" "$validator"
