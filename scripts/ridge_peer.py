#!/usr/bin/env python3
"""The ridge/valley map's rain counts beside an established D8 flow accumulation, in the same run.

A document of 20 random-walk ridgelines (200 segments, elevations 40-150 m, flanks at 30 deg) on
a SIZE x SIZE grid of 1 m cells is written to a temporary folder; `penmodel generate --raw` gives
its DTM and `penmodel analyze --flow` our rain pass counts (Sobel descent, one drop per cell; its
`rain counts: X ms` line on stderr is the time, best of --runs). pysheds (`Grid.flowdir` then
`Grid.accumulation`, D8, numba-compiled; warmed up once) takes the same DTM. Prints both times
and their ratio (ours / pysheds'), and the Spearman rank correlation of the two maps over all
cells and over the sloped cells (DTM above 0), and the overlap (Jaccard) of the valley areas
(count >= --valley-min in both).

    python3 -m venv target/ridge-peer-venv && target/ridge-peer-venv/bin/pip install pysheds scipy
    target/ridge-peer-venv/bin/python scripts/ridge_peer.py --penmodel target/release/penmodel

pysheds 0.5 still calls numpy.in1d, which numpy 2.4 removed; numpy.isin is the same function,
so it is put in its place before pysheds is imported. Issue 12; figures in docs/ridgelines.md.
"""
import argparse
import json
import math
import os
import random
import re
import subprocess
import tempfile
import time

import numpy as np

if not hasattr(np, "in1d"):
    np.in1d = lambda a, b, **k: np.isin(a, b, **k)

import affine  # noqa: E402  (a pysheds dependency)
import pysheds  # noqa: E402
from pysheds.grid import Grid  # noqa: E402
from pysheds.view import Raster, ViewFinder  # noqa: E402
from scipy.stats import spearmanr  # noqa: E402


def scene(size, seed):
    """20 random-walk ridgelines of 10 segments, like benches/ridge.rs's full_dtm scene."""
    rng = random.Random(seed)
    lines = []
    for _ in range(20):
        p = [rng.uniform(0.1 * size, 0.9 * size), rng.uniform(0.1 * size, 0.9 * size)]
        heading = rng.uniform(0, 2 * math.pi)
        pts = []
        for _ in range(11):
            pts.append([p[0], p[1], rng.uniform(40.0, 150.0)])
            heading += rng.uniform(-0.6, 0.6)
            step = rng.uniform(0.02 * size, 0.04 * size)
            p = [min(max(p[0] + step * math.cos(heading), 0.0), size),
                 min(max(p[1] + step * math.sin(heading), 0.0), size)]
        lines.append({"points": pts})
    return {"version": 3, "grid": {"cols": size, "rows": size, "cell_size": 1.0}, "regions": [],
            "ridges": {"slope": 30.0, "lines": lines}}


def ours(penmodel, doc, out):
    r = subprocess.run([penmodel, "analyze", doc, "--flow", out], check=True, capture_output=True, text=True)
    return float(re.search(r"rain counts: ([0-9.]+) ms", r.stderr).group(1))


def theirs(z):
    vf = ViewFinder(affine=affine.Affine(1, 0, 0, 0, -1, z.shape[0]), shape=z.shape, nodata=np.nan)
    dem = Raster(z.astype(np.float64), viewfinder=vf)
    grid = Grid(viewfinder=vf)
    t = time.perf_counter()
    acc = grid.accumulation(grid.flowdir(dem))
    return (time.perf_counter() - t) * 1e3, np.asarray(acc)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--penmodel", default="target/release/penmodel")
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seed", type=int, default=2)
    ap.add_argument("--valley-min", type=int, default=32)
    a = ap.parse_args()
    n = a.size
    with tempfile.TemporaryDirectory() as tmp:
        doc = os.path.join(tmp, "ridges.json")
        with open(doc, "w") as f:
            json.dump(scene(n, a.seed), f)
        dtm_path, flow_path = os.path.join(tmp, "dtm.f32"), os.path.join(tmp, "flow.f32")
        subprocess.run([a.penmodel, "generate", doc, "--raw", dtm_path], check=True, capture_output=True)
        z = np.fromfile(dtm_path, dtype="<f4").reshape(n, n)
        our_ms = min(ours(a.penmodel, doc, flow_path) for _ in range(a.runs))
        flow = np.fromfile(flow_path, dtype="<f4").reshape(n, n)
    theirs(z)  # numba compiles on the first call
    best = min((theirs(z) for _ in range(a.runs)), key=lambda r: r[0])
    their_ms, acc = best
    sloped = z > 0
    rho_all = spearmanr(flow.ravel(), acc.ravel()).statistic
    rho_sloped = spearmanr(flow[sloped], acc[sloped]).statistic
    ours_v, theirs_v = flow >= a.valley_min, acc >= a.valley_min
    jaccard = (ours_v & theirs_v).sum() / max(1, (ours_v | theirs_v).sum())
    print(f"pysheds {pysheds.__version__ if hasattr(pysheds, '__version__') else '0.5'}, numpy {np.__version__}; "
          f"DTM {n} x {n} (200 ridge segments), best of {a.runs}")
    print(f"rain counts (ours, Sobel descent): {our_ms:9.1f} ms")
    print(f"D8 flowdir + accumulation (pysheds): {their_ms:7.1f} ms")
    print(f"time ratio ours / pysheds: {our_ms / their_ms:.2f}")
    print(f"Spearman rank correlation: {rho_all:.3f} all cells, {rho_sloped:.3f} sloped cells ({sloped.mean():.0%})")
    print(f"valley areas (>= {a.valley_min} drops): ours {ours_v.mean():.2%}, D8 {theirs_v.mean():.2%}, Jaccard {jaccard:.3f}")


if __name__ == "__main__":
    main()
