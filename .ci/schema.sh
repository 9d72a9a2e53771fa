#!/usr/bin/env bash
# The JSON schemas of `pdeshape schema --kind design|morph|template` through the Even Better
# TOML language server (@taplo/lsp from npm, locked in .ci/schema/package-lock.json): every
# example valid, per-type checks and completion in [curves.X] tables. Fails if npm or the
# package cannot be installed.
set -euo pipefail
cd "$(dirname "$0")/.."
(cd .ci/schema && npm ci --silent --no-audit --no-fund)
# The binary as the test command builds it (the same features: nothing is rebuilt after it).
cargo test --workspace --release --no-run --quiet
bin="${CARGO_TARGET_DIR:-target}/release/pdeshape"
node .ci/schema/check.mjs "$bin" "$PWD"
