#!/usr/bin/env bash
# The main job: the modeler's built-in demo. Without a pen attached, penmodel runs the simulated
# pen through the whole chain — hand and acoustics, the firmware core, report bytes, the host's
# decoding, a calibration fitted by touching targets, pen events — into the modeler, which shows
# the session in a window, or, without a display, writes it to ./out (frames and their animation,
# the final heightmap as PNG and float32, meshes, renders, the document). The board's firmware
# image is built too, from the same core and protocol crates, and its size printed.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

(cd firmware && cargo build --release --locked -q)
echo "firmware: firmware/target/thumbv7em-none-eabihf/release/pen-firmware"
scripts/firmware-size.sh

cargo build --release --locked -q -p penmodel -p pen-host -p pen-hil
echo
echo "penmodel: the built-in demo (the simulated pen, calibrated, modeling the seed's session)"
target/release/penmodel "$@"
