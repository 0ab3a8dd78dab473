"""Signed distance sampled on a regular grid: the library form of ``gsdf sdf``.

:func:`signed_distance_grid` samples, on the nodes of a :class:`gsdf.Grid`, the exact unsigned distance
(:class:`gsdf.TriangleDistance`, or the nearest point of a cloud) signed by the fast winding number at 1/2
(Barill et al. 2018 §4, robust to holes and soups) or by angle-weighted pseudonormals (Bærentzen & Aanæs 2005,
closed manifold meshes). With ``return_closest=True`` it also returns what libigl's ``signed_distance`` does:
closest face, closest point, normal.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gsdf._checks import as_mesh, as_normals, as_points, choice, positive, progress_callback
from gsdf._memory import SECONDS_PER_QUERY, check_work

__all__ = ["signed_distance_grid"]


def signed_distance_grid(V=None, F=None, *, points=None, resolution=64, sign: str = "winding", beta: float | None = None,
                         return_closest: bool = False, shell: float | None = None, progress=None):
    """Signed distance (negative inside) on the nodes of a regular grid around a mesh/soup or oriented cloud.

    ``|S|`` is the exact distance to the triangles (:class:`gsdf.TriangleDistance`) or to the nearest point of a
    cloud (:class:`gsdf.PointCloudDistance`); the sign is negative where the fast winding number exceeds 1/2
    (Barill et al. 2018 §4: robust to holes and soups), or, with ``sign="pseudonormal"``, the sign of the
    angle-weighted pseudonormal of the closest feature (Bærentzen & Aanæs 2005; closed manifold meshes). On a
    closed surface (every directed edge matched by its reverse) the winding number is integer and constant between
    nodes the surface does not separate (Feng 2026, thesis §2.3.3), so it is evaluated once per such region of
    nodes, with the same signs as per node.

    Parameters
    ----------
    V : (n, 3) float, or a tuple ``(V, F)``
        Mesh vertices (or the whole mesh as one tuple). Omit (``None``) when ``points`` is given.
    F : (m, 3) int, optional
        Triangles (any soup: holes, duplicates, degenerate faces are fine with ``sign="winding"``).
    points : tuple ``(P, N)``, optional
        An oriented point cloud instead of a mesh, P and N (p, 3).
    resolution : int or gsdf.Grid, default 64
        Grid nodes along the longest side of the input's bounding box grown by :data:`gsdf.grid.PAD` × its
        diagonal (:meth:`gsdf.Grid.around`: cubic cells); or the :class:`gsdf.Grid` to sample.
    sign : {"winding", "pseudonormal"}
        ``"pseudonormal"`` needs a mesh and is only meaningful for closed, consistently oriented manifolds.
    beta : float, optional
        Accuracy of the fast winding number (default 2 for meshes, 2.3 for points).
    return_closest : bool, default False
        Also return libigl's ``I, C, N``.
    shell : float, optional
        Thickness of a shell around the surface added to the inside: the signed distance to the union of the
        winding-number solid and the points within ``shell / 2`` of the surface, ``min(S, |S| - shell / 2)``
        (:func:`gsdf.signed_distance`). For open single-layer sheets (ShapeNet-style), which otherwise have no
        inside; mesh2sdf's ``fix=True, level=L`` corresponds to ``shell=2 L``. Off by default.
    progress : callable ``progress(stage, fraction)``, optional
        Called while the winding numbers are evaluated (``stage="winding numbers"``, fraction in [0, 1]).

    Returns
    -------
    S : gsdf.GridField
        Values of shape (nx, ny, nz); node ``(i, j, k)`` at ``S.bbox_min + (i, j, k) * S.spacing``.
    I : (nx*ny*nz,) int64
        With ``return_closest``: index of the closest triangle (of the nearest point for a cloud) for each node,
        in the C order of ``S.values`` (the order of ``S.grid_points()``).
    C : (nx*ny*nz, 3) float64
        The closest point on the surface (the nearest point of a cloud).
    N : (nx*ny*nz, 3) float64
        The normal there: the angle-weighted pseudonormal of the closest feature (face, edge or vertex) with
        ``sign="pseudonormal"``, the unit normal of the closest triangle with ``sign="winding"`` (zero for a
        degenerate triangle), the point's normal for a cloud.

    Examples
    --------
    >>> import gsdf, numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> S = gsdf.signed_distance_grid(V, F, resolution=16)
    >>> S.shape, bool(S([[0.1, 0.1, 0.1]])[0] < 0)
    ((16, 16, 16), True)
    >>> S, I, C, N = gsdf.signed_distance_grid((V, F), resolution=gsdf.Grid(([0, 0, 0], [1, 1, 1]), (8, 8, 8)),
    ...                                        return_closest=True)
    """
    from gsdf.distance._signed import with_shell
    from gsdf.field import GridField
    from gsdf.grid import as_grid

    choice(sign, "sign", ("winding", "pseudonormal"))
    if not isinstance(return_closest, (bool, np.bool_)):
        raise ValueError(f"return_closest: expected True or False, got {return_closest!r}")
    if shell is not None:
        shell = positive(shell, "shell")
    report = progress_callback(progress)
    if beta is not None:
        beta = positive(beta, "beta")
    if points is not None:
        if V is not None or F is not None:
            raise ValueError("points: give either a mesh (V, F) or points=(P, N), not both")
        if sign == "pseudonormal":
            raise ValueError("sign: 'pseudonormal' needs a mesh, not a point cloud")
        try:
            P, Nrm = points
        except (TypeError, ValueError):
            raise ValueError("points: expected a tuple (P, N) of (p, 3) arrays") from None
        P = as_points(P, "P")
        Nrm = as_normals(Nrm, len(P), "N")
        X = P
    else:
        if F is None and isinstance(V, (tuple, list)) and len(V) == 2:
            V, F = V
        if V is None or F is None:
            raise ValueError("V, F: expected a triangle mesh (V, F) or points=(P, N)")
        V, F = as_mesh(V, F)
        X = V
    grid = as_grid(resolution, X=X)
    check_work(grid.size, 2 * SECONDS_PER_QUERY, f"signed_distance_grid: a {'x'.join(map(str, grid.shape))} grid "
               f"({grid.size:,} nodes)")
    Q = grid.points()

    if points is not None:
        from gsdf.distance import PointCloudDistance
        from gsdf.winding import FastWindingNumberPoints

        d, idx, _ = PointCloudDistance(P).query(Q)
        w = _chunked(FastWindingNumberPoints(P, Nrm, beta=positive(2.3 if beta is None else beta, "beta")), Q,
                     report)
        s = np.where(w > 0.5, -d, d)  # Barill et al. 2018 §4: inside where the winding number exceeds 1/2
        S = GridField((s if shell is None else with_shell(s, shell)).reshape(grid.shape), *grid.box)
        return (S, idx, P[idx], Nrm[idx]) if return_closest else S

    from gsdf.distance._signed import _pseudonormal_sign, closest_pseudonormal, warn_pseudonormal
    from gsdf.distance._triangles import TriangleDistance
    from gsdf.spatial._triangle_tree import triangle_tree

    beta = positive(2.0 if beta is None else beta, "beta")
    tt = triangle_tree(V, F)  # one tree for the distance and the winding number
    if sign == "pseudonormal":
        warn_pseudonormal(V, F)
        d, face, closest, bary = TriangleDistance._of_tree(V, F, tt).query_barycentric(Q)
        sgn = _pseudonormal_sign(V, F, Q, closest, face, bary)
        s = sgn * d
    else:
        from gsdf.winding import FastWindingNumber

        fwn = FastWindingNumber._of_tree(tt, beta=beta)
        if _is_cycle(F, V.shape[0]):
            # closed: the winding number is constant between nodes the surface does not separate, evaluated
            # once per such region (_region_inside), after the distance. One node first: on a cold cache its
            # kernels compile here while `gsdf sdf` compiles the distance kernels in a background process
            # (gsdf.cli._background)
            fwn(Q[:1])
            d, face, closest = TriangleDistance._of_tree(V, F, tt).query(Q)
            inside = _region_inside(fwn, Q, d, grid, report)
        else:
            # the winding numbers first: on a cold cache `gsdf sdf` compiles the distance kernels in a background
            # process meanwhile (gsdf.cli._background), which are then ready when the distance is reached
            inside = _chunked(fwn, Q, report) > 0.5
            d, face, closest = TriangleDistance._of_tree(V, F, tt).query(Q)
        s = np.where(inside, -d, d)  # Barill et al. 2018 §4: inside where the winding number exceeds 1/2
    S = GridField((s if shell is None else with_shell(s, shell)).reshape(grid.shape), *grid.box)
    if not return_closest:
        return S
    if sign == "pseudonormal":
        N = closest_pseudonormal(V, F, face, bary)
    else:
        n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        ln = np.linalg.norm(n, axis=1, keepdims=True)
        n = np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)
        N = n[face]
    return S, face, closest, N


#: Queries per winding-number call (the chunk of gsdf.winding's own query loop: the same calls, the same numbers).
CHUNK = 1 << 20


def _chunked(winding, Q, progress, stage: str = "winding numbers") -> np.ndarray:
    """``winding(Q)`` in chunks of :data:`CHUNK` queries, reporting ``progress(stage, fraction)`` after each."""
    n = len(Q)
    if progress is None or n <= CHUNK:
        w = np.asarray(winding(Q), dtype=np.float64)
        if progress is not None:
            progress(stage, 1.0)
        return w
    w = np.empty(n)
    for s in range(0, n, CHUNK):
        e = min(n, s + CHUNK)
        w[s:e] = winding(Q[s:e])
        progress(stage, e / n)
    return w


def _is_cycle(F, n_vertices: int) -> bool:
    """True when the triangles form a cycle: every directed edge (a, b) occurs as often as (b, a) (closed,
    consistently oriented, any number of components, non-manifold edges and cancelling duplicates allowed).
    The generalized winding number of a cycle is an integer, constant on every connected region of the
    complement of the surface (Feng 2026, thesis §2.3.3: piecewise constant and integer for a closed surface)."""
    if F.shape[0] == 0:
        return False
    a = F.ravel().astype(np.int64)
    b = F[:, [1, 2, 0]].ravel().astype(np.int64)
    n = np.int64(max(n_vertices, 1))
    return bool(np.array_equal(np.sort(a * n + b), np.sort(b * n + a)))


def _region_inside(winding, Q, d, grid, progress) -> np.ndarray:
    """``winding(Q) > 0.5`` on the nodes ``Q`` of ``grid`` for a closed surface (:func:`_is_cycle`), with the
    winding number evaluated on few nodes.

    Two neighbouring nodes p, q with ``max(d(p), d(q)) > |p − q|`` (``d`` the distance to the surface) lie in
    one open ball free of the surface, so the segment pq does not cross it and their exact winding numbers are
    equal. The regions these pairs connect (:func:`_regions`) are evaluated at two nodes each, the one farthest
    from the surface and the first; a region whose two rounded values disagree is evaluated at every node (the
    fast winding number's error exceeded 1/2 somewhere: then the per-node values stand, as without regions)."""
    shape = tuple(int(x) for x in grid.shape)
    lo, hi = grid.box
    h = (np.asarray(hi, float) - np.asarray(lo, float)) / (np.array(shape) - 1)
    h = h * (1.0 + 1e-6)  # the margin covers the rounding of d and of the node coordinates
    label, far, first = _regions(np.ascontiguousarray(d, np.float64), *shape, *(float(x) for x in h))
    reps = np.unique(np.concatenate([far, first]))
    ins = np.asarray(_chunked(winding, Q[reps], progress)) > 0.5
    ins_far = ins[np.searchsorted(reps, far)]
    bad = ins_far != ins[np.searchsorted(reps, first)]
    inside = ins_far[label]
    if bad.any():
        rows = np.flatnonzero(bad[label])
        inside[rows] = np.asarray(winding(Q[rows])) > 0.5
    return inside


@njit(cache=True, inline="always")
def _find(parent, x):
    while parent[x] != x:
        parent[x] = parent[parent[x]]  # path halving
        x = parent[x]
    return x


@njit(cache=True)
def _regions(d, nx, ny, nz, hx, hy, hz):
    """Union-find over the nodes of an (nx, ny, nz) grid (C order) joining 6-neighbours p, q with
    ``max(d[p], d[q]) > h`` along their axis. Returns the region (0, 1, ...) of every node, and per region the
    node farthest from the surface and the first node."""
    n = nx * ny * nz
    parent = np.arange(n)
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                p = (i * ny + j) * nz + k
                for axis in range(3):
                    if axis == 0:
                        if k + 1 >= nz or max(d[p], d[p + 1]) <= hz:
                            continue
                        q = p + 1
                    elif axis == 1:
                        if j + 1 >= ny or max(d[p], d[p + nz]) <= hy:
                            continue
                        q = p + nz
                    else:
                        if i + 1 >= nx or max(d[p], d[p + ny * nz]) <= hx:
                            continue
                        q = p + ny * nz
                    a = _find(parent, p)
                    b = _find(parent, q)
                    if a < b:  # the root of a region is its smallest node
                        parent[b] = a
                    elif b < a:
                        parent[a] = b
    count = 0
    for p in range(n):
        parent[p] = _find(parent, p)
        count += parent[p] == p
    far = np.empty(count, np.int64)
    first = np.empty(count, np.int64)
    count = 0
    for p in range(n):  # parent[] becomes -(region + 1): a root (smallest node) is met before its region
        r = parent[p]
        if r == p:
            far[count] = p
            first[count] = p
            parent[p] = -(count + 1)
            count += 1
        else:
            g = -parent[r] - 1
            parent[p] = -(g + 1)
            if d[p] > d[far[g]]:
                far[g] = p
    for p in range(n):
        parent[p] = -parent[p] - 1
    return parent, far, first
