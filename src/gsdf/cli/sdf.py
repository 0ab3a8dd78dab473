"""``gsdf sdf``: a signed distance grid of a mesh/soup or oriented cloud, signed by the winding number."""

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
from gsdf.grid import PAD


def signed_distance_grid(geo, resolution: int, pad: float, sign: str = "winding", beta=None, quiet=True):
    """Signed distance on the nodes of a grid around the loaded input ``geo`` (:func:`gsdf.signed_distance_grid`
    with a progress bar); returns a :class:`gsdf.GridField`."""
    from gsdf.grid import Grid
    from gsdf.ops._distance_grid import signed_distance_grid as grid_sdf

    if sign == "pseudonormal" and not geo.is_mesh:
        raise ValueError("--sign pseudonormal needs a mesh, not a point cloud")
    kw = dict(V=geo.X, F=geo.F) if geo.is_mesh else dict(V=None, points=(geo.X, geo.N))
    grid = Grid.around(geo.X, resolution, pad)
    bar, update = progress_bar(grid.size, "winding numbers", not quiet and sign == "winding")

    def progress(stage, fraction):
        update(round(fraction * grid.size), grid.size)

    with bar:
        return grid_sdf(resolution=grid, sign=sign, beta=beta, progress=progress, **kw)


@click.command("sdf", help="""Signed distance grid of INPUT (mesh, soup or oriented cloud); negative inside.

|d| is the exact distance to the triangles (or nearest point); the sign comes from the fast winding number
at 1/2 (robust to holes and soups), or from angle-weighted pseudonormals (closed manifold meshes only).
Writes the grid as .npz (values, bbox_min, bbox_max); optionally a PNG slice and the zero level set.

\b
Example:
  gsdf sdf bunny.off -o bunny_sdf.npz --resolution 128 --png slice.png --surface zero.ply
""")
@click.argument("input", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, help="Output grid: .npz (reload with gsdf.GridField.load), .npy, "
              ".vtk, .vti or .vtu.")
@click.option("--resolution", type=click.IntRange(2, 2048), default=64, show_default=True,
              help="Grid nodes along the longest side.")
@click.option("--pad", type=click.FloatRange(0), default=PAD, show_default=True,
              help="Box padding, fraction of the diagonal.")
@click.option("--sign", type=click.Choice(["winding", "pseudonormal"]), default="winding", show_default=True)
@click.option("--png", default=None, help="Also write a PNG of the middle slice (z) with isolines.")
@click.option("--surface", "surface_out", default=None, help="Also write the zero level set as a mesh.")
@beta_option
@normals_option
@quiet_option
@no_clobber_option
@report_errors
def sdf(input, output, resolution, pad, sign, png, surface_out, beta, estimate_normals, quiet):
    from gsdf.field import GridField
    from gsdf.io import MESH_WRITE_FORMATS

    check_output(output, GridField.SAVE_EXTENSIONS)
    check_output(png, (".png",), "--png")
    check_output(surface_out, MESH_WRITE_FORMATS, "--surface")
    geo = load_geometry(input, estimate_normals)
    from gsdf.cli._background import BackgroundWarmup

    # cold cache, >= 2 threads, winding sign of a mesh: the distance kernels compile in a second process while
    # this one compiles the fast winding numbers (computed first for this reason)
    with BackgroundWarmup(["distance"] if geo.is_mesh and sign == "winding" else []):
        field = signed_distance_grid(geo, resolution, pad, sign, beta, quiet)
    with output_file(output) as tmp:
        field.save(tmp)
    click.echo(f"{geo.describe()}\nsigned distance grid {field.shape} -> {os.path.abspath(output)}")
    if png:
        from gsdf.view._png import write_field_slice_png

        with output_file(png, what="--png") as tmp:
            write_field_slice_png(tmp, field)
        click.echo(f"slice image -> {os.path.abspath(png)}")
    if surface_out:
        from gsdf.io import write_mesh

        Vs, Fs = field.isosurface(0.0)
        with output_file(surface_out, what="--surface") as tmp:
            write_mesh(tmp, Vs, Fs)
        click.echo(f"zero level set ({len(Fs)} triangles) -> {os.path.abspath(surface_out)}")
