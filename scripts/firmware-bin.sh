#!/usr/bin/env bash
# Builds the board's release image and writes it as a raw binary for the ROM DFU bootloader:
# firmware/target/pen-firmware.bin, to be flashed at 0x08000000 with
#   dfu-util -a 0 -s 0x08000000:leave -D firmware/target/pen-firmware.bin
#
# Needs only rustup's toolchain and the thumbv7em-none-eabihf target (installed here if missing):
# no emulator, no Debian package. The ELF → binary step is LLVM's objcopy as the toolchain
# ships it (`rust-objcopy` in rustc's sysroot, which rustc itself uses to strip binaries); a
# toolchain without it gets the `llvm-tools` rustup component, which has `llvm-objcopy`.
# Checks the image before it is flashed: its vector table must start with the stack's top (the
# stack is the bottom 16 KiB of RAM, firmware/stm32f411ce.x) and a reset vector in the program's
# flash, and the image must fit sectors 0-5.
set -euo pipefail
cd "$(dirname "$0")/.."
SETUP=firmware source scripts/setup.sh
(cd firmware && cargo build --release --locked -q)
sysroot=$(rustc --print sysroot)
find_objcopy() {
    ls "$sysroot"/lib/rustlib/*/bin/rust-objcopy "$sysroot"/lib/rustlib/*/bin/llvm-objcopy 2>/dev/null | head -n 1 || true
}
objcopy=$(find_objcopy)
if [ -z "$objcopy" ]; then
    echo "setup: adding Rust component llvm-tools" >&2
    rustup component add llvm-tools >/dev/null 2>&1
    objcopy=$(find_objcopy)
fi
[ -n "$objcopy" ] || { echo "firmware-bin: no LLVM objcopy in $sysroot (rustup component add llvm-tools)" >&2; exit 1; }
elf=firmware/target/thumbv7em-none-eabihf/release/pen-firmware
bin=firmware/target/pen-firmware.bin
# The tool links against the toolchain's own LLVM library, which lives in the sysroot.
LD_LIBRARY_PATH="$sysroot/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$objcopy" -O binary "$elf" "$bin"

# Word 0: the initial stack pointer, the top of the stack at the bottom of RAM
# (0x2000_0000 + 16 KiB, firmware/stm32f411ce.x); word 1: the reset handler, a Thumb address
# (odd) inside the program's flash, sectors 0–5 (below 0x0804_0000).
read -r sp reset < <(od -A n -t x4 -N 8 --endian=little "$bin")
size=$(stat -c %s "$bin")
if [ "$sp" != 20004000 ] || (( (16#$reset & 1) == 0 || 16#$reset < 0x08000000 || 16#$reset >= 0x08040000 )); then
    echo "firmware-bin: $bin does not start with the board's vector table (stack $sp, reset $reset)" >&2
    exit 1
fi
if (( size > 0x40000 )); then
    echo "firmware-bin: $bin is $size bytes, more than sectors 0–5 (256 KiB) hold" >&2
    exit 1
fi
echo "$bin: $size bytes (stack 0x$sp, reset 0x$reset)"
