#!/usr/bin/env python3
"""Heightmaps read back by GDAL (PyPI rasterio, its Python binding with GDAL inside the wheel).

Checks, with penmodel's own outputs (issue 46):
- `generate --geotiff` (with --origin and --epsg, and without --epsg): rasterio reads its size,
  one float32 band, the geotransform (X, s, 0, Y, 0, -s), the CRS (EPSG or none), and heights
  equal to `generate --raw`'s to the bit;
- `generate --raw16`: rows x cols x 2 bytes, each value within half a 16-bit step of the height;
- a DEM that rasterio (GDAL) writes, uncompressed float32, imported with `penmodel import` and
  written again with `generate --raw`: the same heights, exactly;
- the sidecars' rows, cols, cell size and height range.

Usage: scripts/heightmap_peer.py PENMODEL [--keep DIR]
Installs rasterio and numpy into target/gis-venv first if they are missing. Exit status 0: all
passed; 1: a check failed; 77: rasterio could not be installed (no way to PyPI), nothing checked.
"""
import argparse, json, os, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, "target", "gis-venv")
PY = os.path.join(VENV, "bin", "python")
# rasterio 1.4.4 is the last for CPython 3.11 (1.5 needs 3.12); its wheels bundle GDAL.
REQUIREMENTS = ["rasterio==1.4.4", "numpy>=1.24,<3"]
SKIP = 77


def ensure_venv():
    check = [PY, "-c", "import rasterio, numpy"]
    if os.path.exists(PY) and subprocess.run(check, capture_output=True).returncode == 0:
        return True
    if not os.path.exists(PY):
        if subprocess.run([sys.executable, "-m", "venv", VENV]).returncode != 0:
            return False
    r = subprocess.run([PY, "-m", "pip", "install", "-q", "--disable-pip-version-check", *REQUIREMENTS],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout + r.stderr)
        return False
    return subprocess.run(check, capture_output=True).returncode == 0


def run(penmodel, *args, cwd):
    r = subprocess.run([penmodel, *args], cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"FAIL: penmodel {' '.join(args)} exited {r.returncode}: {r.stderr.strip()}")
    return r.stdout


def checks(penmodel, work):
    import numpy as np
    import rasterio
    from rasterio.transform import Affine

    failures = []

    def expect(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    doc = os.path.join(ROOT, "modeler", "examples", "04-volcano.json")
    run(penmodel, "generate", doc, "--raw", "v.f32", "--raw16", "v.r16", "--geotiff", "v.tif",
        "--origin", "500000,4100000", "--epsg", "32654", cwd=work)
    run(penmodel, "generate", doc, "--geotiff", "local.tif", cwd=work)
    side = json.load(open(os.path.join(work, "v.tif.json")))
    rows, cols, s = side["rows"], side["cols"], side["cell_size_m"]
    raw = np.fromfile(os.path.join(work, "v.f32"), dtype="<f4").reshape(rows, cols)

    with rasterio.open(os.path.join(work, "v.tif")) as ds:
        expect((ds.width, ds.height) == (cols, rows), f"GeoTIFF size {ds.width} x {ds.height} is {cols} x {rows}")
        expect(ds.count == 1 and ds.dtypes[0] == "float32", f"one float32 band ({ds.count}, {ds.dtypes})")
        want = Affine(s, 0.0, 500000.0, 0.0, -s, 4100000.0)
        expect(ds.transform.almost_equals(want, precision=1e-9), f"transform {tuple(ds.transform)[:6]} is {tuple(want)[:6]}")
        expect(ds.crs is not None and ds.crs.to_epsg() == 32654, f"CRS {ds.crs} is EPSG:32654")
        band = ds.read(1)
        expect(np.array_equal(band, raw), f"heights equal generate --raw's (max diff {float(np.max(np.abs(band - raw)))})")
        expect(abs(float(band.min()) - side["height_min_m"]) < 1e-3 and abs(float(band.max()) - side["height_max_m"]) < 1e-3,
               f"sidecar range {side['height_min_m']}..{side['height_max_m']} is the band's {band.min()}..{band.max()}")
    with rasterio.open(os.path.join(work, "local.tif")) as ds:
        expect(ds.transform.almost_equals(Affine(s, 0.0, 0.0, 0.0, -s, 0.0), precision=1e-9),
               f"default origin 0,0: transform {tuple(ds.transform)[:6]}")
        expect(ds.crs is None or ds.crs.to_epsg() is None, f"no --epsg: no EPSG code ({ds.crs})")
        expect(np.array_equal(ds.read(1), raw), "heights without --epsg equal too")

    r16 = open(os.path.join(work, "v.r16"), "rb").read()
    expect(len(r16) == rows * cols * 2, f"RAW16 is rows x cols x 2 = {rows * cols * 2} bytes ({len(r16)})")
    s16 = json.load(open(os.path.join(work, "v.r16.json")))
    v = np.frombuffer(r16, dtype="<u2").reshape(rows, cols).astype(np.float64)
    lo, hi = s16["height_min_m"], s16["height_max_m"]
    step = s16["vertical_scale_m_per_step"]
    err = float(np.max(np.abs(lo + v * step - raw)))
    expect(err <= 0.5 * step + 1e-4, f"RAW16 heights within half a step ({err:.5f} m, step {step:.5f} m)")
    expect((s16["rows"], s16["cols"], s16["byte_order"]) == (rows, cols, "little-endian"), "RAW16 sidecar")

    # A DEM that GDAL writes, in through `penmodel import`, out through `generate --raw`.
    r, c = np.mgrid[0:50, 0:70].astype(np.float64)
    dem = (300.0 + 120.0 * np.sin(c / 9.0) * np.cos(r / 7.0) + 0.5 * c).astype(np.float32)
    profile = dict(driver="GTiff", width=70, height=50, count=1, dtype="float32", compress=None, tiled=False,
                   transform=Affine(10.0, 0.0, 650000.0, 0.0, -10.0, 3700000.0), crs="EPSG:32654")
    with rasterio.open(os.path.join(work, "gdal.tif"), "w", **profile) as ds:
        ds.write(dem, 1)
    run(penmodel, "import", "gdal.tif", "--out", "gdal.json", cwd=work)
    run(penmodel, "generate", "gdal.json", "--raw", "back.f32", cwd=work)
    back = np.fromfile(os.path.join(work, "back.f32"), dtype="<f4")
    expect(back.size == dem.size and np.array_equal(back.reshape(50, 70), dem),
           "a GDAL-written DEM imported and generated again has the same heights")
    d = json.load(open(os.path.join(work, "gdal.json")))
    expect(d["grid"] == {"cols": 70, "rows": 50, "cell_size": 10.0} and d["terrain"]["base"]["path"] == "gdal.tif",
           f"the imported document's grid and base ({d['grid']}, {d['terrain']})")
    return failures


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("penmodel")
    ap.add_argument("--keep", help="write the files to this folder and keep them")
    a = ap.parse_args()
    if not ensure_venv():
        print(f"SKIP: rasterio and numpy could not be installed into {VENV} (no way to PyPI?); nothing was checked")
        return SKIP
    if os.path.realpath(sys.prefix) != os.path.realpath(VENV):
        # Run the checks in the venv's Python.
        return subprocess.run([PY, os.path.abspath(__file__), *sys.argv[1:]]).returncode
    penmodel = os.path.abspath(a.penmodel)
    if a.keep:
        os.makedirs(a.keep, exist_ok=True)
        failures = checks(penmodel, a.keep)
    else:
        with tempfile.TemporaryDirectory() as work:
            failures = checks(penmodel, work)
    print("heightmaps read back by GDAL: " + (f"{len(failures)} check(s) failed" if failures else "all checks passed"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
