"""The base station's electronics in SKiDL: the Black Pill and what it drives (the 12 V boost
converter, the transducer's bridge driver, the switch inputs, the receiver connectors), the pen
(its transducer, SW1–SW3 and cable) and the receiver module, built four times (receivers 0–3;
receivers 4–7 plug into the same kind of connector).

Parts are defined here with SKiDL's own tool (no KiCad symbol libraries: Debian's KiCad is 6.0,
PyPI's SKiDL needs none this way, and every pin's electrical type is stated for the rules
check). The netlist written from it is KiCad's (`kicad6` form): pcbnew imports it with the
footprints named here. Values come from values.py.

`build()` returns the circuit's parts and nets; check.py runs SKiDL's electrical rules check on
it and compares what `write()` makes with the files in docs/hardware/.
"""

import builtins
import contextlib
import csv
import io
import logging
import re

import values as v

# SKiDL warns at import about KiCad libraries it will not use (this design uses none).
logging.disable(logging.WARNING)
with contextlib.redirect_stderr(io.StringIO()):
    import skidl
    from skidl import Net, Part, Pin, POWER, SKIDL, TEMPLATE
logging.disable(logging.NOTSET)

P = Pin.types

# --- Part templates ------------------------------------------------------------------------
# pins: (number, name, electrical type). `meta`: what the bill of materials says of a part.


def template(name, prefix, footprint, pins, description, mpn, alternatives, price_usd):
    t = Part(
        tool=SKIDL,
        name=name,
        ref_prefix=prefix,
        dest=TEMPLATE,
        footprint=footprint,
        description=description,
        pins=[Pin(num=n, name=pn, func=f) for n, pn, f in pins],
    )
    t.meta = dict(mpn=mpn, alternatives=alternatives, price_usd=price_usd, description=description)
    return t


def two_pin(name, prefix, footprint, description, mpn, alternatives, price, names=("1", "2")):
    return template(name, prefix, footprint, [(1, names[0], P.PASSIVE), (2, names[1], P.PASSIVE)],
                    description, mpn, alternatives, price)


R0603 = "Resistor_SMD:R_0603_1608Metric"
C0603 = "Capacitor_SMD:C_0603_1608Metric"
C1206 = "Capacitor_SMD:C_1206_3216Metric"

RES = two_pin("R", "R", R0603, "resistor 1 % 0603", "Yageo RC0603FR-07 series", "any 1 % thick-film 0603", 0.01)
CAP = two_pin("C", "C", C0603, "capacitor X7R 0603, 50 V (decoupling)",
              "Murata GRM188R71H series", "Samsung CL10B series", 0.02)
# Capacitors that set a frequency or a time constant: C0G, whose value does not move with
# voltage or temperature.
CAP_C0G = two_pin("C", "C", C0603, "capacitor C0G/NP0 0603, 50 V, 5 % (sets a frequency)",
                  "Murata GRM1885C1H series", "Samsung CL10C series, TDK C1608C0G", 0.04)
CAP_BULK = two_pin("C", "C", C1206, "capacitor X5R 1206, 25 V", "Murata GRM31CR61E series",
                   "Samsung CL31A series", 0.12)

CAP_TX = two_pin("C", "C", "Capacitor_SMD:C_1206_3216Metric", "capacitor X7R 1206, 50 V (the transducer's DC block)",
                 "Murata GRM31MR71H104", "Samsung CL31B104KBCNNNC", 0.08)

BLACK_PILL_LEFT = ["PB12", "PB13", "PB14", "PB15", "PA8", "PA9", "PA10", "PA11", "PA12", "PA15",
                   "PB3", "PB4", "PB5", "PB6", "PB7", "PB8", "PB9", "5V", "GND", "3V3"]
BLACK_PILL_RIGHT = ["VBAT", "PC13", "PC14", "PC15", "NRST", "PA0", "PA1", "PA2", "PA3", "PA4",
                    "PA5", "PA6", "PA7", "PB0", "PB1", "PB2", "PB10", "3V3_2", "GND_2", "5V_2"]


def black_pill_pins():
    """The two 20-pin headers, numbered 1–20 down the side with PB12 and 21–40 down the other
    (WeAct's pinout of the STM32F411CE board, V2.0 and V3.0; check the silkscreen). One 5 V,
    3.3 V and GND pin each is the supply's output (the board's USB and regulator); their twins
    are plain connections."""
    pins = []
    for i, name in enumerate(BLACK_PILL_LEFT + BLACK_PILL_RIGHT, start=1):
        kind = {"5V": P.PWROUT, "GND": P.PWROUT, "3V3": P.PWROUT}.get(name, P.BIDIR)
        if name.endswith("_2") or name == "VBAT":
            kind = P.PASSIVE
        if name == "NRST":
            kind = P.INPUT
        pins.append((i, name, kind))
    return pins


BLACK_PILL = template("WeAct_BlackPill_F411CE", "A", "penscape:WeAct_BlackPill_2x20_P2.54",
                      black_pill_pins(), "WeAct Black Pill STM32F411CEU6 (25 or 8 MHz crystal, USB-C)",
                      "WeAct STM32F411CEU6 Core Board V3.0", "WeAct V2.0 (same pins); not the F401 (less RAM, 84 MHz)",
                      4.50)

MT3608 = template("MT3608", "U", "Package_TO_SOT_SMD:SOT-23-6",
                  [(1, "SW", P.PASSIVE), (2, "GND", P.PWRIN), (3, "FB", P.INPUT), (4, "EN", P.INPUT),
                   (5, "IN", P.PWRIN), (6, "NC", P.NOCONNECT)],
                  "boost converter 2 A, 1.2 MHz", "Aerosemi MT3608", "an MT3608 module set to 12 V; TI TPS61040 (0.4 A switch, 1.233 V reference: another divider)", 0.10)
L_BOOST = two_pin("L", "L", "Inductor_SMD:L_Bourns_SRR1260", "inductor 22 µH, 1.5 A", "Bourns SRR1260-220M",
                  "Sunlord SWPA6045S220MT", 0.40)
SCHOTTKY = two_pin("D_Schottky", "D", "Diode_SMD:D_SMA", "Schottky diode 40 V 3 A", "SS34",
                   "1N5819 (through-hole), B340A", 0.05, names=("K", "A"))
TC4427 = template("TC4427", "U", "Package_SO:SOIC-8_3.9x4.9mm_P1.27mm",
                  [(1, "NC1", P.NOCONNECT), (2, "INA", P.INPUT), (3, "GND", P.PWRIN), (4, "INB", P.INPUT),
                   (5, "OUTB", P.OUTPUT), (6, "VDD", P.PWRIN), (7, "OUTA", P.OUTPUT), (8, "NC8", P.NOCONNECT)],
                  "dual 1.5 A MOSFET driver, non-inverting", "Microchip TC4427AEOA", "TC4427 CPA (DIP-8), MCP1402 ×2", 1.10)
INVERTER = template("74LVC1G04", "U", "Package_TO_SOT_SMD:SOT-23-5",
                    [(1, "NC", P.NOCONNECT), (2, "A", P.INPUT), (3, "GND", P.PWRIN), (4, "Y", P.OUTPUT),
                     (5, "VCC", P.PWRIN)],
                    "single inverter", "TI SN74LVC1G04DBVR", "Nexperia 74LVC1G04GW", 0.10)
PMOS = template("AO3401A", "Q", "Package_TO_SOT_SMD:SOT-23",
                [(1, "G", P.INPUT), (2, "S", P.PASSIVE), (3, "D", P.PASSIVE)],
                "P-MOSFET −30 V −4 A, SOT-23 (the boost's soft-start switch)", "Alpha & Omega AO3401A",
                "Diodes DMP3099L, Vishay Si2301CDS", 0.08)
NMOS = template("2N7002", "Q", "Package_TO_SOT_SMD:SOT-23",
                [(1, "G", P.INPUT), (2, "S", P.PASSIVE), (3, "D", P.PASSIVE)],
                "N-MOSFET 60 V 0.3 A, SOT-23", "Nexperia 2N7002", "onsemi BSS138", 0.03)
TRANSDUCER_TX = two_pin("MA40S4S", "LS", "penscape:Murata_MA40S4", "ultrasonic transmitter 40 kHz, 10 mm",
                        "Murata MA40S4S", "any 40 kHz open transmitter 10 mm across (not an HC-SR04's: 16 mm, fits neither the footprint nor the 14 mm pen)", 3.50)
TRANSDUCER_RX = two_pin("MA40S4R", "LS", "penscape:Murata_MA40S4", "ultrasonic receiver 40 kHz, 10 mm",
                        "Murata MA40S4R", "any 40 kHz open receiver 10 mm across (not an HC-SR04's: 16 mm, fits neither the footprint nor the post's cup)", 3.50)
TACT = two_pin("SW_Push", "SW", "Button_Switch_SMD:SW_SPST_B3U-1000P", "tact switch 3 × 2.5 mm, 1.2 N",
               "Omron B3U-1000P", "Panasonic EVQ-P7 (side push, for the barrel)", 0.60)
def _alternative_opamp():
    from analysis import chain_gain, chain_peak, db

    peak, _ = chain_peak(v.OPAMP_ALT_GBW)
    loss = db(chain_gain(v.F0)) - db(chain_gain(v.F0, gbw=v.OPAMP_ALT_GBW))
    return (f"ADI {v.OPAMP_ALT}ARZ ({v.OPAMP_ALT_GBW / 1e6:.0f} MHz: the band's centre moves to {peak / 1e3:.1f} kHz, "
            f"{loss:.1f} dB less at 40 kHz)")


OPAMP = template(v.OPAMP, "U", "Package_SO:SOIC-8_3.9x4.9mm_P1.27mm",
                 [(1, "OUTA", P.OUTPUT), (2, "-INA", P.INPUT), (3, "+INA", P.INPUT), (4, "V-", P.PWRIN),
                  (5, "+INB", P.INPUT), (6, "-INB", P.INPUT), (7, "OUTB", P.OUTPUT), (8, "V+", P.PWRIN)],
                 "dual op-amp 50 MHz, rail-to-rail, 2.2–5.5 V", "TI OPA2365AIDR",
                 _alternative_opamp(), 1.60)
COMPARATOR = template("TLV3501", "U", "Package_TO_SOT_SMD:SOT-23-6",
                      [(1, "OUT", P.OUTPUT), (2, "V-", P.PWRIN), (3, "+IN", P.INPUT), (4, "-IN", P.INPUT),
                       (5, "SHDN", P.INPUT), (6, "V+", P.PWRIN)],
                      "comparator 4.5 ns, push-pull output", "TI TLV3501AIDBVR", "TI TLV3201 (40 ns, SOT-23-5 without shutdown: another footprint), ADI ADCMP600", 1.90)
BAT54 = template("BAT54", "D", "Package_TO_SOT_SMD:SOT-23",
                 [(1, "A", P.PASSIVE), (2, "NC", P.NOCONNECT), (3, "K", P.PASSIVE)],
                 "Schottky diode 30 V 200 mA", "Nexperia BAT54", "BAT43 (through-hole), 1N5711", 0.05)


def connector(n, footprint, description, mpn, alternatives, price):
    return template(f"Conn_01x{n:02d}", "J", footprint,
                    [(i, str(i), P.PASSIVE) for i in range(1, n + 1)], description, mpn, alternatives, price)


CONN_PEN = connector(6, "Connector_JST:JST_XH_B6B-XH-A_1x06_P2.50mm_Vertical", "pen cable connector, 6 pins",
                     "JST B6B-XH-A + XHP-6", "any 6-pin 2.5 mm header; a 6-pin mini-DIN for a sturdier plug", 0.30)
CONN_RX = connector(3, "Connector_JST:JST_XH_B3B-XH-A_1x03_P2.50mm_Vertical",
                    "receiver cable connector, 3 pins (3.3 V, signal, GND; shield to GND)",
                    "JST B3B-XH-A + XHP-3", "a 3.5 mm TRS jack (tip signal, ring 3.3 V, sleeve GND)", 0.20)
# Not the receivers' XH: a receiver cable plugged in here would put ±12 V bursts on a module's
# 3.3 V supply. PH (2.0 mm pitch) does not mate with XH.
CONN_GLASSES = connector(3, "Connector_JST:JST_PH_B3B-PH-K_1x03_P2.00mm_Vertical",
                         "glasses cable connector, 3 pins (TX_A, TX_B, GND; shield to GND)",
                         "JST B3B-PH-K + PHR-3", "a 2.5 mm TRS jack (tip TX_A, ring TX_B, sleeve GND)", 0.20)
CONN_PILL = connector(20, "Connector_PinSocket_2.54mm:PinSocket_1x20_P2.54mm_Vertical",
                      "socket strip for the Black Pill, 20 pins", "Samtec SSW-120-01-T-S", "any 2.54 mm 1×20 socket", 0.60)


def add(tmpl, ref, value=None):
    """An instance with a fixed reference and tag, so that the netlist is the same each run."""
    part = tmpl(ref=ref, tag=ref, value=value if value is not None else tmpl.name)
    part.meta = tmpl.meta
    return part


def rc(ref, value):
    return add(RES, ref, v.fmt_r(value))


def cc(ref, value, tmpl=CAP):
    return add(tmpl, ref, v.fmt_c(value))


# --- The circuit ---------------------------------------------------------------------------

# Black Pill pins as the firmware (firmware/src/main.rs) uses them; check.py compares.
PIN_BURST = "PA8"
PIN_GLASSES = "PA9"
PINS_CAPTURE = ["PA15", "PB3", "PB10", "PA3", "PA6", "PA7", "PB0", "PB1"]
PINS_SWITCH = ["PB12", "PB14", "PB15"]
PIN_BOOST_EN = "PB13"
PIN_BOOT_UART_RX = "PA10"
RECEIVERS_BUILT = 4


def receiver_module(k, vcc, gnd, out):
    """Receiver k's module at its post: MA40S4R → stage 1 (non-inverting, 30 dB) → stage 2
    (multiple-feedback band-pass at 40 kHz, 30 dB) → envelope (BAT54, RENV ∥ CENV) →
    comparator (TLV3501 with hysteresis) → 100 Ω → cable. Its references are 100·(k + 1) + n."""
    b = 100 * (k + 1)

    def ref(prefix, n):
        return f"{prefix}{b + n}"

    n = lambda name: Net(f"RX{k}_{name}")  # noqa: E731
    avdd, vref, in1, fb1, g1, out1, a2, out2, env, plus, vth, cmp = (
        n("AVDD"), n("VREF"), n("IN"), n("FB1"), n("G1"), n("AMP1"), n("MFB"), n("AMP2"), n("ENV"),
        n("CMP+"), n("VTH"), n("CMP"))
    for net in (avdd, vref):
        net.drive = POWER  # an RC-filtered supply and a decoupled divider: sources for the chain
    j = add(CONN_RX, ref("J", 1))
    j[1] += vcc
    j[2] += out
    j[3] += gnd
    # Supply filter and mid-supply reference.
    rc(ref("R", 1), v.R_AVDD)[1, 2] += vcc, avdd
    cc(ref("C", 1), v.C_AVDD, CAP_BULK)[1, 2] += avdd, gnd
    rc(ref("R", 2), v.R_VREF)[1, 2] += avdd, vref
    rc(ref("R", 3), v.R_VREF)[1, 2] += vref, gnd
    cc(ref("C", 2), v.C_VREF, CAP_BULK)[1, 2] += vref, gnd
    # The transducer between the input and VREF, biased by RB1.
    add(TRANSDUCER_RX, ref("LS", 1))[1, 2] += in1, vref
    rc(ref("R", 4), v.RB1)[1, 2] += in1, vref
    u = add(OPAMP, ref("U", 1))
    u["V+"] += avdd
    u["V-"] += gnd
    cc(ref("C", 3), 100e-9)[1, 2] += avdd, gnd
    # Stage 1: +INA = input; −INA from the feedback RF1 ∥ CF1 and to VREF through RG1 + CG1.
    u["+INA"] += in1
    u["-INA"] += fb1
    u["OUTA"] += out1
    rc(ref("R", 5), v.RF1)[1, 2] += out1, fb1
    cc(ref("C", 4), v.CF1, CAP_C0G)[1, 2] += out1, fb1
    rc(ref("R", 6), v.RG1)[1, 2] += fb1, g1
    cc(ref("C", 5), v.CG1, CAP_C0G)[1, 2] += g1, vref
    # Stage 2: multiple-feedback band-pass, +INB at VREF.
    u["+INB"] += vref
    minus2 = n("FB2")
    u["-INB"] += minus2
    u["OUTB"] += out2
    rc(ref("R", 7), v.R1_2)[1, 2] += out1, a2
    rc(ref("R", 8), v.R3_2)[1, 2] += a2, vref
    cc(ref("C", 6), v.C2, CAP_C0G)[1, 2] += a2, minus2
    cc(ref("C", 7), v.C2, CAP_C0G)[1, 2] += a2, out2
    rc(ref("R", 9), v.R2_2)[1, 2] += minus2, out2
    # Envelope detector.
    d = add(BAT54, ref("D", 1))
    d["A"] += out2
    d["K"] += env
    rc(ref("R", 10), v.RENV)[1, 2] += env, vref
    cc(ref("C", 8), v.CENV, CAP_C0G)[1, 2] += env, vref
    # Comparator with hysteresis; the threshold from a divider on the analog supply.
    c = add(COMPARATOR, ref("U", 2))
    c["V+"] += avdd
    c["V-", "SHDN"] += gnd, gnd
    cc(ref("C", 9), 100e-9)[1, 2] += avdd, gnd
    rc(ref("R", 11), v.RIN)[1, 2] += env, plus
    rc(ref("R", 12), v.RHYS)[1, 2] += cmp, plus
    c["+IN"] += plus
    rc(ref("R", 13), v.R_TH_TOP)[1, 2] += avdd, vth
    rc(ref("R", 14), v.R_TH_BOT)[1, 2] += vth, gnd
    c["-IN"] += vth
    c["OUT"] += cmp
    rc(ref("R", 15), v.R_OUT)[1, 2] += cmp, out


def build():
    """The whole design in SKiDL's default circuit (reset first). Returns the Black Pill."""
    circuit = builtins.default_circuit  # SKiDL's default circuit lives in builtins
    circuit.reset()
    circuit.no_files = True
    gnd, v5, v33, v12 = Net("GND"), Net("+5V"), Net("+3V3"), Net("+12V")
    v12.drive = POWER  # the boost converter's output, through its diode
    pill = add(BLACK_PILL, "A1")
    pill["GND"] += gnd
    pill["GND_2"] += gnd
    pill["5V"] += v5
    pill["5V_2"] += v5
    pill["3V3"] += v33
    pill["3V3_2"] += v33
    # The Black Pill plugs into two socket strips on the base station's board.
    for side, ref in ((BLACK_PILL_LEFT, "J1"), (BLACK_PILL_RIGHT, "J2")):
        socket = add(CONN_PILL, ref)
        for i, name in enumerate(side, start=1):
            socket[i] += pill[name]

    # The boost converter's 5 V through a soft-start switch (values.py, "USB"): off at plug-in,
    # in reset, in the ROM bootloader and in suspend; on, ramping, when PB13 drives BOOST_EN.
    v5_sw, gate, en, q2_d = Net("+5V_BOOST"), Net("SS_GATE"), Net("BOOST_EN"), Net("SS_PULL")
    v5_sw.drive = POWER  # through Q1
    q1 = add(PMOS, "Q1")
    q1["S", "D", "G"] += v5, v5_sw, gate
    rc("R40", v.R_GS)[1, 2] += v5, gate
    cc("C40", v.C_SS)[1, 2] += gate, v5_sw
    rc("R41", v.R_SS)[1, 2] += gate, q2_d
    q2 = add(NMOS, "Q2")
    q2["D", "S", "G"] += q2_d, gnd, en
    rc("R42", v.R_EN_PD)[1, 2] += en, gnd
    pill[PIN_BOOST_EN] += en
    # PA10 held low for the ROM bootloader (values.py).
    boot_rx = Net("BOOT_UART_RX")
    pill[PIN_BOOT_UART_RX] += boot_rx
    rc("R43", v.R_PA10_PULLDOWN)[1, 2] += boot_rx, gnd

    # 12 V from the switched 5 V: MT3608, VOUT = 0.6 V · (1 + RFB_TOP / RFB_BOT).
    boost = add(MT3608, "U1")
    sw, fb = Net("BOOST_SW"), Net("BOOST_FB")
    boost["IN", "EN", "GND", "SW", "FB"] += v5_sw, v5_sw, gnd, sw, fb
    cc("C1", v.C_BOOST_IN, CAP_BULK)[1, 2] += v5_sw, gnd
    add(L_BOOST, "L1", "22µH")[1, 2] += v5_sw, sw
    d = add(SCHOTTKY, "D1", "SS34")
    d["A"] += sw
    d["K"] += v12
    rc("R1", v.RFB_TOP)[1, 2] += v12, fb
    rc("R2", v.RFB_BOT)[1, 2] += fb, gnd
    cc("C2", v.C_BOOST_OUT, CAP_BULK)[1, 2] += v12, gnd
    reservoir = add(two_pin("CP", "C", "Capacitor_THT:CP_Radial_D6.3mm_P2.50mm", "electrolytic 100 µF 25 V",
                            "Panasonic EEU-FR1E101", "any 100 µF ≥ 25 V low-ESR", 0.15, names=("+", "-")),
                    "C3", "100µF")
    reservoir["+", "-"] += v12, gnd

    # The transmitter: PA8's burst straight to driver A and inverted to driver B, so the
    # transducer between OUTA and OUTB swings ±12 V (24 V peak to peak).
    burst, burst_n = Net("BURST"), Net("BURST_N")
    pill[PIN_BURST] += burst
    rc("R3", v.R_BURST_PULLDOWN)[1, 2] += burst, gnd
    inv = add(INVERTER, "U2")
    inv["A", "Y", "VCC", "GND"] += burst, burst_n, v33, gnd
    cc("C4", 100e-9)[1, 2] += v33, gnd
    drv = add(TC4427, "U3")
    tx_a, tx_b = Net("TX_A"), Net("TX_B")
    out_b = Net("TX_B_DRV")
    drv["INA", "INB", "OUTA", "OUTB", "VDD", "GND"] += burst, burst_n, tx_a, out_b, v12, gnd
    # No DC across the transducer between bursts: B through 100 nF, 1 M across the pair.
    add(CAP_TX, "C10", v.fmt_c(v.C_TX_DC))[1, 2] += out_b, tx_b
    rc("R10", v.R_TX_BLEED)[1, 2] += tx_a, tx_b
    cc("C5", 1e-6, CAP_BULK)[1, 2] += v12, gnd
    cc("C6", 100e-9)[1, 2] += v12, gnd

    # The glasses' transmitter (head tracking, issue 16): PA9 (TIM1 channel 2) drives a second
    # TC4427 in bridge exactly as PA8 drives the pen's. The firmware fires one emitter per slot,
    # so the two never draw from the 12 V reservoir at once.
    gburst, gburst_n = Net("GLASSES_BURST"), Net("GLASSES_BURST_N")
    pill[PIN_GLASSES] += gburst
    rc("R11", v.R_BURST_PULLDOWN)[1, 2] += gburst, gnd
    ginv = add(INVERTER, "U4")
    ginv["A", "Y", "VCC", "GND"] += gburst, gburst_n, v33, gnd
    cc("C11", 100e-9)[1, 2] += v33, gnd
    gdrv = add(TC4427, "U5")
    gtx_a, gtx_b, gout_b = Net("GLASSES_TX_A"), Net("GLASSES_TX_B"), Net("GLASSES_TX_B_DRV")
    gdrv["INA", "INB", "OUTA", "OUTB", "VDD", "GND"] += gburst, gburst_n, gtx_a, gout_b, v12, gnd
    add(CAP_TX, "C12", v.fmt_c(v.C_TX_DC))[1, 2] += gout_b, gtx_b
    rc("R12", v.R_TX_BLEED)[1, 2] += gtx_a, gtx_b
    cc("C13", 1e-6, CAP_BULK)[1, 2] += v12, gnd
    cc("C14", 100e-9)[1, 2] += v12, gnd
    # The glasses' cable (1 TX_A, 2 TX_B, 3 GND and the shield), and the glasses: their half of
    # it and the transducer on the bridge (docs/hardware.md, "The glasses").
    add(CONN_GLASSES, "J4")[1, 2, 3] += gtx_a, gtx_b, gnd
    add(CONN_GLASSES, "J601")[1, 2, 3] += gtx_a, gtx_b, gnd
    add(TRANSDUCER_TX, "LS601")[1, 2] += gtx_a, gtx_b

    # The pen's cable: 1 TX_A, 2 TX_B, 3 SW1, 4 SW2, 5 SW3, 6 GND (and the shield).
    jpen = add(CONN_PEN, "J3")
    jpen[1, 2, 6] += tx_a, tx_b, gnd
    # Switch inputs: cable side pulled up by 4.7 k, 1 k into the pin with 100 nF to ground.
    lines = []
    for i, pin in enumerate(PINS_SWITCH):
        line, at_pin = Net(f"SW{i + 1}"), Net(f"SW{i + 1}_IN")
        lines.append(line)
        jpen[3 + i] += line
        rc(f"R{4 + 2 * i}", v.R_SW_PULLUP)[1, 2] += v33, line
        rc(f"R{5 + 2 * i}", v.R_SW_SERIES)[1, 2] += line, at_pin
        cc(f"C{7 + i}", v.C_SW)[1, 2] += at_pin, gnd
        pill[pin] += at_pin

    # The pen itself: its half of the cable, the transducer and the three switches to ground.
    ppen = add(CONN_PEN, "J501")
    ppen[1, 2, 6] += tx_a, tx_b, gnd
    add(TRANSDUCER_TX, "LS501")[1, 2] += tx_a, tx_b
    for i, line in enumerate(lines):
        ppen[3 + i] += line
        s = add(TACT, f"SW{501 + i}", f"SW{i + 1}")
        s[1, 2] += line, gnd

    # Receivers: a connector per capture channel with a 100 k pull-down, so that one not
    # plugged in never captures; modules 0–3 built.
    for k, pin in enumerate(PINS_CAPTURE):
        rx = Net(f"RX{k}")
        pill[pin] += rx
        rc(f"R{20 + k}", v.R_CAPTURE_PULLDOWN)[1, 2] += rx, gnd
        j = add(CONN_RX, f"J{10 + k}")
        j[1, 2, 3] += v33, rx, gnd
        if k < RECEIVERS_BUILT:
            receiver_module(k, v33, gnd, rx)

    # Every other Black Pill pin is left free.
    for p in pill.pins:
        if not p.is_connected():
            p += circuit.NC
    return pill


class ErcResult:
    def __init__(self, errors, warnings, messages):
        self.errors, self.warnings, self.messages = errors, warnings, messages


def erc():
    """SKiDL's electrical rules check of the built design: counts and messages."""
    from skidl.logger import erc_logger

    messages = []

    class Collect(logging.Handler):
        def emit(self, record):
            messages.append(record.getMessage())

    handler = Collect(level=logging.WARNING)
    erc_logger.addHandler(handler)
    saved = erc_logger.handlers[:]
    for h in saved:
        if h is not handler:
            erc_logger.removeHandler(h)
    try:
        skidl.ERC()
        return ErcResult(erc_logger.error.count + erc_logger.bare_error.count,
                         erc_logger.warning.count + erc_logger.bare_warning.count, messages)
    finally:
        erc_logger.removeHandler(handler)
        for h in saved:
            if h is not handler:
                erc_logger.addHandler(h)


def netlist():
    """The KiCad netlist as text, with the generation date fixed so that it is reproducible."""
    logging.disable(logging.WARNING)
    try:
        with contextlib.redirect_stderr(io.StringIO()):
            text = str(skidl.generate_netlist(tool=skidl.KICAD6, do_backup=False))
    finally:
        logging.disable(logging.NOTSET)
    text = re.sub(r'\(date "[^"]*"\)', '(date "generated by docs/hardware/design/circuit.py")', text, count=1)
    return text


def parts():
    return sorted(builtins.default_circuit.parts, key=lambda p: (re.sub(r"\d+", "", p.ref), int(re.sub(r"\D", "", p.ref) or 0)))


def bom_rows():
    """The bill of materials: one row per kind of part (same part and value), in reference
    order, with the quantity for one base station with four receivers and one pen."""
    groups = {}
    for p in parts():
        key = (p.meta["mpn"], p.value, p.footprint)
        groups.setdefault(key, []).append(p)
    rows = []
    for (mpn, value, footprint), ps in groups.items():
        m = ps[0].meta
        qty = len(ps)
        rows.append({
            "qty": qty,
            "references": " ".join(p.ref for p in ps),
            "value": value,
            "part": mpn,
            "description": m["description"],
            "footprint": footprint,
            "alternatives": m["alternatives"],
            "unit_usd": f"{m['price_usd']:.2f}",
            "total_usd": f"{qty * m['price_usd']:.2f}",
        })
    return rows


# What the schematic does not show: cables and mechanics (docs/hardware.md, "Mechanics").
OTHER_ITEMS = [
    (1, "pen cable", "6-core shielded cable, 0.14 mm², 2 m (TX pair twisted)", "Lapp Unitronic LiYCY 6×0.14",
     "any 6-core shielded control cable; a USB 2.0 cable's 4 cores + shield for a 5-core variant", 4.00),
    (4, "receiver cables", "3-core shielded cable, 0.14 mm², 1.5 m each", "Lapp Unitronic LiYCY 3×0.14",
     "a 3.5 mm TRS audio cable", 2.50),
    (1, "glasses cable", "2-core shielded cable, 0.14 mm², 2 m (TX pair twisted), along a temple",
     "Lapp Unitronic LiYCY 2×0.14", "a thin 3.5 mm TRS audio cable", 2.00),
    (1, "glasses emitter clip", "printed clip holding the MA40S4S on the shutter glasses' bridge, facing forward",
     "docs/hardware.md, \"The glasses\"", "a hot-glued printed cup", 0.50),
    (1, "pen body", "3D-printed pen body, nib holder and reflector cone (PETG)", "docs/hardware.md drawings",
     "a 12 mm aluminium tube with a printed tip", 2.00),
    (2, "receiver posts", "300 mm post on a clamp base, printed receiver cup", "aluminium tube 12 mm, 300 mm",
     "a camera light stand's 1/4\" stud with a printed cup", 6.00),
    (2, "flush receiver mounts", "printed cup with a clamp for the display's bezel", "docs/hardware.md drawings",
     "double-sided foam tape and a printed cup", 1.00),
    (1, "nib", "2 mm POM or brass rod, 12 mm, rounded tip", "Wacom-style replacement nib",
     "a 2 mm brass rod, end rounded", 0.50),
    (1, "board", "base station PCB or perfboard, 100 × 80 mm; receiver modules 30 × 20 mm each", "two-layer PCB",
     "stripboard", 5.00),
]


def bom_csv():
    out = io.StringIO()
    rows = bom_rows()
    w = csv.DictWriter(out, fieldnames=list(rows[0].keys()), lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    electronics = sum(float(r["total_usd"]) for r in rows)
    for qty, name, description, part, alternatives, price in OTHER_ITEMS:
        row = {"qty": qty, "references": "(not in the schematic)", "value": name, "part": part,
               "description": description, "footprint": "", "alternatives": alternatives,
               "unit_usd": f"{price:.2f}", "total_usd": f"{qty * price:.2f}"}
        rows.append(row)
        w.writerow(row)
    total = sum(float(r["total_usd"]) for r in rows)
    w.writerow({"qty": "", "references": "", "value": "", "part": "TOTAL electronics (rough, single quantities)",
                "description": "", "footprint": "", "alternatives": "", "unit_usd": "", "total_usd": f"{electronics:.2f}"})
    w.writerow({"qty": "", "references": "", "value": "", "part": "TOTAL with cables and mechanics",
                "description": "", "footprint": "", "alternatives": "", "unit_usd": "", "total_usd": f"{total:.2f}"})
    return out.getvalue()
