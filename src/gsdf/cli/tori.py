"""``gsdf tori``: Points as Tori signed distance of an oriented point cloud (thesis ch. 5)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import announce, check_output, check_slice, output_file, report_errors, write_picture
from gsdf.cli._options import (
    common_options,
    no_clobber_option,
    normals_option,
    offsets_option,
    output_option,
    pad_option,
    png_option,
    resolution_option,
    slice_options,
    view_option,
)

GRID_EXTENSIONS = (".npz", ".npy", ".vtk", ".vti", ".vtu")


def _load_cloud(path, estimate_normals):
    from gsdf.io import read_points

    P, N = read_points(path)
    if N is None:
        if not estimate_normals:
            raise ValueError(f"{path}: the point cloud has no normals; Points as Tori needs oriented normals "
                             "(pass --estimate-normals for PCA normals oriented away from the centroid)")
        from gsdf.winding._point_areas import estimate_normals as pca

        N = pca(P, orient_towards=P.mean(axis=0))
    return P, N


@click.command("tori", short_help="Points as Tori signed distance of an oriented cloud.",
               help="""Points as Tori: generalized signed distance of an oriented cloud; negative inside.

Fits one torus per point (k = 64 neighbours, §5.1.1) and blends their distances (Eqs. 5.6–5.7). OUTPUT by
extension: .npz with --resolution: a signed distance grid (values, bbox_min, bbox_max); .npz without
--resolution: the fitted tori (reload with gsdf.tori.PointsAsTori.load); .npy/.vtk/.vti/.vtu: the grid (as
gsdf.GridField.save); a mesh extension (.ply/.obj/.off/.stl): the zero level set, or one file per offset with
--offsets (name_<offset>.ext). --png draws the result: a slice of the grid (--axis, --at), the level sets with
the cloud, or the oriented cloud.

\b
Examples:
  gsdf tori kitten.xyz -o kitten.ply --resolution 96
  gsdf tori kitten.xyz -o shells.ply --offsets -0.01,0,0.02
  gsdf tori kitten.xyz -o sdf.npz --resolution 64 --png sdf.png --axis z
""")
@click.argument("points", type=click.Path(dir_okay=False))
@output_option("Output: mesh (.ply/.obj/.off/.stl), grid (.npz/.npy/.vtk/.vti/.vtu) or fitted tori (.npz).")
@click.option("--estimator", type=click.Choice(["jet", "learned"]), default="jet", show_default=True,
              help="Coefficient estimator (jet: weighted least squares; learned: the shipped network, §5.1.2).")
@resolution_option(None, help="Grid nodes along the longest side of the box (default 64 for meshes and grids "
                              "other than .npz; an .npz is a grid only with --resolution).")
@offsets_option("Comma-separated level values to contour (default 0).")
@pad_option(0.1)
@click.option("-k", "k", type=click.IntRange(6, 1024), default=64, show_default=True, help="Neighbours per torus fit.")
@png_option("Also write a PNG of the result.")
@slice_options
@view_option()
@normals_option
@common_options
@no_clobber_option
@report_errors
def tori(points, output, estimator, resolution, offsets, pad, k, png, axis, at, view, estimate_normals, quiet):
    from gsdf.io import MESH_WRITE_FORMATS
    from gsdf.tori import PointsAsTori

    check_output(output, GRID_EXTENSIONS + MESH_WRITE_FORMATS)
    ext = os.path.splitext(output)[1].lower()
    levels = offsets or [0.0]
    base, e = os.path.splitext(output)
    mesh_paths = [output if len(levels) == 1 else f"{base}_{v:g}{e}" for v in levels]
    if ext in MESH_WRITE_FORMATS:
        for path in mesh_paths:
            check_output(path, MESH_WRITE_FORMATS)
    check_output(png, (".png",), "--png")
    check_slice(png, axis, at)
    P, N = _load_cloud(points, estimate_normals)
    pat = PointsAsTori(P, N, estimator=estimator, k=k)
    click.echo(f"{points}: {len(pat.P)} oriented points, {len(pat.tori)} tori fitted (estimator={estimator})")
    if ext == ".npz" and resolution is None:
        with output_file(output) as tmp:
            pat.save(tmp)
        announce(f"fitted tori -> {os.path.abspath(output)}")
        if png:
            write_picture(png, ("oriented points", pat), view=view)
        return
    from gsdf.tori._pat import level_grid

    g = level_grid(pat.P, resolution or 64, max(abs(v) for v in levels), pad)
    if ext in GRID_EXTENSIONS:
        from gsdf.field import GridField

        field = GridField(pat.signed_distance(g.points()).reshape(g.shape), *g.box)
        with output_file(output) as tmp:
            field.save(tmp)
        announce(f"signed distance grid {field.shape} -> {os.path.abspath(output)}")
        if png:
            write_picture(png, ("signed distance [model units]", field), view=view, axis=axis, at=at)
        return
    from gsdf.contour import extract_isosurface
    from gsdf.io import write_mesh

    shown = []
    for v, path in zip(levels, mesh_paths):
        V, F = extract_isosurface(pat.signed_distance, resolution=g, level=v, inside="below")
        with output_file(path) as tmp:
            write_mesh(tmp, V, F)
        announce(f"level {v:g}: {len(F)} triangles -> {os.path.abspath(path)}")
        shown.append((f"level {v:g}", (V, F)))
    if png:
        write_picture(png, *shown, ("input points", pat.P), view=view)
