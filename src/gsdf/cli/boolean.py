"""``gsdf boolean``: union / intersection / difference of meshes or soups (their winding-number regions)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import announce, check_output, output_file, report_errors
from gsdf.cli._options import (
    beta_option,
    common_options,
    exact_option,
    no_clobber_option,
    output_option,
)


@click.command("boolean", short_help="Union, intersection, difference of meshes or soups.",
               help="""Boolean of meshes A and B, robust to holes and soups (Barill et al. 2018, Figs. 12-15).

The boundary of the union, intersection or difference of the regions where the winding numbers of A and B
exceed 1/2, cut exactly along the intersection curves (closed inputs give a closed output). `difference` is
A minus B.

\b
Example:
  gsdf boolean bunny.off cylinder.off --op difference -o carved.ply
""")
@click.argument("a", type=click.Path(dir_okay=False))
@click.argument("b", type=click.Path(dir_okay=False))
@click.option("--op", type=click.Choice(["union", "intersection", "difference"]), required=True)
@output_option("Output mesh (.ply, .obj, .off, .stl).")
@exact_option
@beta_option
@common_options
@no_clobber_option
@report_errors
def boolean(a, b, op, output, exact, beta, quiet):
    from gsdf.io import MESH_WRITE_FORMATS, read_mesh, write_mesh
    from gsdf.ops import BooleanOptions, mesh_boolean

    check_output(output, MESH_WRITE_FORMATS)
    VA, FA = read_mesh(a)
    VB, FB = read_mesh(b)
    V, F = mesh_boolean(VA, FA, VB, FB, op, options=BooleanOptions(beta=2.0 if beta is None else beta, exact=exact))
    with output_file(output) as tmp:
        write_mesh(tmp, V, F)
    announce(f"{op}: {len(FA)} + {len(FB)} triangles -> {len(F)} triangles -> {os.path.abspath(output)}")
