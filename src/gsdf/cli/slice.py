"""``gsdf slice``: closed 2D contours of the solid at given heights, as SVG (3D-printing slices)."""

from __future__ import annotations

import os

import click
import numpy as np

from gsdf.cli._common import (
    announce,
    bbox_of,
    check_output,
    LazyWinding,
    counting,
    load_geometry,
    output_file,
    report_errors,
)
from gsdf.cli._options import (
    AXIS,
    FLOATS,
    POSITIVE,
    beta_option,
    common_options,
    no_clobber_option,
    normals_option,
    output_option,
    resolution_option,
)


@click.command("slice", short_help="Closed 2D contours at given heights, as SVG.",
               help="""Slice INPUT into closed contours of its winding-number solid, written as SVG.

Works directly on soups and point clouds, no meshing (Barill et al. 2018, Fig. 3). Heights are given
explicitly (--heights) or as N evenly spaced layers (--layers) through the bounding box.

The SVG's viewBox spans the contours. --units mm gives it a physical size, --scale millimetres per model unit
(true size for printing); --units model leaves the size out, so a browser fits the drawing to its window;
--units auto (the default) is mm when the drawing is 10 mm to 2 m long at --scale, else model.

\b
Example:
  gsdf slice bunny.off -o bunny_slices.svg --layers 20
  gsdf slice scan.pwn -o s.svg --heights 0.1,0.2,0.3 --axis y
  gsdf slice part_in_metres.stl -o part.svg --layers 50 --units mm --scale 1000
""")
@click.argument("input", type=click.Path(dir_okay=False))
@output_option("Output .svg.")
@click.option("--layers", type=click.IntRange(1, 100000), default=None, help="Number of evenly spaced slices.")
@click.option("--heights", type=FLOATS, default=None, help="Comma-separated slice heights.")
@click.option("--axis", type=AXIS, default="z", show_default=True, help="Axis across the slices (the print direction).")
@resolution_option(256, help="Nodes of each slice's grid along its longer side.")
@click.option("--layout", type=click.Choice(["layers", "stack"]), default="layers", show_default=True,
              help="SVG layers on top of each other, or slices stacked side by side.")
@click.option("--units", type=click.Choice(["auto", "mm", "model"]), default="auto", show_default=True,
              help="Size of the drawing: mm (--scale mm per model unit), model (none: it fits the window), or auto.")
@click.option("--scale", type=POSITIVE, default=1.0, show_default=True,
              help="Millimetres per model unit, for --units mm and auto (1000: the model is in metres).")
@beta_option
@normals_option
@common_options
@no_clobber_option
@report_errors
def slice_cmd(input, output, layers, heights, axis, resolution, layout, units, scale, beta, estimate_normals, quiet):
    from gsdf.contour import slice_contours, write_svg

    check_output(output, (".svg",))
    geo = load_geometry(input, estimate_normals)
    ax = "xyz".index(axis)
    lo, hi = bbox_of(geo.X, 0.02)
    zs = heights
    if zs is None:
        n = layers or 10
        zs = list(lo[ax] + (hi[ax] - lo[ax]) * (np.arange(n) + 0.5) / n)
    bar, func = counting(LazyWinding(geo, beta), "winding numbers", not quiet)
    with bar:
        contours = slice_contours(func, zs, lo, hi, resolution=resolution, axis=ax)
    u, v = (ax + 1) % 3, (ax + 2) % 3                  # the 2D axes of slice_contours
    pts = [P for sl in contours for P in sl]
    frame = np.array([np.concatenate(pts).min(0), np.concatenate(pts).max(0)]) if pts else \
        np.array([[lo[u], lo[v]], [hi[u], hi[v]]])
    w, h = frame[1] - frame[0]
    if layout == "stack":
        h = h * len(zs)
    if units == "auto":
        units = "mm" if 10.0 <= max(w, h) * scale <= 2000.0 else "model"
    with output_file(output) as tmp:
        write_svg(tmp, contours, z_values=zs, bbox=frame, layout=layout, unit_mm=scale if units == "mm" else None)
    n_loops = sum(len(c) for c in contours)
    size = (f"{w * scale:.4g} x {h * scale:.4g} mm ({scale:g} mm per model unit)" if units == "mm" else
            f"{w:.4g} x {h:.4g} model units, no physical size: it fits the window (--units mm --scale S: S mm "
            "per unit)")
    announce(f"{geo.describe()}\n{len(zs)} slices along {axis}, {n_loops} closed contours, drawing {size} -> "
               f"{os.path.abspath(output)}")
slice_cmd.name = "slice"
