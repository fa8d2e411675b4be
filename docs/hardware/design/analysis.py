"""The receiver chain's small-signal response, from the values in values.py: used by check.py
(the requirements) and circuit.py (what the bill of materials says of an alternative op-amp)."""

import math

import numpy as np

import values as v


def chain_gain(f, gbw=v.OPAMP_GBW, a0=1e5):
    """|V(AMP2)| / V(transducer) at `f` Hz: the transducer (its 2.55 nF in series with its
    open-circuit voltage) into stage 1 and stage 2 as built, VREF and the supplies AC ground,
    each op-amp a single-pole amplifier of DC gain `a0` and gain-bandwidth `gbw`."""
    s = 2j * math.pi * f
    nodes = ["src", "in1", "fb1", "g1", "out1", "a2", "m2", "out2"]
    idx = {n: i for i, n in enumerate(nodes)}
    size = len(nodes) + 3  # + the source's and two op-amps' output currents
    m = np.zeros((size, size), complex)
    rhs = np.zeros(size, complex)

    def y(a, b, adm):
        for p, q in ((a, b), (b, a)):
            if p is not None:
                m[idx[p], idx[p]] += adm
                if q is not None:
                    m[idx[p], idx[q]] -= adm

    R = lambda a, b, r: y(a, b, 1 / r)  # noqa: E731
    C = lambda a, b, c: y(a, b, s * c)  # noqa: E731
    C("src", "in1", v.TRANSDUCER_C)
    R("in1", None, v.RB1)
    R("out1", "fb1", v.RF1)
    C("out1", "fb1", v.CF1)
    R("fb1", "g1", v.RG1)
    C("g1", None, v.CG1)
    R("out1", "a2", v.R1_2)
    R("a2", None, v.R3_2)
    C("a2", "m2", v.C2)
    C("a2", "out2", v.C2)
    R("m2", "out2", v.R2_2)
    gain = a0 / (1 + s * a0 / (2 * math.pi * gbw))
    # The source: V(src) = 1.
    k = len(nodes)
    m[idx["src"], k] += 1
    m[k, idx["src"]] = 1
    rhs[k] = 1
    # Op-amps: V(out) = A·(V+ − V−), each output's current an unknown.
    for j, (out, plus, minus) in enumerate((("out1", "in1", "fb1"), ("out2", None, "m2")), start=1):
        m[idx[out], k + j] += 1
        m[k + j, idx[out]] = 1
        if plus is not None:
            m[k + j, idx[plus]] -= gain
        m[k + j, idx[minus]] += gain
    x = np.linalg.solve(m, rhs)
    return abs(x[idx["out2"]])


def db(x):
    return 20 * math.log10(x)




def chain_peak(gbw=v.OPAMP_GBW):
    """The frequency of the chain's largest gain between 20 and 70 kHz (50 Hz steps), and that
    gain in dB."""
    freqs = np.linspace(20e3, 70e3, 1001)
    gains = np.array([chain_gain(f, gbw) for f in freqs])
    i = int(np.argmax(gains))
    return freqs[i], db(gains[i])
