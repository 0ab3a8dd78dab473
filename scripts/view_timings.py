"""Seconds per headless screenshot of a grid field (docs/decisions.md, "view"): gsdf.view's slice mesh with the cut
isosurface against polyscope's own volume grid (gridcubes + slice plane + isosurface), and the depth-peeling passes
of translucent parts.

    python scripts/view_timings.py [FIELD.npz] [--n 128] [--size 1200x900]

Without FIELD, a 128^3 signed distance of an ellipsoid. Needs polyscope and EGL.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import gsdf
from gsdf.render import _polyscope, _scene


def _timed(fn, repeat=3):
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("field", nargs="?")
    ap.add_argument("--n", type=int, default=128)
    ap.add_argument("--size", default="1200x900")
    a = ap.parse_args()
    W, H = (int(t) for t in a.size.split("x"))
    if a.field:
        f = gsdf.load_field(a.field)
    else:
        x = np.linspace(-1, 1, a.n)
        X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
        f = gsdf.GridField(np.sqrt(X ** 2 + 2 * Y ** 2 + 3 * Z ** 2) - 0.7, [-1] * 3, [1] * 3)
    t = time.perf_counter()
    ps = _polyscope.session(headless=True)
    print(f"polyscope import + EGL init: {time.perf_counter() - t:.2f} s")
    shot = "/tmp/gsdf_view_timings.png"
    for passes in (8, 3):
        orig = ps.set_transparency_render_passes
        ps.set_transparency_render_passes = lambda n, p=passes, o=orig: o(p)
        ts = _timed(lambda: gsdf.view(f, screenshot=shot, size=(W, H)))
        ps.set_transparency_render_passes = orig
        print(f"gsdf.view slice mesh + cut isosurface, {passes} depth-peeling passes: "
              + ", ".join(f"{s:.2f}" for s in ts) + " s")

    def volume_grid():
        ps.remove_all_structures()
        ps.remove_all_slice_planes()
        ps.set_window_size(W, H)
        g = ps.register_volume_grid("grid", f.values.shape, f.bbox_min, f.bbox_max)
        g.add_scalar_quantity("value", f.values, defined_on="nodes", enabled=True, cmap="coolwarm",
                              enable_gridcube_viz=True, enable_isosurface_viz=True, isosurface_level=0.0)
        pl = ps.add_slice_plane("cut")
        pl.set_pose(0.5 * (f.bbox_min + f.bbox_max), (0, 0, -1))
        d, up = _scene.camera_direction("y", "z", 35, 25, f.bbox_max - f.bbox_min)
        box = np.array([[x, y, z] for x in (f.bbox_min[0], f.bbox_max[0]) for y in (f.bbox_min[1], f.bbox_max[1])
                        for z in (f.bbox_min[2], f.bbox_max[2])])
        cam, target = _scene.frame_camera(box, W, H, ps.get_vertical_fov_degrees(), d, up)
        ps.look_at_dir(tuple(cam), tuple(target), tuple(up))
        ps.screenshot_to_buffer(transparent_bg=False, include_UI=True)

    ts = _timed(volume_grid)
    print(f"polyscope volume grid {f.values.shape} (gridcubes + slice plane + isosurface): "
          + ", ".join(f"{s:.2f}" for s in ts) + " s")


if __name__ == "__main__":
    main()
