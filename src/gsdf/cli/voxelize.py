"""``gsdf voxelize``: occupancy grid of a mesh/soup or oriented cloud (winding number >= 1/2)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import (
    announce,
    check_output,
    load_geometry,
    output_file,
    progress_bar,
    report_errors,
)
from gsdf.cli._options import (
    beta_option,
    common_options,
    mesh_output_option,
    no_clobber_option,
    normals_option,
    output_option,
    pad_option,
    resolution_option,
)
from gsdf.grid import PAD


@click.command("voxelize", short_help="Occupancy grid (winding number >= 1/2).",
               help="""Voxelize INPUT: a voxel is inside where the winding number at its centre is >= 1/2.

Works on soups with holes and self-intersections and on oriented point clouds (Barill et al. 2018, Fig. 11).
Writes an .npz (occupancy, bbox_min, bbox_max); optionally the voxels' boundary as a mesh.

\b
Example:
  gsdf voxelize soup.obj -o soup_vox.npz --resolution 100 --mesh-output soup_vox.ply
""")
@click.argument("input", type=click.Path(dir_okay=False))
@output_option("Output .npz (occupancy, bbox_min, bbox_max).")
@resolution_option(100, help="Voxels along the longest side of the box.")
@pad_option(PAD)
@mesh_output_option("Also write the boundary faces of the occupied voxels as a mesh (.ply/.obj/.off/.stl).")
@beta_option
@normals_option
@common_options
@no_clobber_option
@report_errors
def voxelize(input, output, resolution, pad, mesh_output, beta, estimate_normals, quiet):
    import numpy as np

    from gsdf.grid import Grid
    from gsdf.io import MESH_WRITE_FORMATS
    from gsdf.ops import save_voxels, voxelize as run, voxels_to_mesh

    check_output(output, (".npz",))
    check_output(mesh_output, MESH_WRITE_FORMATS, "--mesh-output")
    geo = load_geometry(input, estimate_normals)
    kw = {"mesh": (geo.X, geo.F)} if geo.is_mesh else {"points": (geo.X, geo.N)}
    grid = Grid.around(geo.X[np.unique(geo.F)] if geo.is_mesh else geo.X, resolution, pad)  # as gsdf.voxelize
    bar, update = progress_bar(grid.size, "voxelizing", not quiet)
    with bar:
        occ, lo, hi = run(resolution=grid, beta=beta, progress=update, **kw)
    with output_file(output, (".npz",)) as tmp:
        save_voxels(tmp, occ, lo, hi)
    announce(f"{geo.describe()}\n{int(occ.sum())} of {occ.size} voxels inside, grid {occ.shape} -> "
               f"{os.path.abspath(output)}")
    if mesh_output:
        from gsdf.io import write_mesh

        Vv, Fv = voxels_to_mesh(occ, lo, hi)
        with output_file(mesh_output, what="--mesh-output") as tmp:
            write_mesh(tmp, Vv, Fv)
        announce(f"voxel boundary mesh -> {os.path.abspath(mesh_output)}")
