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
    FLOATS,
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

\b
Example:
  gsdf slice bunny.off -o bunny_slices.svg --layers 20
  gsdf slice scan.pwn -o s.svg --heights 0.1,0.2,0.3 --axis y
""")
@click.argument("input", type=click.Path(dir_okay=False))
@output_option("Output .svg.")
@click.option("--layers", type=click.IntRange(1, 100000), default=None, help="Number of evenly spaced slices.")
@click.option("--heights", type=FLOATS, default=None, help="Comma-separated slice heights.")
@click.option("--axis", type=click.Choice(["x", "y", "z"]), default="z", show_default=True)
@resolution_option(256, help="Nodes of each slice's grid along its longer side.")
@click.option("--layout", type=click.Choice(["layers", "stack"]), default="layers", show_default=True,
              help="SVG layers on top of each other, or slices stacked side by side.")
@beta_option
@normals_option
@common_options
@no_clobber_option
@report_errors
def slice_cmd(input, output, layers, heights, axis, resolution, layout, beta, estimate_normals, quiet):
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
    with output_file(output) as tmp:
        write_svg(tmp, contours, z_values=zs, layout=layout)
    n_loops = sum(len(c) for c in contours)
    announce(f"{geo.describe()}\n{len(zs)} slices along {axis}, {n_loops} closed contours -> "
               f"{os.path.abspath(output)}")
slice_cmd.name = "slice"
