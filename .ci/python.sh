#!/usr/bin/env bash
# The Python package (python/): a venv with the pinned test dependencies, the extension built
# once in release by maturin through `pip install ./python`, then pytest against the CLI's
# release binary. Fails when anything is missing (no test skips itself).
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${PY_VENV:-.ci/.venv-python}"
if [ ! -x "$venv/bin/python" ]; then
  python3.11 -m venv "$venv" || python3 -m venv "$venv"
fi
# An absolute path, so a relative or absolute PY_VENV both work after the `cd` below.
venv="$(cd "$venv" && pwd)"
"$venv/bin/pip" install -q --upgrade pip
"$venv/bin/pip" install -q -r python/requirements-test.txt
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
# The extension's lints (it is outside the workspace, so the workspace's clippy skips it).
cargo clippy --manifest-path python/Cargo.toml -- -D warnings
"$venv/bin/pip" install -q --force-reinstall --no-deps ./python
# The binary as the test command builds it (the same features: nothing is rebuilt after it).
cargo test --workspace --release --no-run --quiet
export PDESHAPE_CLI="$CARGO_TARGET_DIR/release/pdeshape"
cd python/tests
"$venv/bin/python" -m pytest -q -p no:cacheprovider .
