#!/usr/bin/env python3
"""The rock field's Poisson-disk stage beside an established sampler, in the same run.

For each radius r (cells) on a W x W field: `penmodel rocks --radii r --json -` (our maximal
sampler; its `timing_ms.seeds_cpu` is the seeds stage of that one diagram) and SciPy's
`scipy.stats.qmc.PoissonDisk(d=2, radius=r/W).fill_space()` (Bridson-style candidates around
accepted points until none fits) on the same square. Prints, per radius, the best of `--runs`
times of each, the point counts, and the ratios (ours / SciPy's).

    python3 scripts/rocks_peer.py --penmodel target/release/penmodel --size 512 --radii 9,3,1

Needs SciPy (`pip install scipy`). Issue 11; figures in docs/rocks.md.
"""
import argparse
import json
import subprocess
import time

import scipy
from scipy.stats import qmc


def ours(penmodel, size, r, seed):
    out = subprocess.run(
        [penmodel, "rocks", "--size", f"{size}x{size}", "--radii", str(r), "--fractions", "0.5",
         "--seed", str(seed), "--json", "-"],
        check=True, capture_output=True, text=True)
    doc = json.loads(out.stdout)
    return doc["timing_ms"]["seeds_cpu"], len(doc["diagrams"][0]["seeds"])


def theirs(size, r, seed):
    engine = qmc.PoissonDisk(d=2, radius=r / size, seed=seed)
    t = time.perf_counter()
    pts = engine.fill_space()
    return (time.perf_counter() - t) * 1e3, len(pts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--penmodel", default="target/release/penmodel")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--radii", default="9,3,1")
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    print(f"SciPy {scipy.__version__}; field {a.size} x {a.size} cells; best of {a.runs}")
    print(f"{'r':>4} {'ours ms':>9} {'ours pts':>9} {'scipy ms':>10} {'scipy pts':>10} {'time ratio':>11} {'count ratio':>12}")
    for r in [float(x) for x in a.radii.split(",")]:
        o = [ours(a.penmodel, a.size, r, s + 1) for s in range(a.runs)]
        t = [theirs(a.size, r, s + 1) for s in range(a.runs)]
        o_ms, t_ms = min(x[0] for x in o), min(x[0] for x in t)
        o_n, t_n = sum(x[1] for x in o) / len(o), sum(x[1] for x in t) / len(t)
        print(f"{r:>4g} {o_ms:>9.2f} {o_n:>9.0f} {t_ms:>10.1f} {t_n:>10.0f} {o_ms / t_ms:>11.4f} {o_n / t_n:>12.3f}")


if __name__ == "__main__":
    main()
