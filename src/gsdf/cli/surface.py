"""``gsdf surface``: the 1/2 level set of the winding number, refined by bisection (point-set surfaces)."""

from __future__ import annotations

import os

import click

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
    NUMBER,
    beta_option,
    bisection_option,
    common_options,
    no_clobber_option,
    normals_option,
    output_option,
    pad_option,
    resolution_option,
)
from gsdf.grid import PAD


@click.command("surface", short_help="The winding number's 1/2 level set as a mesh.",
               help="""Extract the surface of INPUT as the winding number's 1/2 level set.

For oriented point clouds this is the point-set surface of Barill et al. 2018 (Fig. 8); for soups it is a
watertight reconstruction. Vertices are placed by bisection along grid edges rather than linear
interpolation (Fig. 9).

\b
Example:
  gsdf surface kitten.xyz --estimate-normals -o kitten.ply --resolution 128
  gsdf surface scan.pwn -o scan.obj
""")
@click.argument("input", type=click.Path(dir_okay=False))
@output_option("Output mesh (.ply, .obj, .off, .stl).")
@resolution_option(128)
@click.option("--level", type=NUMBER, default=0.5, show_default=True, help="Winding number iso-value.")
@bisection_option
@pad_option(PAD)
@beta_option
@normals_option
@common_options
@no_clobber_option
@report_errors
def surface(input, output, resolution, level, bisection, pad, beta, estimate_normals, quiet):
    from gsdf.contour import extract_isosurface
    from gsdf.io import MESH_WRITE_FORMATS, write_mesh

    check_output(output, MESH_WRITE_FORMATS)
    geo = load_geometry(input, estimate_normals)
    lo, hi = bbox_of(geo.X, pad)
    bar, func = counting(LazyWinding(geo, beta), "winding numbers", not quiet)
    with bar:
        V, F = extract_isosurface(func, lo, hi, resolution=resolution, level=level, bisection_steps=bisection)
    with output_file(output) as tmp:
        write_mesh(tmp, V, F)
    announce(f"{geo.describe()}\nsurface: {len(V)} vertices, {len(F)} triangles -> {os.path.abspath(output)}")
