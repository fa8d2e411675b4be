#!/usr/bin/env python3
"""Our renderer's frame of a scene of full fractal trees beside Mesa's llvmpipe, in the same run.

A version-4 document with a grove of about 30 `table-3.1` trees (the seed's 30-tree scene) on a
flat 256 m square is written to a temporary folder. Ours: `penmodel render DOC --full-trees
--repeat N --size 1280x720` (every tree in full, LOD off; the median of N frames after a first
one). The peer: `penmodel generate DOC --obj` exports the same terrain and full trees (positions
and per-vertex colours), and moderngl draws them through Mesa's llvmpipe (software OpenGL, EGL,
no display) into a 1280 x 720 colour and depth framebuffer from the same orbit camera as
`penmodel render`'s default (azimuth 30 deg, elevation 35 deg, 45 deg field of view, 1.75
half-diagonals away), per-vertex Lambert light; its time is the median of N frames each ended by
glFinish (the pixels stay in the framebuffer, as ours stay in memory). Prints both times, the
ratio (ours / llvmpipe's) and the triangle counts.

    python3 scripts/trees_peer.py --penmodel target/release/penmodel

Installs what it needs itself, quietly: Mesa's EGL and DRI drivers with apt-get when libEGL is
missing, and moderngl and numpy in target/trees-peer-venv, then runs itself there. Issue 14;
figures in docs/renderer.md.
"""
import argparse
import ctypes.util
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, "target", "trees-peer-venv")


def ensure_environment():
    """Mesa's EGL and a venv with moderngl; re-executes this script inside the venv."""
    if ctypes.util.find_library("EGL") is None:
        subprocess.run(["apt-get", "update", "-qq"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["apt-get", "install", "-y", "-qq", "libegl1", "libegl-mesa0", "libgl1-mesa-dri"],
                       check=True, stdout=subprocess.DEVNULL, env=dict(os.environ, DEBIAN_FRONTEND="noninteractive"))
    python = os.path.join(VENV, "bin", "python")
    if os.path.realpath(sys.prefix) == os.path.realpath(VENV):
        return
    if not os.path.exists(python):
        subprocess.run([sys.executable, "-m", "venv", VENV], check=True)
    subprocess.run([python, "-m", "pip", "install", "-q", "moderngl", "numpy"], check=True)
    os.execv(python, [python] + sys.argv)


def document(size, trees):
    side = 100.0
    lo = 0.5 * (size - side)
    region = [[lo, lo], [lo + side, lo], [lo + side, lo + side], [lo, lo + side], [lo, lo]]
    return {"version": 4, "grid": {"cols": size, "rows": size, "cell_size": 1.0}, "regions": [],
            "groves": [{"region": region, "density": float(trees), "mix": [{"preset": "table-3.1"}],
                        "height": 10.0, "seed": 4}]}


def ours(penmodel, doc, png, runs, size):
    out = subprocess.run([penmodel, "render", doc, "--png", png, "--size", f"{size[0]}x{size[1]}",
                          "--full-trees", "--repeat", str(runs)], check=True, capture_output=True, text=True)
    m = re.search(r"render: ([0-9.]+) ms median of \d+, trees: (\d+), polygons: (\d+)", out.stdout)
    if not m:
        sys.exit(f"penmodel render printed no timing: {out.stdout!r}")
    return float(m.group(1)), int(m.group(2)), int(m.group(3))


def read_obj(path):
    import numpy as np
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                v = [float(x) for x in line.split()[1:]]
                verts.append(v[:6] if len(v) >= 6 else v[:3] + [-1.0, -1.0, -1.0])
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) - 1 for t in line.split()[1:]]
                for k in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[k], idx[k + 1]))
    return np.array(verts, dtype="f4"), np.array(faces, dtype="i4")


def theirs(obj, runs, size, extent):
    import moderngl
    import numpy as np

    v, f = read_obj(obj)
    p = v[:, :3]
    # Our terrain ramp is not reproduced: uncoloured vertices (the terrain) get one grass colour.
    col = np.where(v[:, 3:6] < 0, np.array([0.2, 0.45, 0.15], dtype="f4"), v[:, 3:6])
    # Vertex normals from the faces (area-weighted), as the exports' own normals are.
    n = np.zeros_like(p)
    fn = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    for k in range(3):
        np.add.at(n, f[:, k], fn)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    data = np.hstack([p, n, col]).astype("f4")

    ctx = moderngl.create_standalone_context(backend="egl")
    renderer = ctx.info.get("GL_RENDERER", "?")
    prog = ctx.program(
        vertex_shader="""
            #version 330
            uniform mat4 mvp; uniform vec3 light; uniform float ambient;
            in vec3 p; in vec3 n; in vec3 c; out vec3 lit;
            void main() { gl_Position = mvp * vec4(p, 1.0);
                          lit = c * (ambient + (1.0 - ambient) * abs(dot(n, light))); }""",
        fragment_shader="""
            #version 330
            in vec3 lit; out vec4 colour;
            void main() { colour = vec4(lit, 1.0); }""")
    vbo = ctx.buffer(data.tobytes())
    ibo = ctx.buffer(f.astype("i4").tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "3f 3f 3f", "p", "n", "c")], index_buffer=ibo, index_element_size=4)
    fbo = ctx.simple_framebuffer(size, components=4)
    fbo.use()
    ctx.enable(moderngl.DEPTH_TEST)

    # penmodel render's default orbit camera (camera.rs: Orbit::overview).
    az, el, fov = math.radians(30.0), math.radians(35.0), math.radians(45.0)
    dist = 1.75 * 0.5 * math.hypot(extent[0], extent[1])
    target = np.array([0.5 * extent[0], 0.0, 0.5 * extent[1]])
    back = np.array([math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)])
    eye = target + back * dist
    fwd = -back
    right = np.array([math.cos(az), 0.0, -math.sin(az)])
    up = np.cross(right, fwd)
    view = np.identity(4)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -fwd
    view[:3, 3] = -view[:3, :3] @ eye
    near, far = dist * 1e-3, dist * 4.0
    t = 1.0 / math.tan(0.5 * fov)
    aspect = size[0] / size[1]
    proj = np.array([[t / aspect, 0, 0, 0], [0, t, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])
    prog["mvp"].write((proj @ view).T.astype("f4").tobytes())
    light = np.array([-1.0, 1.7, 1.0])  # Style::default's light [x, y, up] in the world frame (X, up, Z)
    prog["light"].value = tuple(light / np.linalg.norm(light))
    prog["ambient"].value = 0.35

    def frame():
        fbo.clear(0.78, 0.85, 0.92, 1.0, depth=1.0)
        vao.render(moderngl.TRIANGLES)
        ctx.finish()

    frame()
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        frame()
        times.append((time.perf_counter() - t0) * 1e3)
    times.sort()
    return times[len(times) // 2], len(f), renderer


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--penmodel", default=os.path.join(ROOT, "target", "release", "penmodel"))
    ap.add_argument("--trees", type=int, default=30, help="trees per hectare of the 1 ha grove")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--grid", type=int, default=256)
    a = ap.parse_args()
    ensure_environment()
    size = (1280, 720)
    with tempfile.TemporaryDirectory() as tmp:
        doc = os.path.join(tmp, "grove.json")
        with open(doc, "w") as f:
            json.dump(document(a.grid, a.trees), f)
        ms_ours, trees, polygons = ours(a.penmodel, doc, os.path.join(tmp, "ours.png"), a.runs, size)
        obj = os.path.join(tmp, "grove.obj")
        subprocess.run([a.penmodel, "generate", doc, "--obj", obj], check=True, capture_output=True)
        ms_theirs, triangles, renderer = theirs(obj, a.runs, size, (float(a.grid), float(a.grid)))
    print(f"scene: {trees} trees in full ({polygons} polygons) on a {a.grid}^2 grid, {size[0]}x{size[1]}")
    print(f"ours (penmodel render --full-trees): {ms_ours:.1f} ms median of {a.runs}")
    print(f"llvmpipe ({renderer}), {triangles} triangles with the terrain: {ms_theirs:.1f} ms median of {a.runs}")
    print(f"ratio ours / llvmpipe: {ms_ours / ms_theirs:.2f}")


if __name__ == "__main__":
    main()
