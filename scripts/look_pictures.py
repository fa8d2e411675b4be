#!/usr/bin/env python3
"""The pictures of docs/renderer.md's "The land look" (issue 20), into docs/pictures/look/.

    python3 scripts/look_pictures.py PENMODEL [OLD_PENMODEL]
    python3 scripts/look_pictures.py PENMODEL --erosion

For each of the five examples: the render in the classic look (`--look classic`, "before") and
in the land look ("after"), 640 x 360 at `penmodel render`'s default camera, and a hillshade of
its heightmap (`penmodel analyze --hillshade`: Lambert only, no shadows: it shows the heightmap's
own creases). Then the demo (`--show headless --seed 1`):
its orbit render and its display view with PENMODEL ("after") and, when given, OLD_PENMODEL (a
build from before the land look, "before"), and the hillshade of its final terrain. Pictures are
quantised to 256 colours so that each stays under about 200 KB.

With --erosion, only the pictures of docs/document.md's "Erosion": example 1 as a version 4
document with its seed 000 taxicab distances, without and with the default erosion
(`"erosion": {}`): its hillshade and its land look render.
"""
import json
import os
import subprocess
import sys
import tempfile

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


def hillshade(penmodel, doc, tmp):
    """`penmodel analyze --hillshade` (Lambert from the map's upper left, 45 deg up, no shadows),
    enlarged to about 320 pixels."""
    png = os.path.join(tmp, "shade.png")
    subprocess.run([penmodel, "analyze", doc, "--hillshade", png], check=True, capture_output=True)
    img = Image.open(png)
    # A 16-bit grey PNG (0..65535 for 0..1): to 8 bits.
    img = img.point(lambda v: v / 257.0).convert("L") if img.mode.startswith("I") else img.convert("L")
    scale = max(1, 320 // max(img.size))
    return img.resize((img.width * scale, img.height * scale), Image.NEAREST)


def erosion(penmodel, tmp):
    """Example 1 without and with the default erosion: hillshade and land look render."""
    with open(os.path.join(ROOT, "modeler", "examples", "01-ridges-and-peaks.json")) as f:
        doc = json.load(f)
    doc["version"] = 4
    for tag, terrain in [("before", {"metric": "taxicab"}), ("after", {"metric": "taxicab", "erosion": {}})]:
        doc["terrain"] = terrain
        path = os.path.join(tmp, f"erosion-{tag}.json")
        with open(path, "w") as f:
            json.dump(doc, f)
        save(hillshade(penmodel, path, tmp), f"erosion-01-hillshade-{tag}.png")
        png = os.path.join(tmp, "r.png")
        subprocess.run(
            [penmodel, "render", path, "--png", png, "--size", "640x360", "--look", "land"],
            check=True,
            capture_output=True,
        )
        save(Image.open(png), f"erosion-01-render-{tag}.png")


def main():
    penmodel = sys.argv[1]
    if "--erosion" in sys.argv[2:]:
        os.makedirs(OUT, exist_ok=True)
        with tempfile.TemporaryDirectory() as tmp:
            erosion(penmodel, tmp)
        return
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
            save(hillshade(penmodel, doc, tmp), f"{name}-hillshade.png")
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
                save(hillshade(penmodel, os.path.join(out, "document.json"), tmp), "demo-hillshade.png")


if __name__ == "__main__":
    main()
