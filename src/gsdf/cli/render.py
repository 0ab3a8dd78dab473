"""``gsdf render``: sphere-traced PNG of a level set of a point cloud's Points-as-Tori SDF (pointwise queries only)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import announce, check_output, output_file, report_errors
from gsdf.cli._options import (
    NUMBER,
    SIZE,
    UP,
    common_options,
    no_clobber_option,
    normals_option,
    output_option,
    view_option,
)


def _up_vector(up):
    """``--up``: an axis name or x,y,z as a vector (``auto``: y)."""
    if isinstance(up, str):
        from gsdf.render._scene import axis_vector

        return axis_vector("y" if up == "auto" else up)
    return up


@click.command("render", short_help="Sphere-traced PNG of a Points as Tori level set.",
               help="""Sphere-trace a level set of the Points as Tori SDF of POINTS into a PNG.

Only pointwise signed distance queries are used (Hart 1996; thesis §5.2, Fig. 5.3): no grid, no mesh.
POINTS is an oriented cloud, or a .npz of tori saved by `gsdf tori ... -o tori.npz`.

\b
Example:
  gsdf render kitten.xyz -o kitten.png --level 0.01 --size 512
""")
@click.argument("points", type=click.Path(dir_okay=False))
@output_option("Output PNG.")
@click.option("--level", type=NUMBER, default=0.0, show_default=True, help="Level set (offset) to render.")
@click.option("--size", type=SIZE, default="384", show_default=True, help="Picture size in pixels: N or WxH.")
@view_option("1,0.6,1.4")
@click.option("--up", type=UP, default="y", show_default=True, help="Up direction of the picture: an axis (x, -y, ...) or x,y,z.")
@normals_option
@common_options
@no_clobber_option
@report_errors
def render(points, output, level, size, view, up, estimate_normals, quiet):
    import numpy as np

    from gsdf.render._png import write_png
    from gsdf.tori import PointsAsTori
    from gsdf.render._trace import sphere_trace
    from gsdf.cli.tori import _load_cloud

    check_output(output, (".png",))
    if points.lower().endswith(".npz"):
        pat = PointsAsTori.load(points)
    else:
        P, N = _load_cloud(points, estimate_normals)
        pat = PointsAsTori(P, N)
    lo, hi = pat.P.min(0), pat.P.max(0)
    m = 0.1 * np.linalg.norm(hi - lo) + abs(level)  # the box of tori.render_png: cloud + 10 % of its diagonal
    img = sphere_trace(pat, lo - m, hi + m, size[0], size[1], level, view=view, up=_up_vector(up))
    with output_file(output) as tmp:
        write_png(tmp, img, min_size=1)  # gsdf's one PNG writer
    announce(f"{len(pat.P)} tori, level {level:g} -> {os.path.abspath(output)}")
