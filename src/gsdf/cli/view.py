"""``gsdf view``: meshes, clouds, curves and the files gsdf writes, in polyscope or as a headless screenshot."""

from __future__ import annotations

import os

import click
import numpy as np

from gsdf.cli._common import announce, check_output, output_file, report_errors
from gsdf.cli._options import NUMBER, SIZE, UP, common_options, no_clobber_option, slice_options

_CLOUD_EXTENSIONS = (".xyz", ".pwn", ".pc", ".npy")
_CURVE_EXTENSIONS = (".txt",)


@click.command("view", short_help="Show meshes, clouds, curves and results (polyscope); --screenshot PNG.",
               help="""Show FILES in polyscope, or with --screenshot render them to a PNG without a display.

FILES: meshes and point clouds (every format gsdf reads), curve files (.txt of the signed heat method's and
the surface winding numbers' demos, OBJ with only 'l' lines: drawn on the mesh given before them), and what
gsdf writes: fields (.npz, .vti, .vtk, .vtu of `gsdf sdf`, `gsdf heat`, `gsdf tori`: a slice with isolines
and the isosurface), `gsdf heat-surface` meshes (the distance with isolines), `gsdf swn` meshes (the winding
number labels, with their share of the area), `gsdf voxelize` voxels, `gsdf reconstruct` meshes.

The screenshot is a 3/4 view framing everything, with a colour bar titled with the field's name and units.
Needs polyscope (the view extra: pip install -e '.[view]' in a checkout); without a display, EGL (Debian/Ubuntu: libegl1 libegl-mesa0
libgl1-mesa-dri).

\b
Examples:
  gsdf view bunny.off
  gsdf sdf bunny.off -o bunny_sdf.npz && gsdf view bunny_sdf.npz --screenshot bunny_sdf.png
  gsdf view fish.ply fish-unsigned.txt --screenshot fish.png --azimuth 60
""")
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False, exists=True))
@click.option("-o", "--output", "--screenshot", "output", default=None, metavar="FILE",
              help="Render to this PNG instead of opening a window (no display needed).")
@click.option("--size", type=SIZE, default="1200x900", show_default=True, help="Screenshot size in pixels: N or WxH.")
@click.option("--up", type=UP, default="auto", show_default=True,
              help="The model's up direction: auto (y, or the normal of a flat scene), an axis (x, -y, ...) or x,y,z.")
@click.option("--azimuth", type=click.FloatRange(-360, 360), default=35.0, show_default=True,
              help="Camera turn about the up axis, degrees.")
@click.option("--elevation", type=click.FloatRange(-89, 89), default=25.0, show_default=True,
              help="Camera height above the horizon, degrees.")
@click.option("--level", type=NUMBER, default=None,
              help="Isosurface / bold isoline level (default: 0 for signed fields, 1/2 for winding numbers).")
@slice_options
@click.option("--field", "field_name", default=None, metavar="NAME",
              help="Vertex property of a PLY/VTK mesh to colour by (default: the first one).")
@click.option("--title", default=None, help="Colour-bar title of the (first) field, units included.")
@common_options
@no_clobber_option
@report_errors
def view(files, output, size, up, azimuth, elevation, level, axis, at, field_name, title, quiet):
    import time

    from gsdf.render._view import ViewOptions
    from gsdf.render._view import view as show

    check_output(output, (".png",), "-o")
    t = time.perf_counter()
    items = items_from_files(files, field_name, title)
    opts = ViewOptions(level=level, slice_axis=axis, slice_at=at)
    try:
        if output is None:
            show(*items, up=up, azimuth=azimuth, elevation=elevation, options=opts)
            return
        with output_file(output, (".png",), what="--screenshot") as tmp:
            img = show(*items, screenshot=tmp, size=size, up=up, azimuth=azimuth, elevation=elevation,
                       options=opts)
    except (RuntimeError, ImportError) as exc:          # no display, no polyscope, no EGL: say what to do
        raise click.ClickException(str(exc)) from exc
    if not quiet:
        announce(f"{len(files)} file(s), {img.shape[1]}x{img.shape[0]} in {time.perf_counter() - t:.1f} s -> "
                   f"{os.path.abspath(output)}")


def items_from_files(paths, field_name=None, title=None) -> list:
    """What :func:`gsdf.view` shows of each file (see the command's help); curve files go on the mesh before them.
    ``title`` names the first field."""
    if field_name is not None and not field_name.strip():
        raise ValueError("--field: expected the name of a vertex property, got an empty string")
    items, mesh, used = [], None, []
    for p in paths:
        (name, item), mesh = _item(p, mesh, field_name, used)
        items.append([name, item, os.path.basename(p)])
    if field_name is not None and not used:
        raise ValueError(f"--field {field_name}: none of the files is a PLY/VTK/VTU mesh with vertex properties")
    fields = [it for it in items if _has_field(it[1])]
    for it in fields:
        if title is not None:
            it[0], title = title, None
        elif len(fields) > 1:                 # which file each colour bar belongs to
            unit = it[0].rfind(" [")
            it[0] = f"{it[0][:unit]} ({it[2]}){it[0][unit:]}" if unit > 0 else f"{it[0]} ({it[2]})"
    return [(name, item) for name, item, _ in items]


def _has_field(item) -> bool:
    from gsdf.field import Field

    return isinstance(item, Field) or (isinstance(item, tuple) and len(item) == 3)


def _item(p, mesh, field_name, used=None):
    """(item for gsdf.view, the mesh (V, F) that later curve files refer to); appends ``p`` to ``used`` when
    ``field_name`` picked one of its vertex properties."""
    from gsdf.io import read_mesh, read_points

    name = os.path.basename(p)
    ext = os.path.splitext(p)[1].lower()
    if ext in _CURVE_EXTENSIONS or (ext == ".obj" and _only_lines(p)):
        if mesh is None:
            raise ValueError(f"{p}: a curve file needs the mesh it lies on before it (gsdf view MESH CURVES)")
        return (f"curves {name}", _curves(p, *mesh)), mesh
    if ext in (".npz", ".vti") or (ext in (".vtk", ".vtu") and _has_cells_with_data(p)):
        return _field_file(p, name, ext)
    if ext in _CLOUD_EXTENSIONS:
        P, N = read_points(p)
        return (name, (P, N) if N is not None else P), mesh
    V, F = read_mesh(p)
    if len(F) == 0:
        P, N = read_points(p)
        return (name, (P, N) if N is not None else P), mesh
    if ext == ".ply":
        labels = _ply_face_labels(p)
        if labels is not None:        # gsdf swn output
            return ("surface winding number", (V, F, labels)), (V, F)
    if ext == ".obj":
        labels = _obj_face_labels(p, len(F))
        if labels is not None:        # gsdf swn output: vertices per corner, labels in a comment block
            return ("surface winding number", (V, F, labels)), (V, F)
    if ext in (".ply", ".vtk", ".vtu"):
        from gsdf.io import read_vertex_data

        data = read_vertex_data(p)
        if data:
            key = field_name if field_name is not None else next(iter(data))
            if key not in data:
                raise ValueError(f"{p}: no vertex property {key!r} (it has {', '.join(data)})")
            if field_name is not None and used is not None:
                used.append(p)
            unit = " [model units]" if key in ("distance", "values", "sdf") else ""
            return (f"{key}{unit}", (V, F, data[key])), (V, F)
    return (name, (V, F)), (V, F)


def _field_file(p, name, ext):
    """A field (.npz, .vti, .vtk, .vtu), gsdf voxels, or saved Points as Tori (.npz)."""
    from gsdf.field import SurfaceField, load_field

    try:
        f = load_field(p)
    except ValueError as exc:
        if ext != ".npz":
            raise
        with np.load(p, allow_pickle=False) as z:
            keys = set(z.files)
        if "occupancy" in keys:
            from gsdf.ops import voxels_to_mesh
            from gsdf.ops._voxelize import load_voxels

            occ, lo, hi = load_voxels(p)
            V, F = voxels_to_mesh(occ, lo, hi)
            return (f"voxels {name}", (V, F)), (V, F)
        if {"P", "N", "tori"} <= keys:
            from gsdf.tori import PointsAsTori

            pat = PointsAsTori.load(p)
            return (f"Points as Tori {name}", pat), None
        raise exc
    from gsdf.render._scene import field_kind

    kind = field_kind(f.values)
    what = {"signed": "signed distance", "winding": "winding number"}.get(kind, "value")
    unit = " [model units]" if kind == "signed" else ""
    if isinstance(f, SurfaceField):
        return (f"{what}{unit}", f), (f.vertices, f.faces)
    return (f"{what}{unit}", f), None


def _has_cells_with_data(p) -> bool:
    """A .vtk/.vtu with point data on tetra or hexahedra (a saved field), not a plain surface mesh."""
    from gsdf.io._external import _read_meshio_raw

    m = _read_meshio_raw(p, os.path.splitext(p)[1].lower())
    types = {c.type for c in m.cells}
    return bool(m.point_data) and bool(types & {"tetra", "hexahedron", "voxel"})


def _only_lines(p) -> bool:
    """An OBJ with polylines (``l``) and no faces: a curve file."""
    heads = set()
    with open(p, "rb") as fh:
        for line in fh:
            tok = line.split(None, 1)
            if tok and tok[0] in (b"l", b"f"):
                heads.add(tok[0])
    return heads == {b"l"}


def _curves(p, V, F):
    """Polylines (k, 3) of a curve file on the mesh (V, F): the signed heat method's format and OBJ lines
    (:func:`gsdf.read_curves`), else the surface winding numbers' demo format (nodes and segments)."""
    from gsdf.io import read_curves
    from gsdf.render._scene import MeshItem, _curves_on_mesh

    try:
        src = read_curves(p, F)
        return _curves_on_mesh(list(src.curves) + [[q] for q in src.points], MeshItem(V, F), p).polylines
    except ValueError as first:
        from gsdf.io._swn_curves import read_swn_curves

        try:
            c = read_swn_curves(p, F)
        except ValueError:
            raise first from None
    X = np.empty((len(c.kinds), 3))
    for k, (kind, i, prm, ev) in enumerate(zip(c.kinds, c.index, c.params, c.edge_vertices)):
        if kind == "v":
            X[k] = V[i]
        elif kind == "e":
            X[k] = (1 - prm[0]) * V[ev[0]] + prm[0] * V[ev[1]]
        else:
            X[k] = prm @ V[F[i]]
    return [X[s] for s in np.asarray(c.segments)]


def _ply_face_labels(p):
    """The integer face property ``label`` of a PLY (``gsdf swn`` writes it), or None."""
    import plyfile

    try:
        ply = plyfile.PlyData.read(p)
    except Exception:
        return None
    if "face" not in ply or "label" not in ply["face"].data.dtype.names:
        return None
    return np.asarray(ply["face"].data["label"], dtype=np.int64)


def _obj_face_labels(p, m):
    """The ``#label`` comment block of an OBJ that ``gsdf swn`` wrote, when it has one label per face."""
    out = []
    with open(p, "rb") as fh:
        for line in fh:
            if line.startswith(b"#label"):
                out.extend(int(t) for t in line[6:].split())
    return np.asarray(out, dtype=np.int64) if out and len(out) == m else None
