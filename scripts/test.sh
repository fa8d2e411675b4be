#!/usr/bin/env bash
# Runs every check and test: formatting, lints, the host workspace's tests, the firmware's
# release image for the board, and the maker pack's design checks (scripts/hardware.sh). Exits
# non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

step() { printf '\n== %s\n' "$*"; }

step "format"
cargo fmt --all -- --check
(cd firmware && cargo fmt -- --check)

step "lint (host workspace)"
cargo clippy --workspace --all-targets --locked -- -D warnings

step "tests (host workspace)"
cargo test --workspace --locked

step "firmware: lint and release image for thumbv7em-none-eabihf"
(cd firmware && cargo clippy --release --locked --workspace -- -D warnings && cargo build --release --locked)
scripts/firmware-size.sh
scripts/firmware-bin.sh

step "hardware: the maker pack's rules check, netlist, bill of materials, pins and values"
scripts/hardware.sh

step "all checks passed"
