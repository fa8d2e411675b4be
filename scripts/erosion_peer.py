#!/usr/bin/env python3
"""Fluvial erosion per step, penmodel beside fastscapelib (its C++ core) in one run.

Both erode the surface of `penmodel bench --erosion` (an N x N grid of 10 m cells, a cone of
0.25*N*10 m over 0.45*N cells around the middle, the same seeded noise) with the same
K, m, n, diffusivity, time step and steps; the grid's edge is held at its height (the base
level). fastscapelib routes with SingleFlowRouter and MSTSinkResolver (its faster resolver),
solves the stream-power law (SPLEroder) and diffuses (DiffusionADIEroder); the uplift is the
rate that raises the first surface toward the sketch, (sketch - h)/T, as penmodel's does.

Usage: scripts/erosion_peer.py PENMODEL [--grid N ...] [--steps S] [--json]
Installs fastscapelib and numpy into target/peer-venv first if they are missing.
"""
import argparse, json, os, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, "target", "peer-venv")
PY = os.path.join(VENV, "bin", "python")

# penmodel's defaults (modeler/terrain/src/document.rs, Fluvial::default); the diffusivity's
# default is DIFFUSION_PER_CELL_AREA times the cell's area.
DT, K, M, N, T, NOISE, SEED = 1000.0, 2.5e-4, 0.5, 1.0, 1e4, 1.0, 1
DIFFUSION_PER_CELL_AREA = 7.5e-5
MASK = (1 << 64) - 1


def ensure_venv():
    if os.path.exists(PY) and subprocess.run([PY, "-c", "import fastscapelib, numpy"],
                                             capture_output=True).returncode == 0:
        return
    subprocess.run([sys.executable, "-m", "venv", VENV], check=True)
    subprocess.run([PY, "-m", "pip", "install", "-q", "fastscapelib==0.3.0", "numpy"], check=True)


def surface(n):
    import numpy as np
    cell = 10.0
    mid = (n - 1) / 2.0
    r, c = np.mgrid[0:n, 0:n].astype(np.float64)
    d = np.hypot(c - mid, r - mid)
    sketch = np.maximum(0.25 * n * cell * (1.0 - d / (0.45 * n)), 0.0).astype(np.float32).astype(np.float64)
    # splitmix64's finaliser of (seed ^ i * golden), as fluvial/mod.rs's `mix`.
    i = np.arange(n * n, dtype=np.uint64)
    with np.errstate(over="ignore"):
        z = np.uint64(SEED) ^ (i * np.uint64(0x9E3779B97F4A7C15))
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    u = (z >> np.uint64(11)).astype(np.float64) / float(1 << 53)
    inner = np.zeros((n, n), bool)
    inner[1:-1, 1:-1] = True
    h = sketch.copy().ravel()
    raised = inner.ravel() & (sketch.ravel() > sketch.min())
    h[raised] += NOISE * u[raised]
    return sketch, h.reshape(n, n), cell


def peer(n, steps):
    import numpy as np
    import fastscapelib as fs
    sketch, h, cell = surface(n)
    grid = fs.RasterGrid([n, n], [cell, cell], fs.NodeStatus.FIXED_VALUE)
    graph = fs.FlowGraph(grid, [fs.SingleFlowRouter(), fs.MSTSinkResolver()])
    spl = fs.SPLEroder(graph, K, M, N, 1e-5)
    diffusion = fs.DiffusionADIEroder(grid, DIFFUSION_PER_CELL_AREA * cell * cell)
    inner = np.zeros((n, n), bool)
    inner[1:-1, 1:-1] = True
    times = []
    for _ in range(steps):
        t = time.perf_counter()
        uplift = np.where(inner, (sketch - h) / T, 0.0)
        h = h + uplift * DT
        filled = graph.update_routes(h)
        area = graph.accumulate(1.0)
        h = h - spl.erode(h, area, DT)
        h = h - diffusion.erode(h, DT)
        times.append(time.perf_counter() - t)
    times.sort()
    return 1e3 * sum(times) / len(times), h


def main():
    if os.environ.get("EROSION_PEER_IN_VENV") != "1":
        ensure_venv()
        env = dict(os.environ, EROSION_PEER_IN_VENV="1")
        sys.exit(subprocess.run([PY, __file__] + sys.argv[1:], env=env).returncode)
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("penmodel")
    ap.add_argument("--grid", type=int, action="append")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    rows = []
    for n in a.grid or [512, 1024]:
        ours = json.loads(subprocess.run(
            [a.penmodel, "bench", "--erosion", "--grid", str(n), "--erosion-steps", str(a.steps), "--json"],
            check=True, capture_output=True, text=True).stdout)["erosion"][0]["ms_per_step"]
        theirs = min(peer(n, a.steps)[0] for _ in range(3))
        rows.append({"grid": n, "steps": a.steps, "penmodel_ms_per_step": ours,
                     "fastscapelib_ms_per_step": theirs, "ratio": theirs / ours})
    if a.json:
        print(json.dumps({"erosion_peer": rows}, indent=2))
    else:
        for r in rows:
            print(f"{r['grid']}²: penmodel {r['penmodel_ms_per_step']:.1f} ms/step, fastscapelib "
                  f"{r['fastscapelib_ms_per_step']:.1f} ms/step: {r['ratio']:.1f}x faster")


if __name__ == "__main__":
    main()
