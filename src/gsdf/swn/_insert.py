"""Insert curves given as surface points into a triangle mesh, so that they run along edges (geometry unchanged).

Surface winding numbers need curves made of mesh edges (thesis §6.4; the authors' demo cuts the mesh the same
way). Nodes on edges become new vertices splitting their edge; a segment crossing a face between two of its
edge points / corners becomes a new edge (a chord); every face touched is re-triangulated inside its own plane
(the polygon of its corners and inserted boundary points, split along the chords, then ear-clipped without
zero-area ears). A face-interior node ('f') first splits the face piece containing it into three at the point
(:func:`_split_at_face_points`); the segments from it then cross those pieces like chords. Segments joining two vertices
that share an edge need no insertion. A curve consisting of one edge between two interior endpoints is split
at its midpoint, or the endpoint exclusion of the jump solve would swallow it.

Python loops here run over the faces the curves touch, not over the mesh.

Example
-------
>>> import numpy as np
>>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
>>> from gsdf.io._swn_curves import SWNCurves
>>> c = SWNCurves(np.array(["e", "e"]), np.array([0, 2]), np.array([[.5, 0, 0], [.5, 0, 0]]),
...               np.array([[0, 1], [2, 0]]), np.array([[0, 1]]))
>>> V2, F2, segs, parent = insert_curves(V, np.array([[0, 1, 2]]), c)
>>> len(V2), len(F2), segs.tolist()
(5, 3, [[3, 4]])
"""

from __future__ import annotations

import numpy as np

from gsdf.mesh._connectivity import MeshTopology

__all__ = ["insert_curves", "insert_surface_points", "polylines_to_curves", "surface_points_to_curves"]

SNAP = 1e-9


def polylines_to_curves(polylines):
    """Vertex polylines -> :class:`gsdf.io._swn_curves.SWNCurves` (all nodes on vertices)."""
    from gsdf.io._swn_curves import SWNCurves

    kinds, index, segs = [], [], []
    for ci, pl in enumerate(polylines):
        P = np.asarray(pl)
        if P.dtype == bool or not np.issubdtype(P.dtype, np.integer) or P.ndim != 1 or len(P) < 2:
            raise ValueError(f"curves[{ci}]: expected an integer vertex polyline of at least 2 vertices")
        base = len(index)
        index += P.tolist()
        segs += [(base + k, base + k + 1) for k in range(len(P) - 1)]
    k = len(index)
    return SWNCurves(np.array(["v"] * k), np.array(index, dtype=np.int64), np.zeros((k, 3)),
                     np.full((k, 2), -1, dtype=np.int64), np.array(segs, dtype=np.int64).reshape(-1, 2))


def surface_points_to_curves(curves, F):
    """Curves as :class:`gsdf.Curve` objects, lists of ``(face, barycentric (3,))`` surface points (the
    signed heat method's spelling; ``(vertex, ())`` is a vertex) or vertex polylines -> :class:`SWNCurves`
    (face nodes, vertex nodes; consecutive nodes of a curve joined by a segment). ValueError names the curve
    and point that is not a valid surface point of the faces ``F`` (m, 3)."""
    from gsdf.curves import Curve
    from gsdf.io._swn_curves import SWNCurves

    F = np.asarray(F)
    m = len(F)
    kinds, index, params, segs = [], [], [], []
    if isinstance(curves, Curve):
        curves = [curves]
    if not isinstance(curves, (list, tuple)) or len(curves) == 0:
        raise ValueError("curves: expected a non-empty list of curves")
    for ci, c in enumerate(curves):
        c = c if isinstance(c, Curve) else Curve(c, name=f"curves[{ci}]")
        if not c.signed:
            raise ValueError(f"curves[{ci}]: surface winding numbers need oriented curves (signed=True)")
        if c.kind == "edges":
            paths = [[(int(v), np.zeros(0)) for v in pl] for pl in c.polylines()]
        elif c.kind == "vertices":
            paths = [[(int(v), np.zeros(0)) for v in c.nodes]]
        else:
            paths = [c.nodes]
        for path in paths:
            base = len(kinds)
            for q, (e, b) in enumerate(path):
                if b.size == 0:
                    kinds.append("v"), index.append(e), params.append((0.0, 0.0, 0.0))
                    continue
                if b.size != 3 or not 0 <= e < m:
                    raise ValueError(f"curves[{ci}][{q}]: expected (face index < {m}, barycentric (3,)), "
                                     f"got ({e}, {b.tolist()})")
                kinds.append("f"), index.append(e), params.append(tuple(b.tolist()))
            segs += [(base + k, base + k + 1) for k in range(len(path) - 1)]
    k = len(kinds)
    return SWNCurves(np.array(kinds), np.array(index, dtype=np.int64), np.array(params, dtype=np.float64).reshape(k, 3),
                     np.full((k, 2), -1, dtype=np.int64), np.array(segs, dtype=np.int64).reshape(-1, 2))


def insert_surface_points(V, F, curves):
    """Cut the mesh along curves given as surface points (geometry unchanged), so that surface winding
    numbers can be solved on it: :func:`insert_curves` of :func:`surface_points_to_curves`.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles.
    curves : list of lists of (face, barycentric (3,))
        Curves as surface points; consecutive points must share a face (a curve crossing an edge has a point
        on it, as :func:`gsdf.level_set_curves` makes them).

    Returns
    -------
    V2 : (n2, 3) float64
        The input vertices, then the points inserted.
    F2 : (m2, 3) int64
        The cut triangles (the same surface).
    segments : (s, 2) int64
        The curves as vertex pairs of ``V2`` along edges of ``F2``, in the input's orientation.
    parent : (m2,) int64
        The input face each cut triangle lies in.

    Raises
    ------
    ValueError
        Points outside their faces, consecutive points without a common face.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> from gsdf.swn import insert_surface_points
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]); F = np.array([[0, 1, 2], [1, 3, 2]])
    >>> curve = [(0, [0.6, 0.2, 0.2]), (0, [0.0, 0.5, 0.5]), (1, [0.2, 0.6, 0.2])]   # crosses edge 1-2 at its middle
    >>> V2, F2, segs, parent = insert_surface_points(V, F, [curve])
    >>> len(V2), len(segs)
    (7, 2)
    >>> res = gsdf.SurfaceWindingNumbers(V2, F2).solve(list(segs))      # the curves' regions, on the cut mesh
    """
    return insert_curves(V, F, surface_points_to_curves(curves, F))


def _area(poly, X) -> float:
    P = X[poly]
    P = P - P[0]  # local coordinates: the round-off is that of the polygon's size, not of its position
    return 0.5 * float(np.linalg.norm(np.cross(P, np.roll(P, -1, axis=0)).sum(axis=0)))


def _ear_clip(poly, X):
    """Triangulate a convex planar polygon (vertex ids in boundary order, possibly with collinear runs of
    inserted points): repeatedly cut off the largest non-degenerate ear whose removal leaves a polygon of
    nonzero area, so no zero-area triangle is made. "Zero" is below 1e-12 of the polygon's area or below the
    area the rounding of its vertices' coordinates can make (an inserted midpoint is off the line of its edge
    by up to an ulp of the coordinates: far from the origin that exceeds 1e-12 of a thin face's area)."""
    poly = list(poly)
    tris = []
    P = X[poly]
    diam = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
    tol = max(1e-12 * _area(poly, X), 64 * np.finfo(float).eps * float(np.abs(P).max()) * diam, 1e-300)
    while len(poly) > 3:
        k = len(poly)
        best, best_a = None, tol
        for i in range(k):
            a, b, c = poly[i - 1], poly[i], poly[(i + 1) % k]
            ar = 0.5 * np.linalg.norm(np.cross(X[b] - X[a], X[c] - X[a]))
            if ar > best_a and _area(poly[:i] + poly[i + 1:], X) > tol:
                best, best_a = i, ar
        if best is None:
            raise ValueError("curves: cannot re-triangulate a face around the inserted points (degenerate)")
        i = best
        tris.append((poly[i - 1], poly[i], poly[(i + 1) % k]))
        poly.pop(i)
    tris.append(tuple(poly))
    return tris


def insert_curves(V, F, curves):
    """Insert the nodes and segments of ``curves`` into the mesh (V, F).

    Parameters
    ----------
    V : (n, 3) float, F : (m, 3) int — a manifold, consistently oriented triangle mesh
    curves : SWNCurves (from :func:`gsdf.io._swn_curves.read_swn_curves` or :func:`polylines_to_curves`)

    Returns
    -------
    V2 : (n2, 3) the original vertices followed by the inserted ones
    F2 : (m2, 3) faces (untouched faces first, in their original order, then the re-triangulated ones)
    segments : (s, 2) vertex pairs of V2 along edges of F2, in the input's orientation
    parent : (m2,) the original face of every new face
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    topo = MeshTopology(F, len(V))
    topo.require_manifold("F")
    topo.require_oriented("F")
    parent0 = None
    if np.any(curves.kinds == "f"):
        V, F, curves, parent0 = _split_at_face_points(V, F, curves)
        topo = MeshTopology(F, len(V))
    cut = _Cut(V, F, topo)
    X, node_vertex = cut.node_vertices(curves)
    X, vseg = cut.split_lone_segments(X, node_vertex[np.asarray(curves.segments, dtype=np.int64)])
    chords, out_segs = cut.route(vseg)
    F2, par = cut.retriangulate(X, chords)
    if parent0 is not None:
        par = parent0[par]
    S = np.array(out_segs, dtype=np.int64).reshape(-1, 2)
    return X, F2, S, par


class _Cut:
    """The mesh being cut: its edges, the points inserted on them (``edge_points``: edge -> [(s along the
    canonical lo -> hi direction, vertex)]), and the steps of :func:`insert_curves`."""

    def __init__(self, V, F, topo):
        self.V, self.F, self.topo = V, F, topo
        self.n = len(V)
        self.E = topo.edges
        self.ekey = self.E[:, 0] * self.n + self.E[:, 1]
        self.edge_points: dict[int, list] = {}
        self.vertex_edge: dict[int, int] = {}

    def edge_id(self, a, b):
        n, ekey = self.n, self.ekey
        lo, hi = min(a, b), max(a, b)
        e = int(np.searchsorted(ekey, lo * n + hi))
        return e if e < len(ekey) and ekey[e] == lo * n + hi else -1

    def node_vertices(self, curves):
        """The vertex of every node (inserting the edge points, one per distinct position): (X, (k,) int)."""
        V, E, n = self.V, self.E, self.n
        kinds, index, params, ev = curves.kinds, curves.index, curves.params, curves.edge_vertices
        newV = [V]
        nv = n
        node_vertex = np.full(len(kinds), -1, dtype=np.int64)
        point_key: dict = {}
        for k in range(len(kinds)):
            if kinds[k] == "v":
                if not 0 <= index[k] < n:
                    raise ValueError(f"curves: node {k} names vertex {index[k]}, out of range for {n} vertices")
                node_vertex[k] = index[k]
                continue
            a, b = int(ev[k, 0]), int(ev[k, 1])
            t = float(params[k, 0])
            if t <= SNAP:
                node_vertex[k] = a
                continue
            if t >= 1 - SNAP:
                node_vertex[k] = b
                continue
            e = self.edge_id(a, b)
            if e < 0:
                raise ValueError(f"curves: node {k} lies on ({a}, {b}), which is not an edge of the mesh")
            s = t if a < b else 1 - t
            key = (e, round(s, 12))
            if key in point_key:
                node_vertex[k] = point_key[key]
            else:
                lo, hi = E[e]
                newV.append(((1 - s) * V[lo] + s * V[hi])[None])
                point_key[key] = nv
                self.edge_points.setdefault(e, []).append((s, nv))
                node_vertex[k] = nv
                nv += 1
        return np.concatenate(newV), node_vertex

    def split_lone_segments(self, X, segs):
        """A lone segment between two vertices sharing an edge, both ends free (interior endpoints of nothing
        else), is split at its midpoint. ``segs`` (s, 2) vertex pairs; returns (X, vertex pairs as a list)."""
        V, E, n, topo = self.V, self.E, self.n, self.topo
        nv = len(X)
        deg = np.bincount(segs.ravel(), minlength=nv)
        extra = []
        for si, (a, b) in enumerate(segs):
            a, b = int(a), int(b)
            if a < n and b < n and deg[a] == 1 and deg[b] == 1 and not topo.boundary_vertices[a] \
                    and not topo.boundary_vertices[b]:
                e = self.edge_id(a, b)
                if e >= 0:
                    lo, hi = E[e]
                    X = np.concatenate([X, (0.5 * (V[lo] + V[hi]))[None]])
                    self.edge_points.setdefault(e, []).append((0.5, nv))
                    extra.append((si, nv))
                    nv += 1
        vseg = [(int(a), int(b)) for a, b in segs]
        for si, mid in extra[::-1]:
            a, b = vseg[si]
            vseg[si:si + 1] = [(a, mid), (mid, b)]
        for e, pts in self.edge_points.items():
            for _, v in pts:
                self.vertex_edge[v] = e
        return X, vseg

    def faces_of(self, v):
        """The faces around a point: a vertex's faces, or the two faces of a split edge."""
        if v < self.n:
            if not hasattr(self, "_vf"):
                F = self.F
                self._vf = (np.argsort(F.ravel(), kind="stable"),
                            np.concatenate([[0], np.cumsum(np.bincount(F.ravel(), minlength=self.n))]))
            vf_ptr, starts = self._vf
            return set((vf_ptr[starts[v]:starts[v + 1]] // 3).tolist())
        e = self.vertex_edge[v]
        return {int(f) for f in self.topo.edge_faces[e] if f >= 0}

    def on_edge(self, v, e):
        if v < self.n:
            return v in (self.E[e, 0], self.E[e, 1])
        return self.vertex_edge[v] == e

    def along(self, e, a, b):
        """Vertices from a to b along split edge e (both on it)."""
        lo, hi = self.E[e]
        pts = sorted([(0.0, int(lo)), (1.0, int(hi))] + self.edge_points.get(e, []))
        ids = [v for _, v in pts]
        i, j = ids.index(a), ids.index(b)
        return ids[i:j + 1] if i <= j else ids[j:i + 1][::-1]

    def route(self, vseg):
        """Every segment along a (possibly split) edge, or across a face as a chord: (chords per face, the
        output segments)."""
        n = self.n
        chords: dict[int, list] = {}
        out_segs = []
        for si, (a, b) in enumerate(vseg):
            if a == b:
                continue
            cand = []
            if a < n and b < n:
                e = self.edge_id(a, b)
                if e >= 0:
                    cand = [e]
            elif a >= n and self.on_edge(b, self.vertex_edge[a]):
                cand = [self.vertex_edge[a]]
            elif b >= n and self.on_edge(a, self.vertex_edge[b]):
                cand = [self.vertex_edge[b]]
            if cand:
                path = self.along(cand[0], a, b)
                out_segs += list(zip(path[:-1], path[1:]))
                continue
            common = self.faces_of(a) & self.faces_of(b)
            if not common:
                raise ValueError(f"curves: segment {si} joins points that share no face (vertices {a}, {b} of the "
                                 "cut mesh): the curve is not connected where it claims to be")
            f = min(common)
            chords.setdefault(f, []).append((a, b))
            out_segs.append((a, b))
        return chords, out_segs

    def retriangulate(self, X, chords):
        """Every face touched (by a chord or a split edge) re-triangulated in its own plane: the polygon of its
        corners and inserted points, split along its chords, ear-clipped. Returns (F2, parent)."""
        F, topo = self.F, self.topo
        touched = set(chords)
        for e in self.edge_points:
            touched |= {int(f) for f in topo.edge_faces[e] if f >= 0}
        keep = np.ones(len(F), dtype=bool)
        newF, parent = [], []
        for f in sorted(touched):
            keep[f] = False
            poly = []
            for k in range(3):
                a, b = int(F[f, k]), int(F[f, (k + 1) % 3])
                poly += self.along(topo.face_edges[f, k], a, b)[:-1]
            polys = [poly]
            for a, b in chords.get(f, []):
                for pi, P in enumerate(polys):
                    if a in P and b in P:
                        i, j = sorted((P.index(a), P.index(b)))
                        if j - i in (1, len(P) - 1):
                            break                                 # already a side
                        polys[pi:pi + 1] = [P[i:j + 1], P[j:] + P[:i + 1]]
                        break
                else:
                    raise ValueError(f"curves: two curve segments cross inside face {f}; insert their crossing "
                                     "point")
            for P in polys:
                for tri in _ear_clip(P, X):
                    newF.append(tri)
                    parent.append(f)
        F2 = np.concatenate([F[keep], np.array(newF, dtype=np.int64).reshape(-1, 3)])
        par = np.concatenate([np.flatnonzero(keep), np.array(parent, dtype=np.int64)])
        return F2, par


def _split_at_face_points(V, F, curves):
    """Make every face-interior node ('f': face i, barycentric (a, b, c) of its corners F[i]) a vertex: the
    triangle of the current mesh containing it (a piece of face i, all pieces lie in face i's plane) is split
    into three at the point, geometry unchanged. Nodes with a barycentric coordinate ≈ 1 become vertex nodes,
    with one ≈ 0 edge nodes (the segments from them are then inserted as for 'e' nodes). Returns
    (V2, F2, curves with the interior nodes as 'v' nodes, parent (m2,) original face of every face)."""
    from gsdf.io._swn_curves import SWNCurves

    m = len(F)
    kinds = np.array(curves.kinds, dtype=object).copy()
    index = np.asarray(curves.index, dtype=np.int64).copy()
    params = np.asarray(curves.params, dtype=np.float64).copy()
    ev = np.asarray(curves.edge_vertices, dtype=np.int64).copy()
    Vl, Fl, parent = [V], [row for row in F.tolist()], list(range(m))
    pieces: dict[int, list] = {}                                # original face -> indices into Fl
    seen: dict = {}
    nv = len(V)
    for k in np.flatnonzero(kinds == "f"):
        f = int(index[k])
        if not 0 <= f < m:
            raise ValueError(f"curves: node {k} names face {f}, out of range for {m} faces")
        b = params[k]
        if not np.isfinite(b).all() or b.min() < -1e-9 or abs(b.sum() - 1) > 1e-6:
            raise ValueError(f"curves: node {k}: barycentric coordinates {b.tolist()} are not in face {f}")
        b = np.clip(b, 0.0, None) / np.clip(b, 0.0, None).sum()
        c = F[f]
        big = b > 1 - SNAP
        if big.any():                                          # at a corner
            kinds[k], index[k], params[k] = "v", int(c[np.argmax(b)]), 0.0
            continue
        small = b < SNAP
        if small.any():                                        # on a side: an edge node from corner i to j
            z = int(np.argmax(small))
            i, j = c[(z + 1) % 3], c[(z + 2) % 3]
            kinds[k], ev[k] = "e", (int(i), int(j))
            params[k] = (b[(z + 2) % 3], 0.0, 0.0)             # t from i towards j
            continue
        key = (f, *np.round(b, 12))
        if key in seen:
            kinds[k], index[k], params[k] = "v", seen[key], 0.0
            continue
        P = b @ V[c]
        # the piece of face f containing P (barycentric coordinates in the piece's own plane)
        best, best_min = None, -np.inf
        for pi in pieces.get(f, [f]):
            T = np.concatenate(Vl)[Fl[pi]]
            e1, e2, r = T[1] - T[0], T[2] - T[0], P - T[0]
            G = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
            y, z2 = np.linalg.solve(G, [r @ e1, r @ e2])
            lam = np.array([1 - y - z2, y, z2])
            if lam.min() > best_min:
                best, best_min, best_lam = pi, lam.min(), lam
        if best_min < SNAP:
            raise ValueError(f"curves: node {k} (face {f}) lies on a segment between other interior nodes of the "
                             "face; give it as a vertex or edge node instead")
        a0, a1, a2 = Fl[best]
        Vl.append(P[None])
        p = nv
        nv += 1
        Fl[best] = [a0, a1, p]
        Fl += [[a1, a2, p], [a2, a0, p]]
        parent += [f, f]
        pieces.setdefault(f, [f]).extend([len(Fl) - 2, len(Fl) - 1])
        seen[key] = p
        kinds[k], index[k], params[k] = "v", p, 0.0
    out = SWNCurves(np.array(kinds.tolist()), index, params, ev, np.asarray(curves.segments, dtype=np.int64))
    return np.concatenate(Vl), np.array(Fl, dtype=np.int64), out, np.array(parent, dtype=np.int64)
