#!/usr/bin/env bash
# End-to-end tests of `pdeshape serve` in headless Chromium: installs Debian's chromium and the
# driver (playwright-core, pinned by e2e/package-lock.json), builds the binary, runs the tests.
# A missing browser or driver fails the run: nothing is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v chromium >/dev/null 2>&1; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq chromium >/dev/null
fi
test -x /usr/bin/chromium
# The binary as the test command builds it (the same features: nothing is rebuilt after it).
cargo test --workspace --release --no-run --quiet
(cd e2e && npm ci --no-audit --no-fund && npm test)
