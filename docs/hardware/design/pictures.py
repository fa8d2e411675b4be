"""The pictures docs/hardware.md shows, drawn from the same values as the schematic:

* receiver.svg, transmitter.svg, switches.svg — schematics (schemdraw, its own SVG writer);
* pen.svg, post.svg — the pen and a receiver post, dimensioned (matplotlib);
* rig.svg — the bench rig's wiring: a Raspberry Pi Pico on the Black Pill's burst, receiver and
  switch pins (docs/hil-rig.md; the pins are hil-tests/rig/src/main.rs's, listed in RIG_WIRES);
* beam.svg — the pen's sound against its tilt: the angle between the fan of sound round the pen
  and each receiver, over the workspace, for tilts 0–60° (matplotlib, computed here).

`all_pictures()` returns (path, SVG text) pairs; check.py compares them with the files.
"""

import io
import math
import pathlib
import re

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import schemdraw  # noqa: E402
import schemdraw.elements as elm  # noqa: E402
import schemdraw.logic as logic  # noqa: E402

import values as v  # noqa: E402

OUT = pathlib.Path(__file__).resolve().parent.parent
schemdraw.use("svg")
plt.rcParams.update({"svg.hashsalt": "penscape", "font.size": 9, "svg.fonttype": "none"})

R = v.fmt_r
C = v.fmt_c


def _svg(drawing):
    """The drawing's SVG with a white rectangle behind it: schemdraw sets the background only in
    CSS, which some viewers ignore (black lines on a dark page)."""
    text = drawing.get_imagedata("svg").decode()
    m = re.search(r'viewBox="([-\d.]+) ([-\d.]+) ([\d.]+) ([\d.]+)"', text)
    if m:
        x, y, w, h = m.groups()
        end = text.index(">") + 1
        text = text[:end] + f'<rect x="{x}" y="{y}" width="{w}" height="{h}" fill="white" />' + text[end:]
    return text


def receiver():
    with schemdraw.Drawing(show=False) as d:
        d.config(fontsize=10, unit=2.2, bgcolor="white")
        # Stage 1: non-inverting, + input on top.
        op1 = elm.Opamp(leads=True).flip().label("U1A\n" + v.OPAMP, loc="center", ofst=(-0.3, 0), fontsize=8)
        elm.Line().left(1.2).at(op1.in2)
        d.push()
        elm.Dot()
        d.push()
        elm.Resistor().down().label(f"RB1\n{R(v.RB1)}", loc="bottom")
        elm.Vdd().down().label("VREF", loc="bottom")
        d.pop()
        elm.Line().left(3.2)
        elm.Crystal().down().label("LS1 MA40S4R\n(receiver)", loc="bottom")
        elm.Vdd().down().label("VREF", loc="bottom")
        d.pop()
        # Feedback RF1 ∥ CF1 below the op-amp; RG1 + CG1 from the − input to VREF.
        elm.Line().down(1.4).at(op1.in1)
        fb = elm.Dot()
        elm.Resistor().right().tox(op1.out).label(f"RF1 {R(v.RF1)}")
        e1 = elm.Dot()
        elm.Line().up().toy(op1.out)
        elm.Line().down(1.4).at(fb.center)
        fb2 = elm.Dot()
        elm.Capacitor().right().tox(op1.out).label(f"CF1 {C(v.CF1)}", loc="bottom")
        elm.Line().up().toy(e1.center)
        elm.Resistor().down().at(fb2.center).label(f"RG1 {R(v.RG1)}", loc="bottom")
        elm.Capacitor().down().label(f"CG1 {C(v.CG1)}", loc="bottom")
        elm.Vdd().down().label("VREF", loc="bottom")
        elm.Line().right(0.8).at(op1.out)
        n1 = elm.Dot().label("30 dB", loc="top", fontsize=8)
        # Stage 2: multiple-feedback band-pass.
        elm.Resistor().right().label(f"R1 {R(v.R1_2)}")
        a = elm.Dot()
        d.push()
        elm.Resistor().down().label(f"R3 {R(v.R3_2)}", loc="bottom")
        elm.Vdd().down().label("VREF", loc="bottom")
        d.pop()
        elm.Capacitor().right().label(f"C {C(v.C2)}")
        m = elm.Dot()
        op2 = elm.Opamp(anchor="in1", leads=True).right().label("U1B", loc="center", ofst=(-0.3, 0), fontsize=8)
        elm.Line().down(0.8).at(op2.in2)
        elm.Vdd().down().label("VREF", loc="bottom")
        elm.Line().up(2.6).at(a.center)
        elm.Capacitor().right().tox(op2.out).label(f"C {C(v.C2)}")
        top = elm.Dot()
        elm.Line().down().toy(op2.out)
        elm.Line().up(1.5).at(m.center)
        elm.Resistor().right().tox(op2.out[0] - 0.6).label(f"R2 {R(v.R2_2)}", loc="bottom")
        elm.Line().right().tox(op2.out)
        elm.Line().right(0.8).at(op2.out)
        elm.Dot().label("40 kHz, 30 dB, Q 5", loc="bottom", fontsize=8)
        # Envelope detector and comparator.
        elm.Diode().right().label("BAT54")
        env = elm.Dot().label("ENV", loc="top")
        d.push()
        elm.Line().down(0.6)
        elm.Dot()
        d.push()
        elm.Resistor().down().label(f"RENV\n{R(v.RENV)}", loc="bottom")
        elm.Vdd().down().label("VREF", loc="bottom")
        d.pop()
        elm.Line().right(1.4)
        elm.Capacitor().down().label(f"CENV\n{C(v.CENV)}", loc="bottom")
        elm.Vdd().down().label("VREF", loc="bottom")
        d.pop()
        elm.Resistor().right(4.0).at(env.center).label(f"RIN {R(v.RIN)}")
        plus = elm.Dot()
        cmp_ = elm.Opamp(anchor="in2", leads=True).flip().right().label("U2\nTLV3501", loc="center",
                                                                       ofst=(-0.3, 0), fontsize=8)
        elm.Line().down(2.2).at(cmp_.in1)
        elm.Vdd().down().label(f"VTH {v.comparator_levels(v.R_TH_BOT)['vth']:.3f} V\n"
                               f"({R(v.R_TH_TOP)} / {R(v.R_TH_BOT)} from 3.3 V)", loc="bottom")
        elm.Line().up(1.6).at(plus.center)
        elm.Resistor().right().tox(cmp_.out).label(f"RHYS {R(v.RHYS)} (hysteresis 50 mV)")
        elm.Line().down().toy(cmp_.out)
        elm.Line().right(0.6).at(cmp_.out)
        elm.Resistor().right().label(f"{R(v.R_OUT)}")
        elm.Line().right(0.6)
        elm.Dot(open=True).label("to the capture pin, over the cable", loc="right")
        elm.Line().right(5.0).color("white")  # room for the label
    return _svg(d)


def _bridge_driver(d, base, pin, names, load):
    """A burst pin's driver: the burst to A, inverted to B, the transducer between the outputs
    (through the DC block, its bleed resistor across it). `names` are the inverter's, the
    driver's, the block's and the bleed's references; `load` labels the transducer."""
    inverter, driver, block, bleed = names
    elm.Line().left(3.0).at(base).color("white")  # room for the label
    elm.Dot(open=True).at(base).label(pin, loc="left")
    elm.Line().right(1.0).at(base)
    pin_dot = elm.Dot()
    d.push()
    elm.Resistor().down().label(f"{R(v.R_BURST_PULLDOWN)}", loc="bottom")
    elm.Ground()
    d.pop()
    elm.Line().right(6.0)
    drv = elm.Ic(pins=[elm.IcPin(name="INA", side="left", slot="1/2"), elm.IcPin(name="INB", side="left", slot="2/2"),
                       elm.IcPin(name="OUTA", side="right", slot="1/2"), elm.IcPin(name="OUTB", side="right", slot="2/2"),
                       elm.IcPin(name="VDD", side="top"), elm.IcPin(name="GND", side="bottom")],
                 size=(2.6, 2.6), label=f"{driver} TC4427", lblloc="center", pinspacing=1.2).right().anchor("INA")
    elm.Line().up(0.8).at(drv.VDD)
    elm.Vdd().label("+12 V")
    elm.Ground().at(drv.GND)
    elm.Wire("|-").at(pin_dot.center).to((pin_dot.center[0] + 1.5, drv.INB[1]))
    logic.Not().right().at((pin_dot.center[0] + 1.5, drv.INB[1])).label(f"{inverter} 74LVC1G04", loc="bottom")
    elm.Line().right().tox(drv.INB)
    # OUTB (on top) through the DC block; the transducer and its bleed resistor on the cable.
    elm.Capacitor().right(3.0).at(drv.OUTB).label(f"{block} {C(v.C_TX_DC)}")
    b = elm.Dot()
    elm.Line().right(1.5)
    elm.Crystal().down().toy(drv.OUTA).label(load, loc="bottom")
    a = elm.Dot()
    elm.Line().left().tox(drv.OUTA)
    elm.Resistor().down().at(b.center).toy(a.center).label(f"{bleed}\n{R(v.R_TX_BLEED)}", loc="bottom")
    # Room for the transducer's label, clear of its text: schemdraw's bounds leave labels out.
    elm.Line().right(3.5).at((a.center[0], a.center[1] - 1.5)).color("white")


def transmitter():
    with schemdraw.Drawing(show=False) as d:
        d.config(fontsize=10, unit=2.2, bgcolor="white")
        # Boost: +5 V → L1 → SW → D1 → +12 V; R1/R2 set it (0.6 V · (1 + R1/R2)).
        elm.Vdd().label("+5 V (USB)")
        elm.Line().down(0.5)
        vin = elm.Dot()
        elm.Inductor().right().label("L1 22 µH")
        sw = elm.Dot()
        elm.Diode().right().label("D1 SS34")
        out = elm.Dot()
        elm.Line().right(2.0)
        div = elm.Dot()
        elm.Line().right(2.0)
        res = elm.Dot()
        elm.Line().right(1.5)
        elm.Dot(open=True).label(f"+12 V ({v.boost_vout():.2f} V)", loc="right")
        elm.Line().right(3.0).color("white")  # room for the label
        elm.Capacitor().down().at(vin.center).label("C1 22 µF", loc="bottom")
        elm.Ground()
        elm.Capacitor().down().at(out.center).label("C2 22 µF", loc="bottom")
        elm.Ground()
        elm.Resistor().down().at(div.center).label(f"R1 {R(v.RFB_TOP)}", loc="bottom")
        fb = elm.Dot()
        elm.Resistor().down().label(f"R2 {R(v.RFB_BOT)}", loc="bottom")
        elm.Ground()
        elm.Capacitor(polar=True).down().at(res.center).label("C3 100 µF", loc="bottom")
        elm.Ground()
        ic = elm.Ic(pins=[elm.IcPin(name="SW", side="top"), elm.IcPin(name="FB", side="right"),
                          elm.IcPin(name="IN", side="left", slot="1/2"), elm.IcPin(name="EN", side="left", slot="2/2"),
                          elm.IcPin(name="GND", side="bottom")],
                    size=(3.2, 2.0), label="U1 MT3608", lblloc="center", pinspacing=0.7).right().anchor("SW").at(
                        (sw.center[0], sw.center[1] - 3.5))
        elm.Line().at(ic.SW).to(sw.center)
        elm.Line().right(1.2).at(ic.FB)
        elm.Line().up().toy(fb.center)
        elm.Line().right().tox(fb.center)
        elm.Ground().at(ic.GND)
        elm.Line().left(1.0).at(ic.IN)
        elm.Tag().left().label("+5 V")
        elm.Line().left(1.0).at(ic.EN)
        elm.Tag().left().label("+5 V")
        # The pen's driver, and below it the glasses' (issue 16): the same bridge on PA9.
        base = (sw.center[0] - 6.0, sw.center[1] - 10.0)
        _bridge_driver(d, base, "PA8 (TIM1 CH1)", ("U2", "U3", "C10", "R10"),
                       f"LS501 MA40S4S\nin the pen\n{v.tx_swing():.1f} V p-p")
        _bridge_driver(d, (base[0], base[1] - 7.0), "PA9 (TIM1 CH2)", ("U4", "U5", "C12", "R12"),
                       f"J4: glasses cable\nLS601 MA40S4S\non the glasses\n{v.tx_swing():.1f} V p-p")
    return _svg(d)


def switches():
    with schemdraw.Drawing(show=False) as d:
        d.config(fontsize=10, unit=2.2, bgcolor="white")
        elm.Ground()
        elm.Button().up().label("SW1 (tip)\nin the pen", loc="bottom")
        elm.Line().up(0.5)
        elm.Line().right(3.0).label("pen cable", loc="top")
        line = elm.Dot()
        d.push()
        elm.Resistor().up().label(f"{R(v.R_SW_PULLUP)}", loc="bottom")
        elm.Vdd().label("+3.3 V")
        d.pop()
        elm.Resistor().right().label(f"{R(v.R_SW_SERIES)}")
        at = elm.Dot()
        d.push()
        elm.Capacitor().down().label(f"{C(v.C_SW)}", loc="bottom")
        elm.Ground()
        d.pop()
        elm.Line().right(1.0)
        elm.Dot(open=True).label("PB12, internal pull-up on", loc="right")
        elm.Line().right(4.0).color("white")  # room for the label
        elm.Label().at((line.center[0] + 1.0, line.center[1] - 4.4)).label(
            "SW2 → PB14, SW3 → PB15: the same. Closing: τ = 1 k × 100 nF = 100 µs; "
            f"opening: (4.7 k + 1 k) × 100 nF = {(v.R_SW_SERIES + v.R_SW_PULLUP) * v.C_SW * 1e3:.2f} ms", fontsize=9)
    return _svg(d)


# The bench rig (docs/hil-rig.md): (Black Pill pin, what it is, Pico pin, what the rig does).
RIG_WIRES = [
    ("PA8", "burst", "GP2", "burst in (PIO0)"),
    ("PA8", "burst", "GP3", "burst in (PIO1)"),
    ("PA15", "receiver 0", "GP6", "receiver 0 out"),
    ("PB3", "receiver 1", "GP7", "receiver 1 out"),
    ("PB10", "receiver 2", "GP8", "receiver 2 out"),
    ("PA3", "receiver 3", "GP9", "receiver 3 out"),
    ("PA6", "receiver 4", "GP10", "receiver 4 out"),
    ("PA7", "receiver 5", "GP11", "receiver 5 out"),
    ("PB0", "receiver 6", "GP12", "receiver 6 out"),
    ("PB1", "receiver 7", "GP13", "receiver 7 out"),
    ("PB12", "SW1 (tip)", "GP18", "SW1, open drain"),
    ("PB14", "SW2", "GP19", "SW2, open drain"),
    ("PB15", "SW3", "GP20", "SW3, open drain"),
    ("GND", "", "GND", ""),
]


def rig():
    """The two boards side by side, one wire per signal, as the rig's firmware assigns them."""
    rows = len(RIG_WIRES)
    fig, ax = plt.subplots(figsize=(8.4, 0.36 * rows + 1.6))
    ax.set_xlim(-4.2, 16.5)
    ax.set_ylim(-rows - 0.6, 2.0)
    ax.axis("off")
    box = dict(fill=False, linewidth=1.4)
    ax.add_patch(plt.Rectangle((0, -rows + 0.5), 3.2, rows + 0.2, **box))
    ax.add_patch(plt.Rectangle((9.5, -rows + 0.5), 3.2, rows + 0.2, **box))
    ax.text(1.6, 1.3, "Black Pill: base station\n(STM32F411, 3.3 V)", ha="center", va="center", fontsize=10)
    ax.text(11.1, 1.3, "Raspberry Pi Pico: bench rig\n(RP2040, 3.3 V)", ha="center", va="center", fontsize=10)
    first = {}
    for i, (pin, what, gp, does) in enumerate(RIG_WIRES):
        y = -i
        if pin in first:
            # The same Black Pill pin again (the burst to both PIO blocks): a branch, not a pin.
            ax.plot([6.2, 6.2, 9.5], [first[pin], y, y], color="black", linewidth=1)
            ax.plot([6.2], [first[pin]], "o", color="black", markersize=4)
        else:
            first[pin] = y
            ax.plot([3.2, 9.5], [y, y], color="black", linewidth=1)
            ax.text(3.0, y, pin, ha="right", va="center", fontsize=9)
            ax.text(-0.2, y, what, ha="right", va="center", fontsize=8, color="#444444")
        ax.text(9.7, y, gp, ha="left", va="center", fontsize=9)
        ax.text(12.9, y, does, ha="left", va="center", fontsize=8, color="#444444")
    ax.text(6.35, -rows + 0.3,
            "Receiver modules and pen cable unplugged: the rig is their outputs. Switch lines: pulled low\n"
            "for pressed, let go for released (the base station's 4.7 k pull-ups). Ground wire short, beside the signals.",
            ha="center", va="top", fontsize=8)
    return _fig_svg(fig)


# --- Mechanics -----------------------------------------------------------------------------------

EMITTER_MM = 8.0      # the sound's centre above the tip (pen-sim's emitter_offset_mm)
BEAM_HALF_DEG = 40.0  # the MA40S4 pair's −6 dB half-angle (Murata: 80° full)


def _fig_svg(fig):
    buf = io.StringIO()
    fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
    plt.close(fig)
    return buf.getvalue()


def pen():
    fig, (tip, whole) = plt.subplots(1, 2, figsize=(10, 3.6), gridspec_kw={"width_ratios": [1, 1.6]})
    for ax in (tip, whole):
        ax.set_aspect("equal")
        ax.axis("off")
    # Tip, to scale (mm along the pen's axis from the nib's point).
    nose = np.array([[2, 2], [5, 4], [5, -4], [2, -2], [2, 2]])
    tip.plot(nose[:, 0], nose[:, 1], "k-", lw=1)
    tip.plot([0, 3], [0, 0], "k-", lw=4, solid_capstyle="round")                      # nib Ø2
    tip.add_patch(plt.Rectangle((3.0, -1.5), 1.6, 3.0, fc="#c33", ec="k"))             # SW1
    tip.add_patch(plt.Polygon([[5, -4], [5, 4], [9, 0]], fc="#bbb", ec="k"))           # 90° cone
    for y in (-6.5, 6.5):                                                               # struts
        tip.plot([5, 11], [np.sign(y) * 4, y], "k-", lw=0.8)
    tip.add_patch(plt.Rectangle((11, -4.95), 7.1, 9.9, fc="#8ac", ec="k"))             # MA40S4S
    body = np.array([[11, 7], [30, 7], [30, -7], [11, -7]])
    tip.plot(body[:, 0], body[:, 1], "k-", lw=1.2)
    tip.plot([EMITTER_MM, EMITTER_MM], [-9, 9], "b:", lw=1)
    for y in (1, -1):
        tip.annotate("", xy=(EMITTER_MM, 11 * y), xytext=(EMITTER_MM, 3 * y),
                     arrowprops=dict(arrowstyle="->", color="b", lw=1.2))
    tip.text(EMITTER_MM + 0.6, 10.5, "sound leaves all round\n(the fan), normal to the axis", color="b", fontsize=7)
    tip.text(14.5, 0, "MA40S4S\nfacing\nthe tip", ha="center", va="center", fontsize=7)
    tip.text(7, -6.5, "90° cone", ha="center", fontsize=7)
    tip.text(3.8, -3.0, "SW1", ha="center", va="top", fontsize=7, color="#c33")
    tip.annotate("", xy=(0, -11), xytext=(EMITTER_MM, -11), arrowprops=dict(arrowstyle="<->", lw=0.8))
    tip.text(EMITTER_MM / 2, -13.5, f"{EMITTER_MM:.0f} mm (≤ 10)", ha="center", fontsize=8)
    tip.set_xlim(-2, 31)
    tip.set_ylim(-15, 14)
    tip.set_title("Tip, to scale (mm)", fontsize=9)
    # The whole pen, to scale.
    outline = np.array([[0, 0], [5, 4], [11, 7], [140, 7], [140, -7], [11, -7], [5, -4], [0, 0]])
    whole.plot(outline[:, 0], outline[:, 1], "k-", lw=1.2)
    for x, name in ((38, "SW2"), (52, "SW3")):
        whole.add_patch(plt.Rectangle((x, 7), 8, 1.5, fc="#c33", ec="k"))
        whole.text(x + 4, 10, name, ha="center", fontsize=8)
    whole.plot([140, 165], [0, 0], "k-", lw=2.5)
    whole.text(140, -12, "6-core shielded cable:\nTX+, TX−, SW1, SW2, SW3, GND (+ shield)", fontsize=8)
    whole.annotate("", xy=(0, -20), xytext=(140, -20), arrowprops=dict(arrowstyle="<->", lw=0.8))
    whole.text(70, -25, "140 mm, Ø 14 mm; SW2/SW3 38 and 52 mm from the tip, under the index finger",
               ha="center", fontsize=8)
    whole.set_xlim(-5, 200)
    whole.set_ylim(-29, 16)
    whole.set_title("The pen (side view)", fontsize=9)
    fig.tight_layout()
    return _fig_svg(fig)


def post():
    fig, ax = plt.subplots(figsize=(5, 5))
    ax.set_aspect("equal")
    ax.axis("off")
    ax.plot([-60, 60], [0, 0], "k-", lw=3)                     # clamp base
    ax.add_patch(plt.Rectangle((-6, 0), 12, 290, fc="#ddd", ec="k"))
    # The cup at 300 mm, tilted down towards the workspace centre.
    tilt = _post_tilt_deg()
    t = math.radians(tilt)
    cx, cy = 0, 300
    w, h = 16, 12
    pts = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
    rot = np.array([[math.cos(-t), -math.sin(-t)], [math.sin(-t), math.cos(-t)]])
    ax.add_patch(plt.Polygon(pts @ rot.T + [cx, cy], fc="#8ac", ec="k"))
    ax.annotate("", xy=(cx + 90 * math.cos(-t), cy + 90 * math.sin(-t)), xytext=(cx, cy),
                arrowprops=dict(arrowstyle="->", color="b"))
    ax.text(cx + 20, cy + 12, f"MA40S4R, axis {tilt:.0f}° below level,\nat the workspace's centre", fontsize=8, color="b")
    ax.annotate("", xy=(-30, 0), xytext=(-30, 300), arrowprops=dict(arrowstyle="<->", lw=0.8))
    ax.text(-35, 150, "z = 300 mm\nabove the\ndisplay's surface\nto the centre of\nthe transducer's\nface (survey it\nto ± 0.5 mm)", ha="right",
            va="center", fontsize=8)
    ax.text(0, -20, "clamp base on the display's frame; the cable down the tube", ha="center", fontsize=8)
    ax.set_xlim(-130, 140)
    ax.set_ylim(-35, 345)
    ax.set_title("Receiver post (receivers 0 and 3; 4 and 5 in bigger builds)", fontsize=9)
    return _fig_svg(fig)


def _receivers():
    return np.array([[-40, -40, 300], [640, -40, 0], [-40, 380, 0], [640, 380, 300]], float)


def _post_tilt_deg():
    """How far a raised receiver's axis points below level to aim at the workspace's centre
    (300, 170, 100) mm from receiver 0 (−40, −40, 300)."""
    r0 = _receivers()[0]
    c = np.array([300, 170, 100.0])
    dvec = c - r0
    return math.degrees(math.atan2(-dvec[2], math.hypot(dvec[0], dvec[1])))


def beam_margins(tilts_deg):
    """For each tilt of the pen (leaning towards the user, −y, as a right hand holds it): how far
    each receiver is off the fan of sound (the plane through the emitter normal to the pen's
    axis), over pen tips on a grid of the display (x 0–600 mm in 7 steps, y 0–340 mm in 5) at
    heights 0, 50 and 150 mm. Returns, per tilt, the worst angle of any receiver, the worst of
    each point's third-best receiver (three are needed for a fix), and the share of points where
    all four / at least three receivers are inside the beam's −6 dB half-angle."""
    recv = _receivers()
    xs, ys, zs = np.linspace(0, 600, 7), np.linspace(0, 340, 5), [0, 50, 150]
    worst_all, worst_third, share4, share3 = [], [], [], []
    for tilt in tilts_deg:
        a = math.radians(tilt)
        axis = np.array([0, -math.sin(a), math.cos(a)])
        offs = []
        for x in xs:
            for y in ys:
                for z in zs:
                    e = np.array([x, y, z]) + axis * EMITTER_MM
                    dirs = recv - e
                    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
                    offs.append(np.sort(np.degrees(np.arcsin(np.clip(np.abs(dirs @ axis), 0, 1)))))
        offs = np.array(offs)
        worst_all.append(offs[:, 3].max())
        worst_third.append(offs[:, 2].max())
        share4.append((offs[:, 3] <= BEAM_HALF_DEG).mean())
        share3.append((offs[:, 2] <= BEAM_HALF_DEG).mean())
    return tuple(np.array(x) for x in (worst_all, worst_third, share4, share3))


def beam():
    tilts = np.arange(0, 61, 5)
    worst, third, share4, share3 = beam_margins(tilts)
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(9, 3.6))
    ax.plot(tilts, worst, "o-", label="worst receiver")
    ax.plot(tilts, third, "s--", label="worst third-best receiver")
    ax.axhline(BEAM_HALF_DEG, color="r", lw=1)
    ax.text(1, BEAM_HALF_DEG + 1.5, f"−6 dB half-angle ({BEAM_HALF_DEG:.0f}°)", color="r", fontsize=8)
    ax.axvspan(25, 45, color="#eee")
    ax.text(35, 25, "usual hand\n(pen-sim: 35°)", ha="center", fontsize=8)
    ax.set_xlabel("pen tilt from the display's normal, °")
    ax.set_ylabel("angle off the fan of sound, °")
    ax.set_ylim(0, 90)
    ax.legend(fontsize=8, loc="lower right")
    ax2.plot(tilts, 100 * share4, "o-", label="all four receivers")
    ax2.plot(tilts, 100 * share3, "s--", label="at least three")
    ax2.axvspan(25, 45, color="#eee")
    ax2.set_xlabel("pen tilt from the display's normal, °")
    ax2.set_ylabel("tip positions inside the −6 dB beam, %")
    ax2.set_ylim(0, 105)
    ax2.legend(fontsize=8, loc="lower left")
    fig.suptitle("The pen's fan of sound against its tilt: tips over the display, 0–150 mm up, reference receivers",
                 fontsize=9)
    fig.tight_layout()
    return _fig_svg(fig)


def all_pictures():
    return [
        (OUT / "receiver.svg", receiver()),
        (OUT / "transmitter.svg", transmitter()),
        (OUT / "switches.svg", switches()),
        (OUT / "pen.svg", pen()),
        (OUT / "post.svg", post()),
        (OUT / "beam.svg", beam()),
        (OUT / "rig.svg", rig()),
    ]
