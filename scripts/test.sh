#!/usr/bin/env bash
# Runs every check and test: formatting, lints, the host workspace's tests, the real-kernel
# test, the firmware's release image for the board, the bench rig's image (hil-tests/rig), and
# the maker pack's design checks (scripts/hardware.sh). Exits non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

step() { printf '\n== %s\n' "$*"; }

step "format"
cargo fmt --all -- --check
(cd firmware && cargo fmt -- --check)
(cd hil-tests/rig && cargo fmt -- --check)

step "lint (host workspace)"
cargo clippy --workspace --all-targets --locked -- -D warnings

step "tests (host workspace)"
# PEN_REQUIRE_X: the window test fails, rather than skips, without Xvfb (setup.sh installs it).
PEN_REQUIRE_X=1 cargo test --workspace --locked --exclude pen-kernel

step "real kernel: Debian's kernel in QEMU, the descriptor through uhid, pend on hidraw, uinput"
# On its own so its boot mode, time and per-step results are in the log.
cargo test -p pen-kernel --locked -- --nocapture

step "firmware: lint and release image for thumbv7em-none-eabihf"
(cd firmware && cargo clippy --release --locked --workspace -- -D warnings && cargo build --release --locked)
scripts/firmware-size.sh
scripts/firmware-bin.sh

step "bench rig: lint and release image for thumbv6m-none-eabi (Raspberry Pi Pico)"
(cd hil-tests/rig && cargo clippy --release --locked -- -D warnings && cargo build --release --locked)
scripts/rig-size.sh

step "hardware: the maker pack's rules check, netlist, bill of materials, pins and values"
scripts/hardware.sh

step "all checks passed"
