#!/usr/bin/env bash
# Prints the firmware image's flash and static RAM use against the targets (64 KiB, 16 KiB).
# Flash: vector table, code, read-only data and the initial values of .data.
# Static RAM: .data, .bss and .uninit (the stack grows down from the top of RAM, not counted).
set -euo pipefail
elf=${1:-"$(dirname "$0")/../firmware/target/thumbv7em-none-eabihf/release/pen-firmware"}
size -A "$elf" | awk '
    $1 == ".vector_table" || $1 == ".text" || $1 == ".rodata" { flash += $2 }
    $1 == ".data" { flash += $2; ram += $2 }
    $1 == ".bss" || $1 == ".uninit" { ram += $2 }
    END {
        printf "firmware image: flash %d bytes (%.1f KiB of 64 KiB target), static RAM %d bytes (%.1f KiB of 16 KiB target)\n",
            flash, flash / 1024, ram, ram / 1024
        if (flash > 65536 || ram > 16384) { print "firmware image exceeds its size targets"; exit 1 }
    }'
