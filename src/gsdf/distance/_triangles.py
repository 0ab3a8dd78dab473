"""Exact unsigned distance from points to triangle meshes and soups.

Two layers:

* :func:`closest_point_triangle` -- the closest point on one triangle to a point, region based (the
  Voronoi regions of Ericson, *Real-Time Collision Detection*, §5.1.5), returning the squared distance,
  the closest point and its barycentric coordinates. The region tests and the face-region projection use
  cross products computed directly (not Ericson's products of dot products, whose cancellation squares
  the condition number on slivers), and zero-area triangles -- a repeated vertex, three collinear
  vertices -- fall back to the closest point on their three segments (a zero-length segment is a point).
  The result is never NaN for finite input.
* :class:`TriangleDistance` -- a bounding volume hierarchy (:func:`gsdf.spatial._bvh.build_triangle_bvh`)
  built once, then queried by a ``numba`` kernel that runs in parallel over the queries; each query walks
  the tree with a small explicit stack, visiting the nearer child box first and pruning every box whose
  squared distance is not below the best squared distance found so far. Inside a leaf, each triangle is
  first rejected by its own bounding box and its plane before the exact test. Queries are visited in
  Morton (Z-curve) order, so consecutive queries share cached tree nodes, and each one starts from the
  previous query's nearest triangle as an upper bound; results are written back in input order.

Cost: building is O(m log m) for m triangles; one query is O(log m) for well-spread geometry (it
degrades towards O(m) only when many triangles are nearly equidistant, e.g. the centre of a sphere).
Memory is O(m) for the tree plus O(chunk) per query batch.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numba import njit, prange

from gsdf._checks import as_mesh, as_points, integer, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf._normalize import Frame
from gsdf.spatial._morton import morton_order
from gsdf.spatial._bvh import build_triangle_bvh
from gsdf.threads import apply_env

__all__ = ["TriangleDistance", "unsigned_distance", "closest_point_triangle", "brute_force_distance"]

#: Triangles with ``|(b - a) x (c - a)| <= _DEGENERATE * (longest edge)^2`` are treated as degenerate and
#: handled through their three segments. Both the segment fallback (error at most the triangle height,
#: ``<= _DEGENERATE * longest edge``) and the plane projection (error ~ machine epsilon / sin(angle)) are
#: then accurate to about ``1e-8`` of the triangle size; for well-shaped triangles the result is exact up
#: to rounding.
_DEGENERATE = 1e-8

#: Queries are processed in chunks of this many points so that temporaries stay bounded.
CHUNK = 1 << 20

#: Queries per parallel task (each task allocates one traversal stack).
_BLOCK = 256

#: Traversal stack size. The tree splits at the median, so its depth is at most ~log2(m) + 1 < 64.
_STACK = 128


# ----------------------------------------------------------------------------------------------------
# point - segment / point - triangle
# ----------------------------------------------------------------------------------------------------


@njit(cache=True)
def _segment(px, py, pz, ax, ay, az, bx, by, bz):
    """Closest point on segment ab to p: returns (squared distance, t) with the point a + t (b - a)."""
    ex, ey, ez = bx - ax, by - ay, bz - az
    wx, wy, wz = px - ax, py - ay, pz - az
    ee = ex * ex + ey * ey + ez * ez
    t = 0.0
    if ee > 0.0:
        t = (wx * ex + wy * ey + wz * ez) / ee
        if t <= 0.0:
            t = 0.0
        elif t >= 1.0:
            t = 1.0
    dx = wx - t * ex
    dy = wy - t * ey
    dz = wz - t * ez
    return dx * dx + dy * dy + dz * dz, t


@njit(cache=True)
def _closest_point_triangle(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point on triangle abc to p.

    Returns ``(d2, qx, qy, qz, u, v, w)``: squared distance, closest point, and barycentric coordinates
    ``q = u a + v b + w c`` (exact zeros/ones on edges and vertices).
    """
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    bcx, bcy, bcz = cx - bx, cy - by, cz - bz
    nx = aby * acz - abz * acy
    ny = abz * acx - abx * acz
    nz = abx * acy - aby * acx
    n2 = nx * nx + ny * ny + nz * nz
    lab = abx * abx + aby * aby + abz * abz
    lac = acx * acx + acy * acy + acz * acz
    lbc = bcx * bcx + bcy * bcy + bcz * bcz
    lmax = max(lab, max(lac, lbc))
    thr = _DEGENERATE * lmax
    if n2 > thr * thr:
        # signed sub-areas (times |n|^2 scale) opposite a, b, c, from cross products relative to p
        pax, pay, paz = ax - px, ay - py, az - pz
        pbx, pby, pbz = bx - px, by - py, bz - pz
        pcx, pcy, pcz = cx - px, cy - py, cz - pz
        # va = n . (pb x pc), vb = n . (pc x pa), vc = n . (pa x pb)
        va = nx * (pby * pcz - pbz * pcy) + ny * (pbz * pcx - pbx * pcz) + nz * (pbx * pcy - pby * pcx)
        vb = nx * (pcy * paz - pcz * pay) + ny * (pcz * pax - pcx * paz) + nz * (pcx * pay - pcy * pax)
        vc = nx * (pay * pbz - paz * pby) + ny * (paz * pbx - pax * pbz) + nz * (pax * pby - pay * pbx)
        if va >= 0.0 and vb >= 0.0 and vc >= 0.0:
            # face region: orthogonal projection onto the plane
            s = -(pax * nx + pay * ny + paz * nz) / n2  # (p - a) . n / |n|^2
            qx = px - s * nx
            qy = py - s * ny
            qz = pz - s * nz
            tot = va + vb + vc
            if tot > 0.0:
                u = va / tot
                v = vb / tot
                w = vc / tot
            else:  # pragma: no cover - cannot happen for n2 > 0
                u = v = w = 1.0 / 3.0
            return s * s * n2, qx, qy, qz, u, v, w
        # outside: the closest point lies on an edge opposite a negative coordinate
        best = np.inf
        u = v = w = 0.0
        if va < 0.0:
            d2, t = _segment(px, py, pz, bx, by, bz, cx, cy, cz)
            best = d2
            u, v, w = 0.0, 1.0 - t, t
        if vb < 0.0:
            d2, t = _segment(px, py, pz, cx, cy, cz, ax, ay, az)
            if d2 < best:
                best = d2
                u, v, w = t, 0.0, 1.0 - t
        if vc < 0.0:
            d2, t = _segment(px, py, pz, ax, ay, az, bx, by, bz)
            if d2 < best:
                best = d2
                u, v, w = 1.0 - t, t, 0.0
        qx = u * ax + v * bx + w * cx
        qy = u * ay + v * by + w * cy
        qz = u * az + v * bz + w * cz
        # exact endpoints when the segment parameter clamps
        if u == 1.0:
            qx, qy, qz = ax, ay, az
        elif v == 1.0:
            qx, qy, qz = bx, by, bz
        elif w == 1.0:
            qx, qy, qz = cx, cy, cz
        return best, qx, qy, qz, u, v, w
    # degenerate (zero or negligible area): closest point on the three segments
    best, t = _segment(px, py, pz, ax, ay, az, bx, by, bz)
    u, v, w = 1.0 - t, t, 0.0
    d2, t = _segment(px, py, pz, bx, by, bz, cx, cy, cz)
    if d2 < best:
        best = d2
        u, v, w = 0.0, 1.0 - t, t
    d2, t = _segment(px, py, pz, cx, cy, cz, ax, ay, az)
    if d2 < best:
        best = d2
        u, v, w = t, 0.0, 1.0 - t
    qx = u * ax + v * bx + w * cx
    qy = u * ay + v * by + w * cy
    qz = u * az + v * bz + w * cz
    if u == 1.0:
        qx, qy, qz = ax, ay, az
    elif v == 1.0:
        qx, qy, qz = bx, by, bz
    elif w == 1.0:
        qx, qy, qz = cx, cy, cz
    return best, qx, qy, qz, u, v, w


@njit(parallel=True, cache=True)
def _closest_point_triangles_kernel(P, A, B, C, d2, Q, bary):
    for i in prange(P.shape[0]):
        r = _closest_point_triangle(
            P[i, 0], P[i, 1], P[i, 2], A[i, 0], A[i, 1], A[i, 2], B[i, 0], B[i, 1], B[i, 2], C[i, 0], C[i, 1], C[i, 2]
        )
        d2[i] = r[0]
        Q[i, 0] = r[1]
        Q[i, 1] = r[2]
        Q[i, 2] = r[3]
        bary[i, 0] = r[4]
        bary[i, 1] = r[5]
        bary[i, 2] = r[6]


def closest_point_triangle(P, A, B, C):
    """Closest points on triangles ``(A[i], B[i], C[i])`` to points ``P[i]`` (all (n, 3), broadcastable rows).

    Returns ``(d, closest (n, 3), bary (n, 3))`` with ``closest = bary[:, :1] * A + bary[:, 1:2] * B +
    bary[:, 2:] * C`` (up to rounding).
    """
    P = as_points(P, "P")
    A, B, C = (as_points(X, name) for X, name in ((A, "A"), (B, "B"), (C, "C")))
    n = max(X.shape[0] for X in (P, A, B, C))
    try:
        P, A, B, C = (np.ascontiguousarray(np.broadcast_to(X, (n, 3))) for X in (P, A, B, C))
    except ValueError as exc:
        raise ValueError(f"P, A, B, C: row counts do not broadcast ({exc})") from exc
    frame = Frame.of(np.concatenate([A, B, C]))  # scale invariance (gsdf._normalize)
    A, B, C = (frame.geometry(X, name) for X, name in ((A, "A"), (B, "B"), (C, "C")))
    P, excess = frame.queries(P, "P", want_excess=True)
    d2 = np.empty(n)
    Q = np.empty((n, 3))
    bary = np.empty((n, 3))
    _closest_point_triangles_kernel(P, A, B, C, d2, Q, bary)
    return frame.length(np.sqrt(d2) + excess), frame.point(Q), bary


# ----------------------------------------------------------------------------------------------------
# BVH nearest-triangle query
# ----------------------------------------------------------------------------------------------------


@njit(cache=True)
def _box_d2(px, py, pz, lo, hi, i):
    d = 0.0
    t = lo[i, 0] - px
    if t > 0.0:
        d += t * t
    else:
        t = px - hi[i, 0]
        if t > 0.0:
            d += t * t
    t = lo[i, 1] - py
    if t > 0.0:
        d += t * t
    else:
        t = py - hi[i, 1]
        if t > 0.0:
            d += t * t
    t = lo[i, 2] - pz
    if t > 0.0:
        d += t * t
    else:
        t = pz - hi[i, 2]
        if t > 0.0:
            d += t * t
    return d


@njit(cache=True)
def _tri_box_d2(px, py, pz, D, j):
    """Squared distance from p to the bounding box of packed triangle ``j`` (columns 13:19)."""
    d = 0.0
    t = D[j, 13] - px
    if t > 0.0:
        d += t * t
    else:
        t = px - D[j, 16]
        if t > 0.0:
            d += t * t
    t = D[j, 14] - py
    if t > 0.0:
        d += t * t
    else:
        t = py - D[j, 17]
        if t > 0.0:
            d += t * t
    t = D[j, 15] - pz
    if t > 0.0:
        d += t * t
    else:
        t = pz - D[j, 18]
        if t > 0.0:
            d += t * t
    return d


@njit(cache=True)
def _tri_d2(px, py, pz, D, j):
    """Squared distance from p to triangle ``j`` of the packed array ``D`` (see :func:`_pack`).

    Same arithmetic as :func:`_closest_point_triangle` for the distance, without building the point.
    """
    ax, ay, az = D[j, 0], D[j, 1], D[j, 2]
    bx, by, bz = D[j, 3], D[j, 4], D[j, 5]
    cx, cy, cz = D[j, 6], D[j, 7], D[j, 8]
    n2 = D[j, 12]
    if n2 > 0.0:
        nx, ny, nz = D[j, 9], D[j, 10], D[j, 11]
        pax, pay, paz = ax - px, ay - py, az - pz
        pbx, pby, pbz = bx - px, by - py, bz - pz
        pcx, pcy, pcz = cx - px, cy - py, cz - pz
        va = nx * (pby * pcz - pbz * pcy) + ny * (pbz * pcx - pbx * pcz) + nz * (pbx * pcy - pby * pcx)
        vb = nx * (pcy * paz - pcz * pay) + ny * (pcz * pax - pcx * paz) + nz * (pcx * pay - pcy * pax)
        vc = nx * (pay * pbz - paz * pby) + ny * (paz * pbx - pax * pbz) + nz * (pax * pby - pay * pbx)
        if va >= 0.0 and vb >= 0.0 and vc >= 0.0:
            s = -(pax * nx + pay * ny + paz * nz) / n2
            return s * s * n2
        best = np.inf
        if va < 0.0:
            best, t = _segment(px, py, pz, bx, by, bz, cx, cy, cz)
        if vb < 0.0:
            d2, t = _segment(px, py, pz, cx, cy, cz, ax, ay, az)
            if d2 < best:
                best = d2
        if vc < 0.0:
            d2, t = _segment(px, py, pz, ax, ay, az, bx, by, bz)
            if d2 < best:
                best = d2
        return best
    best, t = _segment(px, py, pz, ax, ay, az, bx, by, bz)
    d2, t = _segment(px, py, pz, bx, by, bz, cx, cy, cz)
    if d2 < best:
        best = d2
    d2, t = _segment(px, py, pz, cx, cy, cz, ax, ay, az)
    if d2 < best:
        best = d2
    return best


@njit(parallel=True, cache=True)
def _nearest_kernel(Q, perm, D, order, start, end, right, lo, hi, out_d2, out_face, out_c, out_bary):
    """Nearest triangle for every query ``Q[perm[k]]``, processed in the order ``k``.

    ``perm`` orders the queries along a space-filling curve: consecutive queries then share tree nodes
    (cache) and each query starts from the previous query's nearest triangle as an upper bound.
    ``D`` is the packed triangle array of :func:`_pack` in tree order.
    """
    nq = perm.shape[0]
    nblocks = (nq + _BLOCK - 1) // _BLOCK
    for blk in prange(nblocks):
        stack = np.empty(_STACK, np.int64)
        stack_d = np.empty(_STACK, np.float64)
        i0 = blk * _BLOCK
        i1 = min(nq, i0 + _BLOCK)
        bj = np.int64(-1)  # not the literal -1: one compiled _tri_d2
        for k in range(i0, i1):
            qi = perm[k]
            px = Q[qi, 0]
            py = Q[qi, 1]
            pz = Q[qi, 2]
            best = np.inf
            if bj >= 0:  # warm start from the previous query's nearest triangle
                best = _tri_d2(px, py, pz, D, bj)
            sp = 0
            node = 0
            if _box_d2(px, py, pz, lo, hi, np.int64(0)) >= best:  # not the literal 0: one specialisation
                node = -1
            while node >= 0:
                r = right[node]
                if r < 0:
                    for j in range(start[node], end[node]):
                        # cheap lower bounds first: the triangle's box, then its plane
                        if _tri_box_d2(px, py, pz, D, j) >= best:
                            continue
                        n2 = D[j, 12]
                        if n2 > 0.0:
                            s = (px - D[j, 0]) * D[j, 9] + (py - D[j, 1]) * D[j, 10] + (pz - D[j, 2]) * D[j, 11]
                            if s * s >= best * n2:
                                continue
                        d2 = _tri_d2(px, py, pz, D, j)
                        if d2 < best:
                            best = d2
                            bj = j
                    node = -1
                else:
                    left = node + 1
                    dl = _box_d2(px, py, pz, lo, hi, left)
                    dr = _box_d2(px, py, pz, lo, hi, r)
                    if dl <= dr:
                        near = left
                        far = r
                        dn = dl
                        dfar = dr
                    else:
                        near = r
                        far = left
                        dn = dr
                        dfar = dl
                    if dfar < best:
                        stack[sp] = far
                        stack_d[sp] = dfar
                        sp += 1
                    if dn < best:
                        node = near
                    else:
                        node = -1
                if node < 0:
                    # pop the next box that can still hold something closer
                    while sp > 0:
                        sp -= 1
                        if stack_d[sp] < best:
                            node = stack[sp]
                            break
            res = _closest_point_triangle(
                px, py, pz, D[bj, 0], D[bj, 1], D[bj, 2], D[bj, 3], D[bj, 4], D[bj, 5], D[bj, 6], D[bj, 7], D[bj, 8]
            )
            out_d2[qi] = res[0]
            out_face[qi] = order[bj]
            out_c[qi, 0] = res[1]
            out_c[qi, 1] = res[2]
            out_c[qi, 2] = res[3]
            out_bary[qi, 0] = res[4]
            out_bary[qi, 1] = res[5]
            out_bary[qi, 2] = res[6]


@njit(cache=True)
def _pack(T, degenerate):
    """Pack triangles ``T`` (m, 9) as (m, 19): corners a, b, c; plane normal n = (b - a) x (c - a) and
    |n|^2 (all zero for degenerate triangles); box lo, hi."""
    m = T.shape[0]
    D = np.zeros((m, 19))
    for j in range(m):
        for k in range(9):
            D[j, k] = T[j, k]
        for k in range(3):
            D[j, 13 + k] = min(T[j, k], min(T[j, 3 + k], T[j, 6 + k]))
            D[j, 16 + k] = max(T[j, k], max(T[j, 3 + k], T[j, 6 + k]))
        abx, aby, abz = T[j, 3] - T[j, 0], T[j, 4] - T[j, 1], T[j, 5] - T[j, 2]
        acx, acy, acz = T[j, 6] - T[j, 0], T[j, 7] - T[j, 1], T[j, 8] - T[j, 2]
        bcx, bcy, bcz = T[j, 6] - T[j, 3], T[j, 7] - T[j, 4], T[j, 8] - T[j, 5]
        nx = aby * acz - abz * acy
        ny = abz * acx - abx * acz
        nz = abx * acy - aby * acx
        n2 = nx * nx + ny * ny + nz * nz
        lab = abx * abx + aby * aby + abz * abz
        lac = acx * acx + acy * acy + acz * acz
        lbc = bcx * bcx + bcy * bcy + bcz * bcz
        lmax = max(lab, max(lac, lbc))
        thr = degenerate * lmax
        if n2 > thr * thr:
            D[j, 9] = nx
            D[j, 10] = ny
            D[j, 11] = nz
            D[j, 12] = n2
    return D


@njit(cache=True)
def _refit_boxes(D, start, end, right):
    """Node boxes (k, 3) lo, hi of a preorder tree (left child i + 1, right child ``right[i]``, −1 for leaves)
    over the packed triangles ``D`` in tree order (boxes in columns 13:16 / 16:19), as the build computes them."""
    k = start.shape[0]
    lo = np.empty((k, 3))
    hi = np.empty((k, 3))
    for i in range(k - 1, -1, -1):
        r = right[i]
        if r < 0:
            for d in range(3):
                lo[i, d] = np.inf
                hi[i, d] = -np.inf
            for j in range(start[i], end[i]):
                for d in range(3):
                    lo[i, d] = min(lo[i, d], D[j, 13 + d])
                    hi[i, d] = max(hi[i, d], D[j, 16 + d])
        else:
            for d in range(3):
                lo[i, d] = min(lo[i + 1, d], lo[r, d])
                hi[i, d] = max(hi[i + 1, d], hi[r, d])
    return lo, hi


class TriangleDistance:
    """Unsigned distance to a triangle mesh or soup, with the tree built once.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles (any soup: duplicated, degenerate, non-manifold or unreferenced elements are fine).
    leaf_size : int, default 8
        Maximum triangles per leaf of the bounding volume hierarchy (>= 1); changes speed only.

    Attributes
    ----------
    V, F
        The mesh, as given (float64, int64).
    n_faces : int
        Number of triangles.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    >>> td = gsdf.TriangleDistance(V, [[0, 1, 2]])           # build once ...
    >>> d, face, closest = td.query([[0.2, 0.2, 0.5]])       # ... query many times
    >>> float(d[0]), int(face[0]), closest[0].tolist()
    (0.5, 0, [0.2, 0.2, 0.0])
    """

    def __init__(self, V, F, leaf_size: int = 8):
        V, F = as_mesh(V, F)
        leaf = integer(leaf_size, "leaf_size", 1)
        self.V = V
        self.F = F
        # the tree and the kernels work in the normalised frame of the mesh (scale invariance, gsdf._normalize)
        self._frame = Frame.of_mesh(V, F)
        Vf = self._frame.geometry(V)
        self.bvh = build_triangle_bvh(Vf, F, leaf)
        # triangle corners in tree order, contiguous per leaf
        self._D = _pack(np.ascontiguousarray(Vf[F[self.bvh.order]].reshape(-1, 9)), _DEGENERATE)

    @property
    def n_faces(self) -> int:
        """Number of triangles."""
        return int(self.F.shape[0])

    def _query(self, Q, chunk: int = CHUNK, want_bary: bool = True):
        """Validated queries -> (d, face, closest, bary) in input units; ``bary`` is None unless ``want_bary``."""
        apply_env()  # GSDF_NUM_THREADS
        fr = self._frame
        Q, excess = fr.queries(Q, want_excess=True)
        d2, face, closest, bary = self._query_frame(Q, chunk, want_bary)
        d = np.sqrt(d2, out=d2)
        d += excess
        return fr.length(d), face, fr.point(closest), bary

    def _query_frame(self, Q, chunk: int, want_bary: bool):
        nq = Q.shape[0]
        d2 = np.empty(nq)
        face = np.empty(nq, np.int64)
        closest = np.empty((nq, 3))
        bary = np.empty((nq, 3)) if want_bary else None
        scratch = None if want_bary else np.empty((min(nq, chunk), 3))
        b = self.bvh
        for s in range(0, nq, chunk):
            e = min(nq, s + chunk)
            Qc = Q[s:e]
            _nearest_kernel(
                Qc, morton_order(Qc), self._D, b.order, b.start, b.end, b.right, b.lo, b.hi,
                d2[s:e], face[s:e], closest[s:e], bary[s:e] if want_bary else scratch[: e - s],
            )
        return d2, face, closest, bary

    def refit(self, V):
        """Move the vertices (same faces) and keep the tree.

        The tree's element order and splits stay, the boxes are recomputed bottom-up from the new triangles
        (O(n), against the build's O(n log n)). Queries stay exact (every box bounds its triangles); a tree
        refitted after large moves only prunes less well. For meshes whose vertices move a little per round (an
        iterative fit).

        Parameters
        ----------
        V : (n, 3) float
            The new vertex positions, as many as before.

        Returns
        -------
        TriangleDistance
            ``self``.

        Raises
        ------
        ValueError
            A different number of vertices, NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float); F = np.array([[0, 1, 2]])
        >>> td = TriangleDistance(V, F).refit(V + [0.0, 0.0, 1.0])
        >>> float(td.query([[0.2, 0.2, 0.0]])[0][0])
        1.0
        """
        V = as_points(V, "V")
        if V.shape != self.V.shape:
            raise ValueError(f"V: expected {self.V.shape[0]} vertices (the tree's), got {V.shape[0]}")
        self.V = V
        self._frame = Frame.of_mesh(V, self.F)
        Vf = self._frame.geometry(V)
        b = self.bvh
        if getattr(self, "_F_tree", None) is None:
            self._F_tree = np.ascontiguousarray(self.F[b.order])
        self._D = _pack(np.ascontiguousarray(Vf[self._F_tree].reshape(-1, 9)), _DEGENERATE)
        lo, hi = _refit_boxes(self._D, b.start, b.end, b.right)
        self.bvh = dataclasses.replace(b, lo=lo, hi=hi)
        return self

    @query_shaped()
    def query(self, Q):
        """Unsigned distance from each query point to the nearest triangle.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        d : (q,) float64
            Euclidean distance.
        face : (q,) int64
            Index into ``F`` of a nearest triangle (ties broken arbitrarily).
        closest : (q, 3) float64
            The closest point on that triangle.

        Raises
        ------
        ValueError
            ``Q`` of the wrong shape or with NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
        >>> d, face, closest = gsdf.TriangleDistance(V, [[0, 1, 2]]).query([[2.0, 0.0, 0.0]])
        >>> float(d[0]), closest[0].tolist()
        (1.0, [1.0, 0.0, 0.0])
        """
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        d, face, closest, _ = self._query(Q, want_bary=False)
        return d, face, closest

    @query_shaped()
    def query_barycentric(self, Q):
        """Like :meth:`query`, and the barycentric coordinates of each closest point in its triangle.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        d : (q,) float64
            Euclidean distance.
        face : (q,) int64
            Index into ``F`` of a nearest triangle.
        closest : (q, 3) float64
            The closest point on that triangle.
        bary : (q, 3) float64
            Its barycentric coordinates in ``F[face]`` (exact zeros on edges, an exact one at vertices).

        Raises
        ------
        ValueError
            ``Q`` of the wrong shape or with NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
        >>> d, face, closest, bary = gsdf.TriangleDistance(V, [[0, 1, 2]]).query_barycentric([[2.0, 0.0, 0.0]])
        >>> bary[0].tolist()
        [0.0, 1.0, 0.0]
        """
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        return self._query(Q)


@query_shaped()
def unsigned_distance(V, F, Q, return_closest: bool = False):
    """Unsigned distance from points ``Q`` to the triangle mesh/soup ``(V, F)``.

    To query the same geometry repeatedly, build a :class:`TriangleDistance` once.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions, model units.
    F : (m, 3) int
        Triangles (any soup).
    Q : (q, 3) float
        Query points.
    return_closest : bool, default False
        Also return the nearest triangle and the closest point on it.

    Returns
    -------
    d : (q,) float64
        Distance to the nearest triangle.
    face : (q,) int64
        Only with ``return_closest``: index into ``F`` of a nearest triangle.
    closest : (q, 3) float64
        Only with ``return_closest``: the closest point on it.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    >>> F = np.array([[0, 1, 2]])
    >>> d = gsdf.unsigned_distance(V, F, [[0.2, 0.2, 0.5], [0.2, 0.2, -0.5]])
    >>> np.round(d, 3).tolist()
    [0.5, 0.5]
    """
    V, F = as_mesh(V, F)
    Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
    d, face, closest = TriangleDistance(V, F).query(Q)
    if return_closest:
        return d, face, closest
    return d


@njit(parallel=True, cache=True)
def _brute_kernel(Q, T, out_d2, out_face):
    for i in prange(Q.shape[0]):
        best = np.inf
        bj = 0
        for j in range(T.shape[0]):
            r = _closest_point_triangle(
                Q[i, 0], Q[i, 1], Q[i, 2],
                T[j, 0], T[j, 1], T[j, 2], T[j, 3], T[j, 4], T[j, 5], T[j, 6], T[j, 7], T[j, 8],
            )
            if r[0] < best:
                best = r[0]
                bj = j
        out_d2[i] = best
        out_face[i] = bj


def brute_force_distance(V, F, Q):
    """O(q m) reference: distance from every query to every triangle. Returns ``(d, face)``. For testing."""
    V, F = as_mesh(V, F)
    Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
    frame = Frame.of_mesh(V, F)
    T = np.ascontiguousarray(frame.geometry(V)[F].reshape(-1, 9))
    Q, excess = frame.queries(Q, want_excess=True)
    d2 = np.empty(Q.shape[0])
    face = np.empty(Q.shape[0], np.int64)
    _brute_kernel(Q, T, d2, face)
    return frame.length(np.sqrt(d2) + excess), face
