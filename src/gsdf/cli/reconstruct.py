"""``gsdf reconstruct``: one closed manifold genus-0 mesh from a point cloud (Chen, Li & Huang 2026 + guarantee)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import check_output, output_file, report_errors
from gsdf.cli._options import (
    common_options,
    no_clobber_option,
    output_option,
    png_option,
    resolution_option,
    view_option,
)

_METHODS = ("simply-connected", "winding", "heat", "pat")


@click.command("reconstruct", short_help="One closed manifold mesh from a point cloud.",
               help="""Reconstruct a closed surface from a point cloud (normals optional).

The default method is guaranteed: the output is one closed, edge- and vertex-manifold triangle mesh of genus 0
(with --clusters: one such sphere per single-linkage cluster), whatever the input — outliers, holes, handles.
--method winding|heat|pat extracts the level set of another gsdf field instead, with no such promise; the
printed report gives components and genus either way. CLOUD: any format gsdf.read_points reads; OUTPUT: any
format gsdf.write_mesh writes (.ply/.obj/.off/.stl).

\b
Examples:
  gsdf reconstruct scan.xyz -o scan.ply --png scan.png
  gsdf reconstruct vessels.ply -o vessels.obj --clusters
  gsdf reconstruct scan.xyz -o scan_wn.ply --method winding
""")
@click.argument("cloud", type=click.Path(dir_okay=False))
@output_option("Output mesh (.ply/.obj/.off/.stl).")
@click.option("--method", type=click.Choice(_METHODS), default="simply-connected", show_default=True,
              help="simply-connected (guaranteed sphere) or a comparison level set.")
@click.option("--outliers", type=click.Choice(["auto", "none"]), default="auto", show_default=True,
              help="auto: pre-filter plus alternation (§3.3); none: use every point, one pass.")
@click.option("--clusters", is_flag=True, help="One sphere per single-linkage cluster of the cloud (§6.1).")
@click.option("--max-iterations", type=click.IntRange(1, 20), default=4, show_default=True,
              help="Alternation rounds of the outlier removal.")
@resolution_option(128, help="Grid nodes along the longest side of the box, for the comparison methods (ignored "
                             "by simply-connected).")
@png_option("Also write a PNG preview of the result (shaded by height).")
@view_option("0.3,0.2,1")
@common_options
@no_clobber_option
@report_errors
def reconstruct(cloud, output, method, outliers, clusters, max_iterations, resolution, png, view, quiet):
    import numpy as np

    from gsdf.io import read_points, write_mesh
    from gsdf.mesh._topology import mesh_topology

    check_output(output, (".ply", ".obj", ".off", ".stl"))
    check_output(png, (".png",), "--png")
    P, N = read_points(cloud)

    def say(stage, fraction):
        if not quiet and fraction < 1:
            click.echo(f"  {stage} ...", err=True)

    click.echo(f"{cloud}: {len(P)} points{' with normals' if N is not None else ''}; method {method}")
    if method == "simply-connected":
        from gsdf.recon import ReconstructionOptions, reconstruct_simply_connected
        V, F, rep = reconstruct_simply_connected(P, N, outliers=outliers, clusters=clusters,
                                                 options=ReconstructionOptions(max_iterations=max_iterations),
                                                 progress=say, return_report=True)
        click.echo(f"  {rep['iterations']} round(s); {int(rep['outliers'].sum())} points judged outliers; "
                   f"{rep['n_tets']} tets; {rep['timings']['total']:.2f} s")
    else:
        from gsdf.recon import _compare as compare
        fn = {"winding": compare.reconstruct_winding, "heat": compare.reconstruct_heat,
              "pat": compare.reconstruct_pat}[method]
        say(f"{method} level set", 0.0)
        V, F, rep = fn(P, N, resolution=resolution, return_report=True)
        click.echo(f"  {rep['time']:.2f} s")
    top = mesh_topology(V, F)
    manifold = top["closed"] and top["edge_manifold"] and top["vertex_manifold"]
    click.echo(f"  {len(V)} vertices, {len(F)} faces; components {top['components']}, genus {top['genus']}, "
               f"{'closed manifold' if manifold else 'NOT a closed manifold'}")
    with output_file(output, (".ply", ".obj", ".off", ".stl")) as tmp:
        write_mesh(tmp, V, F)
    click.echo(f"mesh -> {os.path.abspath(output)}")
    if png is not None:
        from gsdf.render._raster import render_function_png
        with output_file(png, (".png",), what="--png") as tmp:
            render_function_png(tmp, V, F, np.asarray(V)[:, 1], view=view)
        click.echo(f"preview -> {os.path.abspath(png)}")
