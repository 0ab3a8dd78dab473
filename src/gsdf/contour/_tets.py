"""Tetrahedral meshes: point location and marching tetrahedra (level sets of piecewise-linear functions)."""

from __future__ import annotations

import numpy as np

__all__ = ["locate_in_tets", "marching_tetrahedra"]


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
    (2 and 2); crossing points are shared per mesh edge.

    A node exactly at the level counts as below it (libigl's ``marching_tets`` does the same: a node is above
    when its value exceeds the level). A field constrained to the level on input points (the signed heat
    method's "zero" constraint, Feng & Crane 2024 §8.1) has many such nodes, and whole tets at the level;
    the surface is then the boundary of the region above the level: it runs through the nodes at the level
    and over the faces of the tets at the level that border a tet above it. Crossing points of different
    edges that coincide at a node are welded and zero-area triangles dropped; a pair of coincident opposite
    triangles (a tet face of three nodes at the level between two tets above it: a sheet of zero thickness)
    cancels; where sheets touch along an edge the faces are paired across the wedges above the level (regions
    above stay apart) and the vertices split per fan. The result is closed away from the mesh boundary,
    edge- and vertex-manifold, and consistently oriented, along the gradient of ``values`` (the orientation
    of the majority of each component where flat tets have no gradient). ``report=True`` returns
    ``(V, F, report)`` with :func:`gsdf.mesh._topology.manifold_report`.

    Parameters
    ----------
    X : (n, 3) float
        Vertex positions of the tet mesh.
    T : (m, 4) int
        Tetrahedra as vertex indices.
    values : (n,) float
        One value per vertex, linear over each tet.
    level : float, default 0.0
        The level extracted; strictly between the minimum and the maximum of ``values``.
    report : bool, default False
        Also return the checks of the mesh: a dict with ``closed``, ``edge_manifold``, ``vertex_manifold``,
        ``welded`` and the counts of non-manifold edges and vertices.

    Returns
    -------
    V : (k, 3) float64
        Crossing points, welded.
    F : (f, 3) int64
        Triangles, normals along the gradient of ``values`` (outward for a signed distance).
    report : dict
        Only with ``report=True``.

    Raises
    ------
    ValueError
        ``level`` not finite, outside the range of ``values`` over the tets, or cutting no tet (no surface).

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> T = np.array([[0, 1, 2, 3]])
    >>> V, F = gsdf.marching_tetrahedra(X, T, X[:, 0] - 0.5)     # the plane x = 1/2 cuts one triangle
    >>> V.shape, F.shape, np.allclose(V[:, 0], 0.5)
    ((3, 3), (1, 3), True)
    """
    from gsdf._checks import as_faces, as_points, as_values, finite, flag

    X = as_points(X, "X")
    T = as_faces(T, len(X), "T", corners=4)
    report = flag(report, "report")
    s = as_values(values, "values", (len(X),)) - finite(level, "level")
    st = s[T]          # the range that counts is the tets' (vertices in no tet carry values no tet interpolates)
    if not (st.min() < 0 < st.max()):
        raise ValueError(f"level {level} is outside the field's range [{st.min() + level:.6g}, "
                         f"{st.max() + level:.6g}] (over the tets): no surface")
    # values within round-off of the level are put exactly on it, and a node on the level counts as below it:
    # crossings at such a node then coincide exactly and are welded below
    s = np.where(np.abs(s) <= 1e-12 * float(np.abs(s).max()), 0.0, s)
    pos = s[T] > 0
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
    if not tris:       # below and above the level, but in different tets: no tet is cut
        raise ValueError(f"level {level} cuts no tet (the values below and above it lie in different tets): "
                         "no surface")
    E = np.concatenate(tris)  # (k, 3 corners, 2 endpoints)
    tet_of = np.concatenate(tet_of)
    Es = np.sort(E.reshape(-1, 2), axis=1)
    uniq, inv = np.unique(Es, axis=0, return_inverse=True)
    sa, sb = s[uniq[:, 0]], s[uniq[:, 1]]
    t = sa / (sa - sb)
    V = X[uniq[:, 0]] + t[:, None] * (X[uniq[:, 1]] - X[uniq[:, 0]])
    V[t == 1.0] = X[uniq[t == 1.0, 1]]  # a crossing at a node is that node, bitwise (so it welds)
    V[t == 0.0] = X[uniq[t == 0.0, 0]]
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
    from gsdf.mesh._topology import manifold_report, weld

    V, F = weld(V, F.astype(np.int64))
    F = _cancel_opposite_pairs(F)
    rep = manifold_report(V, F)
    if not (rep["vertex_manifold"] and rep["edge_manifold"]):
        V, F = _split_sheets(V, F)
        rep = manifold_report(V, F)
    return (V, F, rep) if report else (V, F)


def _cancel_opposite_pairs(F):
    """Drop pairs of triangles on the same three vertices with opposite orientations (they cancel as a chain:
    a sheet of zero thickness); an unpaired copy stays."""
    if len(F) == 0:
        return F
    key = np.sort(F, axis=1)
    # orientation parity of each triangle relative to its sorted key
    r = np.argsort(F, axis=1, kind="stable")
    parity = ((r[:, 0] > r[:, 1]).astype(int) + (r[:, 0] > r[:, 2]) + (r[:, 1] > r[:, 2])) % 2
    _, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    net = np.zeros(inv.max() + 1, np.int64)
    np.add.at(net, inv, 1 - 2 * parity)
    cnt = np.bincount(inv)
    if (cnt == 1).all():
        return F
    keep = np.zeros(len(F), bool)
    # keep |net| triangles of the net orientation in every group
    order = np.argsort(inv, kind="stable")
    seen = np.zeros_like(net)
    for f in order[cnt[inv[order]] > 1].tolist():
        g, sgn = inv[f], 1 - 2 * parity[f]
        if net[g] != 0 and np.sign(net[g]) == sgn and seen[g] < abs(net[g]):
            keep[f] = True
            seen[g] += 1
    keep[cnt[inv] == 1] = True
    return F[keep]


def _pair_across_wedges(V, F, hs, shifted=False):
    """At an edge with more than two faces (faces oriented along the gradient), pair each face with its
    angular neighbour across a wedge above the level: the surfaces of regions above the level that touch along
    the edge stay apart (as the level itself counts as below); ``shifted``: across the wedges below instead.
    ``hs`` are half-edge ids 3 f + k."""
    hs = np.asarray(hs)
    f, k = hs // 3, hs % 3
    p, q, c = F[f, k], F[f, (k + 1) % 3], F[f, (k + 2) % 3]
    a, b = min(p[0], q[0]), max(p[0], q[0])
    o = np.where(p == a, 1, -1)  # +1: the face runs a -> b
    d = V[b] - V[a]
    d = d / max(np.linalg.norm(d), np.finfo(float).tiny)
    e1 = np.cross(d, [1.0, 0, 0]) if abs(d[0]) < 0.9 else np.cross(d, [0, 1.0, 0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    r = V[c] - V[a]
    order = np.argsort(np.arctan2(r @ e2, r @ e1), kind="stable")
    n = len(order)
    out = []
    for i in range(n):
        x, y = order[i], order[(i + 1) % n]
        if o[x] > 0 > o[y]:  # the wedge from x to y (counter-clockwise about a -> b) is above the level
            out.append((int(hs[x]), int(hs[y])))
    if 2 * len(out) != n:  # orientations do not alternate around the edge (degenerate tets): angular neighbours
        out = [(int(hs[order[i]]), int(hs[order[i + 1]])) for i in range(0, n - 1, 2)]
    if shifted:  # the other way round
        out = [(int(hs[order[i]]), int(hs[order[(i + 1) % n]])) for i in range(1, n, 2)]
    return out


def _orient_consistently(V, F):
    """Flip faces so that every component is consistently oriented, each component keeping the orientation of
    the (area-weighted) majority of its faces."""
    from gsdf.mesh._connectivity import MeshTopology

    topo = MeshTopology(F, len(V))
    flip = topo.orientation_classes()
    if flip is None or not flip.any():
        return F
    area = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    comp = topo.face_components
    vote = np.zeros(int(comp.max()) + 1)
    np.add.at(vote, comp, np.where(flip, -1.0, 1.0) * (area + 1e-300))
    flip = flip ^ (vote[comp] < 0)
    F = F.copy()
    F[flip] = F[flip][:, [0, 2, 1]]
    return F


def _split_sheets(V, F):
    """Split the vertices where sheets touch (:func:`split_nonmanifold_vertices`), pairing the faces of an edge
    with more than two across the wedges above the level; where a vertex's fan then still runs twice through
    such an edge (so no vertex copy can separate the sheets), pair that edge's faces the other way round.
    Then orient every component consistently."""
    from gsdf.mesh._topology import _edges, split_nonmanifold_vertices

    def key_of(F_, hs):
        E, _ = _edges(F_)
        e = E[hs[0]]
        return min(e), max(e)

    shifted = set()
    for _ in range(3):
        def pair(hs):
            return _pair_across_wedges(V, F, hs, key_of(F, hs) in shifted)

        V2, F2 = split_nonmanifold_vertices(V, F, pair_ok=pair)
        E, _ = _edges(F2)
        und = np.sort(E, axis=1)
        u, inv, cnt = np.unique(und, axis=0, return_inverse=True, return_counts=True)
        bad = np.flatnonzero(cnt[inv.reshape(-1)] > 2)
        if len(bad) == 0:
            break
        # the original vertices of the edges still shared by more than two faces: pair those the other way
        src = np.empty(len(V2), np.int64)
        src[F2.reshape(-1)] = F.reshape(-1)
        new = {(int(min(src[a], src[b])), int(max(src[a], src[b]))) for a, b in und[bad]}
        if new <= shifted:
            break
        shifted |= new
    return V2, _orient_consistently(V2, F2)
