#!/usr/bin/env bash
# Prints the firmware image's flash and static RAM use against what the part gives the program
# (firmware/stm32f411ce.x): 256 KiB of flash (sectors 0-5; 6 and 7 hold the configuration) and
# the 112 KiB of RAM above the 16 KiB stack. The linker refuses an image that does not fit; this
# warns well before: above 75 % of either (DESIGN.md: at least 25 % headroom), so that growth is
# seen and decided on, not met as a cliff.
# Flash: vector table, code, read-only data and the initial values of .data.
# Static RAM: .data, .bss and .uninit (the stack is below them, at the bottom of RAM).
set -euo pipefail
elf=${1:-"$(dirname "$0")/../firmware/target/thumbv7em-none-eabihf/release/pen-firmware"}
size -A "$elf" | awk '
    $1 == ".vector_table" || $1 == ".text" || $1 == ".rodata" { flash += $2 }
    $1 == ".data" { flash += $2; ram += $2 }
    $1 == ".bss" || $1 == ".uninit" { ram += $2 }
    # The stack guard: every static above the stack (0x2000_4000), none where an overflow runs.
    ($1 == ".data" || $1 == ".bss" || $1 == ".uninit") && $2 > 0 && $3 < 536887296 {
        printf "firmware image: %s at %#x, inside the stack (below 0x20004000)\n", $1, $3; bad = 1
    }
    END {
        flash_max = 256 * 1024; ram_max = 112 * 1024
        printf "firmware image: flash %d bytes (%.1f KiB, %.0f %% of 256 KiB), static RAM %d bytes (%.1f KiB, %.0f %% of 112 KiB; stack 16 KiB)\n",
            flash, flash / 1024, 100 * flash / flash_max, ram, ram / 1024, 100 * ram / ram_max
        if (bad) exit 1
        if (flash > flash_max || ram > ram_max) { print "firmware image exceeds the part"; exit 1 }
        if (flash > 0.75 * flash_max) print "warning: firmware flash above 75 % of its 256 KiB: less than the 25 % headroom DESIGN.md asks"
        if (ram > 0.75 * ram_max) print "warning: firmware static RAM above 75 % of its 112 KiB: less than the 25 % headroom DESIGN.md asks"
    }'
