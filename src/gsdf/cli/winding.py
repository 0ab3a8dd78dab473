"""``gsdf winding``: generalized winding numbers of a mesh/soup or oriented cloud at query points."""

from __future__ import annotations

import os

import click
import numpy as np

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
    exact_option,
    no_clobber_option,
    normals_option,
    output_option,
)

VALUE_EXTENSIONS = (".npy", ".txt", ".csv")


def read_queries(path: str) -> np.ndarray:
    """Query points (q, 3), q > 0, finite: an .npy array or any point file :func:`gsdf.read_points` reads."""
    from gsdf._checks import as_points, numpy_file
    from gsdf.io import read_points

    if path.lower().endswith(".npy"):
        numpy_file(path, "QUERIES")
        try:
            Q = np.load(path, allow_pickle=False)
        except Exception as exc:  # numpy raises ValueError, EOFError, TokenError ... for a broken .npy
            raise ValueError(f"{path}: cannot read queries ({exc})") from exc
        if Q.dtype == bool or not np.issubdtype(Q.dtype, np.number):
            raise ValueError(f"{path}: expected a numeric (q, 3) array of query points, got dtype {Q.dtype}")
        if Q.size == 0:
            raise ValueError(f"{path}: contains no query points")
        return as_points(Q, f"{path}: queries")
    return read_points(path)[0]


def write_values(path: str, values: np.ndarray) -> None:
    """One value per query: ``.npy``, or text (``.txt``/``.csv``, one value per line), written safely."""
    with output_file(path, VALUE_EXTENSIONS) as tmp:
        if path.lower().endswith(".npy"):
            np.save(tmp, values)
        else:
            np.savetxt(tmp, values, fmt="%.10g")


@click.command("winding", short_help="Winding numbers at query points.",
               help="""Winding numbers of INPUT (mesh, soup or oriented cloud) at the points of QUERIES.

QUERIES is any point file (XYZ, PLY, OBJ, NPY (q,3)). Writes one value per query (.npy or text).

\b
Example:
  gsdf winding bunny.off queries.xyz -o w.npy
  gsdf winding scan.ply queries.npy -o w.txt --exact
""")
@click.argument("input", type=click.Path(dir_okay=False))
@click.argument("queries", type=click.Path(dir_okay=False))
@output_option("Output file: .npy, or text (.txt/.csv, one value per line).")
@exact_option
@click.option("--order", type=click.IntRange(0, 2), default=2, show_default=True,
              help="Taylor order of the fast winding number.")
@beta_option
@normals_option
@common_options
@no_clobber_option
@report_errors
def winding(input, queries, output, exact, order, beta, estimate_normals, quiet):
    from gsdf.winding import FastWindingNumber, FastWindingNumberPoints, winding_number, winding_number_points

    check_output(output, VALUE_EXTENSIONS)
    geo = load_geometry(input, estimate_normals)
    Q = read_queries(queries)
    if exact:
        w = winding_number(geo.X, geo.F, Q) if geo.is_mesh else winding_number_points(geo.X, geo.N, Q)
    else:
        if geo.is_mesh:
            fwn = FastWindingNumber(geo.X, geo.F, beta=2.0 if beta is None else beta, order=order)
        else:
            fwn = FastWindingNumberPoints(geo.X, geo.N, beta=2.3 if beta is None else beta, order=order)
        bar, update = progress_bar(len(Q), "winding numbers", not quiet)
        with bar:
            w = fwn(Q, progress=update)
    write_values(output, w)
    announce(f"{geo.describe()}\n{len(Q)} winding numbers (min {w.min():.4g}, max {w.max():.4g}) -> "
               f"{os.path.abspath(output)}")
