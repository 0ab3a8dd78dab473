"""Regenerate the opening picture of every guide page and of the README from real, broken data.

``python docs/make_gallery.py [--only NAME ...] [--cgal DIR] [--authors DIR]`` writes ``docs/guide/img/*.png``
(one per guide page, and ``readme.png``), the pictures the pages open with, and ``docs/img/*.png``, the
pictures of the scripts in ``examples/`` (run in a temporary folder). It prints each picture's time and the
total run time.

The data:

* CGAL's demo data (``--cgal``, default ``$GSDF_CGAL_DATA``, else ``../cgal/data`` next to the checkout, else
  ``~/.cache/gsdf-data/cgal/data``; Debian ships it in the package ``libcgal-demo``): broken soups
  (``meshes/elephant-with-holes.off``, ``meshes/mech-holes-shark.off``, ``meshes/holes.off``) and raw scan
  clouds (``points_3/kitten.xyz``, ``points_3/oni.pwn``);
* the demo meshes and curves of the signed heat method and of surface winding numbers (``--authors``, default
  ``$GSDF_AUTHOR_DATA``, else ``../shared/data`` next to the checkout): ``shm-surface/bumpy-sphere.*``,
  ``swn/bunny.obj``, ``swn/bunny-heart.txt``, ``swn/double-torus.*``.

Every picture is a headless :func:`gsdf.view` screenshot (polyscope, ``pip install -e ".[view]"``; EGL where
there is no display), several side by side where a page compares, stored as a 256-colour PNG (< 300 KB).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "src"))  # draw with the checkout, not an installed copy

import gsdf  # noqa: E402

GUIDE_IMG = os.path.join(HERE, "guide", "img")
EXAMPLES_IMG = os.path.join(HERE, "img")
SIZE = (1000, 750)          # one panel; pages that compare put two or three side by side
MAX_BYTES = 300_000

#: name -> (the page that opens with it, what it shows)
PICTURES = {
    "readme": ("README.md, docs/index.md", "a broken soup, broken curves on a surface, a raw scan cloud"),
    "inside_outside": ("guide/inside_outside.md", "winding number of elephant-with-holes.off (a soup with holes)"),
    "sdf_grid": ("guide/sdf_grid.md", "signed distance grid of mech-holes-shark.off, signed by the winding number"),
    "curves_on_surfaces": ("guide/curves_on_surfaces.md", "signed heat distance to the 32 broken curves of the "
                                                           "bumpy sphere (signed heat method demo)"),
    "point_cloud_sdf": ("guide/point_cloud_sdf.md", "kitten.xyz, a raw scan cloud, and its Points as Tori "
                                                     "distance"),
    "offsets": ("guide/offsets.md", "a +4 % offset of mech-holes-shark.off from the signed heat method"),
    "surface_winding": ("guide/surface_winding.md", "surface winding numbers of the authors' bunny and double "
                                                    "torus curves"),
    "reconstruction": ("guide/reconstruction.md", "oni.pwn, a raw scan, reconstructed as one closed genus-0 mesh"),
    "batches": ("guide/batches.md", "a batch: SDF grids of three broken soups in the unit sphere frame"),
    "parameters": ("guide/parameters.md", "winding-number sign and signed heat method on elephant-with-holes"),
}


def data_dirs(cgal=None, authors=None):
    """The CGAL demo data folder and the authors' data folder (ValueError saying how to get them)."""
    cands = [cgal, os.environ.get("GSDF_CGAL_DATA"), os.path.join(ROOT, "..", "cgal", "data"),
             os.path.expanduser("~/.cache/gsdf-data/cgal/data")]
    cgal = next((c for c in cands if c and os.path.isdir(os.path.join(c, "meshes"))), None)
    if cgal is None:
        raise SystemExit("make_gallery: CGAL's demo data not found; pass --cgal DIR (the 'data' folder of the "
                         "Debian package libcgal-demo: meshes/, points_3/) or set GSDF_CGAL_DATA")
    cands = [authors, os.environ.get("GSDF_AUTHOR_DATA"), os.path.join(ROOT, "..", "shared", "data")]
    authors = next((a for a in cands if a and os.path.isdir(os.path.join(a, "swn"))), None)
    if authors is None:
        raise SystemExit("make_gallery: the authors' demo data not found; pass --authors DIR (with swn/ and "
                         "shm-surface/) or set GSDF_AUTHOR_DATA")
    return os.path.abspath(cgal), os.path.abspath(authors)


# ------------------------------------------------------------------------------------------------ helpers

def shot(*items, size=SIZE, **kw):
    """A headless gsdf.view screenshot as an (h, w, 3) array."""
    with tempfile.TemporaryDirectory() as d:
        return gsdf.view(*items, screenshot=os.path.join(d, "shot.png"), size=size, **kw)


def side_by_side(*images):
    """Pictures of one height next to each other."""
    h = max(im.shape[0] for im in images)
    out = np.full((h, sum(im.shape[1] for im in images), 3), 255, np.uint8)
    x = 0
    for im in images:
        out[:im.shape[0], x:x + im.shape[1]] = im
        x += im.shape[1]
    return out


def save(img, path):
    """A 256-colour PNG with Floyd–Steinberg dithering (a palette keeps screenshots small: a flat background,
    smooth shading; the dithering keeps shading and colour bars free of bands); fewer colours if it would
    exceed MAX_BYTES. Returns the file's size in bytes."""
    from PIL import Image

    im = Image.fromarray(np.ascontiguousarray(img))
    for colours in (256, 160, 96):
        palette = im.quantize(colors=colours, method=Image.Quantize.MEDIANCUT)
        im.quantize(palette=palette, dither=Image.Dither.FLOYDSTEINBERG).save(path, optimize=True)
        if os.path.getsize(path) <= MAX_BYTES:
            break
    return os.path.getsize(path)


def grid_field(f, X, resolution, pad=0.1):
    """A :class:`gsdf.GridField` of the pointwise function ``f`` on the grid around the points ``X``
    (:meth:`gsdf.Grid.around`)."""
    g = gsdf.Grid.around(X, resolution, pad=pad)
    return gsdf.GridField(np.asarray(f(g.points())).reshape(g.shape), *g.box)


def mesh(cgal, name):
    return gsdf.read_mesh(os.path.join(cgal, "meshes", name))


# ----------------------------------------------------------------------------------------------- pictures

def inside_outside(cgal, authors):
    V, F = mesh(cgal, "elephant-with-holes.off")
    w = grid_field(gsdf.FastWindingNumber(V, F), V, 96, pad=0.05)
    return shot(("winding number", w), ("elephant-with-holes.off", (V, F)), azimuth=145)


def sdf_grid(cgal, authors):
    V, F = mesh(cgal, "mech-holes-shark.off")
    field = gsdf.signed_distance_grid(V, F, resolution=96)
    return shot(("signed distance [model units]", field), ("mech-holes-shark.off", (V, F)), azimuth=35)


def curves_on_surfaces(cgal, authors):
    d = os.path.join(authors, "shm-surface")
    V, F = gsdf.read_mesh(os.path.join(d, "bumpy-sphere.obj"))
    src = gsdf.read_curves(os.path.join(d, "bumpy-sphere.txt"), F)
    phi = gsdf.SurfaceSignedHeatSolver(V, F).compute_distance(list(src.curves), points=src.points,
                                                             curve_signs=src.curve_signs,
                                                             level_set_constraint="none")
    return shot(("signed distance [model units]", (V, F, phi)), ("broken curves", src))


def point_cloud_sdf(cgal, authors):
    P, N = gsdf.read_points(os.path.join(cgal, "points_3", "kitten.xyz"))
    pat = gsdf.PointsAsTori(P, N, estimator="learned")
    field = grid_field(pat.signed_distance, P, 80)
    half = (SIZE[0] * 7 // 10, SIZE[1])
    return side_by_side(shot(("kitten.xyz", (P, N)), size=half, azimuth=-35),
                        shot(("Points as Tori distance [model units]", field), size=half, azimuth=-35))


def offsets(cgal, authors):
    V, F = mesh(cgal, "mech-holes-shark.off")
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    lo, hi = V.min(0) - 0.15 * diag, V.max(0) + 0.15 * diag
    field = gsdf.signed_heat_volume(mesh=(V, F), resolution=80, bbox_min=lo, bbox_max=hi)
    return shot(("signed heat distance [model units]", field), azimuth=35,
                options=gsdf.ViewOptions(level=0.04 * diag))


def surface_winding(cgal, authors):
    """The pictures ``gsdf swn ... --png`` writes (the labels with their share of the area, the curves), for two
    of the authors' demos side by side."""
    from PIL import Image

    d = os.path.join(authors, "swn")
    panels = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, curves in (("bunny", "bunny-heart"), ("double-torus", "double-torus")):
            png = os.path.join(tmp, f"{name}.png")
            run_gsdf("swn", os.path.join(d, f"{name}.obj"), os.path.join(d, f"{curves}.txt"), "-o",
                     os.path.join(tmp, f"{name}.ply"), "--png", png, "-q")
            im = Image.open(png).convert("RGB")
            panels.append(np.asarray(im.resize((im.size[0] * 3 // 4, im.size[1] * 3 // 4), Image.LANCZOS)))
    return side_by_side(*panels)


def reconstruction(cgal, authors):
    P, _ = gsdf.read_points(os.path.join(cgal, "points_3", "oni.pwn"))
    V, F = gsdf.reconstruct_simply_connected(P)
    d = gsdf.unsigned_distance(V, F, P)
    top = float(np.percentile(d, 99))
    return shot(("reconstruction (one closed genus-0 mesh)", (V, F)), ("distance of the scan points [model units]",
                                                                          (P, d)), azimuth=-145,
                options=gsdf.ViewOptions(vrange=(0.0, float(f"{top:.1g}"))))


def batches(cgal, authors):
    names = ("elephant-with-holes.off", "mech-holes-shark.off", "holes.off")
    with tempfile.TemporaryDirectory() as tmp:
        for n in names:
            os.symlink(os.path.join(cgal, "meshes", n), os.path.join(tmp, n))
        out = os.path.join(tmp, "grids")
        r = gsdf.run_batch(tmp, "sdf-grid", out, {"resolution": 64, "normalize": "sphere"}, workers=1)
        assert r.counts["done"] == len(names), r.summary()
        items = []
        for k, n in enumerate(names):
            with np.load(os.path.join(out, n[:-4] + ".npz")) as z:
                shift = np.array([2.6 * k, 0.0, 0.0])
                items.append(("signed distance, unit-sphere frame",
                              gsdf.GridField(z["sdf"], z["bbox_min"] + shift, z["bbox_max"] + shift)))
    return shot(*items, size=(SIZE[0] * 6 // 5, SIZE[1] * 3 // 5), elevation=20, azimuth=0,
                options=gsdf.ViewOptions(slice_axis="z", vrange=(-1.5, 1.5)))


def parameters(cgal, authors):
    V, F = mesh(cgal, "elephant-with-holes.off")
    grid = gsdf.Grid.around(V, 64)
    a = gsdf.signed_distance_grid(V, F, resolution=grid)
    b = gsdf.signed_heat_volume(mesh=(V, F), resolution=grid.shape, bbox_min=grid.bbox_min, bbox_max=grid.bbox_max)
    vr = gsdf.ViewOptions(vrange=(-0.6, 0.6))
    half = (SIZE[0] * 7 // 10, SIZE[1])
    return side_by_side(shot(("winding-number sign [model units]", a), size=half, azimuth=145, options=vr),
                        shot(("signed heat method [model units]", b), size=half, azimuth=145, options=vr))


def readme(cgal, authors):
    panel = (640, 560)
    V, F = mesh(cgal, "elephant-with-holes.off")
    w = grid_field(gsdf.FastWindingNumber(V, F), V, 80, pad=0.05)
    d = os.path.join(authors, "shm-surface")
    Vb, Fb = gsdf.read_mesh(os.path.join(d, "bumpy-sphere.obj"))
    src = gsdf.read_curves(os.path.join(d, "bumpy-sphere.txt"), Fb)
    phi = gsdf.SurfaceSignedHeatSolver(Vb, Fb).compute_distance(list(src.curves), points=src.points,
                                                               curve_signs=src.curve_signs,
                                                               level_set_constraint="none")
    P, N = gsdf.read_points(os.path.join(cgal, "points_3", "kitten.xyz"))
    pat = gsdf.PointsAsTori(P, N, estimator="learned")
    field = grid_field(pat.signed_distance, P, 64)
    return side_by_side(shot(("winding number", w), ("elephant-with-holes.off", (V, F)), size=panel, azimuth=145),
                        shot(("distance to broken curves", (Vb, Fb, phi)), ("curves", src), size=panel),
                        shot(("Points as Tori distance", field), size=panel, azimuth=-35))


def run_gsdf(*args):
    """A ``gsdf`` command of this checkout."""
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    subprocess.run([sys.executable, "-m", "gsdf.cli.main", *map(str, args)], check=True, env=env)


def load(png):
    from PIL import Image

    return np.asarray(Image.open(png).convert("RGB"))


def examples():
    """Run every script of examples/ in a temporary folder and keep the PNG it writes (docs/examples.md)."""
    made = []
    for script in sorted(os.listdir(os.path.join(ROOT, "examples"))):
        if not script.endswith(".py"):
            continue
        with tempfile.TemporaryDirectory() as tmp:
            env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "src") + os.pathsep
                       + os.environ.get("PYTHONPATH", ""), MPLBACKEND="Agg")
            subprocess.run([sys.executable, os.path.join(ROOT, "examples", script)], check=True, cwd=tmp, env=env)
            for f in sorted(os.listdir(tmp)):
                if f.endswith(".png"):
                    n = save(load(os.path.join(tmp, f)), os.path.join(EXAMPLES_IMG, f))
                    made.append((f, n))
    return made


FUNCS = {name: globals()[name] for name in PICTURES}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="*", choices=sorted(PICTURES) + ["examples"], default=None,
                    help="regenerate only these pictures")
    ap.add_argument("--cgal", default=None, help="CGAL's demo data folder (meshes/, points_3/)")
    ap.add_argument("--authors", default=None, help="the authors' data folder (swn/, shm-surface/)")
    args = ap.parse_args(argv)
    cgal, authors = data_dirs(args.cgal, args.authors)
    todo = args.only or (list(PICTURES) + ["examples"])
    os.makedirs(GUIDE_IMG, exist_ok=True)
    t0 = time.perf_counter()
    for name in todo:
        t = time.perf_counter()
        if name == "examples":
            for f, n in examples():
                print(f"docs/img/{f}: {n / 1000:.0f} KB (examples/)", flush=True)
            print(f"  examples: {time.perf_counter() - t:.1f} s", flush=True)
            continue
        img = FUNCS[name](cgal, authors)
        path = os.path.join(GUIDE_IMG, f"{name}.png")
        n = save(img, path)
        print(f"docs/guide/img/{name}.png: {img.shape[1]}x{img.shape[0]}, {n / 1000:.0f} KB, "
              f"{time.perf_counter() - t:.1f} s -- {PICTURES[name][1]}", flush=True)
    print(f"gallery: {len(todo)} picture(s) in {time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    main()
