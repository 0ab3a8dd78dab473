"""Source geometry of the signed heat method on triangle meshes (Feng & Crane 2024, §5.6 and App. A).

Sign convention: the normal of an oriented curve is its tangent turned 90° *clockwise* in the face (the
paper and potpourri3d turn it counter-clockwise), so that C φ = b (∇φ ≈ Y) makes the region to the *left* of
the curve — the region a counter-clockwise curve encloses — negative ("negative inside"), while point sources
and unoriented curves (whose normals point away from the source) still give positive distance. Compared with
potpourri3d: gsdf's result for curves C is potpourri3d's for C reversed (with signed curves alone, the negative
of potpourri3d's; not with signed curves and points together).

Curves arrive as :class:`gsdf.Curve` (type-checked by :func:`gsdf.curves.as_curves`); :func:`parse_curves` checks
them against the mesh and :func:`assemble` turns them, with the point sources of :func:`parse_points`, into the
one :class:`~gsdf.heat._sources.Sources` of the core:

* vertex polylines (and edge sets, chained into polylines) run along mesh edges;
* surface points ``(face_index, barycentric (3,))`` (``(vertex_index, ())`` is also accepted, the potpourri3d
  spelling of a vertex). Consecutive points normally share a face (or lie on one edge); a segment whose end
  points share no face is split where it crosses mesh edges: it is traced face by face, heading in each face for
  the end point projected into the face's plane (exactly the straight segment on planar regions, an
  approximation of it on curved ones).

Every node becomes a row of a sparse interpolation matrix (nodes × |V|), which serves the level-set
constraints (§7.1, Eq. 14) and the shift of Alg. 13.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from gsdf.heat._sources import Sources
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.mesh._triangle_ops import NEXT

BARY_TOL = 1e-6


class CurvePart(NamedTuple):
    """One source curve parsed on a triangle mesh: a vertex polyline (``vertices``) or surface points (``faces``,
    ``bary``), with its sign, its ``curve_normals`` entry and the name errors use (``curves[k]``, k the index
    of the :class:`~gsdf.curves.Curve` it comes from; an edge set gives one part per chained polyline)."""

    vertices: np.ndarray | None
    faces: np.ndarray | None
    bary: np.ndarray | None
    signed: bool
    normals: object
    index: int

    @property
    def name(self) -> str:
        return f"curves[{self.index}]"


class PointSources(NamedTuple):
    """Isolated point sources parsed on a triangle mesh: per point the three vertices ``ids`` (p, 3) and weights
    ``w`` (p, 3) of its interpolation row, and the face it was given in (-1 for a vertex index)."""

    ids: np.ndarray
    w: np.ndarray
    faces: np.ndarray


# ---------------------------------------------------------------------------------------------- parsing
def surface_points(ops: TriangleMeshOperators, nodes, name: str):
    """Typed ``(face, barycentric)`` pairs (:class:`~gsdf.curves.Curve` nodes) checked against the mesh:
    ``(vertex, ())`` is a vertex (as a corner of its first face), face indices in range, three finite
    coordinates summing to 1 (tolerance ``BARY_TOL``), none below ``-BARY_TOL``; clipped at 0 and renormalized.
    Returns ``(faces (q,), bary (q, 3))``."""
    n, m = ops.n_vertices, ops.n_faces
    faces = np.empty(len(nodes), np.int64)
    bary = np.zeros((len(nodes), 3))
    vf = ops.vertex_faces()
    for q, (e, b) in enumerate(nodes):
        if b.size == 0:                                       # potpourri3d spelling of a vertex: (v, [])
            if not 0 <= e < n:
                raise ValueError(f"{name}[{q}]: vertex index {e} out of range for {n} vertices")
            row = vf.indptr[e]
            if vf.indptr[e + 1] == row:
                raise ValueError(f"{name}[{q}]: vertex {e} belongs to no face")
            faces[q] = vf.indices[row]
            bary[q, vf.data[row] - 1] = 1.0
            continue
        if b.size != 3:
            raise ValueError(f"{name}[{q}]: barycentric coordinates must have 3 entries, got {b.size}")
        if not 0 <= e < m:
            raise ValueError(f"{name}[{q}]: face index {e} out of range for {m} faces")
        if not np.isfinite(b).all():
            raise ValueError(f"{name}[{q}]: barycentric coordinates are not finite: {b}")
        if abs(b.sum() - 1.0) > BARY_TOL:
            raise ValueError(f"{name}[{q}]: barycentric coordinates {b} do not sum to 1 (sum {b.sum():.9g})")
        if b.min() < -BARY_TOL:
            raise ValueError(f"{name}[{q}]: negative barycentric coordinate in {b} (point outside face {e})")
        b = np.clip(b, 0.0, None)
        b[b < 1e-12] = 0.0
        faces[q], bary[q] = e, b / b.sum()
    return faces, bary


def _vertex_range(a: np.ndarray, n: int, name: str) -> np.ndarray:
    if a.min() < 0 or a.max() >= n:
        bad = int(a[(a < 0) | (a >= n)][0])
        raise ValueError(f"{name}: vertex index {bad} out of range for {n} vertices")
    return a


def parse_curves(ops: TriangleMeshOperators, curves, curve_normals=None) -> list:
    """:class:`~gsdf.curves.Curve` objects (already type-checked) as :class:`CurvePart` on the mesh ``ops``: vertex
    indices in range, surface points checked (:func:`surface_points`), edge sets chained into polylines.
    ``curve_normals``: one entry per curve (or one (3,) vector for all), see :func:`assemble`."""
    normals = per_curve_normals(curve_normals, len(curves))
    parts = []
    for k, c in enumerate(curves):
        nk = None if normals is None else normals[k]
        if c.kind == "points":
            f, b = surface_points(ops, c.nodes, f"curves[{k}]")
            parts.append(CurvePart(None, f, b, c.signed, nk, k))
            continue
        if c.kind == "edges" and nk is not None and np.asarray(nk).shape != (3,):
            raise ValueError(f"curve_normals[{k}]: an edge-set curve takes one (3,) normal")
        for p in c.polylines():
            parts.append(CurvePart(_vertex_range(p, ops.n_vertices, f"curves[{k}]"), None, None, c.signed, nk, k))
    return parts


def parse_points(ops: TriangleMeshOperators, points) -> PointSources | None:
    """Point sources (:func:`gsdf.curves.as_point_sources`: vertex indices or ``(face, barycentric)`` pairs) on
    the mesh ``ops``; None when there are none."""
    if not points:
        return None
    n = ops.n_vertices
    ids = np.zeros((len(points), 3), np.int64)
    w = np.zeros((len(points), 3))
    faces = np.full(len(points), -1, np.int64)
    for q, it in enumerate(points):
        if isinstance(it, (int, np.integer)):
            if not 0 <= it < n:
                raise ValueError(f"points[{q}]: vertex index {it!r} out of range for {n} vertices")
            ids[q] = it
            w[q, 0] = 1.0
            continue
        f, b = surface_points(ops, [it], f"points[{q}]")
        ids[q] = ops.F[f[0]]
        w[q] = b[0]
        faces[q] = f[0]
    return PointSources(ids, w, faces)


# ---------------------------------------------------------------------------------------------- segments
def _faces_of_node(ops, f, b):
    """Faces containing a surface point given by (face, bary): all faces of its vertex / edge, or {f}."""
    nz = np.flatnonzero(b > 0)
    verts = ops.F[f, nz]
    vf = ops.vertex_faces()
    cand = None
    for v in verts:
        s = set(vf.indices[vf.indptr[v]:vf.indptr[v + 1]].tolist())
        cand = s if cand is None else cand & s
    return cand


def _bary_in_face(ops, p, f):
    """Barycentric coordinates of 3D point p with respect to face f (least squares, clipped)."""
    P = ops.V[ops.F[f]]
    T = np.stack([P[1] - P[0], P[2] - P[0]], axis=1)
    uv = np.linalg.lstsq(T, p - P[0], rcond=None)[0]
    b = np.array([1 - uv.sum(), uv[0], uv[1]])
    b[np.abs(b) < 1e-12] = 0.0
    b = np.clip(b, 0, None)
    return b / b.sum()


def _trace(ops, fa, ba, fb, bb, name):
    """Split the straight segment from (fa, ba) to (fb, bb) where it crosses edges: walk face by face, in each
    face heading for the target projected into the face's plane. Returns the crossing points (faces, bary)."""
    if ops.intrinsic:
        raise ValueError(f"{name}: consecutive points of a curve on an intrinsic triangulation must share a face")
    V, F = ops.V, ops.F
    target = bb @ V[F[fb]]
    target_faces = _faces_of_node(ops, fb, bb)
    f, b = fa, ba
    out_f, out_b = [], []
    for _ in range(4 * int(np.sqrt(ops.n_faces)) + 50):
        cand = _faces_of_node(ops, f, b)
        if cand & target_faces:
            return out_f, out_b
        p = b @ V[F[f]]
        best = (0.0, -1, -1, None)
        for g in cand:                                        # the face the ray runs through: longest chord
            n = ops.normals[g]
            d = target - p
            d = d - n * (d @ n)
            P = V[F[g]]
            for a in range(3):
                q0, q1 = P[a], P[NEXT[a]]
                M = np.stack([d, q0 - q1], axis=1)
                (t, s), *_ = np.linalg.lstsq(M, q0 - p, rcond=None)
                if -1e-9 <= s <= 1 + 1e-9 and t > 1e-9 and t * np.linalg.norm(d) > best[0] + 1e-12 * ops.h:
                    # the exit is the nearest crossing ahead in this face; keep the face whose exit is farthest
                    others = []
                    for a2 in range(3):
                        if a2 == a:
                            continue
                        M2 = np.stack([d, P[a2] - P[NEXT[a2]]], axis=1)
                        (t2, s2), *_ = np.linalg.lstsq(M2, P[a2] - p, rcond=None)
                        if -1e-9 <= s2 <= 1 + 1e-9 and 1e-9 < t2 < t - 1e-9:
                            others.append(t2)
                    if not others:
                        best = (t * np.linalg.norm(d), g, a, np.clip(s, 0, 1))
        if best[1] < 0:
            break
        _, g, a, s = best
        nb = np.zeros(3)
        nb[a], nb[NEXT[a]] = 1 - s, s
        nb[nb < 1e-12] = 0.0
        nb /= nb.sum()
        out_f.append(g)
        out_b.append(nb)
        f, b = g, nb
    raise ValueError(f"{name}: could not trace the segment to face {fb} across the mesh (consecutive points "
                     "must share a face, or be joined by a straight path across edges)")


def _bary_curve_segments(ops, faces, bary, name, return_faces=False):
    """Split a barycentric curve into face segments and edge segments (python over nodes; cheap)."""
    F = ops.F
    nodes_f, nodes_b = [faces[0]], [bary[0]]
    for q in range(1, len(faces)):
        fa, ba, fb, bb = nodes_f[-1], nodes_b[-1], faces[q], bary[q]
        if fa != fb:
            common = _faces_of_node(ops, fa, ba) & _faces_of_node(ops, fb, bb)
            if not common:
                tf, tb = _trace(ops, fa, ba, fb, bb, f"{name}[{q}]")
                nodes_f += tf
                nodes_b += tb
        nodes_f.append(fb)
        nodes_b.append(bb)
    if return_faces:
        return [int(f) for f in nodes_f], nodes_b, None, None, None
    # express consecutive pairs in a shared face; segment vectors from the face's corner positions ops.P (3D for
    # an input mesh, a planar layout for an intrinsic triangulation)
    nq = len(nodes_f)
    L = np.zeros(max(nq - 1, 0))
    seg_face, seg_edge = [], []
    for q in range(nq - 1):
        fa, ba, fb, bb = nodes_f[q], nodes_b[q], nodes_f[q + 1], nodes_b[q + 1]
        common = _faces_of_node(ops, fa, ba) & _faces_of_node(ops, fb, bb)
        if not common:
            raise ValueError(f"{name}: points {q} and {q + 1} share no face")
        g = min(common)
        wa, wb = _to_face(F, fa, ba, g), _to_face(F, fb, bb, g)
        D = (wb - wa) @ ops.P[g]
        ln = float(np.linalg.norm(D))
        L[q] = ln
        if ln == 0:
            continue
        va = set(F[fa, ba > 0].tolist())
        vb = set(F[fb, bb > 0].tolist())
        both = va | vb
        if len(both) == 2 and len(va) <= 2 and len(vb) <= 2:
            i, j = sorted(both)
            e = int(ops.edge_lookup(i, j))
            if e >= 0:
                ci, cj = int(np.flatnonzero(F[g] == i)[0]), int(np.flatnonzero(F[g] == j)[0])
                s = 1.0 if D @ (ops.P[g, cj] - ops.P[g, ci]) > 0 else -1.0
                seg_edge.append((e, s, ln))
                continue
        seg_face.append((g, D, 0.5 * (wa + wb)))
    ids = F[np.array(nodes_f)]
    w = np.array(nodes_b)
    return ids, w, L, seg_face, seg_edge


def _to_face(F, f, b, g):
    """Barycentric coordinates, in face g, of the point with barycentric b in face f (its support must be
    vertices of g)."""
    out = np.zeros(3)
    for c in np.flatnonzero(b > 0):
        hit = np.flatnonzero(F[g] == F[f, c])
        out[hit[0]] += b[c]
    return out


# ---------------------------------------------------------------------------------------------- X0
def per_curve_normals(curve_normals, n_curves: int):
    """``curve_normals`` as a list with one entry per curve (None stays None): one (3,) vector is used for
    every curve; a list must have ``n_curves`` entries (ValueError otherwise)."""
    from gsdf._checks import as_values

    if curve_normals is None:
        return None
    if isinstance(curve_normals, np.ndarray) and curve_normals.shape == (3,):
        return [as_values(curve_normals, "curve_normals")] * n_curves
    if isinstance(curve_normals, (str, bytes)) or not isinstance(curve_normals, (list, tuple, np.ndarray)):
        raise ValueError(f"curve_normals: expected a list with one entry per curve, got "
                         f"{type(curve_normals).__name__}")
    curve_normals = list(curve_normals)
    if len(curve_normals) != n_curves:
        raise ValueError(f"curve_normals: has {len(curve_normals)} entries but there are {n_curves} curves")
    # every entry real and finite (None: the face normals); shapes are checked per curve part
    return [None if c is None else as_values(c, f"curve_normals[{k}]") for k, c in enumerate(curve_normals)]


def _parse_normals(part: CurvePart, n_nodes: int):
    """Normals of a curve part: None, or unit (n_nodes, 3) per node (a single (3,) vector is broadcast)."""
    if part.normals is None:
        return None
    name = f"curve_normals[{part.index}]"
    a = np.asarray(part.normals, dtype=np.float64)
    if a.shape == (3,):
        a = np.broadcast_to(a, (n_nodes, 3))
    if a.shape != (n_nodes, 3):
        raise ValueError(f"{name}: expected a (3,) vector or one per curve point ({n_nodes}, 3), "
                         f"got shape {a.shape}")
    nrm = np.linalg.norm(a, axis=1)
    if not np.isfinite(a).all() or np.any(nrm == 0):
        raise ValueError(f"{name}: normals must be finite and nonzero")
    return a / nrm[:, None]


def _edge_vectors_to_basis(ops, e, N):
    """Complex edge-basis coordinates of 3D vectors N (k, 3) at edges e (k,), in the basis of the first face of
    each edge, the edge's reference basis (see ``TriangleMeshOperators.slot_sigma``)."""
    first = ops.edge_ref_slot[e]
    f, a = first // 3, first % 3
    return np.einsum("kj,kj->k", ops.slot_u[f, a], N) + 1j * np.einsum("kj,kj->k", ops.slot_w[f, a], N)


def _signed_vertex_polylines(ops, parts):
    """The per-curve source data of signed vertex polylines with face normals, for all curves at once (the
    loop of :func:`assemble` costs tens of µs per curve; scans with many holes give hundreds of loops).
    Same values, in the same order, as the loop. None unless every curve is such a polyline."""
    if not parts or any(p.vertices is None or not p.signed or p.normals is not None for p in parts):
        return None
    vs_list = [p.vertices for p in parts]
    lens = np.fromiter(map(len, vs_list), np.int64, count=len(vs_list))
    vs = np.concatenate(vs_list)
    start = np.concatenate([[0], np.cumsum(lens)[:-1]])
    inner = np.ones(len(vs) - 1, bool)                          # pairs (vs[i], vs[i+1]) inside one curve
    inner[(start + lens - 1)[:-1]] = False
    a_all, b_all = vs[:-1][inner], vs[1:][inner]
    e_all = ops.edge_lookup(a_all, b_all)
    same = a_all == b_all
    if np.any((e_all < 0) & ~same):
        return None                                             # the loop raises the error naming the curve
    keep = ~same
    pair_curve = np.repeat(np.arange(len(lens)), lens - 1)
    a, b, e = a_all[keep], b_all[keep], e_all[keep]
    ln = ops.edge_len[e]
    val = -1j * np.where(a < b, 1.0, -1.0) * ln                 # along an edge: N = -i|γ| in the edge basis
    ids = np.repeat(vs[:, None], 3, axis=1)
    w = np.zeros((len(vs), 3))
    w[:, 0] = 1.0
    mw = np.zeros((len(a), 6))
    mw[:, :2] = 0.5
    mid = np.stack([a, b, a, b, a, b], 1)
    node_curve = np.repeat(np.arange(len(lens)), lens)
    return e, val, ids, w, vs.copy(), node_curve, ln, mid, mw


def assemble(ops: TriangleMeshOperators, parts, points=None, batch: bool = True) -> Sources:
    """The :class:`~gsdf.heat._sources.Sources` of curves (:func:`parse_curves`) and points
    (:func:`parse_points`) on the mesh ``ops``: X0 of Eq. 12 per edge (Eq. 11 for signed curves, App. A.1 for
    points, App. A.2 for unsigned curves), the interpolation rows of the curve nodes and points, and the shift
    rows (segment midpoints, weighted by the segment lengths, Alg. 13).

    A part's ``normals`` (None, a (3,) vector, or (k, 3) per curve point) replaces the face normals n in
    N = T × n (Eq. 11) for signed curves, e.g. on nonorientable domains; segment normals are the mean of the
    two end-point normals (for vertex polylines) or the normal of the input point nearest to the segment
    midpoint (for surface-point curves, whose segments may be split). ``batch=False`` takes the per-curve loop
    for signed vertex polylines too (the same values; for tests)."""
    if not parts and points is None:
        raise ValueError("curves: no sources given (empty curve list and no points)")
    n = ops.n_vertices
    X0 = np.zeros(ops.n_edges, np.complex128)
    node_ids, node_w, node_vertex, node_curve = [], [], [], []
    mid_ids, mid_w, seg_len = [], [], []
    face_segs_f, face_segs_N = [], []
    edge_e, edge_val = [], []
    unsigned_edges, unsigned_ends = [], []
    fast = _signed_vertex_polylines(ops, parts) if batch else None
    if fast is not None:
        # every curve is a signed vertex polyline with face normals: all of them at once
        e_all, val_all, ids, w, isv, cur, ln, mid, mw = fast
        edge_e.append(e_all)
        edge_val.append(val_all)
        node_ids, node_w, node_vertex, node_curve = [ids], [w], [isv], [cur]
        mid_ids, mid_w, seg_len = [mid], [mw], [ln]
    for k, part in enumerate(parts if fast is None else ()):
        if part.vertices is not None:
            vs = part.vertices
            e = ops.edge_lookup(vs[:-1], vs[1:])
            same = vs[:-1] == vs[1:]
            if np.any((e < 0) & ~same):
                q = int(np.flatnonzero((e < 0) & ~same)[0])
                raise ValueError(f"{part.name}: vertices {vs[q]} and {vs[q + 1]} (points {q}, {q + 1}) are not "
                                 "joined by a mesh edge; give the curve as (face, barycentric) points instead")
            keep = ~same
            a, b, e = vs[:-1][keep], vs[1:][keep], e[keep]
            ln = ops.edge_len[e]
            nrm = _parse_normals(part, len(vs)) if part.signed else None
            if nrm is not None:
                nseg = (nrm[:-1] + nrm[1:])[keep]
                N = np.cross(ops.V[b] - ops.V[a], nseg / np.linalg.norm(nseg, axis=1, keepdims=True))
                edge_e.append(e)
                edge_val.append(_edge_vectors_to_basis(ops, e, N))
            elif part.signed:
                s = np.where(a < b, 1.0, -1.0)
                edge_e.append(e)
                edge_val.append(-1j * s * ln)                 # along an edge: N = -i|γ| in the edge basis
            else:
                unsigned_edges.append(np.stack([a, b], axis=1))
                if vs[0] != vs[-1]:
                    unsigned_ends.append((vs[0], vs[1], ops.edge_len[e[0]]))
                    unsigned_ends.append((vs[-1], vs[-2], ops.edge_len[e[-1]]))
            ids = np.repeat(vs[:, None], 3, axis=1)
            w = np.zeros((len(vs), 3))
            w[:, 0] = 1.0
            isv = vs.copy()
            mw = np.zeros((len(a), 6))
            mw[:, :2] = 0.5
            mid = np.stack([a, b, a, b, a, b], 1)
        else:
            fs, bs = part.faces, part.bary
            if not part.signed:
                raise ValueError(f"{part.name}: unsigned curves must run along mesh edges (give vertex indices)")
            ids, w, ln, seg_face, seg_edge = _bary_curve_segments(ops, fs, bs, part.name)
            nrm = _parse_normals(part, len(fs))
            if nrm is not None:
                if ops.intrinsic:
                    raise ValueError(f"curve_normals[{part.index}]: not available for surface-point curves on an "
                                     "intrinsic triangulation")
                Pin = np.einsum("kj,kjd->kd", bs, ops.V[ops.F[fs]])

                def seg_normal(mid):
                    return nrm[np.argmin(np.linalg.norm(Pin[None] - mid[:, None], axis=2), axis=1)]
            if seg_face:
                ff = np.array([s[0] for s in seg_face])
                D = np.array([s[1] for s in seg_face])
                face_segs_f.append(ff)
                nf = ops.normals[ff] if nrm is None else seg_normal(
                    np.einsum("kj,kjd->kd", np.array([s[2] for s in seg_face]), ops.V[ops.F[ff]]))
                face_segs_N.append(np.cross(D, nf))                # N|γ| = (pB - pA) × n, Eq. 11
            if seg_edge and nrm is not None:
                ee = np.array([s[0] for s in seg_edge], np.int64)
                i, j = ops.edges[ee, 0], ops.edges[ee, 1]
                sg = np.array([s[1] for s in seg_edge])
                D = (ops.V[j] - ops.V[i]) * (sg * np.array([s[2] for s in seg_edge]) / ops.edge_len[ee])[:, None]
                N = np.cross(D, seg_normal(0.5 * (ops.V[i] + ops.V[j])))
                edge_e.append(ee)
                edge_val.append(_edge_vectors_to_basis(ops, ee, N))
            elif seg_edge:
                edge_e.append(np.array([s[0] for s in seg_edge], np.int64))
                edge_val.append(-1j * np.array([s[1] * s[2] for s in seg_edge]))
            onehot = (w > 0).sum(1) == 1
            isv = np.where(onehot, ids[np.arange(len(ids)), np.argmax(w, 1)], -1)
            mid, mw = np.concatenate([ids[:-1], ids[1:]], 1), 0.5 * np.concatenate([w[:-1], w[1:]], 1)
        node_ids.append(ids)
        node_w.append(w)
        node_vertex.append(isv)
        node_curve.append(np.full(len(ids), k))
        mid_ids.append(mid)
        mid_w.append(mw)
        seg_len.append(ln)
    if edge_e:
        np.add.at(X0, np.concatenate(edge_e), np.concatenate(edge_val))
    if face_segs_f:
        ff = np.concatenate(face_segs_f)
        ee, zz = ops.slot_coords(ff, np.concatenate(face_segs_N))
        np.add.at(X0, ee.ravel(), zz.ravel())
    if unsigned_edges:
        _unsigned_curve_source(ops, np.concatenate(unsigned_edges), unsigned_ends, X0)

    S = Sources(X0=X0)
    if node_ids:
        S.node_rows = _rows(np.concatenate(node_ids), np.concatenate(node_w), n)
        S.node_vertex = np.concatenate(node_vertex).astype(np.int64)
        S.node_curve = np.concatenate(node_curve)
        mids = np.concatenate(mid_ids), np.concatenate(mid_w)
        S.shift_rows = _rows(*mids, n)
        S.shift_weights = np.concatenate(seg_len)
        S.extra["midpoints"] = mids                    # (s, 6) vertices and weights, for the L1 shift (§7.2)
    else:
        S.node_rows = sp.csr_matrix((0, n))
        S.node_vertex = S.node_curve = np.zeros(0, np.int64)
    if points is not None:
        ids, w = points.ids, points.w
        onehot = (w > 0).sum(1) == 1
        S.point_rows = _rows(ids, w, n)
        S.point_vertex = np.where(onehot, ids[np.arange(len(ids)), np.argmax(w, 1)], -1).astype(np.int64)
        wv = np.bincount(ids.ravel(), weights=w.ravel(), minlength=n)
        _vertex_point_source(ops, wv, X0)
    return S


def _rows(ids: np.ndarray, w: np.ndarray, n: int) -> sp.csr_matrix:
    """Sparse interpolation rows (k, n) from per-row vertices ``ids`` (k, c) and weights ``w`` (k, c)."""
    k = len(ids)
    return sp.csr_matrix((w.ravel(), (np.repeat(np.arange(k), ids.shape[1]), ids.ravel())), shape=(k, n))


def _corner_frames(ops):
    """Per corner (f, k): unit direction e1 of slot k (from v_k to v_{k+1}) and w = n × e1."""
    E = ops.P[:, NEXT] - ops.P
    e1 = E / ops.slot_len[..., None]
    w = np.cross(ops.normals[:, None, :], e1)
    return e1, w


def _add_face_vectors(ops, faces, N, X0):
    ee, zz = ops.slot_coords(faces, N)
    np.add.at(X0, ee.ravel(), zz.ravel())


def _vertex_point_source(ops, wv, X0):
    """Radially symmetric source around vertices with weights wv (App. A.1, Eq. 19): per corner of angle α at
    vertex i, the vector (sin α e1 + (1 - cos α) n × e1) / Θ_i, i.e. i(1 - e^{iα})/Θ_i in the basis of edge ij,
    added to all three edges of the face. Barycentric point sources are split over the face's vertices."""
    F = ops.F
    Theta = np.bincount(F.ravel(), weights=ops.angles.ravel(), minlength=ops.n_vertices)
    sel = wv[F] != 0                                          # corners at source vertices
    f, k = np.nonzero(sel)
    if len(f) == 0:
        return
    e1, w = _corner_frames(ops)
    a = ops.angles[f, k]
    v = F[f, k]
    wt = wv[v] / Theta[v] if ops.point_weight == 1.0 else wv[v] * ops.point_weight / Theta[v]
    N = (np.sin(a)[:, None] * e1[f, k] + (1 - np.cos(a))[:, None] * w[f, k]) * wt[:, None]
    _add_face_vectors(ops, f, N, X0)


def _unsigned_curve_source(ops, segs, ends, X0):
    """Unoriented curves along edges (App. A.2). Type-A segments: in every face adjacent to a curve edge, the
    normal pointing into that face (length-weighted) goes to the face's two other edges (as geometry-central
    does, so that the two sides do not cancel on the curve edge). Type-C arcs at the end points: the
    outward directions of the half-disk beyond the end point, integrated per corner (Eq. 19 restricted to
    the arc), normalized by the angle of the arc and weighted by the length of the end edge."""
    F = ops.F
    e = ops.edge_lookup(segs[:, 0], segs[:, 1])
    count = np.bincount(e, minlength=ops.n_edges).astype(np.float64)
    cnt = count[ops.face_edges]                               # (m, 3)
    f, a = np.nonzero(cnt > 0)
    if len(f):
        E = ops.P[f, NEXT[a]] - ops.P[f, a]
        N = np.cross(ops.normals[f], E) * cnt[f, a][:, None]  # into the face, length-weighted
        ee, zz = ops.slot_coords(f, N)
        mask = np.ones_like(ee, dtype=bool)
        mask[np.arange(len(f)), a] = False
        np.add.at(X0, ee[mask], zz[mask])
    if not ends:
        return
    e1, w = _corner_frames(ops)
    vf = ops.vertex_faces()
    for v, u, ln in ends:
        fs = vf.indices[vf.indptr[v]:vf.indptr[v + 1]]
        ks = vf.data[vf.indptr[v]:vf.indptr[v + 1]] - 1
        t = ops.V[u] - ops.V[v]
        t = t / np.linalg.norm(t)
        E1, W = e1[fs, ks], w[fs, ks]
        alpha = ops.angles[fs, ks]
        phi0 = np.arctan2(W @ t, E1 @ t)
        s = np.mod(phi0 + np.pi / 2, 2 * np.pi)
        integ = np.zeros((len(fs), 3))
        meas = np.zeros(len(fs))
        for lo, hi in ((np.maximum(0, s), np.minimum(alpha, s + np.pi)),
                       (np.maximum(0, s - 2 * np.pi), np.minimum(alpha, s - np.pi))):
            ok = hi > lo
            lo, hi = np.where(ok, lo, 0), np.where(ok, hi, 0)
            integ += (np.sin(hi) - np.sin(lo))[:, None] * E1 + (np.cos(lo) - np.cos(hi))[:, None] * W
            meas += hi - lo
        tot = meas.sum()
        if tot <= 0:
            continue
        _add_face_vectors(ops, fs, integ * (ln / tot), X0)
