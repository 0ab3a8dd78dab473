"""``gsdf heat-surface``: generalized signed distance to (broken) curves on a surface mesh (signed heat method)."""

from __future__ import annotations

import os

import click
import numpy as np

from gsdf.cli._common import announce, check_output, output_file, report_errors, write_picture
from gsdf.cli._options import (
    NONNEGATIVE,
    common_options,
    level_set_option,
    no_clobber_option,
    output_option,
    png_option,
    soft_weight_option,
    t_coef_option,
    view_option,
)


@click.command("heat-surface", short_help="Signed distance to curves on a surface mesh.",
               help="""Signed distance to curves on the surface MESH (signed heat method).

Curves come from --curves FILE: the text format of the signed heat method's demo (blocks signed_curve,
unsigned_curve, unsigned_point; nodes 'v i', 'e i t', 'f i a b c') or OBJ 'l' lines (1-based vertex
indices). The region to the left of an oriented curve (counter-clockwise seen from the face normals) is
negative. Writes the mesh with the distance as PLY vertex property 'distance', and optionally a PNG (the
distance with isolines and the curves, a 3/4 view framing the surface, a colour bar).

With --voxels, MESH is a binary volume (.npy bool array, or the .npz of 'gsdf voxelize') and the surface is its
digital surface (§8.5: boundary quads, corrected normals); the curve is then --curves (vertex indices of the
output surface) or --cut 'z<12.5', the boundary of the quads whose centres satisfy the inequality.

\b
Example:
  gsdf heat-surface bunny.off --curves loops.txt -o bunny_sdf.ply --png bunny_sdf.png
  gsdf heat-surface ball.npy --voxels --cut 'z<20' -o ball_sdf.ply
""")
@click.argument("mesh", type=click.Path(dir_okay=False))
@click.option("--curves", "curves_path", default=None, type=click.Path(dir_okay=False),
              help="Curve file (demo .txt format or OBJ with 'l' lines).  [required without --cut]")
@click.option("--voxels", is_flag=True, help="MESH is a binary volume (.npy / .npz); use its digital surface.")
@click.option("--spacing", default=None, help="--voxels: voxel size 's' or 'sx,sy,sz' (default 1, or the .npz's).")
@click.option("--normal-radius", type=NONNEGATIVE, default=3.0, show_default=True,
              help="--voxels: integral-invariant radius of the corrected normals, in voxels (0: trivial normals).")
@click.option("--cut", default=None, help="--voxels: curve = boundary of the quads with centre 'x|y|z < value' "
              "(or '>'), world coordinates.")
@output_option("Output mesh (.ply) with the 'distance' vertex property.")
@level_set_option
@t_coef_option
@soft_weight_option("Default: exact.")
@click.option("--swn", is_flag=True,
              help="First classify the curves with surface winding numbers and keep only their bounding part "
                   "(thesis §6.4.1); curves must run along mesh edges.")
@png_option("Also write a PNG of the distance with isolines and the curves.")
@view_option()
@common_options
@no_clobber_option
@report_errors
def heat_surface(mesh, curves_path, voxels, spacing, normal_radius, cut, output, level_set, t_coef, soft_weight,
                 png, view, quiet, swn=False):
    from gsdf.heat import SurfaceSignedHeatSolver
    from gsdf.io import read_mesh, write_mesh
    from gsdf.io._curves import read_curves

    check_output(output, (".ply",))  # only PLY stores the distance per vertex
    check_output(png, (".png",), "--png")
    if voxels:
        if swn:
            raise click.UsageError("--swn and --voxels cannot be combined")
        V, F, phi, what, shown = _heat_voxels(mesh, curves_path, spacing, normal_radius, cut, level_set, t_coef,
                                              soft_weight)
    else:
        if cut is not None or spacing is not None:
            raise click.UsageError("--cut and --spacing need --voxels")
        if curves_path is None:
            raise click.UsageError("Missing option '--curves'.")
        V, F = read_mesh(mesh)
        src = read_curves(curves_path, F)
        if swn:
            from gsdf.swn._solver import SurfaceWindingNumbers, bounding_segments

            if not all(isinstance(c, np.ndarray) and c.ndim == 1 for c in src.curves) or not src.curves:
                raise ValueError(f"{curves_path}: --swn needs curves along mesh vertices ('v' nodes or OBJ 'l' lines)")
            if src.curve_signs is not None and not all(src.curve_signs):
                raise ValueError(f"{curves_path}: --swn needs signed (oriented) curves")
            sw = SurfaceWindingNumbers(V, F)
            res = sw.solve(list(src.curves))
            segs = bounding_segments(sw, res)
            kept = len(segs) / max(int(np.abs(res.chain).sum()), 1)
            click.echo(f"surface winding numbers: {100 * kept:.0f}% of the curve edges bound a region, the rest is "
                       "dropped as nonbounding")
            if not segs:
                raise ValueError(f"{curves_path}: no part of the curves bounds a region (all nonbounding)")
            src.curves, src.curve_signs = segs, None
        solver = SurfaceSignedHeatSolver(V, F, t_coef=t_coef)
        phi = solver.compute_distance(src.curves, points=src.points, curve_signs=src.curve_signs,
                                      level_set_constraint=level_set, soft_weight=soft_weight)
        what = f"{len(V)} vertices, {len(F)} triangles; {len(src.curves)} curves, {len(src.points)} points"
        shown = list(src.curves) + [[p] for p in src.points]
    with output_file(output) as tmp:
        write_mesh(tmp, V, F, vertex_data={"distance": phi})
    announce(f"{mesh}: {what}\ndistance in [{phi.min():.6g}, {phi.max():.6g}] -> {os.path.abspath(output)}")
    if png:
        curves = [("curves", shown)] if shown else []       # drawn on the mesh before them
        write_picture(png, ("signed distance [model units]", (V, F, phi)), *curves, view=view)


def _heat_voxels(path, curves_path, spacing, normal_radius, cut, level_set, t_coef, soft_weight):
    """--voxels: the signed heat method on the digital surface of a binary volume (§8.5)."""
    import re

    from gsdf.heat.voxel._domain import VoxelSurfaceSignedHeatSolver
    from gsdf.contour._surface_curves import region_boundary_curves
    from gsdf.io._curves import read_curves

    origin = np.zeros(3)
    if path.lower().endswith(".npz"):
        from gsdf.ops._voxelize import load_voxels

        occ, lo, hi = load_voxels(path)
        origin, size = lo, (hi - lo) / np.array(occ.shape)
    else:
        from gsdf._checks import numpy_file

        numpy_file(path)
        try:
            occ = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as exc:
            raise ValueError(f"{path}: not a .npy binary volume ({exc})") from exc
        size = 1.0
    if spacing is not None:
        try:
            size = [float(v) for v in spacing.split(",")]
        except ValueError:
            raise click.BadParameter(f"expected 's' or 'sx,sy,sz', got {spacing!r}", param_hint="--spacing")
        size = size[0] if len(size) == 1 else size
    if (cut is None) == (curves_path is None):
        raise click.UsageError("--voxels needs exactly one of --curves and --cut")
    solver = VoxelSurfaceSignedHeatSolver(occ, spacing=size, normal_radius=normal_radius, t_coef=t_coef)
    V = solver.vertices + origin
    if cut is not None:
        m = re.fullmatch(r"\s*([xyz])\s*([<>])\s*([-+0-9.eE]+)\s*", cut)
        if m is None:
            raise click.BadParameter(f"expected e.g. 'z<12.5', got {cut!r}", param_hint="--cut")
        c = (solver.face_centres + origin)[:, "xyz".index(m.group(1))]
        region = c < float(m.group(3)) if m.group(2) == "<" else c > float(m.group(3))
        if region.all() or not region.any():
            raise ValueError(f"--cut {cut!r}: selects {'all' if region.any() else 'none'} of the surface (no curve)")
        curves, points, signs = region_boundary_curves(solver.faces, region), [], None
    else:
        src = read_curves(curves_path)
        curves, points, signs = src.curves, src.points, src.curve_signs
    phi = solver.compute_distance(curves, points=points, curve_signs=signs, level_set_constraint=level_set,
                                  soft_weight=soft_weight)
    what = (f"{int(occ.sum())} voxels -> {len(V)} vertices, {len(solver.faces)} quads; {len(curves)} curves, "
            f"{len(points)} points")
    return V, solver.faces, phi, what, list(curves) + [[p] for p in points]
