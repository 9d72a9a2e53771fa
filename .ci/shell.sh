#!/usr/bin/env bash
# Thin-shell strength analysis: installs CalculiX and runs the tests that need it. They fail (not
# skip) when the solver is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v ccx >/dev/null 2>&1; then
    apt-get update -qq
    apt-get install -y -qq calculix-ccx
fi
cargo test --release --workspace --test shell_ccx -- --ignored
cargo test --release -p pdeshape-cli --test shell -- --ignored
