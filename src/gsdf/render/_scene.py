"""The scene of :func:`gsdf.view`, without polyscope: what the items become (surfaces, clouds, curves, slices,
isosurfaces, isolines, colour ranges) and where the camera goes.

Everything here is numpy (plus gsdf's own contouring), so the scene can be built and checked where polyscope or
an OpenGL context is missing; :mod:`gsdf.render._polyscope` only registers the parts built here.

Items and what they become (:func:`coerce`):

==========================================================  ================================================
item                                                        shown as
==========================================================  ================================================
``(V, F)``, ``(V, F, report)`` (reconstruction output)      surface mesh (quads are split into triangles)
``(V, F, values)`` values (n,) / (m,) / (m, 3) float        mesh coloured per vertex / face / corner
``(V, F, labels)`` integer (n,) or (m,)                     mesh coloured by label, with a legend
``(V, F, result)`` of :func:`gsdf.surface_winding_number`   the face labels, with a legend
:class:`gsdf.SurfaceField`                                  mesh coloured per vertex, with isolines
:class:`gsdf.GridField`, :class:`gsdf.TetField`             a slice with isolines, and the isosurface
(n, 3) float array, ``(P, N)``, ``(P, values)``             point cloud (shaded by its normals)
:class:`gsdf.PointsAsTori`                                  its oriented cloud
list of (k, 3) float arrays                                 polylines in space
:class:`gsdf.Curve`, list of them, or what                  curves on the mesh given before them (vertex
:func:`gsdf.read_curves` returns                            polylines or surface points)
``(name, item)``                                            the item, its field titled ``name``
==========================================================  ================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: Colours of the categorical labels (label values in increasing order cycle through them).
PALETTE = ((0.80, 0.80, 0.82), (0.95, 0.55, 0.20), (0.25, 0.55, 0.85), (0.40, 0.75, 0.35),
           (0.85, 0.30, 0.45), (0.60, 0.45, 0.80), (0.55, 0.40, 0.30), (0.95, 0.85, 0.30))
#: Colours of curve items, in turn (the first, green, stands out on the coolwarm map and on the label colours).
CURVE_COLORS = ((0.10, 0.70, 0.30), (0.95, 0.35, 0.10), (0.75, 0.15, 0.60), (0.10, 0.45, 0.85))
MESH_COLOR = (0.75, 0.75, 0.78)
CLOUD_COLOR = (0.35, 0.55, 0.85)
_AXES = {"x": 0, "y": 1, "z": 2}


# ---------------------------------------------------------------------------------------------------------------
# items: what the user passed, normalised
# ---------------------------------------------------------------------------------------------------------------

@dataclass
class MeshItem:
    V: np.ndarray
    F: np.ndarray
    values: np.ndarray | None = None     # float (n,) / (m,) / (m, 3), or integer labels (n,) / (m,)
    name: str | None = None


@dataclass
class CloudItem:
    P: np.ndarray
    N: np.ndarray | None = None
    values: np.ndarray | None = None
    name: str | None = None


@dataclass
class CurvesItem:
    polylines: list
    name: str | None = None


@dataclass
class VolumeItem:
    field: object                        # gsdf.GridField or gsdf.TetField
    name: str | None = None


def _is_int(a) -> bool:
    return np.asarray(a).dtype.kind in "iub"


def _float_points(a) -> bool:
    a = np.asarray(a) if not isinstance(a, np.ndarray) else a
    return a.dtype.kind == "f" and a.ndim == 2 and a.shape[1] == 3


def _faces(F, nv: int, where: str) -> np.ndarray:
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] not in (3, 4) or not _is_int(F):
        raise ValueError(f"{where}: faces must be an (m, 3) or (m, 4) integer array, got {F.dtype} {F.shape}")
    F = F.astype(np.int64)
    if len(F) and (F.min() < 0 or F.max() >= nv):
        raise ValueError(f"{where}: face indices must lie in [0, {nv})")
    if F.shape[1] == 4:                   # quads (digital surfaces of voxels): two triangles each
        F = np.concatenate([F[:, [0, 1, 2]], F[:, [0, 2, 3]]])
    return F


def _points(X, where: str) -> np.ndarray:
    from gsdf._checks import as_points

    return as_points(X, where)


def coerce(items) -> list:
    """The items of :func:`gsdf.view` as MeshItem / CloudItem / CurvesItem / VolumeItem (see the module
    docstring); curves given by vertex indices or surface points are placed on the mesh given before them."""
    out, last_mesh = [], None
    for k, it in enumerate(items):
        name = None
        if isinstance(it, tuple) and len(it) == 2 and isinstance(it[0], str):
            name, it = it
        got = _coerce_one(it, last_mesh, f"item {k}")
        for g in got:
            if name is not None:
                g.name = name
            if isinstance(g, MeshItem):
                last_mesh = g
        out.extend(got)
    if not out:
        raise ValueError("view: nothing to show (no items)")
    return out


def _coerce_one(it, last_mesh, where):
    from gsdf.curves import Curve
    from gsdf.field import GridField, SurfaceField, TetField

    if isinstance(it, (GridField, TetField)):
        return [VolumeItem(it)]
    if isinstance(it, SurfaceField):
        return [MeshItem(it.vertices, it.faces, it.values)]
    if hasattr(it, "P") and hasattr(it, "N") and hasattr(it, "signed_distance"):       # gsdf.PointsAsTori
        return [CloudItem(np.asarray(it.P, float), np.asarray(it.N, float))]
    if hasattr(it, "curves") and hasattr(it, "points") and hasattr(it, "curve_signs"):  # gsdf.read_curves
        return [_curves_on_mesh(list(it.curves) + [[p] for p in it.points], last_mesh, where)]
    if isinstance(it, Curve):
        return [_curves_on_mesh([it], last_mesh, where)]
    if isinstance(it, np.ndarray):
        if _float_points(it):
            return [CloudItem(_points(it, where))]
        raise ValueError(f"{where}: an array item must be an (n, 3) float point cloud, got {it.dtype} {it.shape}")
    if isinstance(it, tuple) and len(it) in (2, 3) and _array_like(it[0]) and _array_like(it[1]):
        first, second = np.asarray(it[0]), np.asarray(it[1])
        if first.ndim == 2 and first.shape[1:] == (3,) and first.dtype.kind in "fiu" and second.ndim == 2 \
                and _is_int(second):
            V = _points(first, f"{where}: vertices")
            F = _faces(second, len(V), where)
            return [MeshItem(V, F, _mesh_values(it[2] if len(it) == 3 else None, V, second, F, where))]
        if _float_points(first) and second.dtype.kind == "f":
            P = _points(first, f"{where}: points")
            if second.shape == P.shape:
                N = _points(second, f"{where}: normals")
                return [CloudItem(P, N, _finite(it[2], where) if len(it) == 3 else None)]
            if second.shape == (len(P),) and len(it) == 2:
                return [CloudItem(P, None, _finite(second, where))]
    if isinstance(it, (list, tuple)) and len(it):
        if all(isinstance(p, np.ndarray) and _float_points(p) for p in it):
            return [CurvesItem([_points(p, where) for p in it])]
        return [_curves_on_mesh(list(it), last_mesh, where)]
    raise ValueError(f"{where}: cannot show a {type(it).__name__}; see help(gsdf.view) for the items it shows")


def _array_like(x) -> bool:
    try:
        a = np.asarray(x)
    except ValueError:
        return False
    return a.dtype != object


def _finite(v, where):
    v = np.asarray(v, dtype=np.float64)
    if not np.isfinite(v).all():
        raise ValueError(f"{where}: values contain NaN or infinite entries")
    return v


def _mesh_values(extra, V, F_given, F, where):
    """The values of a ``(V, F, values)`` item on the (triangulated) mesh."""
    if extra is None or isinstance(extra, dict):          # (V, F, report) of a reconstruction
        return None
    if hasattr(extra, "face_labels") and hasattr(extra, "corner_values"):    # surface winding numbers
        extra = np.asarray(extra.face_labels)
    v = np.asarray(extra)
    quads = F_given.shape[1] == 4
    m = len(F_given)
    if v.ndim == 1 and len(v) == m and (len(v) != len(V) or _is_int(v)) and quads:
        v = np.concatenate([v, v])                         # per quad -> per triangle
    ok = (v.ndim == 1 and len(v) in (len(V), len(F))) or (v.ndim == 2 and v.shape == (len(F), 3) and not quads)
    if not ok:
        raise ValueError(f"{where}: values must have one entry per vertex ({len(V)}), per face ({m}) or per "
                         f"corner ({m}, 3), got shape {v.shape}")
    if v.dtype == bool:
        v = v.astype(np.int64)
    return v if _is_int(v) else _finite(v, where)


def _curves_on_mesh(curves, mesh, where) -> CurvesItem:
    """Vertex-index polylines, edge lists and surface points on ``mesh`` as 3D polylines."""
    from gsdf.curves import Curve

    polys = []
    for c in curves:
        if isinstance(c, np.ndarray) and _float_points(c):
            polys.append(_points(c, where))
            continue
        if mesh is None:
            raise ValueError(f"{where}: curves given by vertex indices or surface points need the mesh before "
                             "them in the items, e.g. view((V, F), curves)")
        V, F = mesh.V, mesh.F
        if isinstance(c, list) and len(c) == 1 and not isinstance(c[0], (list, tuple)) and np.ndim(c[0]) == 0:
            polys.append(V[[int(c[0])]])                   # a point source at a vertex
            continue
        if isinstance(c, list) and len(c) == 1 and isinstance(c[0], tuple):
            polys.append(_surface_points([c[0]], V, F, where))
            continue
        cv = c if isinstance(c, Curve) else Curve(c, name=where)
        if cv.kind == "points":
            polys.append(_surface_points(cv.nodes, V, F, where))
        else:
            for pl in cv.polylines():
                if pl.max() >= len(V):
                    raise ValueError(f"{where}: vertex index {int(pl.max())} out of range for {len(V)} vertices")
                polys.append(V[pl])
    return CurvesItem(polys)


def _surface_points(nodes, V, F, where):
    out = []
    for face, bary in nodes:
        b = np.asarray(bary, float)
        if b.size == 0:                                     # (vertex, ()) means a vertex
            out.append(V[int(face)])
        else:
            if not 0 <= int(face) < len(F):
                raise ValueError(f"{where}: face index {int(face)} out of range for {len(F)} faces")
            out.append(b @ V[F[int(face)]])
    return np.asarray(out, float).reshape(-1, 3)


# ---------------------------------------------------------------------------------------------------------------
# the parts polyscope draws
# ---------------------------------------------------------------------------------------------------------------

@dataclass
class Scalar:
    """A colour-mapped field; ``vrange`` is the range of the colour map, ``data`` the range of the values."""
    title: str
    values: np.ndarray
    on: str                              # "vertices" | "faces" | "corners"
    vrange: tuple
    cmap: str
    data: tuple


@dataclass
class Labels:
    title: str
    colors: np.ndarray                   # (n, 3) per element
    on: str                              # "vertices" | "faces"
    legend: dict                         # label -> (rgb, share of the elements)


@dataclass
class SurfacePart:
    name: str
    V: np.ndarray
    F: np.ndarray
    scalar: Scalar | None = None
    labels: Labels | None = None
    color: tuple = MESH_COLOR
    transparency: float | None = None    # None: opaque
    flat: bool = False                   # flat material (slices: the colours are the colour map's)
    edges: bool = False
    cut: int | None = None               # index of the plane that cuts it (None: not cut)


@dataclass
class CurvePart:
    name: str
    nodes: np.ndarray
    edges: np.ndarray
    color: tuple
    radius: float                        # relative to the scene's length scale
    flat: bool = False
    cut: int | None = None


@dataclass
class CloudPart:
    name: str
    P: np.ndarray
    radius: float                        # relative
    color: tuple = CLOUD_COLOR
    colors: np.ndarray | None = None     # (n, 3) per point (normal shading)
    scalar: Scalar | None = None


@dataclass
class Plane:
    origin: np.ndarray
    normal: np.ndarray                   # the kept side


@dataclass
class VolumePart:
    """The whole volume field, for the interactive window (registered disabled: polyscope's own volume grid or
    tet mesh, with its draggable slice plane)."""
    name: str
    field: object
    scalar: Scalar
    level: float | None


@dataclass
class Scene:
    parts: list = field(default_factory=list)
    planes: list = field(default_factory=list)
    volumes: list = field(default_factory=list)
    frame: list = field(default_factory=list)          # point sets the camera must frame

    def bars(self) -> list:
        """The scalars that get a colour bar, in order, one per title."""
        seen, out = set(), []
        for p in self.parts:
            s = getattr(p, "scalar", None)
            if s is not None and s.title not in seen:
                seen.add(s.title)
                out.append(s)
        return out

    def legends(self) -> list:
        return [p.labels for p in self.parts if getattr(p, "labels", None) is not None]


# ---------------------------------------------------------------------------------------------------------------
# colour ranges and isolines
# ---------------------------------------------------------------------------------------------------------------

def round_up(a: float) -> float:
    """``a`` > 0 rounded up to 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a power of ten (0.7495 -> 0.8,
    0.59 -> 0.6), so that the colour bar's ticks (the ends, their halves and 0) read well."""
    e = 10.0 ** math.floor(math.log10(a))
    m = next((m for m in (1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0) if a <= m * e * (1 + 1e-9)), 10.0)
    return float(f"{m * e:.12g}")


def field_kind(v: np.ndarray, title: str | None = None) -> str:
    """"winding" (values gather at 0 and 1: a winding number or an occupancy; with a ``title`` that says so, values
    gathered at 0 and other integers: a thin shape, or a soup that covers some regions twice), "signed" (changes
    sign) or "plain"."""
    v = np.asarray(v, float).ravel()
    if v.size == 0:
        return "plain"
    near0, near1 = np.abs(v) < 0.1, np.abs(v - 1.0) < 0.1
    # the inside of a thin shape is a small part of the box: a title that names a winding number (or an
    # occupancy) needs only some values near 1
    hinted = title is not None and any(w in title.lower() for w in ("winding number", "occupancy"))
    if near1.mean() > 0.02 and near0.mean() > 0.02 and (near0 | near1).mean() > 0.6 and v.min() > -0.5 \
            and v.max() < 1.5:
        return "winding"
    if hinted and near0.mean() > 0.02 and (np.abs(v - np.round(v)) < 0.1).mean() > 0.6 and v.max() > 0.5:
        return "winding"        # doubly covered regions of a soup wind twice
    if v.min() < 0.0 < v.max():
        return "signed"
    return "plain"


def colour_range(v, kind: str, vrange=None) -> tuple:
    """The range of the colour map: ``vrange`` if given; symmetric about 0 with a rounded half-width
    ("signed"); [0, 1] ("winding"); else the data range."""
    v = np.asarray(v, float)
    if vrange is not None:
        from gsdf._checks import as_values

        try:
            if isinstance(vrange, (str, bytes)):
                raise ValueError
            lo, hi = (float(x) for x in as_values(vrange, "vrange", (2,)))
        except ValueError:
            lo = hi = math.nan
        if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
            raise ValueError(f"vrange: expected (low, high) with low < high, got {vrange!r}")
        return lo, hi
    if kind == "winding":                   # 0 outside, 1 inside: ticks 0, 1/4, 1/2, 3/4, 1 (beyond: the end colours)
        return 0.0, 1.0
    if kind == "signed":
        a = round_up(float(np.max(np.abs(v))) or 1.0)
        return -a, a
    lo, hi = float(v.min()), float(v.max())
    return (lo, hi) if hi > lo else (lo - 0.5, lo + 0.5)


def default_level(kind: str):
    return {"signed": 0.0, "winding": 0.5}.get(kind)


def nice_levels(lo: float, hi: float, n: int = 16) -> list:
    """About ``n`` round isovalues in [lo, hi] (steps 1, 2, 2.5, 5 times a power of ten)."""
    if not hi > lo or n <= 0:
        return []
    raw = (hi - lo) / n
    e = 10.0 ** math.floor(math.log10(raw))
    step = min((m * e for m in (1, 2, 2.5, 5, 10) if m * e >= raw * (1 - 1e-9)), default=10 * e)
    k0, k1 = math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9)
    return [round(k * step, 12) for k in range(k0, k1 + 1)]


def isoline_parts(name, V, F, values, levels, highlight, cut=None) -> list:
    """Isolines of a per-vertex field as two curve parts: thin dark lines at ``levels`` and a thicker black one at
    ``highlight`` (marching triangles of :meth:`gsdf.SurfaceField.isolines`: exact, independent of the shader)."""
    from gsdf.field import SurfaceField

    sf = SurfaceField(V, F, values)
    thin, thick = [], []
    for L in levels:
        if highlight is None or abs(L - highlight) > 1e-9 * max(1.0, abs(L)):
            thin.extend(sf.isolines(float(L)))
    if highlight is not None and float(values.min()) < highlight < float(values.max()):
        thick.extend(sf.isolines(float(highlight)))
    out = []
    for polys, suffix, radius, color in ((thin, "isolines", 0.0012, (0.15, 0.15, 0.15)),
                                         (thick, f"isoline {highlight:g}" if highlight is not None else "", 0.0024,
                                          (0.02, 0.02, 0.02))):
        polys = [p for p in polys if len(p) >= 2]
        if polys:
            nodes, edges = polyline_graph(polys)
            out.append(CurvePart(f"{name} {suffix}", nodes, edges, color, radius, flat=True, cut=cut))
    return out


def polyline_graph(polys) -> tuple:
    """Polylines as one node array and its edge list (a curve network)."""
    nodes = np.concatenate(polys)
    off = np.cumsum([0] + [len(p) for p in polys])
    edges = np.concatenate([np.column_stack([np.arange(a, b - 1), np.arange(a + 1, b)])
                            for a, b in zip(off[:-1], off[1:]) if b - a >= 2] or [np.zeros((0, 2), np.int64)])
    return nodes, edges.astype(np.int64)


# ---------------------------------------------------------------------------------------------------------------
# camera
# ---------------------------------------------------------------------------------------------------------------

def axis_vector(spec, name: str = "axis") -> np.ndarray:
    """"x", "-y", "+z" (or a nonzero 3-vector of real numbers) as a unit vector; anything else is a ValueError
    naming ``name``."""
    if not isinstance(spec, str):
        from gsdf._checks import as_values

        try:
            if isinstance(spec, (bytes, bool, int, float, np.generic)):
                raise ValueError
            v = as_values(spec, name).ravel()
        except ValueError:
            v = np.zeros(0)
        n = float(np.linalg.norm(v)) if v.shape == (3,) else 0.0
        if not n > 0:
            raise ValueError(f"{name}: expected an axis x, y, z, -x, -y, -z or a nonzero 3-vector, got {spec!r}")
        return v / n
    s = str(spec).strip().lower()
    sign = -1.0 if s.startswith("-") else 1.0
    s = s.lstrip("+-")
    if s not in _AXES:
        raise ValueError(f"{name}: expected an axis x, y, z, -x, -y or -z, got {spec!r}")
    v = np.zeros(3)
    v[_AXES[s]] = sign
    return v


def camera_direction(up, front, azimuth: float, elevation: float, extent) -> tuple:
    """The direction from the target towards the camera, and the up vector.

    up : "x" / "y" / "-z" ... or "auto": y, except for a flat scene (thinnest side below 10 % of the longest),
        seen from its normal side (elevation at least 55°).
    front : the axis the unrotated camera looks along (it looks towards -front); "auto": the thinner of the two
        sides across ``up`` (the broad side faces the camera).
    azimuth, elevation : degrees; turn about ``up`` (towards the right) and height above the horizon.
    """
    extent = np.asarray(extent, float)
    if isinstance(up, str) and up == "auto":
        thin = int(np.argmin(extent))
        if extent[thin] < 0.1 * extent.max():
            upv = np.zeros(3)
            upv[thin] = 1.0
            elevation = max(float(elevation), 55.0)
        else:
            upv = np.array([0.0, 1.0, 0.0])
    else:
        upv = axis_vector(up, "up")
    a_up = int(np.argmax(np.abs(upv)))
    if front == "auto":
        cand = [i for i in range(3) if i != a_up]
        if abs(extent[cand[0]] - extent[cand[1]]) > 0.05 * extent.max():
            f = min(cand, key=lambda i: extent[i])
        else:
            f = 2 if a_up != 2 else 1
        fr = np.zeros(3)
        fr[f] = 1.0
        if a_up == 2 and f == 1:
            fr[1] = -1.0                  # z up: the camera in front of the -y face, as in CAD programs
    else:
        fr = axis_vector(front, "front")
        if abs(fr @ upv) > 0.5:
            raise ValueError(f"front {front!r} is parallel to up {up!r}")
    right = np.cross(upv, fr)
    az, el = math.radians(float(azimuth)), math.radians(float(elevation))
    d = math.cos(el) * (math.cos(az) * fr + math.sin(az) * right) + math.sin(el) * upv
    return d / np.linalg.norm(d), upv


def direction_camera(view_dir, up="auto") -> tuple:
    """A camera along a given direction (from the scene towards the camera): the unit direction and the up
    vector (``up``, or y unless the direction is within 15° of it, then z)."""
    from gsdf._checks import as_values

    try:
        d = as_values(view_dir, "view").reshape(-1)
    except ValueError as exc:
        raise ValueError(f"view: expected a nonzero direction (x, y, z), got {view_dir!r} ({exc})") from None
    if d.shape != (3,) or not np.linalg.norm(d) > 0:
        raise ValueError(f"view: expected a nonzero direction (x, y, z), got {view_dir!r}")
    d = d / np.linalg.norm(d)
    if not (isinstance(up, str) and up == "auto"):
        upv = axis_vector(up, "up")
    else:
        upv = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < math.cos(math.radians(15)) else np.array([0.0, 0.0, 1.0])
    if np.linalg.norm(np.cross(d, upv)) < 1e-6:
        raise ValueError(f"view: the direction {d.round(6).tolist()} is parallel to the up axis {up!r}")
    return d, upv


def frame_camera(pts, width: int, height: int, fov_deg: float, view_dir, upv, fill: float = 0.86,
                 keep_clear=()) -> tuple:
    """Camera position and target for a perspective camera looking along ``-view_dir`` so that the points ``pts``
    span ``fill`` of the tighter image side, centred (the target is moved until the projected box is centred).

    keep_clear : pixel boxes (x0, y0, x1, y1) of the picture (colour bars, legends) that the points must not
        cover; when they would, the points are framed in the part of the picture beside the boxes.
    Returns (camera, target).
    """
    pts = np.asarray(pts, float)
    if len(pts) > 64:              # the extremes of every projection are vertices of the convex hull
        from scipy.spatial import ConvexHull, QhullError

        try:
            pts = pts[ConvexHull(pts).vertices]
        except (QhullError, ValueError):       # flat or degenerate: all points
            pass
    back = np.asarray(view_dir, float) / np.linalg.norm(view_dir)
    right = np.cross(upv, back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    ty = math.tan(math.radians(fov_deg) / 2)
    tx = ty * width / height

    def project(target, d):
        rel = pts - target
        Z = d - rel @ back
        return (rel @ right) / Z, (rel @ up) / Z

    def place(x0, x1):
        """Frame the points in the columns x0..x1 (fractions of the width); return camera, target, pixels."""
        hx, cx = (x1 - x0) * tx, (x0 + x1 - 1.0) * tx      # usable half-width and centre, in tan units
        target = 0.5 * (pts.min(0) + pts.max(0))
        radius = 0.5 * float(np.linalg.norm(pts.max(0) - pts.min(0))) or 1.0
        d = radius / math.sin(math.atan(min(hx, ty) * fill))

        def fit(target, d):
            """The distance at which the projected spread fits (bisection; the spread shrinks with distance)."""
            near = float(np.max(pts @ back - target @ back)) + 1e-6 * radius
            a, b = near, max(d, near) * 2.0
            while True:
                xp, yp = project(target, b)
                if np.ptp(xp) <= 2 * hx * fill and np.ptp(yp) <= 2 * ty * fill:
                    break
                a, b = b, 2.0 * b
            for _ in range(40):
                m = 0.5 * (a + b)
                xp, yp = project(target, m)
                if np.ptp(xp) <= 2 * hx * fill and np.ptp(yp) <= 2 * ty * fill:
                    b = m
                else:
                    a = m
            return b

        def centre(C, Z, c):
            """The sideways shift s that centres the projections (C - s) / Z on c (bisection: monotone in s)."""
            def g(s):
                q = (C - s) / Z
                return q.max() + q.min() - 2 * c
            L = float(np.abs(C).max() + np.abs(c) * Z.max()) + 1.0
            a, b = -L, L
            while g(a) < 0:
                a *= 2
            while g(b) > 0:
                b *= 2
            for _ in range(60):
                m = 0.5 * (a + b)
                a, b = (m, b) if g(m) > 0 else (a, m)
            return 0.5 * (a + b)

        for _ in range(30):
            d = fit(target, d)
            rel = pts - target
            Z = d - rel @ back
            sx, sy = centre(rel @ right, Z, cx), centre(rel @ up, Z, 0.0)
            target = target + sx * right + sy * up
            if abs(sx) < 1e-6 * radius and abs(sy) < 1e-6 * radius:
                break
        d = fit(target, d)
        xp, yp = project(target, d)
        return target + back * d, target, (0.5 + 0.5 * xp / tx) * width, (0.5 - 0.5 * yp / ty) * height

    cam, target, px, py = place(0.0, 1.0)
    for (x0, y0, x1, y1) in keep_clear:
        if np.any((px >= x0) & (px <= x1) & (py >= y0) & (py <= y1)):
            if x0 + x1 < width:               # a box on the left: frame right of it
                cam, target, px, py = place(min(x1 / width, 0.5), 1.0)
            else:
                cam, target, px, py = place(0.0, max(x0 / width, 0.5))
            break
    return cam, target


def extent_of(items) -> tuple:
    """(low corner, high corner) of everything shown."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for it in items:
        if isinstance(it, MeshItem):
            P = it.V[np.unique(it.F)] if len(it.F) else it.V
        elif isinstance(it, CloudItem):
            P = it.P
        elif isinstance(it, CurvesItem):
            P = np.concatenate(it.polylines) if it.polylines else np.zeros((0, 3))
        else:
            P = np.array([it.field.bbox_min, it.field.bbox_max], float)
        if len(P):
            lo, hi = np.minimum(lo, P.min(0)), np.maximum(hi, P.max(0))
    if not np.isfinite(hi - lo).all():
        raise ValueError("view: nothing to show (the items are empty)")
    return lo, hi


# ---------------------------------------------------------------------------------------------------------------
# building the scene
# ---------------------------------------------------------------------------------------------------------------

def build(items, options, view_dir, upv) -> Scene:
    """The parts of ``items`` (from :func:`coerce`) seen from ``view_dir``; ``options`` a
    :class:`gsdf.ViewOptions`."""
    sc = Scene()
    lo, hi = extent_of(items)
    scale = float(np.linalg.norm(hi - lo)) or 1.0
    names: dict = {}

    def uniq(n):
        names[n] = names.get(n, 0) + 1
        return n if names[n] == 1 else f"{n} ({names[n]})"

    n_curves = 0
    volumes = [it for it in items if isinstance(it, VolumeItem)]
    with_mesh = any(isinstance(it, MeshItem) for it in items)
    for it in items:
        if isinstance(it, MeshItem):
            _add_mesh(sc, it, options, uniq, cut_by_volume=bool(volumes))
        elif isinstance(it, CloudItem):
            _add_cloud(sc, it, options, uniq, view_dir, upv, scale, with_mesh)
        elif isinstance(it, CurvesItem):
            polys = [p for p in it.polylines if len(p)]
            if not polys:
                continue
            nodes, edges = polyline_graph(polys)
            color = CURVE_COLORS[n_curves % len(CURVE_COLORS)]
            n_curves += 1
            sc.parts.append(CurvePart(uniq(it.name or "curves"), nodes, edges, color, 0.004))
            singles = [p for p in polys if len(p) == 1]             # point sources: small balls
            if singles:
                sc.parts.append(CloudPart(uniq((it.name or "curves") + " points"), np.concatenate(singles), 0.006,
                                          color=color))
            sc.frame.append(nodes)
        else:
            _add_volume(sc, it, options, uniq, view_dir, upv)
    if not sc.frame:
        raise ValueError("view: nothing to show (the items are empty)")
    # one colour bar per title: fields with the same title but another colour scale get their own title
    scales: dict = {}
    for p in sc.parts:
        s = getattr(p, "scalar", None)
        if s is None:
            continue
        key, title, k = (s.vrange, s.cmap), s.title, 1
        while scales.setdefault(title, key) != key:
            k += 1
            title = f"{s.title} ({k})"
        s.title = title
    return sc


def _scalar(title, v, on, options):
    kind = field_kind(v, title)
    vr = colour_range(v, kind, options.vrange)
    cmap = options.colormap or ("coolwarm" if kind in ("signed", "winding") else "viridis")
    return Scalar(title, v, on, vr, cmap, (float(v.min()), float(v.max()))), kind


def _levels(scalar, options):
    iso = options.isolines
    if isinstance(iso, (int, np.integer)):
        lo, hi = max(scalar.vrange[0], scalar.data[0]), min(scalar.vrange[1], scalar.data[1])
        return nice_levels(lo, hi, int(iso))
    return [float(x) for x in iso]


def _add_mesh(sc, it, options, uniq, cut_by_volume):
    name = uniq(it.name or "mesh")
    part = SurfacePart(name, it.V, it.F)
    if cut_by_volume:
        part.cut, part.transparency, part.edges = 0, 0.55, True      # the soup around a volume field's slice
    sc.parts.append(part)
    sc.frame.append(it.V[np.unique(it.F)])
    v = it.values
    if v is None:
        return
    on = "corners" if v.ndim == 2 else ("vertices" if len(v) == len(it.V) else "faces")
    if _is_int(v):
        part.labels = _labels(it.name or "label", v, on, it.V, it.F)
        if on == "faces":
            seg = label_boundaries(it.F, v)
            if len(seg):
                used, e = np.unique(seg, return_inverse=True)
                sc.parts.append(CurvePart(f"{name} boundaries", it.V[used], e.reshape(-1, 2), (0.05, 0.05, 0.05),
                                          0.0015, flat=True, cut=part.cut))
        return
    part.scalar, kind = _scalar(it.name or "value", v, on, options)
    if on == "vertices":
        level = options.level if options.level is not None else default_level(kind)
        sc.parts.extend(isoline_parts(name, it.V, it.F, v, _levels(part.scalar, options), level, part.cut))


def label_boundaries(F, lab) -> np.ndarray:
    """The mesh edges between two faces with different labels, as (k, 2) vertex pairs."""
    m = len(F)
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    face = np.tile(np.arange(m), 3)
    E = np.sort(E, axis=1)
    order = np.lexsort((E[:, 1], E[:, 0]))
    E, face = E[order], face[order]
    same = np.all(E[1:] == E[:-1], axis=1)                 # consecutive copies of one edge: its two faces
    i = np.flatnonzero(same)
    differ = np.asarray(lab)[face[i]] != np.asarray(lab)[face[i + 1]]
    return E[i[differ]]


def _labels(title, lab, on, V, F):
    lab = np.asarray(lab).astype(np.int64)
    values = sorted(set(np.unique(lab).tolist()))
    pal = {l: PALETTE[i % len(PALETTE)] for i, l in enumerate(values)}
    colors = np.array([pal[l] for l in values])[np.searchsorted(values, lab)]
    if on == "faces":                                    # share of the area, not of the face count
        A = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
        w = A / max(A.sum(), 1e-300)
    else:
        w = np.full(len(lab), 1.0 / max(len(lab), 1))
    legend = {l: (pal[l], float(w[lab == l].sum())) for l in values}
    return Labels(title, colors, on, legend)


def _add_cloud(sc, it, options, uniq, view_dir, upv, scale, with_mesh=False):
    """A cloud: spheres of about half the point spacing (a third of that, without normals drawn, over a mesh such
    as its reconstruction), shaded by the normals or coloured by the values."""
    P = it.P
    ext = float(np.linalg.norm(P.max(0) - P.min(0))) or scale
    radius = min(0.5 / math.sqrt(max(len(P), 1)), 0.01) * ext / scale * (0.35 if with_mesh else 1.0)
    name = uniq(it.name or "cloud")
    part = CloudPart(name, P, radius)
    sc.parts.append(part)
    sc.frame.append(P)
    if it.values is not None:
        part.scalar, _ = _scalar(it.name or "value", it.values, "vertices", options)
    elif it.N is not None:
        # a headlight Lambert term of each normal: the cloud reads as a surface; normals facing away are grey
        N = it.N / np.maximum(np.linalg.norm(it.N, axis=1, keepdims=True), 1e-300)
        light = view_dir + 0.4 * upv
        lam = N @ (light / np.linalg.norm(light))
        base = np.asarray(CLOUD_COLOR)
        part.colors = np.clip(np.where(lam[:, None] >= 0, base * (0.35 + 0.65 * lam[:, None]),
                                       0.45 * (0.35 + 0.65 * -lam[:, None])), 0, 1)
    if it.N is not None and not with_mesh:          # every k-th normal as a short segment (about 700 of them)
        k = max(1, len(P) // 700)
        n = it.N[::k] / np.maximum(np.linalg.norm(it.N[::k], axis=1, keepdims=True), 1e-300)
        nodes = np.concatenate([P[::k], P[::k] + 0.03 * ext * n])
        edges = np.column_stack([np.arange(len(n)), np.arange(len(n)) + len(n)])
        sc.parts.append(CurvePart(uniq(name + " normals"), nodes, edges, (0.2, 0.2, 0.2), radius * 0.2, flat=True))
        sc.frame.append(nodes[len(n):])


def _add_volume(sc, it, options, uniq, view_dir, upv):
    from gsdf.field import GridField

    f = it.field
    lo, hi = np.asarray(f.bbox_min, float), np.asarray(f.bbox_max, float)
    name = uniq(it.name or "field")
    title = it.name or "value"
    vals = np.asarray(f.values, float)
    scalar, kind = _scalar(title, vals.ravel(), "vertices", options)
    level = options.level if options.level is not None else default_level(kind)
    ax = options.slice_axis
    if ax is None:                       # the axis across up that faces the camera most
        cand = [i for i in range(3) if abs(upv[i]) < 0.5]
        ax = max(cand, key=lambda i: abs(view_dir[i]))
    else:
        ax = int(np.argmax(np.abs(axis_vector(ax))))
    at = 0.5 * (lo[ax] + hi[ax]) if options.slice_at is None else float(options.slice_at)
    if not lo[ax] <= at <= hi[ax]:
        raise ValueError(f"slice_at {at:g} is outside the field's box [{lo[ax]:g}, {hi[ax]:g}] along "
                         f"{'xyz'[ax]}")
    if isinstance(f, GridField):
        SP, SF, SV = grid_slice(vals, lo, hi, ax, at)
    else:
        SP, SF, SV = tet_slice(f, ax, at)
    # the plane that cuts the isosurface (and meshes shown with the field): the camera side is kept
    normal = np.zeros(3)
    normal[ax] = 1.0 if view_dir[ax] > 0 else -1.0
    origin = np.where(np.arange(3) == ax, at, 0.5 * (lo + hi))
    sc.planes.append(Plane(origin, normal))
    cut = len(sc.planes) - 1
    sc.volumes.append(VolumePart(name, f, scalar, level))
    if len(SF):
        s = Scalar(title, SV, "vertices", scalar.vrange, scalar.cmap, scalar.data)
        sc.parts.append(SurfacePart(uniq(name + " slice"), SP, SF, scalar=s, flat=True))
        sc.parts.extend(isoline_parts(name + " slice", SP, SF, SV, _levels(s, options), level))
        sc.frame.append(SP)
    if level is not None and float(vals.min()) < level < float(vals.max()):
        IV, IF = f.isosurface(float(level))
        if len(IF):
            sc.parts.append(SurfacePart(uniq(f"{name} level {level:g}"), IV, IF, color=(0.8, 0.8, 0.82),
                                        transparency=0.45, cut=cut))
            sc.frame.append(IV)
    if not len(SF):
        sc.frame.append(np.array([lo, hi]))


def grid_slice(values, lo, hi, axis: int, at: float) -> tuple:
    """A planar grid mesh at ``at`` along ``axis`` through the grid, values interpolated linearly between the two
    node layers around it: (P, F, values)."""
    n = np.array(values.shape)
    h = (hi - lo) / (n - 1)
    t = float(np.clip((at - lo[axis]) / h[axis], 0, n[axis] - 1))
    k0 = int(min(math.floor(t), n[axis] - 2))
    w = t - k0
    A = np.take(values, k0, axis=axis) * (1 - w) + np.take(values, k0 + 1, axis=axis) * w
    o = [i for i in range(3) if i != axis]
    U, W = np.meshgrid(np.linspace(lo[o[0]], hi[o[0]], n[o[0]]), np.linspace(lo[o[1]], hi[o[1]], n[o[1]]),
                       indexing="ij")
    P = np.zeros(U.shape + (3,))
    P[..., o[0]], P[..., o[1]], P[..., axis] = U, W, at
    a, b = n[o[0]], n[o[1]]
    idx = np.arange(a * b).reshape(a, b)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    F = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    return P.reshape(-1, 3), F, A.reshape(-1)


def tet_slice(f, axis: int, at: float) -> tuple:
    """The cross-section of a tet field's mesh by the plane ``x[axis] = at`` with the field's values on it:
    (P, F, values). Marching tetrahedra of the coordinate, with the values interpolated along the same edges
    (crossing points shared per tet edge)."""
    X, T = f.vertices, f.tets
    s = X[:, axis] - at
    span = float(np.ptp(X[:, axis])) or 1.0
    s = np.where(s == 0.0, 1e-9 * span, s)            # no node exactly on the plane
    pos = s[T] > 0
    npos = pos.sum(axis=1)
    corners = []                                       # (k, 3 corners, 2 edge ends)
    for k in (1, 3):                                   # one node apart: a triangle
        sel = npos == k
        if sel.any():
            lone = pos[sel] if k == 1 else ~pos[sel]
            Ts = np.take_along_axis(T[sel], np.argsort(~lone, axis=1, kind="stable"), axis=1)
            corners.append(np.stack([Ts[:, [0, 1]], Ts[:, [0, 2]], Ts[:, [0, 3]]], 1))
    sel = npos == 2                                    # two and two: a quad, two triangles
    if sel.any():
        Ts = np.take_along_axis(T[sel], np.argsort(~pos[sel], axis=1, kind="stable"), axis=1)
        ac, ad, bd, bc = Ts[:, [0, 2]], Ts[:, [0, 3]], Ts[:, [1, 3]], Ts[:, [1, 2]]
        corners += [np.stack([ac, ad, bd], 1), np.stack([ac, bd, bc], 1)]
    if not corners:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros(0)
    E = np.sort(np.concatenate(corners).reshape(-1, 2), axis=1)
    uniq, inv = np.unique(E, axis=0, return_inverse=True)
    t = (s[uniq[:, 0]] / (s[uniq[:, 0]] - s[uniq[:, 1]]))[:, None]
    P = X[uniq[:, 0]] + t * (X[uniq[:, 1]] - X[uniq[:, 0]])
    v = f.values[uniq[:, 0]] + t[:, 0] * (f.values[uniq[:, 1]] - f.values[uniq[:, 0]])
    return P, inv.reshape(-1, 3).astype(np.int64), v
