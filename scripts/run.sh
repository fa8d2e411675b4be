#!/usr/bin/env bash
# The main job. Until the modeler exists this is the most end-to-end path there is: build the
# board's firmware image and the host tools from the one protocol crate, run the simulated pen
# through the firmware core, then show the report descriptor the device presents and a pen
# report decoded by the host.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

cargo build --release --locked -q -p pen-host -p pen-sim
(cd firmware && cargo build --release --locked -q)
echo "firmware: firmware/target/thumbv7em-none-eabihf/release/pen-firmware"
scripts/firmware-size.sh

echo
echo "the simulated pen through the firmware core (pen-sim accuracy):"
target/release/pen-sim accuracy

penctl=target/release/penctl
echo
echo "USB HID report descriptor (penctl descriptor):"
$penctl descriptor
echo
report=010dd204c9fd7a03341204030201050712
echo "a pen report as the host decodes it (penctl decode $report):"
$penctl decode "$report"
