"""``gsdf winding``: generalized winding numbers of a mesh/soup or oriented cloud at query points."""

from __future__ import annotations

import os

import click
import numpy as np

from ._common import beta_option, ensure_parent, load_geometry, normals_option, progress_bar, quiet_option, \
    report_errors


def read_queries(path: str) -> np.ndarray:
    from ..io import read_points

    if path.lower().endswith(".npy"):
        try:
            return np.load(path)
        except (OSError, ValueError) as exc:
            raise ValueError(f"{path}: cannot read queries ({exc})") from exc
    return read_points(path)[0]


def write_values(path: str, values: np.ndarray) -> None:
    ensure_parent(path)
    if path.lower().endswith(".npy"):
        np.save(path, values)
    else:
        np.savetxt(path, values, fmt="%.10g")


@click.command("winding", help="""Winding numbers of INPUT (mesh, soup or oriented cloud) at the points of QUERIES.

QUERIES is any point file (XYZ, PLY, OBJ, NPY (q,3)). Writes one value per query (.npy or text).

\b
Example:
  gsdf winding bunny.off queries.xyz -o w.npy
  gsdf winding scan.ply queries.npy -o w.txt --exact
""")
@click.argument("input", type=click.Path(dir_okay=False))
@click.argument("queries", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, help="Output file: .npy or text (one value per line).")
@click.option("--exact", is_flag=True, help="Exact direct sum instead of the fast tree approximation.")
@click.option("--order", type=click.IntRange(0, 2), default=2, show_default=True, help="Taylor order.")
@beta_option
@normals_option
@quiet_option
@report_errors
def winding(input, queries, output, exact, order, beta, estimate_normals, quiet):
    from ..winding import FastWindingNumber, FastWindingNumberPoints, winding_number, winding_number_points

    geo = load_geometry(input, estimate_normals)
    Q = read_queries(queries)
    if exact:
        w = winding_number(geo.V, geo.F, Q) if geo.is_mesh else winding_number_points(geo.P, geo.N, Q)
    else:
        if geo.is_mesh:
            fwn = FastWindingNumber(geo.V, geo.F, beta=2.0 if beta is None else beta, order=order)
        else:
            fwn = FastWindingNumberPoints(geo.P, geo.N, beta=2.3 if beta is None else beta, order=order)
        bar, update = progress_bar(len(Q), "winding numbers", not quiet)
        with bar:
            w = fwn(Q, progress=update)
    write_values(output, w)
    click.echo(f"{geo.describe()}\n{len(Q)} winding numbers (min {w.min():.4g}, max {w.max():.4g}) -> "
               f"{os.path.abspath(output)}")
