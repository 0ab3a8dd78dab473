"""``gsdf voxelize``: occupancy grid of a mesh/soup or oriented cloud (winding number >= 1/2)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import (
    beta_option,
    check_output,
    load_geometry,
    no_clobber_option,
    normals_option,
    output_file,
    progress_bar,
    quiet_option,
    report_errors,
)


@click.command("voxelize", help="""Voxelize INPUT: a voxel is inside where the winding number at its centre is >= 1/2.

Works on soups with holes and self-intersections and on oriented point clouds (Barill et al. 2018, Fig. 11).
Writes an .npz (occupancy, bbox_min, bbox_max); optionally the voxels' boundary as a mesh.

\b
Example:
  gsdf voxelize soup.obj -o soup_vox.npz --resolution 100 --mesh-out soup_vox.ply
""")
@click.argument("input", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, help="Output .npz.")
@click.option("--resolution", type=click.IntRange(1, 4096), default=100, show_default=True,
              help="Voxels along the longest side.")
@click.option("--pad", type=click.FloatRange(0), default=0.05, show_default=True)
@click.option("--mesh-out", default=None, help="Also write the boundary faces of the occupied voxels.")
@beta_option
@normals_option
@quiet_option
@no_clobber_option
@report_errors
def voxelize(input, output, resolution, pad, mesh_out, beta, estimate_normals, quiet):
    from gsdf.io import MESH_WRITE_FORMATS
    from gsdf.ops import save_voxels, voxelize as run, voxels_to_mesh

    check_output(output, (".npz",))
    check_output(mesh_out, MESH_WRITE_FORMATS, "--mesh-out")
    geo = load_geometry(input, estimate_normals)
    kw = {"mesh": (geo.X, geo.F)} if geo.is_mesh else {"points": (geo.X, geo.N)}
    bar, update = progress_bar(1, "voxelizing", not quiet)
    with bar:
        def progress(done, total):
            bar.total = total
            update(done, total)
        occ, lo, hi = run(resolution=resolution, pad=pad, beta=beta, progress=progress, **kw)
    with output_file(output, (".npz",)) as tmp:
        save_voxels(tmp, occ, lo, hi)
    click.echo(f"{geo.describe()}\n{int(occ.sum())} of {occ.size} voxels inside, grid {occ.shape} -> "
               f"{os.path.abspath(output)}")
    if mesh_out:
        from gsdf.io import write_mesh

        Vv, Fv = voxels_to_mesh(occ, lo, hi)
        with output_file(mesh_out, what="--mesh-out") as tmp:
            write_mesh(tmp, Vv, Fv)
        click.echo(f"voxel boundary mesh -> {os.path.abspath(mesh_out)}")
