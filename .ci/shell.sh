#!/usr/bin/env bash
# Thin-shell strength analysis: installs CalculiX and runs the tests that need it (closed forms,
# the container, the strength optimisation, `render --color shear`), then reads the container's
# VTU with meshio (pinned in .ci/shell-requirements.txt, in a venv here) and checks it against
# the report. They fail (not skip) when the solver or the reader is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v ccx >/dev/null 2>&1; then
    apt-get update -qq
    apt-get install -y -qq calculix-ccx
fi
# --workspace: the features of the README's test command, so nothing is rebuilt after it.
cargo test --release --workspace --test integration --test cli -- --ignored shell
bin="${CARGO_TARGET_DIR:-target}/release/pdeshape"
venv="${SHELL_VENV:-.ci/.venv-shell}"
if [ ! -x "$venv/bin/python" ]; then
    python3.11 -m venv "$venv" || python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q -r .ci/shell-requirements.txt
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$bin" shell examples/yoghurt.toml --json -q \
    -o "$out/yoghurt.vtu" > "$out/yoghurt.json"
"$venv/bin/python" .ci/shell_vtu_check.py "$out/yoghurt.vtu" "$out/yoghurt.json"
