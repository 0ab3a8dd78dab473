"""``gsdf sdf``: a signed distance grid of a mesh/soup or oriented cloud, signed by the winding number."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import (
    announce,
    check_output,
    check_slice,
    load_geometry,
    output_file,
    progress_bar,
    report_errors,
    write_picture,
)
from gsdf.cli._options import (
    beta_option,
    common_options,
    mesh_output_option,
    no_clobber_option,
    normals_option,
    output_option,
    pad_option,
    png_option,
    resolution_option,
    slice_options,
    view_option,
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
    with bar:
        return grid_sdf(resolution=grid, sign=sign, beta=beta, progress=update, **kw)


@click.command("sdf", short_help="Signed distance grid, sign from the winding number.",
               help="""Signed distance grid of INPUT (mesh, soup or oriented cloud); negative inside.

|d| is the exact distance to the triangles (or nearest point); the sign comes from the fast winding number
at 1/2 (robust to holes and soups), or from angle-weighted pseudonormals (closed manifold meshes only).
Writes the grid as .npz (values, bbox_min, bbox_max); optionally a picture (a slice with isolines and the zero
level set cut open, with a colour bar) and the zero level set as a mesh.

\b
Example:
  gsdf sdf bunny.off -o bunny_sdf.npz --resolution 128 --png slice.png --mesh-output zero.ply
  gsdf sdf bunny.off -o bunny_sdf.npz --png slice.png --axis x --at 0.02
""")
@click.argument("input", type=click.Path(dir_okay=False))
@output_option("Output grid: .npz (reload with gsdf.GridField.load), .npy, .vtk, .vti or .vtu.")
@resolution_option(64)
@pad_option(PAD)
@click.option("--sign", type=click.Choice(["winding", "pseudonormal"]), default="winding", show_default=True,
              help="Sign by the winding number at 1/2, or by angle-weighted pseudonormals (closed manifold "
                   "meshes only).")
@png_option("Also write a PNG: a slice of the field with isolines, and the zero level set.")
@slice_options
@view_option()
@mesh_output_option("Also write the zero level set as a mesh (.ply/.obj/.off/.stl).")
@beta_option
@normals_option
@common_options
@no_clobber_option
@report_errors
def sdf(input, output, resolution, pad, sign, png, axis, at, view, mesh_output, beta, estimate_normals, quiet):
    from gsdf.field import GridField
    from gsdf.io import MESH_WRITE_FORMATS

    check_output(output, GridField.SAVE_EXTENSIONS)
    check_output(png, (".png",), "--png")
    check_slice(png, axis, at)
    check_output(mesh_output, MESH_WRITE_FORMATS, "--mesh-output")
    geo = load_geometry(input, estimate_normals)
    from gsdf.cli._background import BackgroundWarmup

    # cold cache, >= 2 threads, winding sign of a mesh: the distance kernels compile in a second process while
    # this one compiles the fast winding numbers (computed first for this reason)
    with BackgroundWarmup(["distance"] if geo.is_mesh and sign == "winding" else []):
        field = signed_distance_grid(geo, resolution, pad, sign, beta, quiet)
    with output_file(output) as tmp:
        field.save(tmp)
    announce(f"{geo.describe()}\nsigned distance grid {field.shape} -> {os.path.abspath(output)}")
    if png:
        write_picture(png, ("signed distance [model units]", field), view=view, axis=axis, at=at)
    if mesh_output:
        from gsdf.io import write_mesh

        Vs, Fs = field.isosurface(0.0)
        with output_file(mesh_output, what="--mesh-output") as tmp:
            write_mesh(tmp, Vs, Fs)
        announce(f"zero level set ({len(Fs)} triangles) -> {os.path.abspath(mesh_output)}")
