"""``gsdf surface``: the 1/2 level set of the winding number, refined by bisection (point-set surfaces)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import (
    bbox_of,
    beta_option,
    check_output,
    counting,
    load_geometry,
    no_clobber_option,
    normals_option,
    output_file,
    quiet_option,
    report_errors,
)
from gsdf.grid import PAD


@click.command("surface", help="""Extract the surface of INPUT as the winding number's 1/2 level set.

For oriented point clouds this is the point-set surface of Barill et al. 2018 (Fig. 8); for soups it is a
watertight reconstruction. Vertices are placed by bisection along grid edges rather than linear
interpolation (Fig. 9).

\b
Example:
  gsdf surface kitten.xyz --estimate-normals -o kitten.ply --resolution 128
  gsdf surface scan.pwn -o scan.obj
""")
@click.argument("input", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, help="Output mesh (.ply, .obj, .off, .stl).")
@click.option("--resolution", type=click.IntRange(2, 2048), default=128, show_default=True)
@click.option("--level", type=float, default=0.5, show_default=True, help="Winding number iso-value.")
@click.option("--bisection", type=click.IntRange(0, 60), default=10, show_default=True,
              help="Bisection steps per vertex (0: plain marching cubes).")
@click.option("--pad", type=click.FloatRange(0), default=PAD, show_default=True,
              help="Box padding, fraction of the diagonal.")
@beta_option
@normals_option
@quiet_option
@no_clobber_option
@report_errors
def surface(input, output, resolution, level, bisection, pad, beta, estimate_normals, quiet):
    from gsdf.contour import extract_isosurface
    from gsdf.io import MESH_WRITE_FORMATS, write_mesh

    check_output(output, MESH_WRITE_FORMATS)
    geo = load_geometry(input, estimate_normals)
    lo, hi = bbox_of(geo.X, pad)
    bar, func = counting(geo.winding(beta), "winding numbers", not quiet)
    with bar:
        V, F = extract_isosurface(func, lo, hi, resolution=resolution, level=level, bisection_steps=bisection)
    with output_file(output) as tmp:
        write_mesh(tmp, V, F)
    click.echo(f"{geo.describe()}\nsurface: {len(V)} vertices, {len(F)} triangles -> {os.path.abspath(output)}")
