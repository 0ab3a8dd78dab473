"""Fields: values on a domain, evaluation anywhere, and isosurfaces — what every volumetric method returns."""

from __future__ import annotations

import numpy as np

from ._checks import as_points, positive


class Field:
    """Abstract scalar field on a domain in R^3.

    Subclasses implement ``__call__(Q) -> (q,)`` and ``isosurface(level) -> (V, F)``.
    """

    def __call__(self, Q) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def isosurface(self, level: float = 0.0):  # pragma: no cover - interface
        raise NotImplementedError


class GridField(Field):
    """Values on the nodes of a regular grid spanning ``[bbox_min, bbox_max]``.

    Parameters
    ----------
    values : (nx, ny, nz) float array
        Node values; node ``(i, j, k)`` sits at ``bbox_min + (i, j, k) * spacing``.
    bbox_min, bbox_max : (3,) float
        Corners of the grid.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.field import GridField
    >>> x = np.linspace(-1, 1, 33)
    >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    >>> f = GridField(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, [-1, -1, -1], [1, 1, 1])
    >>> round(float(f([[0.5, 0.0, 0.0]])[0]), 6)
    0.0
    """

    def __init__(self, values, bbox_min, bbox_max):
        values = np.asarray(values, dtype=np.float64)
        if values.ndim != 3 or min(values.shape) < 2:
            raise ValueError(f"values: expected a 3D grid with at least 2 nodes per axis, got shape {values.shape}")
        if not np.isfinite(values).all():
            raise ValueError("values: contains NaN or infinite entries")
        lo = as_points(bbox_min, "bbox_min")[0]
        hi = as_points(bbox_max, "bbox_max")[0]
        if np.any(hi <= lo):
            raise ValueError(f"bbox_max {hi} must exceed bbox_min {lo} on every axis")
        self.values = np.ascontiguousarray(values)
        self.bbox_min = lo
        self.bbox_max = hi
        self.meta: dict = {}

    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(self.values.shape)

    @property
    def spacing(self) -> np.ndarray:
        return (self.bbox_max - self.bbox_min) / (np.array(self.values.shape) - 1)

    def grid_points(self) -> np.ndarray:
        """Node positions, shape (nx*ny*nz, 3), in C order of ``values``."""
        return grid_points(self.bbox_min, self.bbox_max, self.values.shape)

    def __call__(self, Q) -> np.ndarray:
        """Trilinear interpolation at query points ``Q`` (q, 3); points outside are clamped to the box."""
        Q = as_points(Q, "Q", allow_empty=True)
        n = np.array(self.values.shape)
        t = (Q - self.bbox_min) / self.spacing
        t = np.clip(t, 0.0, n - 1.0)
        i0 = np.minimum(np.floor(t).astype(np.int64), n - 2)
        f = t - i0
        v = self.values
        out = np.zeros(Q.shape[0])
        for dx in (0, 1):
            wx = f[:, 0] if dx else 1.0 - f[:, 0]
            for dy in (0, 1):
                wy = f[:, 1] if dy else 1.0 - f[:, 1]
                for dz in (0, 1):
                    wz = f[:, 2] if dz else 1.0 - f[:, 2]
                    out += wx * wy * wz * v[i0[:, 0] + dx, i0[:, 1] + dy, i0[:, 2] + dz]
        return out

    def isosurface(self, level: float = 0.0, close: bool = False, report: bool = False):
        """Marching cubes (scikit-image) at ``level``; returns ``(V, F)`` in world coordinates.

        With ``close=True`` a level set that reaches the box is capped on the box faces (the grid is padded
        with one layer of nodes above the level and the cap vertices are projected back onto the box); the
        result is welded (cap and surface share their seam vertices) and checked: with ``report=True``
        ``(V, F, report)`` is returned, ``report`` from :func:`gsdf.mesh.topology.manifold_report` (closed,
        edge- and vertex-manifold, welded). Where the level set touches itself at a grid node (a pinch), that
        vertex is split per fan, so the mesh stays vertex-manifold and the report says it is not welded.
        Raises ValueError if the level is outside the range of the field.
        """
        from skimage.measure import marching_cubes

        from ._checks import finite
        from .mesh.topology import manifold_report, split_nonmanifold_vertices, weld

        level = finite(level, "level")
        for name, flag in (("close", close), ("report", report)):
            if not isinstance(flag, (bool, np.bool_)):
                raise ValueError(f"{name}: expected True or False, got {flag!r}")
        vmin, vmax = float(self.values.min()), float(self.values.max())
        if not (vmin < level < vmax):
            raise ValueError(f"level {level} is outside the field's range [{vmin:.6g}, {vmax:.6g}]: no surface")
        # scikit-image works in float32: hand it values relative to the level scaled to [-1, 1] and a unit
        # spacing, so fields and boxes of any magnitude (1e-150 or 1e150) keep their sign pattern
        rel = self.values * 0.5 - level * 0.5
        rel = rel / float(np.abs(rel).max())
        h = self.spacing
        if close:
            rel = np.pad(rel, 1, mode="constant", constant_values=1.0)
        verts, faces, _, _ = marching_cubes(rel, level=0.0)
        verts = np.asarray(verts, dtype=np.float64)
        F = faces.astype(np.int64)
        if not close:
            V = self.bbox_min + verts * h
            return (V, F, manifold_report(V, F)) if report else (V, F)
        V = np.clip((verts - 1.0) * h + self.bbox_min, self.bbox_min, self.bbox_max)
        V, F = weld(V, F)
        rep = manifold_report(V, F)
        if not rep["vertex_manifold"]:
            V, F = split_nonmanifold_vertices(V, F)
            rep = manifold_report(V, F)
        return (V, F, rep) if report else (V, F)

    def isosurfaces(self, levels, close: bool = False):
        """Several level sets at once: a list of ``(V, F)``, one per level (e.g. offsets ±1 %, ±3 %)."""
        return [self.isosurface(float(v), close=close) for v in np.atleast_1d(np.asarray(levels, dtype=float))]

    def save(self, path) -> None:
        """Write the field: ``.npz`` (``values``, ``bbox_min``, ``bbox_max``), ``.vtk`` (legacy structured
        points, binary, opens in ParaView) or ``.vtu`` (meshio hexahedra with point data ``values``)."""
        p = str(path).lower()
        if p.endswith(".vtk"):
            _write_vtk_structured_points(path, self.values, self.bbox_min, self.spacing)
        elif p.endswith(".vtu"):
            import meshio

            P = self.grid_points()
            nx, ny, nz = self.shape
            idx = np.arange(nx * ny * nz).reshape(self.shape)
            c = idx[:-1, :-1, :-1].ravel()
            sx, sy = ny * nz, nz
            hexes = np.column_stack([c, c + sx, c + sx + sy, c + sy, c + 1, c + sx + 1, c + sx + sy + 1, c + sy + 1])
            meshio.write(path, meshio.Mesh(P, [("hexahedron", hexes)], point_data={"values": self.values.ravel()}))
        else:
            np.savez_compressed(path, values=self.values, bbox_min=self.bbox_min, bbox_max=self.bbox_max,
                                kind="grid")

    @classmethod
    def load(cls, path) -> "GridField":
        try:
            with np.load(path) as d:
                return cls(d["values"], d["bbox_min"], d["bbox_max"])
        except (OSError, KeyError, ValueError) as exc:
            raise ValueError(f"{path}: not a gsdf grid field file ({exc})") from exc


def grid_points(bbox_min, bbox_max, shape) -> np.ndarray:
    """Positions of the nodes of a regular grid, shape (prod(shape), 3), C order."""
    axes = [np.linspace(bbox_min[d], bbox_max[d], int(shape[d])) for d in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return np.column_stack((X.ravel(), Y.ravel(), Z.ravel()))


def grid_shape(bbox_min, bbox_max, resolution) -> tuple[int, int, int]:
    """Grid node counts: ``resolution`` nodes along the longest axis, the same spacing on the others."""
    r = int(resolution)
    if r < 2:
        raise ValueError(f"resolution must be at least 2, got {resolution}")
    ext = np.asarray(bbox_max, float) - np.asarray(bbox_min, float)
    h = positive(ext.max(), "bounding box size") / (r - 1)
    return tuple(int(max(2, np.ceil(e / h - 1e-9) + 1)) for e in ext)


def _write_vtk_structured_points(path, values, origin, spacing) -> None:
    """Legacy VTK STRUCTURED_POINTS, binary big-endian float64; x varies fastest as VTK expects."""
    nx, ny, nz = values.shape
    header = (f"# vtk DataFile Version 3.0\ngsdf field\nBINARY\nDATASET STRUCTURED_POINTS\n"
              f"DIMENSIONS {nx} {ny} {nz}\nORIGIN {' '.join(repr(float(v)) for v in origin)}\n"
              f"SPACING {' '.join(repr(float(v)) for v in spacing)}\nPOINT_DATA {nx * ny * nz}\n"
              f"SCALARS values double 1\nLOOKUP_TABLE default\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(values.transpose(2, 1, 0)).astype(">f8").tobytes())
        f.write(b"\n")


class TetField(Field):
    """Values on the vertices of a tetrahedral mesh: barycentric evaluation and marching tetrahedra.

    Parameters
    ----------
    vertices : (n, 3) float
    tets : (m, 4) int
    values : (n,) float
    delaunay : scipy.spatial.Delaunay, optional
        Point locator whose simplices are ``tets`` (what :func:`gsdf.signed_heat_volume` with ``domain="tet"``
        builds). Without it, points are located among ``tets`` themselves (any tet mesh, e.g. TetGen's): the
        tets whose centroids are nearest to the query are tested by their barycentric coordinates.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.field import TetField
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
    >>> f = TetField(V, [[0, 1, 2, 3]], V[:, 0])
    >>> float(f([[0.25, 0.25, 0.25]])[0])
    0.25
    """

    def __init__(self, vertices, tets, values, delaunay=None):
        self.vertices = as_points(vertices, "vertices")
        T = np.asarray(tets)
        if T.ndim != 2 or T.shape[1] != 4 or len(T) == 0:
            raise ValueError(f"tets: expected shape (m, 4) with m > 0, got {T.shape}")
        if not np.issubdtype(T.dtype, np.integer) or T.min() < 0 or T.max() >= len(self.vertices):
            raise ValueError("tets: expected integer vertex indices within range")
        self.tets = np.ascontiguousarray(T, dtype=np.int64)
        v = np.asarray(values, dtype=np.float64).ravel()
        if v.shape[0] != len(self.vertices) or not np.isfinite(v).all():
            raise ValueError(f"values: expected {len(self.vertices)} finite values, got shape {np.shape(values)}")
        self.values = v
        self._delaunay = delaunay
        self.meta: dict = {}

    @property
    def bbox_min(self):
        return self.vertices.min(axis=0)

    @property
    def bbox_max(self):
        return self.vertices.max(axis=0)

    def __call__(self, Q) -> np.ndarray:
        """Barycentric (piecewise linear) interpolation at ``Q`` (q, 3); outside the mesh: nearest vertex."""
        Q = as_points(Q, "Q", allow_empty=True)
        out = np.empty(len(Q))
        if self._delaunay is not None:
            D = self._delaunay
            s = D.find_simplex(Q)
            inside = s >= 0
            if inside.any():
                Tr = D.transform[s[inside]]
                b = np.einsum("qij,qj->qi", Tr[:, :3], Q[inside] - Tr[:, 3])
                bary = np.column_stack([b, 1.0 - b.sum(axis=1)])
                out[inside] = (bary * self.values[D.simplices[s[inside]]]).sum(axis=1)
        else:
            s, bary = locate_in_tets(self.vertices, self.tets, Q)
            inside = s >= 0
            out[inside] = (bary[inside] * self.values[self.tets[s[inside]]]).sum(axis=1)
        if (~inside).any():
            from scipy.spatial import cKDTree

            out[~inside] = self.values[cKDTree(self.vertices).query(Q[~inside])[1]]
        return out

    def isosurface(self, level: float = 0.0, report: bool = False):
        """Marching tetrahedra at ``level``: a welded triangle mesh ``(V, F)``, oriented so that normals point
        toward increasing values (outward for a signed distance); ``report=True`` adds its
        :func:`gsdf.mesh.topology.manifold_report` (see :func:`marching_tetrahedra`)."""
        return marching_tetrahedra(self.vertices, self.tets, self.values, level, report=report)

    def isosurfaces(self, levels):
        return [self.isosurface(float(v)) for v in np.atleast_1d(np.asarray(levels, dtype=float))]

    def save(self, path) -> None:
        """``.npz`` (vertices, tets, values) or ``.vtu``/``.vtk`` (meshio tetra with point data ``values``)."""
        p = str(path).lower()
        if p.endswith(".vtu") or p.endswith(".vtk"):
            import meshio

            meshio.write(path, meshio.Mesh(self.vertices, [("tetra", self.tets)], point_data={"values": self.values}))
        else:
            np.savez_compressed(path, vertices=self.vertices, tets=self.tets, values=self.values, kind="tet")

    @classmethod
    def load(cls, path) -> "TetField":
        try:
            with np.load(path) as d:
                return cls(d["vertices"], d["tets"], d["values"])
        except (OSError, KeyError, ValueError) as exc:
            raise ValueError(f"{path}: not a gsdf tet field file ({exc})") from exc


def locate_in_tets(X, T, Q, k: int = 16, chunk: int = 1 << 15):
    """Tet containing each query (−1 if none) among arbitrary tets, and its barycentric coordinates.

    Candidates are the ``k`` tets with the nearest centroids (then 4k, 16k for queries not found yet); a tet
    contains q when all four barycentric coordinates are ≥ −1e-10. Vectorized over chunks of queries.
    """
    from scipy.spatial import cKDTree

    X = np.asarray(X, float)
    T = np.asarray(T, np.int64)
    Q = np.asarray(Q, float)
    A = X[T[:, 1:]] - X[T[:, :1]]
    det = np.linalg.det(A)
    ok = np.abs(det) > 1e-14 * np.abs(A).max(axis=(1, 2)) ** 3
    Ainv = np.zeros_like(A)
    Ainv[ok] = np.linalg.inv(A[ok])  # λ_{1..3} = (q − x0) · Ainv (row vector convention)
    kd = cKDTree(X[T].mean(axis=1))
    s = np.full(len(Q), -1, np.int64)
    bary = np.zeros((len(Q), 4))
    todo = np.arange(len(Q))
    for kk in (k, 4 * k, 16 * k):
        kk = min(kk, len(T))
        for c in range(0, len(todo), chunk):
            qi = todo[c:c + chunk]
            _, cand = kd.query(Q[qi], k=kk, workers=-1)
            cand = cand.reshape(len(qi), kk)
            b3 = np.einsum("qkj,qkji->qki", (Q[qi][:, None, :] - X[T[cand, 0]]), Ainv[cand])
            b = np.concatenate([1.0 - b3.sum(axis=2, keepdims=True), b3], axis=2)
            good = (b.min(axis=2) >= -1e-10) & ok[cand]
            hit = good.any(axis=1)
            j = np.argmax(good, axis=1)
            s[qi[hit]] = cand[hit, j[hit]]
            bary[qi[hit]] = b[hit, j[hit]]
        todo = todo[s[todo] < 0]
        if len(todo) == 0 or kk == len(T):
            break
    return s, bary


def marching_tetrahedra(X, T, values, level: float = 0.0, report: bool = False):
    """Level set of a piecewise-linear function on a tet mesh (vectorized marching tetrahedra).

    Each tet with vertices on both sides contributes one triangle (1 vertex apart) or a quad split in two
    (2 and 2); crossing points are shared per mesh edge. Where the level passes exactly through mesh nodes,
    crossing points of different edges coincide: they are welded, zero-area triangles dropped, and a vertex
    where separate sheets touch is split per fan, so the result is edge- and vertex-manifold (closed away from
    the mesh boundary). Two cases stay open, and the report says so: flat (zero-volume) tets, which a
    Delaunay of cospherical points such as a regular grid contains, and tet faces lying wholly on the level
    (three nodes exactly at ``level``). Triangles are oriented along the gradient of ``values``. ``report=True`` returns
    ``(V, F, report)`` with :func:`gsdf.mesh.topology.manifold_report`.
    """
    from ._checks import finite

    X = np.asarray(X, float)
    T = np.asarray(T, np.int64)
    s = np.asarray(values, float) - finite(level, "level")
    if not (s.min() < 0 < s.max()):
        raise ValueError(f"level {level} is outside the field's range [{s.min() + level:.6g}, {s.max() + level:.6g}]: no surface")
    # values within round-off of the level are put exactly on it, and a node on the level counts as above it
    # (a symbolic +0 perturbation): crossings at such a node then coincide exactly and are welded below
    s = np.where(np.abs(s) <= 1e-12 * float(np.abs(s).max()), 0.0, s)
    pos = s[T] >= 0
    npos = pos.sum(axis=1)
    tris, tet_of = [], []
    # one vertex apart: lone vertex and the three others
    for k, lone_is_pos in ((1, True), (3, False)):
        sel = npos == k
        if not sel.any():
            continue
        P = pos[sel] if lone_is_pos else ~pos[sel]
        order = np.argsort(~P, axis=1, kind="stable")  # lone vertex first
        Ts = np.take_along_axis(T[sel], order, axis=1)
        a = Ts[:, 0]
        tris.append(np.stack([np.stack([a, Ts[:, 1]], 1), np.stack([a, Ts[:, 2]], 1), np.stack([a, Ts[:, 3]], 1)], 1))
        tet_of.append(np.flatnonzero(sel))
    sel = npos == 2
    if sel.any():
        order = np.argsort(~pos[sel], axis=1, kind="stable")  # two positive first
        Ts = np.take_along_axis(T[sel], order, axis=1)
        a, b, c, d = Ts.T
        e_ac, e_ad, e_bd, e_bc = (np.stack(p, 1) for p in ((a, c), (a, d), (b, d), (b, c)))
        tris.append(np.stack([e_ac, e_ad, e_bd], 1))
        tris.append(np.stack([e_ac, e_bd, e_bc], 1))
        tet_of += [np.flatnonzero(sel)] * 2
    E = np.concatenate(tris)  # (k, 3 corners, 2 endpoints)
    tet_of = np.concatenate(tet_of)
    Es = np.sort(E.reshape(-1, 2), axis=1)
    uniq, inv = np.unique(Es, axis=0, return_inverse=True)
    sa, sb = s[uniq[:, 0]], s[uniq[:, 1]]
    t = sa / (sa - sb)
    V = X[uniq[:, 0]] + t[:, None] * (X[uniq[:, 1]] - X[uniq[:, 0]])
    V[t == 1.0] = X[uniq[t == 1.0, 1]]  # a crossing at a node is that node, bitwise (so it welds)
    F = inv.reshape(-1, 3)
    # orient along the gradient of the linear interpolant of each triangle's tet
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    Tt = T[tet_of]
    M = X[Tt[:, 1:]] - X[Tt[:, :1]]  # (k, 3, 3) rows p_i - p_0
    ds = s[Tt[:, 1:]] - s[Tt[:, :1]]
    ok = np.abs(np.linalg.det(M)) > 0
    up = np.zeros_like(n)
    up[ok] = np.linalg.solve(M[ok], ds[ok][:, :, None])[:, :, 0]
    flip = (n * up).sum(axis=1) < 0
    F[flip] = F[flip][:, [0, 2, 1]]
    keep = np.linalg.norm(n, axis=1) > 0
    from .mesh.topology import manifold_report, split_nonmanifold_vertices, weld

    V, F = weld(V, F[keep].astype(np.int64))
    rep = manifold_report(V, F)
    if not rep["vertex_manifold"]:
        V, F = split_nonmanifold_vertices(V, F)
        rep = manifold_report(V, F)
    return (V, F, rep) if report else (V, F)
