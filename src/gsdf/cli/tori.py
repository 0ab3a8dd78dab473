"""``gsdf tori``: Points as Tori signed distance of an oriented point cloud (thesis ch. 5)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import (
    check_output,
    no_clobber_option,
    normals_option,
    output_file,
    parse_floats,
    quiet_option,
    report_errors,
)
from gsdf.grid import PAD

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


@click.command("tori", help="""Points as Tori: generalized signed distance of an oriented cloud; negative inside.

Fits one torus per point (k = 64 neighbours, §5.1.1) and blends their distances (Eqs. 5.6–5.7). OUT by
extension: .npz with --grid: a signed distance grid (values, bbox_min, bbox_max); .npz without --grid: the fitted
tori (reload with gsdf.tori.PointsAsTori.load); .npy/.vtk/.vti/.vtu: the grid (as gsdf.GridField.save); a mesh extension (.ply/.obj/.off/.stl): the zero level set, or one
file per offset with --offsets (name_<offset>.ext).

\b
Examples:
  gsdf tori kitten.xyz -o kitten.ply --grid 96
  gsdf tori kitten.xyz -o shells.ply --offsets -0.01,0,0.02
  gsdf tori kitten.xyz -o sdf.npz --grid 64
""")
@click.argument("points", type=click.Path(dir_okay=False))
@click.option("-o", "--output", "out", required=True, help="Output: mesh (.ply/.obj/.off/.stl) or .npz.")
@click.option("--estimator", type=click.Choice(["jet", "learned"]), default="jet", show_default=True,
              help="Coefficient estimator (jet: weighted least squares; learned: the shipped network, §5.1.2).")
@click.option("--grid", type=click.IntRange(4, 1024), default=None,
              help="Grid nodes along the longest side (default 64 for meshes; required for an .npz grid).")
@click.option("--offsets", default=None, help="Comma-separated level values to contour (default 0).")
@click.option("--pad", type=click.FloatRange(0), default=PAD, show_default=True, help="Box padding, fraction of the diagonal.")
@click.option("-k", "k", type=click.IntRange(6, 1024), default=64, show_default=True, help="Neighbours per torus fit.")
@normals_option
@quiet_option
@no_clobber_option
@report_errors
def tori(points, out, estimator, grid, offsets, pad, k, estimate_normals, quiet):
    from gsdf.io import MESH_WRITE_FORMATS
    from gsdf.tori import PointsAsTori

    check_output(out, GRID_EXTENSIONS + MESH_WRITE_FORMATS)
    ext = os.path.splitext(out)[1].lower()
    levels = parse_floats(offsets, "--offsets") or [0.0]
    base, e = os.path.splitext(out)
    mesh_paths = [out if len(levels) == 1 else f"{base}_{v:g}{e}" for v in levels]
    if ext in MESH_WRITE_FORMATS:
        for path in mesh_paths:
            check_output(path, MESH_WRITE_FORMATS)
    P, N = _load_cloud(points, estimate_normals)
    pat = PointsAsTori(P, N, estimator=estimator, k=k)
    click.echo(f"{points}: {len(pat.P)} oriented points, {len(pat.tori)} tori fitted (estimator={estimator})")
    if ext == ".npz" and grid is None:
        with output_file(out) as tmp:
            pat.save(tmp)
        click.echo(f"fitted tori -> {os.path.abspath(out)}")
        return
    from gsdf.tori._pat import level_grid

    g = level_grid(pat.P, grid or 64, max(abs(v) for v in levels), pad)
    if ext in GRID_EXTENSIONS:
        from gsdf.field import GridField

        field = GridField(pat.signed_distance(g.points()).reshape(g.shape), *g.box)
        with output_file(out) as tmp:
            field.save(tmp)
        click.echo(f"signed distance grid {field.shape} -> {os.path.abspath(out)}")
        return
    from gsdf.contour import extract_isosurface
    from gsdf.io import write_mesh

    for v, path in zip(levels, mesh_paths):
        V, F = extract_isosurface(pat.signed_distance, resolution=g, level=v, inside="below")
        with output_file(path) as tmp:
            write_mesh(tmp, V, F)
        click.echo(f"level {v:g}: {len(F)} triangles -> {os.path.abspath(path)}")
