#!/usr/bin/env python3
"""`penmodel generate --glb` checked by outside tools (issue 46): the Khronos glTF validator (npm
`gltf-validator`) and a real consumer, PyPI's pygltflib.

Checks, on a document with a river, a rock field, a tree and a grove (DOC, written by the caller):
- the validator reports no errors for `--glb`, `--tree-detail 0.2` and `--no-trees --no-rocks
  --no-water` (it does not know EXT_mesh_gpu_instancing and says so as information: the
  instances' accessors are checked here instead: counts, unit rotations, positive scales);
- pygltflib reads back: every primitive has a material; the materials ground, water (BLEND),
  rock, bark and leaves; EXT_mesh_gpu_instancing used and required; the instances of all tree
  nodes add up to TREES, each with TRANSLATION, ROTATION and SCALE accessors of that count, and
  one stands at AT (x, z) when given; one node per shared mesh; the terrain has COLOR_0;
- `--tree-detail 0.2` writes a smaller file with the same instances;
- `--no-trees --no-rocks --no-water` leaves only the terrain.

Usage: scripts/gltf_peer.py PENMODEL DOC TREES [X,Z] [--keep DIR]
Installs gltf-validator into target/gltf-npm (npm) and pygltflib into target/gltf-venv (pip)
first if they are missing. Exit status 0: all passed; 1: a check failed; 77: node/npm or the
packages could not be had (no way to the registries), nothing checked.
"""
import argparse, json, os, shutil, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NPM_DIR = os.path.join(ROOT, "target", "gltf-npm")
VALIDATOR = "gltf-validator@2.0.0-dev.3.10"
VENV = os.path.join(ROOT, "target", "gltf-venv")
PY = os.path.join(VENV, "bin", "python")
REQUIREMENTS = ["pygltflib==1.16.5"]
SKIP = 77

VALIDATE_JS = r"""
const fs = require('fs');
const validator = require('gltf-validator');
const bytes = new Uint8Array(fs.readFileSync(process.argv[2]));
validator.validateBytes(bytes, {maxIssues: 100}).then((r) => {
  console.log(JSON.stringify({numErrors: r.issues.numErrors, numWarnings: r.issues.numWarnings,
    messages: r.issues.messages.filter((m) => m.severity <= 1)}));
}, (e) => { console.error(String(e)); process.exit(2); });
"""

READ_PY = r"""
import json, sys
from pygltflib import GLTF2
g = GLTF2().load(sys.argv[1])
out = {"materials": [], "nodes": [], "extensionsUsed": g.extensionsUsed or [],
       "extensionsRequired": g.extensionsRequired or [], "primitives_without_material": 0}
for m in g.materials:
    out["materials"].append({"name": m.name, "alphaMode": m.alphaMode,
                             "base": m.pbrMetallicRoughness.baseColorFactor})
blob = g.binary_blob()
def floats(i):
    import struct
    a = g.accessors[i]; v = g.bufferViews[a.bufferView]
    n = {"VEC3": 3, "VEC4": 4}[a.type]
    start = v.byteOffset + (a.byteOffset or 0)
    return [struct.unpack_from("<%df" % n, blob, start + 4 * n * k) for k in range(a.count)]
for node in g.nodes:
    mesh = g.meshes[node.mesh]
    prims = [{"material": p.material, "color": p.attributes.COLOR_0 is not None} for p in mesh.primitives]
    out["primitives_without_material"] += sum(1 for p in mesh.primitives if p.material is None)
    n = {"name": node.name, "mesh": mesh.name, "primitives": prims}
    ext = (node.extensions or {}).get("EXT_mesh_gpu_instancing")
    if ext:
        att = ext["attributes"]
        n["counts"] = {k: g.accessors[att[k]].count for k in ("TRANSLATION", "ROTATION", "SCALE")}
        n["translations"] = floats(att["TRANSLATION"])
        n["rotations"] = floats(att["ROTATION"])
        n["scales"] = floats(att["SCALE"])
    out["nodes"].append(n)
print(json.dumps(out))
"""


def have(cmd):
    return shutil.which(cmd) is not None


def ensure_validator():
    if not (have("node") and have("npm")):
        return "node and npm are not installed"
    pkg = os.path.join(NPM_DIR, "node_modules", "gltf-validator")
    if os.path.isdir(pkg):
        return None
    os.makedirs(NPM_DIR, exist_ok=True)
    r = subprocess.run(["npm", "install", "--no-audit", "--no-fund", "--prefix", NPM_DIR, VALIDATOR],
                       capture_output=True, text=True)
    if r.returncode != 0 or not os.path.isdir(pkg):
        return "npm could not install " + VALIDATOR + ": " + (r.stdout + r.stderr).strip()[-400:]
    return None


def ensure_venv():
    check = [PY, "-c", "import pygltflib"]
    if os.path.exists(PY) and subprocess.run(check, capture_output=True).returncode == 0:
        return None
    if not os.path.exists(PY):
        if subprocess.run([sys.executable, "-m", "venv", VENV]).returncode != 0:
            return "python3 -m venv failed"
    r = subprocess.run([PY, "-m", "pip", "install", "-q", "--disable-pip-version-check", *REQUIREMENTS],
                       capture_output=True, text=True)
    if r.returncode != 0 or subprocess.run(check, capture_output=True).returncode != 0:
        return "pip could not install pygltflib: " + (r.stdout + r.stderr).strip()[-400:]
    return None


def run(penmodel, *args, cwd):
    r = subprocess.run([penmodel, *args], cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"FAIL: penmodel {' '.join(args)} exited {r.returncode}: {r.stderr.strip()}")


def validate(path, work):
    js = os.path.join(work, "validate.js")
    with open(js, "w") as f:
        f.write(VALIDATE_JS)
    env = dict(os.environ, NODE_PATH=os.path.join(NPM_DIR, "node_modules"))
    r = subprocess.run(["node", js, path], capture_output=True, text=True, env=env)
    if r.returncode != 0:
        raise SystemExit(f"FAIL: the validator did not run on {path}: {r.stderr.strip()}")
    return json.loads(r.stdout)


def read(path, work):
    py = os.path.join(work, "read.py")
    with open(py, "w") as f:
        f.write(READ_PY)
    r = subprocess.run([PY, py, path], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"FAIL: pygltflib could not read {path}: {r.stderr.strip()}")
    return json.loads(r.stdout)


def checks(penmodel, doc, trees, at, work):
    failures = []

    def expect(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    run(penmodel, "generate", doc, "--glb", "full.glb", cwd=work)
    run(penmodel, "generate", doc, "--glb", "coarse.glb", "--tree-detail", "0.2", cwd=work)
    run(penmodel, "generate", doc, "--glb", "bare.glb", "--no-trees", "--no-rocks", "--no-water", cwd=work)
    for name in ("full.glb", "coarse.glb", "bare.glb"):
        v = validate(os.path.join(work, name), work)
        expect(v["numErrors"] == 0, f"{name}: the Khronos validator finds no errors "
               f"({v['numErrors']} errors, {v['numWarnings']} warnings: {v['messages'][:5]})")

    g = read(os.path.join(work, "full.glb"), work)
    names = [m["name"] for m in g["materials"]]
    expect(set(names) >= {"ground", "water", "rock", "bark", "leaves"}, f"materials {names}")
    expect(g["primitives_without_material"] == 0, "every primitive has a material")
    water = [m for m in g["materials"] if m["name"] == "water"]
    expect(bool(water) and water[0]["alphaMode"] == "BLEND", f"water is alpha-blended ({water})")
    ext = "EXT_mesh_gpu_instancing"
    expect(ext in g["extensionsUsed"] and ext in g["extensionsRequired"],
           f"{ext} used and required ({g['extensionsUsed']}, {g['extensionsRequired']})")
    tree_nodes = [n for n in g["nodes"] if "counts" in n]
    total = sum(n["counts"]["TRANSLATION"] for n in tree_nodes)
    expect(total == trees, f"{total} tree instances in {len(tree_nodes)} nodes, the document has {trees} trees")
    expect(all(len(set(n["counts"].values())) == 1 for n in tree_nodes),
           "each node's TRANSLATION, ROTATION and SCALE have the same count")
    expect(len({n["mesh"] for n in tree_nodes}) == len(tree_nodes), "one node per shared mesh")
    # The validator does not know the extension (it says so as information): its data checked here.
    unit = all(abs(sum(q * q for q in r) - 1.0) < 1e-5 for n in tree_nodes for r in n["rotations"])
    positive = all(min(s) > 0.0 for n in tree_nodes for s in n["scales"])
    expect(unit and positive, "instance rotations are unit quaternions and scales positive")
    terrain = [n for n in g["nodes"] if n["name"] == "terrain"]
    expect(bool(terrain) and terrain[0]["primitives"][0]["color"], "the terrain has vertex colours (COLOR_0)")
    expect(any(n["name"] == "water" for n in g["nodes"]), "a water node")
    expect(any(n["name"].startswith("rocks") for n in g["nodes"]), "a rocks node")
    if at is not None:
        near = any(abs(t[0] - at[0]) < 1e-3 and abs(t[2] - at[1]) < 1e-3 for n in tree_nodes for t in n["translations"])
        expect(near, f"a tree instance stands at x, z = {at}")

    c = read(os.path.join(work, "coarse.glb"), work)
    coarse = sum(n["counts"]["TRANSLATION"] for n in c["nodes"] if "counts" in n)
    small, big = (os.path.getsize(os.path.join(work, n)) for n in ("coarse.glb", "full.glb"))
    expect(coarse == trees and small < big, f"--tree-detail 0.2: {coarse} instances, {small} < {big} bytes")

    b = read(os.path.join(work, "bare.glb"), work)
    expect([n["name"] for n in b["nodes"]] == ["terrain"] and not b["extensionsUsed"],
           f"--no-trees --no-rocks --no-water: nodes {[n['name'] for n in b['nodes']]}")
    return failures


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("penmodel")
    ap.add_argument("doc")
    ap.add_argument("trees", type=int)
    ap.add_argument("at", nargs="?")
    ap.add_argument("--keep")
    a = ap.parse_args()
    for why in (ensure_validator(), ensure_venv()):
        if why:
            print("SKIP: " + why)
            return SKIP
    at = tuple(float(v) for v in a.at.split(",")) if a.at else None
    doc = os.path.abspath(a.doc)
    if a.keep:
        os.makedirs(a.keep, exist_ok=True)
        failures = checks(a.penmodel, doc, a.trees, at, a.keep)
    else:
        with tempfile.TemporaryDirectory() as work:
            failures = checks(a.penmodel, doc, a.trees, at, work)
    if failures:
        print(f"{len(failures)} checks failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
