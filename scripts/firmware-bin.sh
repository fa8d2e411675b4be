#!/usr/bin/env bash
# Builds the board's release image and writes it as a raw binary for the ROM DFU bootloader:
# firmware/target/pen-firmware.bin, to be flashed at 0x08000000 with
#   dfu-util -a 0 -s 0x08000000:leave -D firmware/target/pen-firmware.bin
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
(cd firmware && cargo build --release --locked -q)
# rustc ships rust-objcopy (LLVM's objcopy) in its sysroot; older toolchains have it in the
# llvm-tools component instead.
sysroot=$(rustc --print sysroot)
objcopy=$(ls "$sysroot"/lib/rustlib/*/bin/rust-objcopy "$sysroot"/lib/rustlib/*/bin/llvm-objcopy 2>/dev/null | head -n 1 || true)
if [ -z "$objcopy" ]; then
    rustup component add llvm-tools >/dev/null 2>&1
    objcopy=$(ls "$sysroot"/lib/rustlib/*/bin/llvm-objcopy | head -n 1)
fi
elf=firmware/target/thumbv7em-none-eabihf/release/pen-firmware
bin=firmware/target/pen-firmware.bin
# The tool links against the toolchain's own LLVM library, which lives in the sysroot.
LD_LIBRARY_PATH="$sysroot/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$objcopy" -O binary "$elf" "$bin"
echo "$bin: $(stat -c %s "$bin") bytes"
