#!/usr/bin/env bash
# Prints the bench rig's image size (hil-tests/rig): flash (boot loader, vector table, code,
# read-only data, .data's initial values) and static RAM (.data, .bss, .uninit; the stack is
# not counted). The Pico has 2 MiB of flash and 264 KiB of RAM, so there is no budget to
# enforce: the figure is printed so that a change that bloats the image shows.
set -euo pipefail
elf=${1:-"$(dirname "$0")/../hil-tests/rig/target/thumbv6m-none-eabi/release/pen-rig"}
size -A "$elf" | awk '
    $1 == ".boot2" || $1 == ".vector_table" || $1 == ".text" || $1 == ".rodata" { flash += $2 }
    $1 == ".data" { flash += $2; ram += $2 }
    $1 == ".bss" || $1 == ".uninit" { ram += $2 }
    END { printf "bench rig image: flash %d bytes (%.1f KiB), static RAM %d bytes (%.1f KiB)\n", flash, flash / 1024, ram, ram / 1024 }'
