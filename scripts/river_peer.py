#!/usr/bin/env python3
"""The river's diamond step beside scipy.ndimage, in the same run.

Writes a document with one meandering river (40 control points, 6 m wide) on a SIZE x SIZE grid,
runs `penmodel river DOC --iterations N --masks DIR --morph L --json -` for each level L (our
dilation and erosion of the river's mask by the (2L-1) x (2L-1) diamond, best of 5, and the
masks as PNGs), then scipy.ndimage.binary_dilation / binary_erosion with the same diamond
(scipy.ndimage.generate_binary_structure(2, 1) iterated L-1 times) on the same mask. Prints, per
level, the best of `--runs` times of each, whether the masks are equal, and the ratio of times
(ours / SciPy's).

    python3 scripts/river_peer.py --penmodel target/release/penmodel --size 1024 --levels 2,4,6

Needs SciPy, NumPy and Pillow. Issue 13; figures in docs/rivers.md.
"""
import argparse
import json
import math
import os
import subprocess
import tempfile
import time

import numpy as np
import scipy
from PIL import Image
from scipy import ndimage


def meander(size, anchors=14):
    """The control points of `penmodel_terrain::river::meander`: a sine course fitted by
    Catmull-Rom tangents through `anchors` points at even arc length."""
    stroke = [(size * (0.04 + 0.92 * t), size * (0.5 + math.sin(t * math.tau * 3.0) / 6.0))
              for t in (k / 400 for k in range(401))]
    arcs = [0.0]
    for a, b in zip(stroke, stroke[1:]):
        arcs.append(arcs[-1] + math.dist(a, b))
    pts, at = [], 0
    for k in range(anchors):
        want = arcs[-1] * k / (anchors - 1)
        while at + 2 < len(stroke) and arcs[at + 1] < want:
            at += 1
        f = (want - arcs[at]) / (arcs[at + 1] - arcs[at])
        a, b = stroke[at], stroke[at + 1]
        pts.append((a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f))
    pts[0], pts[-1] = stroke[0], stroke[-1]
    n = len(pts)

    def tangent(i):
        p, q = pts[max(i - 1, 0)], pts[min(i + 1, n - 1)]
        d = 1.0 if i in (0, n - 1) else 2.0
        return ((q[0] - p[0]) / d, (q[1] - p[1]) / d)

    out = [pts[0]]
    for i in range(n - 1):
        t0, t1 = tangent(i), tangent(i + 1)
        out += [(pts[i][0] + t0[0] / 3, pts[i][1] + t0[1] / 3),
                (pts[i + 1][0] - t1[0] / 3, pts[i + 1][1] - t1[1] / 3), pts[i + 1]]
    return [[x, y] for x, y in out]


def ours(penmodel, doc, level, iterations, folder):
    out = subprocess.run(
        [penmodel, "river", doc, "--iterations", str(iterations), "--masks", folder, "--morph", str(level),
         "--json", "-"], check=True, capture_output=True, text=True)
    m = json.loads(out.stdout)["morph"]
    load = lambda name: np.asarray(Image.open(os.path.join(folder, name))) > 127
    return m["dilate_ms"], m["erode_ms"], load("morph-mask.png"), load("morph-dilate.png"), load("morph-erode.png")


def best(runs, f):
    times, out = [], None
    for _ in range(runs):
        t = time.perf_counter()
        out = f()
        times.append((time.perf_counter() - t) * 1e3)
    return min(times), out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--penmodel", default="target/release/penmodel")
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--levels", default="2,4,6")
    ap.add_argument("--iterations", type=int, default=1)
    ap.add_argument("--runs", type=int, default=5)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        doc = os.path.join(tmp, "river.json")
        with open(doc, "w") as f:
            json.dump({"version": 3, "grid": {"cols": a.size, "rows": a.size, "cell_size": 1.0}, "regions": [],
                       "rivers": [{"points": meander(a.size), "width": 6.0, "depth": 3.0,
                                   "iterations": a.iterations}]}, f)
        print(f"SciPy {scipy.__version__}; river of 40 control points on {a.size} x {a.size} cells, "
              f"its mask after {a.iterations} iteration(s); best of {a.runs} (ours: best of 5 in penmodel)")
        print(f"{'level':>5} {'window':>11} {'op':>7} {'ours ms':>9} {'scipy ms':>9} {'equal':>6} {'time ratio':>11}")
        for level in [int(x) for x in a.levels.split(",")]:
            d_ms, e_ms, mask, dil, ero = ours(a.penmodel, doc, level, a.iterations, tmp)
            cross = ndimage.generate_binary_structure(2, 1)
            it = level - 1
            if it == 0:
                sd_ms, sd, se_ms, se = 0.0, mask, 0.0, mask
            else:
                sd_ms, sd = best(a.runs, lambda: ndimage.binary_dilation(mask, structure=cross, iterations=it))
                se_ms, se = best(a.runs, lambda: ndimage.binary_erosion(mask, structure=cross, iterations=it))
            shape = f"{mask.shape[1]}x{mask.shape[0]}"
            for op, o_ms, s_ms, o, s in [("dilate", d_ms, sd_ms, dil, sd), ("erode", e_ms, se_ms, ero, se)]:
                ratio = o_ms / s_ms if s_ms > 0 else float("nan")
                print(f"{level:>5} {shape:>11} {op:>7} {o_ms:>9.3f} {s_ms:>9.3f} {str(bool((o == s).all())):>6} {ratio:>11.3f}")


if __name__ == "__main__":
    main()
