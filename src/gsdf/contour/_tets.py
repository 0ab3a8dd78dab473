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
    (2 and 2); crossing points are shared per mesh edge. Where the level passes exactly through mesh nodes,
    crossing points of different edges coincide: they are welded, zero-area triangles dropped, and a vertex
    where separate sheets touch is split per fan, so the result is edge- and vertex-manifold (closed away from
    the mesh boundary). Two cases stay open, and the report says so: flat (zero-volume) tets, which a
    Delaunay of cospherical points such as a regular grid contains, and tet faces lying wholly on the level
    (three nodes exactly at ``level``). Triangles are oriented along the gradient of ``values``.

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
        ``level`` not finite or outside the range of ``values`` (no surface).

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> T = np.array([[0, 1, 2, 3]])
    >>> V, F = gsdf.marching_tetrahedra(X, T, X[:, 0] - 0.5)     # the plane x = 1/2 cuts one triangle
    >>> V.shape, F.shape, np.allclose(V[:, 0], 0.5)
    ((3, 3), (1, 3), True)
    """
    from gsdf._checks import finite

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
    from gsdf.mesh._topology import manifold_report, split_nonmanifold_vertices, weld

    V, F = weld(V, F[keep].astype(np.int64))
    rep = manifold_report(V, F)
    if not rep["vertex_manifold"]:
        V, F = split_nonmanifold_vertices(V, F)
        rep = manifold_report(V, F)
    return (V, F, rep) if report else (V, F)
