#!/usr/bin/env python3
"""The pictures of docs/renderer.md's "The land look" (issue 20), into docs/pictures/look/.

    python3 scripts/look_pictures.py PENMODEL [OLD_PENMODEL]

For each of the five examples: the render in the classic look (`--look classic`, "before") and
in the land look ("after"), 640 x 360 at `penmodel render`'s default camera, and a hillshade of
its heightmap (`penmodel generate --raw`; Lambert only, light from the north-west 45 degrees up,
no shadows: it shows the heightmap's own creases). Then the demo (`--show headless --seed 1`):
its orbit render and its display view with PENMODEL ("after") and, when given, OLD_PENMODEL (a
build from before the land look, "before"), and the hillshade of its final terrain. Pictures are
quantised to 256 colours so that each stays under about 200 KB.
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "docs", "pictures", "look")
EXAMPLES = ["01-ridges-and-peaks", "02-twin-hills", "03-island-with-crater", "04-volcano", "05-terraced-mountain"]


def save(img, name):
    img = img.convert("RGB")
    if img.width > 640:
        img = img.resize((640, round(img.height * 640 / img.width)), Image.LANCZOS)
    img.quantize(256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(
        os.path.join(OUT, name), optimize=True
    )
    print(name, os.path.getsize(os.path.join(OUT, name)) // 1024, "KB")


def hillshade(z, cell):
    """Lambert of the surface normal against light from the north-west (row 0 is north), 45 deg up."""
    gy, gx = np.gradient(z.astype(np.float64), cell)
    n = np.stack([-gx, -gy, np.ones_like(gx)])
    n /= np.linalg.norm(n, axis=0)
    light = np.array([-0.5, -0.5, np.sqrt(0.5)])
    shade = np.clip(np.tensordot(light, n, axes=1), 0.0, 1.0)
    img = Image.fromarray((shade * 255).astype(np.uint8), "L")
    scale = max(1, 320 // max(z.shape))
    return img.resize((z.shape[1] * scale, z.shape[0] * scale), Image.NEAREST)


def heights(penmodel, doc, tmp):
    import json

    raw = os.path.join(tmp, "h.f32")
    subprocess.run([penmodel, "generate", doc, "--raw", raw], check=True, capture_output=True)
    grid = json.load(open(doc))["grid"]
    z = np.fromfile(raw, dtype="<f4").reshape(grid["rows"], grid["cols"])
    return z, grid["cell_size"]


def main():
    penmodel = sys.argv[1]
    old = sys.argv[2] if len(sys.argv) > 2 else None
    os.makedirs(OUT, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name in EXAMPLES:
            doc = os.path.join(ROOT, "modeler", "examples", name + ".json")
            for look, tag in [("classic", "before"), ("land", "after")]:
                png = os.path.join(tmp, "r.png")
                subprocess.run(
                    [penmodel, "render", doc, "--png", png, "--size", "640x360", "--look", look],
                    check=True,
                    capture_output=True,
                )
                save(Image.open(png), f"{name}-{tag}.png")
            save(hillshade(*heights(penmodel, doc, tmp)), f"{name}-hillshade.png")
        for binary, tag in [(penmodel, "after"), (old, "before")]:
            if binary is None:
                continue
            out = os.path.join(tmp, "demo-" + tag)
            subprocess.run(
                [binary, "--show", "headless", "--out", out, "--seed", "1", "--speed", "20"],
                check=True,
                capture_output=True,
            )
            save(Image.open(os.path.join(out, "render.png")), f"demo-render-{tag}.png")
            save(Image.open(os.path.join(out, "display.png")), f"demo-display-{tag}.png")
            if tag == "after":
                import json

                grid = json.load(open(os.path.join(out, "document.json")))["grid"]
                z = np.fromfile(os.path.join(out, "terrain.f32"), dtype="<f4").reshape(grid["rows"], grid["cols"])
                save(hillshade(z, grid["cell_size"]), "demo-hillshade.png")


if __name__ == "__main__":
    main()
