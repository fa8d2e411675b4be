"""Component values of the base station, computed here and used by the schematic (circuit.py),
its pictures (pictures.py) and the checks (check.py): one place for every number.

Each value is derived from a requirement in a comment beside it and rounded to a standard series
(E24 for capacitors, E96 for resistors); the checks recompute what the rounded parts achieve
(gain, centre frequency, thresholds, the boost converter's output) from these values, with the
op-amp's finite gain-bandwidth, so a change that breaks a requirement fails the test command.
"""

import math

# --- Standard series -----------------------------------------------------------------------

E24 = [1.0, 1.1, 1.2, 1.3, 1.5, 1.6, 1.8, 2.0, 2.2, 2.4, 2.7, 3.0,
       3.3, 3.6, 3.9, 4.3, 4.7, 5.1, 5.6, 6.2, 6.8, 7.5, 8.2, 9.1]


def e96():
    return [round(10 ** (i / 96), 2) for i in range(96)]


def nearest(value, series):
    """The value of `series` (one decade, scaled to any) nearest to `value`, in log terms."""
    decade = 10 ** math.floor(math.log10(value))
    candidates = [s * decade * m for s in series for m in (0.1, 1, 10)]
    return min(candidates, key=lambda c: abs(math.log(c / value)))


def r96(value):
    return float(f"{nearest(value, e96()):.4g}")


def c24(value):
    return float(f"{nearest(value, E24):.3g}")


# --- Supplies ------------------------------------------------------------------------------

V33 = 3.3      # the Black Pill's regulator; the analog chain and the comparators run on it
V5 = 5.0       # USB
V12 = 12.0     # the transmitter's rail, boosted from USB 5 V

# --- Receiver chain: MA40S4R → stage 1 → stage 2 → envelope → comparator -----------------------

F0 = 40e3             # the transducers' resonance, Hz
GAIN_TARGET_DB = 60   # the "≈ 60 dB"; 30 dB per stage
OPAMP = "OPA2365"     # dual, 50 MHz gain-bandwidth, rail-to-rail, 2.2–5.5 V
OPAMP_GBW = 50e6
OPAMP_ALT = "AD8606"  # the alternative the bill of materials names: 8 MHz, rail-to-rail, 2.7–5.5 V
OPAMP_ALT_GBW = 8e6

# Mid-supply reference: both op-amp stages and the detector sit on it. A 10 k / 10 k divider
# from 3.3 V, decoupled with 10 µF (corner 3 Hz): 1.65 V.
R_VREF = 10e3
C_VREF = 10e-6
VREF = V33 / 2

# Stage 1, non-inverting, AC-coupled: gain 1 + RF1/RG1 ≈ 31.6 (30 dB) with a high input
# impedance the transducer can drive (RB1 biases the input to VREF). RG1 in series with CG1
# makes the high-pass corner; CF1 across RF1 the low-pass corner: a broad band round 40 kHz,
# the narrow band is stage 2's.
RB1 = 100e3
RF1 = 100e3
RG1 = r96(RF1 / (10 ** (30 / 20) - 1))               # 3.27 k → gain 31.6
CG1 = c24(1 / (2 * math.pi * RG1 * 4.8e3))            # high-pass at ≈ 5 kHz
CF1 = c24(1 / (2 * math.pi * RF1 * 72e3))             # low-pass at ≈ 72 kHz

# Stage 2, multiple-feedback band-pass, inverting: centre F0, Q 5 (−3 dB band 8 kHz, about an
# 8-period burst's 5 kHz spectrum plus the transducers' spread), gain 31.6 (30 dB) at F0.
# With C1 = C2 = C (the textbook design equations):
#   R1 = Q / (2π f0 C A0),  R2 = Q / (π f0 C),  R3 = Q / (2π f0 C (2Q² − A0))   (needs 2Q² > A0)
Q2 = 5.0
A2 = 10 ** (30 / 20)
C2 = 1e-9
R1_2 = r96(Q2 / (2 * math.pi * F0 * C2 * A2))
R2_2 = r96(Q2 / (math.pi * F0 * C2))
R3_2 = r96(Q2 / (2 * math.pi * F0 * C2 * (2 * Q2 ** 2 - A2)))

# Envelope detector: a Schottky diode (BAT54) charges CENV from stage 2's output; RENV lets it
# fall back to VREF. τ = RENV·CENV = 220 µs: the envelope droops 11 % between two 40 kHz peaks
# (25 µs) yet is back at rest long before the next cycle (6.5 ms). RENV is low (10 k) so that
# the comparator's hysteresis network (below) barely moves the resting level.
RENV = 10e3
CENV = c24(220e-6 / RENV)

# Comparator (TLV3501, 4.5 ns): ENV through RIN to +IN, positive feedback RHYS from its output;
# −IN at the threshold VTH from a divider on 3.3 V (ratiometric with VREF, so the supply's
# tolerance moves both alike). Hysteresis at the envelope: ΔV = 3.3 V · RIN / RHYS ≈ 50 mV,
# larger than the envelope's ripple near the threshold and the noise (≈ 0.5 mV RMS at the
# envelope: 4.5 nV/√Hz × 1000 over 8 kHz), small against a signal that reaches volts.
RIN = 10e3
HYSTERESIS_TARGET = 0.050
RHYS = r96(V33 * RIN / HYSTERESIS_TARGET)
THRESHOLD_ABOVE_REST = 0.150   # the envelope must rise this much over its rest to trigger
R_TH_TOP = 10e3


def comparator_levels(r_th_bot=None):
    """The comparator's levels, seen at the envelope node (V): the resting envelope with the
    output low, the rising trip point (output goes high) and the falling one (back low)."""
    # At rest the diode is off: ENV is VREF through RENV, pulled towards the output (0 V or
    # 3.3 V) through RIN + RHYS.
    def rest(vout):
        g1, g2 = 1 / RENV, 1 / (RIN + RHYS)
        return (VREF * g1 + vout * g2) / (g1 + g2)

    vth = V33 * r_th_bot / (R_TH_TOP + r_th_bot) if r_th_bot else None
    # +IN = ENV + (VOUT − ENV)·RIN/(RIN + RHYS); the output flips when +IN crosses VTH.
    k = RIN / (RIN + RHYS)

    def env_at(vout):
        return (vth - vout * k) / (1 - k)

    return {
        "rest": rest(0.0),
        "vth": vth,
        "rise": env_at(0.0) if vth else None,
        "fall": env_at(V33) if vth else None,
    }


# The threshold divider's bottom resistor: the rising trip point THRESHOLD_ABOVE_REST above the
# resting envelope.
def _solve_r_th_bot():
    rest = comparator_levels()["rest"]
    k = RIN / (RIN + RHYS)
    vth = (rest + THRESHOLD_ABOVE_REST) * (1 - k)
    return r96(R_TH_TOP * vth / (V33 - vth))


R_TH_BOT = _solve_r_th_bot()

# The receiver module's analog supply: 10 Ω and 10 µF from the cable's 3.3 V (corner 1.6 kHz)
# keep the base station's digital noise out of a chain with 60 dB of gain.
R_AVDD = 10.0
C_AVDD = 10e-6
# The comparator's output through 100 Ω into the shielded cable (damps its ringing).
R_OUT = 100.0

# --- Transmitter: MT3608 boost 5 V → 12 V, TC4427 bridge driver ------------------------------

# MT3608: VOUT = 0.6 V · (1 + RFB_TOP / RFB_BOT).
MT3608_VREF = 0.6
RFB_BOT = 1.0e3
RFB_TOP = r96(RFB_BOT * (V12 / MT3608_VREF - 1))


def boost_vout():
    return MT3608_VREF * (1 + RFB_TOP / RFB_BOT)


L_BOOST = 22e-6          # MT3608 datasheet range 4.7–22 µH; 22 µH keeps the ripple low at light load
C_BOOST_IN = 22e-6
C_BOOST_OUT = 22e-6
# The burst's charge comes from a 100 µF reservoir on 12 V: 8 periods into the bridge
# (the MA40S4S is about 2.5 nF): Q = 8 · 2 · 2.5 nF · 24 V ≈ 1 µC → 10 mV of droop.
C_RESERVOIR = 100e-6
TRANSDUCER_C = 2.55e-9
BURST_PERIODS = 8


def burst_droop():
    return BURST_PERIODS * 2 * TRANSDUCER_C * 2 * V12 / C_RESERVOIR


# At rest PA8 is low, so driver A is low and driver B (through the inverter) high: 12 V would
# sit across the transducer between bursts. A 100 nF capacitor in series with B's output takes
# that DC, and 1 M across the transducer's leads keeps it at 0 V at rest (τ 0.1 s); during a
# burst the transducer sees 0 → 24 V steps (2.5 nF against 100 nF: 97.5 % of the swing).
C_TX_DC = 100e-9
R_TX_BLEED = 1e6


def tx_swing():
    """The transducer's share of the drivers' 24 V swing through the DC-blocking capacitor."""
    return 2 * V12 * C_TX_DC / (C_TX_DC + TRANSDUCER_C)


# PA8 is an input with no pull during reset: 100 k holds the driver's input low, so the
# transducer is not driven before the firmware runs.
R_BURST_PULLDOWN = 100e3

# --- USB: the boost converter behind a soft-start switch -------------------------------------

# Behind the boost's inductor and diode the transmitter's capacitors (C1 22 µF, C2 22 µF, C3
# 100 µF, C5 and C13 1 µF each: 146 µF) would charge straight from VBUS at plug-in; USB 2.0
# (§7.2.4.1) allows a device 10 µF there. A P-MOSFET (Q1) in front of the converter keeps them
# off VBUS until the firmware, once the host has configured the device, drives BOOST_EN (PB13)
# high, and takes them off again in suspend. Q2 (an N-MOSFET) then pulls Q1's gate down through
# R_SS; C_SS from Q1's gate to its drain holds the gate at Q1's Miller plateau while the drain
# rises, so the drain rises at dV/dt = I / C_SS with I = (V5 − |V_PLATEAU|) / R_SS − |V_PLATEAU|
# / R_GS, and the capacitors charge at C · dV/dt. R_EN_PD holds Q2 off while the Black Pill is
# in reset or in its ROM bootloader.
C_SWITCHED = 22e-6 + 22e-6 + 100e-6 + 1e-6 + 1e-6
# The gate-source voltage at the plateau: AO3401A (Alpha & Omega datasheet, gate charge curve:
# about −2 V at a few hundred mA; its threshold is −0.5 to −1.3 V).
V_PLATEAU = 2.0
R_GS = 100e3
R_SS = 100e3
C_SS = 47e-9
R_EN_PD = 100e3
# USB 2.0's unconfigured current, which the ramp must stay below.
USB_UNIT_LOAD_A = 0.100


def soft_start():
    """The drain's slope (V/s), the switched capacitors' charging current (A) and the ramp's
    length to 5 V (s)."""
    i_gate = (V5 - V_PLATEAU) / R_SS - V_PLATEAU / R_GS
    slope = i_gate / C_SS
    return slope, C_SWITCHED * slope, V5 / slope


# PA10 (USART1_RX) is one of the ROM bootloader's interfaces: floating, noise on it can make the
# bootloader take the USART instead of USB (AN2606, STM32F411 boot loader: the first interface
# to see activity wins). 10 k holds it low; the firmware leaves it an input.
R_PA10_PULLDOWN = 10e3

# --- Switch inputs ---------------------------------------------------------------------------

# Per switch: 1 k in series and 100 nF to ground at the pin (τ = 100 µs as the switch closes:
# spikes picked up along the cable are filtered, bounce is left to the firmware), and a 4.7 k
# pull-up to 3.3 V on the cable side, so that the line rises in (4.7 k + 1 k) · 100 nF = 0.57 ms
# as the switch opens (the chip's own 40 k pull-up alone would take 4 ms).
R_SW_SERIES = 1e3
C_SW = 100e-9
R_SW_PULLUP = 4.7e3
# Capture inputs of receivers that are not plugged in are held low by 100 k (no false captures).
R_CAPTURE_PULLDOWN = 100e3


def fmt_r(v):
    for unit, scale in (("M", 1e6), ("k", 1e3), ("", 1)):
        if v >= scale:
            s = f"{v / scale:.3g}"
            return s + unit if unit else s + "Ω"
    return f"{v:.3g}Ω"


def fmt_c(v):
    for unit, scale in (("µF", 1e-6), ("nF", 1e-9), ("pF", 1e-12)):
        if v >= scale * 0.999:
            return f"{v / scale:.3g}{unit}"
    return f"{v:.3g}F"
