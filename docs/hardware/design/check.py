"""The maker pack's checks, run by scripts/test.sh through scripts/hardware.sh:

* SKiDL's electrical rules check of the design: no error and no warning (and, so that a clean
  result means something, the same check must object once a pin is disconnected);
* the KiCad netlist, the bill of materials and the pictures in docs/hardware/ are what the
  design makes now (`scripts/hardware.sh --update` rewrites them);
* the Black Pill's pins in the schematic are the ones firmware/src/main.rs uses, and the ones
  docs/hardware.md's pin map lists;
* the computed values do what their comments promise: the receiver chain's gain and band at
  40 kHz (nodal analysis with the op-amp's finite gain-bandwidth), the comparator's threshold
  and hysteresis, the boost converter's output, the switch filters.

Prints one line per check and `hardware: N passed, M failed`; exits 1 if any failed.
"""

import difflib
import math
import pathlib
import re
import sys

import numpy as np

import circuit
import values as v
from analysis import chain_gain, chain_peak, db

HERE = pathlib.Path(__file__).resolve().parent
OUT = HERE.parent
ROOT = OUT.parent.parent
NETLIST = OUT / "penscape-base.net"
BOM = OUT / "bom.csv"

results = []


def check(name, ok, detail=""):
    results.append(ok)
    print(f"{'ok  ' if ok else 'FAIL'} {name}{': ' + detail if detail else ''}")


def check_chain():
    g40 = db(chain_gain(v.F0))
    check("receiver chain: gain at 40 kHz 60 ± 3 dB", abs(g40 - 60) <= 3, f"{g40:.1f} dB")
    freqs = np.linspace(20e3, 70e3, 2001)
    gains = np.array([chain_gain(f) for f in freqs])
    peak = freqs[int(np.argmax(gains))]
    check("receiver chain: peak within 40 ± 2 kHz", abs(peak - v.F0) <= 2e3, f"{peak / 1e3:.2f} kHz")
    band = freqs[gains >= gains.max() / math.sqrt(2)]
    width = band[-1] - band[0]
    check("receiver chain: −3 dB band 4–10 kHz (passes an 8-period burst, rejects the rest)",
          4e3 <= width <= 10e3, f"{band[0] / 1e3:.1f}–{band[-1] / 1e3:.1f} kHz")
    alt_peak, alt_gain = chain_peak(v.OPAMP_ALT_GBW)
    check(f"receiver chain with the alternative op-amp ({v.OPAMP_ALT_GBW / 1e6:.0f} MHz): 60 ± 3 dB, peak 40 ± 2 kHz",
          abs(db(chain_gain(v.F0, gbw=v.OPAMP_ALT_GBW)) - 60) <= 3 and abs(alt_peak - v.F0) <= 2e3,
          f"{db(chain_gain(v.F0, gbw=v.OPAMP_ALT_GBW)):.1f} dB at 40 kHz, peak {alt_peak / 1e3:.1f} kHz")
    rejection = db(chain_gain(v.F0)) - max(db(chain_gain(20e3)), db(chain_gain(80e3)))
    check("receiver chain: ≥ 15 dB less at 20 and 80 kHz", rejection >= 15, f"{rejection:.1f} dB")
    return g40, peak, band


def check_comparator():
    lv = v.comparator_levels(v.R_TH_BOT)
    above = lv["rise"] - lv["rest"]
    hyst = lv["rise"] - lv["fall"]
    check("comparator: trips 150 ± 10 mV above the resting envelope", abs(above - 0.150) <= 0.010,
          f"rest {lv['rest']:.3f} V, trips at {lv['rise']:.3f} V (VTH {lv['vth']:.3f} V)")
    check("comparator: hysteresis 50 ± 5 mV", abs(hyst - 0.050) <= 0.005, f"{hyst * 1e3:.1f} mV")
    # With the output high the hysteresis network pulls the resting envelope up: it must stay
    # below the falling trip point, or the output would never return low.
    g1, g2 = 1 / v.RENV, 1 / (v.RIN + v.RHYS)
    rest_high = (v.VREF * g1 + v.V33 * g2) / (g1 + g2)
    check("comparator: returns low after the burst", rest_high < lv["fall"] - 0.010,
          f"rest with output high {rest_high:.3f} V < {lv['fall']:.3f} V")
    return lv


def check_power_and_switches():
    slope, inrush, ramp = v.soft_start()
    check("soft start: the switched 146 µF charge below USB's 100 mA unit load", inrush < v.USB_UNIT_LOAD_A,
          f"{slope:.0f} V/s, {inrush * 1e3:.0f} mA, 5 V in {ramp * 1e3:.0f} ms")
    check("soft start: the ramp ends within 100 ms (the firmware waits that long before bursts)", ramp < 0.1,
          f"{ramp * 1e3:.0f} ms")
    vout = v.boost_vout()
    check("boost: 12 V ± 3 %", abs(vout - 12) <= 0.36, f"{vout:.2f} V")
    swing = v.tx_swing()
    check("transmitter: ≥ 95 % of the 24 V swing reaches the transducer past its DC block", swing >= 0.95 * 24,
          f"{swing:.1f} V peak to peak")
    droop = v.burst_droop()
    check("12 V rail: a burst droops it < 1 %", droop < 0.12, f"{droop * 1e3:.1f} mV")
    press = v.R_SW_SERIES * v.C_SW
    release = (v.R_SW_SERIES + v.R_SW_PULLUP) * v.C_SW
    check("switch inputs: τ 100 µs closing, < 1 ms opening (debounce 5 ms)",
          abs(press - 100e-6) < 1e-9 and release < 1e-3, f"{press * 1e6:.0f} µs, {release * 1e3:.2f} ms")


# --- Pins: firmware, schematic, docs -----------------------------------------------------------


def firmware_pins():
    """The Black Pill pins firmware/src/main.rs hands to each function."""
    text = (ROOT / "firmware/src/main.rs").read_text()
    burst = re.findall(r"burst_pin\(p\.(P[A-C]\d+)\)", text)
    glasses = re.findall(r"glasses_pin\(p\.(P[A-C]\d+)\)", text)
    captures = re.findall(r"capture_pin\(p\.(P[A-C]\d+)\)", text)
    switches = re.findall(r"Input::new\(p\.(P[A-C]\d+),\s*Pull::Up\)", text)
    return burst, glasses, captures, switches


def doc_pins():
    """docs/hardware.md's pin map: pin → function text."""
    rows = {}
    for line in (ROOT / "docs/hardware.md").read_text().splitlines():
        m = re.match(r"\|\s*(P[A-C]\d+)\s*\|\s*([^|]+)\|", line)
        if m:
            rows[m.group(1)] = m.group(2).strip()
    return rows


def net_of(part, pin_name):
    p = part[pin_name]
    return p.net.name if p.net is not None else None


def check_rig():
    """The bench rig's picture (pictures.RIG_WIRES) against the board and the rig's firmware:
    its Black Pill pins are the schematic's burst, capture and switch pins, in order, and its
    Pico pins are those hil-tests/rig/src/main.rs hands to the PIO blocks and the switch lines."""
    import pictures

    wires = [w for w in pictures.RIG_WIRES if w[0] != "GND"]
    pill = []
    for pin, _, _, _ in wires:
        if pin not in pill:
            pill.append(pin)
    want = [circuit.PIN_BURST] + list(circuit.PINS_CAPTURE) + list(circuit.PINS_SWITCH)
    check("rig picture: its Black Pill pins are the schematic's", pill == want, f"picture {pill}")
    text = (ROOT / "hil-tests/rig/src/main.rs").read_text()
    used = [f"GP{a or b}" for a, b in re.findall(r"make_pio_pin\(p\.PIN_(\d+)\)|Flex::new\(p\.PIN_(\d+)\)", text)]
    pico = [gp for _, _, gp, _ in wires]
    check("rig picture: its Pico pins are the rig firmware's, in order", pico == used, f"picture {pico}, main.rs {used}")


def check_pins(pill):
    burst, glasses, captures, switches = firmware_pins()
    check("firmware: burst pin is the schematic's", burst == [circuit.PIN_BURST], f"main.rs {burst}")
    check("firmware: glasses' burst pin is the schematic's", glasses == [circuit.PIN_GLASSES], f"main.rs {glasses}")
    check("firmware: capture pins (receivers 0–7, in order) are the schematic's",
          captures == circuit.PINS_CAPTURE, f"main.rs {captures}")
    check("firmware: switch pins (SW1–SW3, in order) are the schematic's",
          switches == circuit.PINS_SWITCH, f"main.rs {switches}")
    boost_en = re.findall(r"Output::new\(p\.(P[A-C]\d+),\s*Level::Low", (ROOT / "firmware/src/main.rs").read_text())
    check("firmware: the boost's enable pin is the schematic's", boost_en == [circuit.PIN_BOOST_EN],
          f"main.rs {boost_en}")
    # In the netlist: the burst reaches the driver, each capture pin its connector and module,
    # each switch pin its filter.
    parts = {p.ref: p for p in circuit.parts()}
    ok = net_of(pill, circuit.PIN_BURST) == net_of(parts["U3"], "INA") == net_of(parts["U2"], "A")
    check("schematic: the burst pin drives the TC4427 and the inverter", ok)
    ok = net_of(pill, circuit.PIN_GLASSES) == net_of(parts["U5"], "INA") == net_of(parts["U4"], "A")
    check("schematic: the glasses' burst pin drives their TC4427 and inverter", ok)
    bad = []
    for k, pin in enumerate(circuit.PINS_CAPTURE):
        net = net_of(pill, pin)
        if net != net_of(parts[f"J{10 + k}"], "2"):
            bad.append(f"receiver {k}: {pin} not on J{10 + k} pin 2")
        if k < circuit.RECEIVERS_BUILT and net != net_of(parts[f"R{100 * (k + 1) + 15}"], "2"):
            bad.append(f"receiver {k}: {pin} not at its comparator's output resistor")
    check("schematic: each capture pin reaches its receiver connector and comparator", not bad, "; ".join(bad))
    bad = [f"SW{i + 1}" for i, pin in enumerate(circuit.PINS_SWITCH)
           if net_of(pill, pin) != net_of(parts[f"R{5 + 2 * i}"], "2")]
    check("schematic: each switch pin is behind its 1 k / 100 nF filter", not bad, ", ".join(bad))
    docs = doc_pins()
    expected = {circuit.PIN_BURST: "burst", circuit.PIN_GLASSES: "glasses' burst"}
    expected.update({pin: f"receiver {k}" for k, pin in enumerate(circuit.PINS_CAPTURE)})
    expected.update({pin: f"SW{i + 1}" for i, pin in enumerate(circuit.PINS_SWITCH)})
    expected.update({circuit.PIN_BOOST_EN: "boost enable", circuit.PIN_BOOT_UART_RX: "pulled down"})
    bad = [f"{pin} ({what}): docs say {docs.get(pin)!r}" for pin, what in expected.items()
           if what not in (docs.get(pin) or "")]
    check("docs/hardware.md: the pin map lists the same pins", not bad, "; ".join(bad))


# --- Generated files ---------------------------------------------------------------------------


def compare(path, text, update):
    if update:
        path.write_text(text)
        check(f"{path.relative_to(ROOT)} written", True)
        return
    old = path.read_text() if path.exists() else ""
    same = old == text
    detail = ""
    if not same:
        diff = list(difflib.unified_diff(old.splitlines(), text.splitlines(), lineterm="", n=0))
        detail = f"differs from the design ({len(diff)} diff lines, first: {diff[2:4]}); run scripts/hardware.sh --update"
    check(f"{path.relative_to(ROOT)} is the design's", same, detail)


def main():
    update = "--update" in sys.argv[1:]
    pill = circuit.build()
    erc = circuit.erc()
    check("ERC: no errors, no warnings", erc.errors == 0 and erc.warnings == 0,
          f"{erc.errors} errors, {erc.warnings} warnings" + "".join("\n     " + m for m in erc.messages))
    parts = circuit.parts()
    nets = {p.net.name for part in parts for p in part.pins if p.net is not None}
    print(f"     {len(parts)} parts, {len(nets)} nets")
    compare(NETLIST, circuit.netlist(), update)
    compare(BOM, circuit.bom_csv(), update)
    check_pins(pill)
    check_chain()
    check_comparator()
    check_power_and_switches()
    check_rig()

    import pictures

    for path, text in pictures.all_pictures():
        compare(path, text, update)

    # The rules check objects to a broken design: disconnect a comparator's shutdown pin.
    shdn = {p.ref: p for p in circuit.parts()}["U102"]["SHDN"]
    shdn.disconnect()
    broken = circuit.erc()
    check("ERC objects when a pin is left unconnected", broken.warnings + broken.errors > 0,
          f"{broken.errors} errors, {broken.warnings} warnings")

    failed = results.count(False)
    print(f"hardware: {len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
