#!/bin/sh
# A new user's first steps, as the README gives them: clones this repository into a new
# directory, runs the commands of the README's "Install" block exactly as written, then every
# command of its "The first hour" block with the `pdeshape` that `cargo install` put on the PATH,
# and prints how long each command took. `cargo install` is pointed at a directory of its own
# (CARGO_INSTALL_ROOT) so the user's ~/.cargo/bin is left alone; nothing else is set.
#
#   .ci/fresh-clone.sh                 # everything (about 15 minutes on 2 cores)
#   .ci/fresh-clone.sh --install-only  # skip `cargo test` (the README's second command)
#
# Not part of .ci/run (its first command alone builds the tool from scratch); the test suite
# checks the README's blocks on every run (`readme` in crates/pdeshape-cli/tests/cli).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
skip_tests=no
[ "${1:-}" = "--install-only" ] && skip_tests=yes
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT INT TERM
git clone -q "$here" "$work/pdeshape"
cd "$work/pdeshape"
export CARGO_INSTALL_ROOT="$work/install"
export PATH="$CARGO_INSTALL_ROOT/bin:$PATH"

# The lines of the first ```sh block after a heading.
block() {
    awk -v h="$1" '
        $0 == h { inside = 1; next }
        inside && /^```sh/ { code = 1; next }
        code && /^```/ { exit }
        code && NF && $1 !~ /^#/ { print }
    ' README.md
}

run() {
    start=$(date +%s)
    echo "\$ $1"
    sh -c "$1"
    echo "  ($(($(date +%s) - start)) s)"
}

block "## Install" > "$work/install.txt"
block "## The first hour" > "$work/first.txt"
[ -s "$work/install.txt" ] && [ -s "$work/first.txt" ] || {
    echo "error: README.md has no sh block under '## Install' or '## The first hour'" >&2
    exit 1
}
while IFS= read -r cmd; do
    case "$cmd" in
        "cargo test"*) [ "$skip_tests" = yes ] && { echo "(skipped: $cmd)"; continue; } ;;
    esac
    run "$cmd"
done < "$work/install.txt"
command -v pdeshape > /dev/null || { echo "error: pdeshape is not on the PATH after the install block" >&2; exit 1; }
while IFS= read -r cmd; do
    run "$cmd"
done < "$work/first.txt"
echo "fresh clone: every command of the README's install and first-hour blocks succeeded"
