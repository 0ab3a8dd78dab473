"""``gsdf swn``: surface winding numbers of (broken, nonbounding) curves on a surface mesh (thesis ch. 6)."""

from __future__ import annotations

import os

import click
import numpy as np

from gsdf.cli._common import announce, check_output, output_file, progress_bar, report_errors, write_picture
from gsdf.cli._options import (
    POSITIVE,
    common_options,
    no_clobber_option,
    output_option,
    png_option,
    view_option,
)


def write_swn_obj(path, V, F, corner_values, face_labels) -> None:
    """OBJ with the winding number as per-corner texture coordinate ``vt w 0`` (one per corner, like the
    demo's ``*_w.obj``: faces ``f v/vt``), and the face labels as a ``# label`` comment block."""
    m = len(F)
    vt = np.asarray(corner_values, np.float64).reshape(-1)
    idx = np.arange(1, 3 * m + 1).reshape(m, 3)
    with open(path, "w") as fh:
        fh.write(f"# surface winding numbers (gsdf swn)\n#  vertices: {len(V)}\n#     faces: {m}\n")
        np.savetxt(fh, V, fmt="v %.17g %.17g %.17g")
        np.savetxt(fh, np.column_stack([vt, np.zeros_like(vt)]), fmt="vt %.17g %.17g")
        cols = np.column_stack([F[:, 0] + 1, idx[:, 0], F[:, 1] + 1, idx[:, 1], F[:, 2] + 1, idx[:, 2]])
        np.savetxt(fh, cols, fmt="f %d/%d %d/%d %d/%d")
        fh.write("# face labels, in face order\n")
        lab = np.asarray(face_labels, dtype=np.int64).reshape(-1)
        for k in range(0, len(lab), 32):                     # comment lines: other OBJ readers skip them
            fh.write("#label " + " ".join(str(int(x)) for x in lab[k:k + 32]) + "\n")


def write_swn_ply(path, V, F, corner_values, face_labels) -> None:
    """Binary PLY: vertices; faces with ``vertex_indices``, int ``label`` and float ``w0 w1 w2`` (corner values)."""
    from plyfile import PlyData, PlyElement

    v = np.empty(len(V), dtype=[("x", "f8"), ("y", "f8"), ("z", "f8")])
    v["x"], v["y"], v["z"] = V.T
    f = np.empty(len(F), dtype=[("vertex_indices", "i4", (3,)), ("label", "i4"), ("w0", "f8"), ("w1", "f8"),
                                ("w2", "f8")])
    f["vertex_indices"] = F
    f["label"] = face_labels
    f["w0"], f["w1"], f["w2"] = np.asarray(corner_values).T
    PlyData([PlyElement.describe(v, "vertex"), PlyElement.describe(f, "face")]).write(path)


@click.command("swn", short_help="Surface winding numbers of broken curves.",
               help="""Surface winding numbers of the curves in CURVES on the surface MESH.

CURVES: the SWN demo's curve files ('#offset', 'v i', 'e i t' nodes and 'l j k' segments between nodes;
edge points are inserted into the mesh by cutting, geometry unchanged) or an OBJ with 'l' lines (1-based
vertex polylines along mesh edges). The mesh must be manifold and consistently oriented.

Writes OUTPUT (.ply: faces with an int 'label' and float corner values 'w0 w1 w2'; .obj: the winding number as
per-corner texture coordinates 'vt w 0', like the demo's output), for the cut mesh.

\b
Example:
  gsdf swn torus.obj torus-phi.txt -o torus_w.obj --png torus_w.png
""")
@click.argument("mesh", type=click.Path(dir_okay=False))
@click.argument("curves", type=click.Path(dir_okay=False))
@output_option("Output mesh: .ply or .obj.")
@click.option("--method", type=click.Choice(["lp", "reduced", "none"]), default="lp", show_default=True,
              help="Residual: full LP (HiGHS), reduced LP (one unknown per curve piece), or none (naive rounding).")
@click.option("--epsilon", type=click.FloatRange(min=0, min_open=True, max=1), default=1e-2, show_default=True,
              help="LP weight of jumps along the input curves (gap-closing jumps weigh 1).")
@click.option("--time-limit", type=POSITIVE, default=300.0, show_default=True,
              help="Seconds HiGHS may take.")
@png_option("Also write a PNG of the face labels (with their share of the area) and the curves.")
@view_option()
@common_options
@no_clobber_option
@report_errors
def swn(mesh, curves, output, method, epsilon, time_limit, png, view, quiet):
    from gsdf.io import read_mesh
    from gsdf.io._swn_curves import read_swn_curves
    from gsdf.swn._solver import SurfaceWindingNumbers, SWNOptions
    from gsdf.swn._insert import insert_curves

    check_output(output, (".ply", ".obj"))
    check_output(png, (".png",), "--png")
    ext = os.path.splitext(output)[1].lower()
    say = (lambda s: None) if quiet else (lambda s: click.echo(f"  {s} ...", err=True))
    say("reading")
    V, F = read_mesh(mesh)
    c = read_swn_curves(curves, F)
    say(f"inserting {len(c.segments)} curve segments")
    V2, F2, segs, _ = insert_curves(V, F, c)
    say("building operators")
    solver = SurfaceWindingNumbers(V2, F2)
    bar, update = progress_bar(5, "swn steps", enabled=not quiet)
    try:
        res = solver.solve(list(segs), method=method, options=SWNOptions(epsilon=epsilon, time_limit=time_limit),
                           progress=update)
    finally:
        bar.close()
    with output_file(output, (".ply", ".obj")) as tmp:
        (write_swn_ply if ext == ".ply" else write_swn_obj)(tmp, V2, F2, res.corner_values, res.face_labels)
    A = solver.dec.areas
    labs = np.unique(res.face_labels)
    share = ", ".join(f"{int(k)}: {100 * A[res.face_labels == k].sum() / A.sum():.1f}%" for k in labs)
    nb = float(np.abs(res.residual[res.chain != 0]).sum() / max(np.abs(res.chain).sum(), 1))
    announce(f"{mesh}: {len(V2)} vertices, {len(F2)} triangles after inserting the curves (+{len(V2) - len(V)}); "
               f"b1 = {solver.betti_1}, {int(res.endpoints.sum())} endpoints\n"
               f"method {method}: labels (area) {share}; nonbounding share of the input {nb:.2f}; "
               f"{res.timings['total']:.2f} s -> {os.path.abspath(output)}")
    if png:
        curves = [V2[np.asarray(s)] for s in segs]
        write_picture(png, ("surface winding number", (V2, F2, res)), ("curves", curves), view=view)
