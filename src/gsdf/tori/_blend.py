"""Shared machinery of the self-normalized and LogSumExp convolutional formulas (thesis §3.2, §5.1.3).

Per query x (Eq. 5.7): σ_x = ½ max_i ‖x − p_i‖ (the farthest point of a cloud is a vertex of its convex hull,
so only hull vertices are scanned) and λ_x = C/σ_x with C = 64. The sums of Eqs. 5.6, 5.8, 5.9 run over the
points within R_eval of x (at most ``k_eval``, default 64, the nearest), falling back to the 32 nearest when
fewer lie within R_eval (§5.1.3). Near the cloud the points within R_eval come from a fixed-radius grid
(:mod:`gsdf.spatial._radius_grid`), far from it the 32 nearest from a BVH walk warm-started by the previous
(Morton-sorted) query; both in one numba-parallel kernel.
Exponents are shifted by the nearest distance d_min instead of σ_x: the self-normalized ratios are unchanged
and the shift is exact in the LogSumExp formulas (we add d_min back), while no weight can underflow.
"""

from __future__ import annotations

import numpy as np

from numba import njit, prange

from gsdf._checks import as_points
from gsdf._memory import SECONDS_PER_QUERY, check_bytes
from gsdf.spatial._bvh import build_bvh
from gsdf.spatial._radius_grid import build_radius_grid, gather_within

CHUNK = 1 << 16


@njit(cache=True, inline="always")
def _box_d2(lo, hi, i, x0, x1, x2):
    a = max(lo[i, 0] - x0, 0.0, x0 - hi[i, 0])
    b = max(lo[i, 1] - x1, 0.0, x1 - hi[i, 1])
    c = max(lo[i, 2] - x2, 0.0, x2 - hi[i, 2])
    return a * a + b * b + c * c


@njit(cache=True, inline="always")
def _insert(bd, bi, k, d2, e):
    """Insert (d2, e) into the ascending top-k lists bd, bi (the last entry drops out)."""
    m = k - 1
    while m > 0 and bd[m - 1] > d2:
        bd[m] = bd[m - 1]
        bi[m] = bi[m - 1]
        m -= 1
    bd[m] = d2
    bi[m] = e


@njit(cache=True, inline="always")
def _push_children(lo, hi, node, right_child, x0, x1, x2, stack, sp):
    """Push both children of ``node``, the nearer one on top (visited first); returns the new stack size."""
    left = node + 1
    if _box_d2(lo, hi, left, x0, x1, x2) <= _box_d2(lo, hi, right_child, x0, x1, x2):
        stack[sp] = right_child
        stack[sp + 1] = left
    else:
        stack[sp] = left
        stack[sp + 1] = right_child
    return sp + 2


@njit(parallel=True, cache=True)
def _knn_kernel(Q, Ps, order, lo, hi, right, start, end, k, shrink, k_min, r2, out_d, out_i):
    """k nearest points of every query: depth-first over the BVH, nearer child first, boxes pruned against the
    current k-th distance (divided by (1 + eps)² for approximate search). Points ``Ps`` are in tree order.

    With ``k_min < k`` only the ``k_min`` nearest plus those within sqrt(r2) are wanted: the pruning bound is
    then min(d_k, max(r2, d_kmin)); rows are padded with inf distances."""
    for j in prange(Q.shape[0]):
        x0, x1, x2 = Q[j, 0], Q[j, 1], Q[j, 2]
        bd = np.full(k, np.inf)
        bi = np.zeros(k, np.int64)
        stack = np.empty(128, np.int64)
        stack[0] = 0
        sp = 1
        while sp > 0:
            sp -= 1
            node = stack[sp]
            bound = min(bd[k - 1], max(r2, bd[k_min - 1]))
            if _box_d2(lo, hi, node, x0, x1, x2) * shrink >= bound:
                continue
            r = right[node]
            if r < 0:
                for e in range(start[node], end[node]):
                    a, b, c = Ps[e, 0] - x0, Ps[e, 1] - x1, Ps[e, 2] - x2
                    d2 = a * a + b * b + c * c
                    if d2 < bd[k - 1] and d2 < max(r2, bd[k_min - 1]):
                        _insert(bd, bi, k, d2, e)
            else:
                sp = _push_children(lo, hi, node, r, x0, x1, x2, stack, sp)
        for m in range(k):
            out_d[j, m] = np.sqrt(bd[m])
            out_i[j, m] = order[bi[m]]


@njit(cache=True)
def _select(cd, ci, n, k):
    """Partially order (cd, ci)[:n] so that its k smallest cd come first (quickselect, Hoare partition)."""
    lo, hi = 0, n - 1
    while lo < hi:
        piv = cd[(lo + hi) // 2]
        i, j = lo, hi
        while i <= j:
            while cd[i] < piv:
                i += 1
            while cd[j] > piv:
                j -= 1
            if i <= j:
                cd[i], cd[j] = cd[j], cd[i]
                ci[i], ci[j] = ci[j], ci[i]
                i += 1
                j -= 1
        if k - 1 <= j:
            hi = j
        elif k - 1 >= i:
            lo = i
        else:
            return


@njit(cache=True)
def _nearest_walk(x0, x1, x2, Ps, lo, hi, right, start, end, k, wb, shrink, bd, bi, stack):
    """k nearest points of x (tree order indices) into bd (squared distances, ascending) and bi: depth-first
    over the BVH, nearer child first, boxes pruned against min(k-th distance, wb) (÷ shrink for approximate
    search); only points with squared distance <= wb are accepted."""
    for m in range(k):
        bd[m] = np.inf
        bi[m] = 0
    stack[0] = 0
    sp = 1
    while sp > 0:
        sp -= 1
        node = stack[sp]
        bx = _box_d2(lo, hi, node, x0, x1, x2)
        # the (1 + eps)² shrink relaxes only the k-th distance test: the warm-start bound wb is a hard limit
        # on accepted points, so shrinking it too could leave fewer than k points (inf rows, NaN sums)
        if bx > wb or bx * shrink > bd[k - 1]:
            continue
        rr = right[node]
        if rr < 0:
            for e in range(start[node], end[node]):
                u, v, w = Ps[e, 0] - x0, Ps[e, 1] - x1, Ps[e, 2] - x2
                d2 = u * u + v * v + w * w
                if d2 < bd[k - 1] and d2 <= wb:
                    _insert(bd, bi, k, d2, e)
        else:
            sp = _push_children(lo, hi, node, rr, x0, x1, x2, stack, sp)


@njit(cache=True)
def _blend_block(Q, j0, j1, Ps, order, lo, hi, right, start, end, g_org, g_cell, g_dims, g_keys, g_start, g_rows,
                 g_pts, g_order, use_grid, k, k_min, r2, shrink, out_d, out_i):
    bd = np.empty(k)
    bi = np.empty(k, np.int64)
    stack = np.empty(128, np.int64)
    prev = np.empty(k_min, np.int64)
    have_prev = False
    cd = np.empty(2048)
    ci = np.empty(2048, np.int64)
    for j in range(j0, j1):
        x0, x1, x2 = Q[j, 0], Q[j, 1], Q[j, 2]
        nin = 0
        if use_grid:
            nin = gather_within(x0, x1, x2, g_org, g_cell, g_dims, g_keys, g_start, g_rows, g_pts, g_order, r2, cd, ci)
        for m in range(k):
            out_d[j, m] = np.inf
            out_i[j, m] = 0
        if nin >= k_min and nin <= cd.shape[0]:
            c = min(nin, k)
            if nin > k:
                _select(cd, ci, nin, k)
            jm = 0
            for m in range(c):
                if cd[m] < cd[jm]:
                    jm = m
            for m in range(c):
                mm = jm if m == 0 else (0 if m == jm else m)
                out_d[j, m] = np.sqrt(cd[mm])
                out_i[j, m] = ci[mm]
            continue
        if (not use_grid) or nin > cd.shape[0]:  # no grid, or more within R_eval than the buffer: tree walk
            _nearest_walk(x0, x1, x2, Ps, lo, hi, right, start, end, k, r2, shrink, bd, bi, stack)
            if bd[k_min - 1] <= r2:
                for m in range(k):
                    if bd[m] <= r2:
                        out_d[j, m] = np.sqrt(bd[m])
                        out_i[j, m] = order[bi[m]]
                continue
        # far from the cloud: the k_min nearest
        wb = np.inf
        if have_prev:
            wb = 0.0
            for m in range(k_min):
                e = prev[m]
                u, v, w = Ps[e, 0] - x0, Ps[e, 1] - x1, Ps[e, 2] - x2
                wb = max(wb, u * u + v * v + w * w)
        _nearest_walk(x0, x1, x2, Ps, lo, hi, right, start, end, k_min, wb, shrink, bd, bi, stack)
        for m in range(k_min):
            prev[m] = bi[m]
            out_d[j, m] = np.sqrt(bd[m])
            out_i[j, m] = order[bi[m]]
        have_prev = True


@njit(parallel=True, cache=True)
def _blend_kernel(Q, Ps, order, lo, hi, right, start, end, g_org, g_cell, g_dims, g_keys, g_start, g_rows, g_pts,
                  g_order, use_grid, k, k_min, r2, shrink, out_d, out_i):
    """Neighbours for the sums of §5.1.3: the (up to k) nearest within sqrt(r2) when at least k_min lie there,
    else the k_min nearest; padded with (inf, 0). Rows start with the nearest point; the k_min-nearest rows
    are ascending, the within-r rows are otherwise unordered (the sums do not need an order).

    Phase 1 gathers the points within r from the grid cells around x (:mod:`gsdf.spatial._radius_grid`).
    Phase 2 (too few within r: x is far from the cloud) is a k_min-nearest walk of the BVH, warm-started: the
    previous far query of the same block of 64 (queries are Morton-sorted) gives k_min points whose largest
    distance to x bounds the k_min-th nearest distance, so boxes beyond it are pruned from the start."""
    q = Q.shape[0]
    B = 64
    nb = (q + B - 1) // B
    for blk in prange(nb):
        _blend_block(Q, blk * B, min(q, blk * B + B), Ps, order, lo, hi, right, start, end, g_org, g_cell, g_dims,
                     g_keys, g_start, g_rows, g_pts, g_order, use_grid, k, k_min, r2, shrink, out_d, out_i)


class PointKNN:
    """k nearest neighbours of query points in a fixed cloud, in parallel (numba), on a median-split BVH.

    Examples
    --------
    >>> import numpy as np
    >>> d, i = PointKNN(np.eye(3)).query(np.zeros((1, 3)) + [0.9, 0, 0], k=2)
    >>> i.tolist(), d.round(3).tolist()
    ([[0, 1]], [[0.1, 1.345]])
    """

    def __init__(self, P, leaf_size: int = 8):
        self.P = np.ascontiguousarray(P, dtype=np.float64)
        self.t = build_bvh(self.P, self.P, self.P, leaf_size)
        self.Ps = np.ascontiguousarray(self.P[self.t.order])

    def query(self, Q, k: int, eps: float = 0.0, k_min=None, radius=np.inf):
        """Distances and indices (q, k) of the k nearest points, ascending; with ``k_min`` only the ``k_min``
        nearest and those within ``radius`` (up to k) are returned, the rest of each row is (inf, any index)."""
        k = int(min(k, len(self.P)))
        k_min = k if k_min is None else int(min(max(k_min, 1), k))
        Q = np.ascontiguousarray(Q, dtype=np.float64)
        check_bytes(16 * len(Q) * k, f"{len(Q)} queries x {k} nearest neighbours")
        d, i = np.empty((len(Q), k)), np.empty((len(Q), k), np.int64)
        t = self.t
        r2 = float(radius) ** 2 if k_min < k else np.inf
        _knn_kernel(Q, self.Ps, t.order, t.lo, t.hi, t.right, t.start, t.end, k, (1.0 + eps) ** 2, k_min, r2, d, i)
        if k_min < k:  # candidates accepted before the k_min nearest were known may lie beyond the radius
            tail = d[:, k_min:]
            tail[tail > radius] = np.inf
        return d, i


def hull_vertices(P: np.ndarray, most: int = 128) -> np.ndarray:
    """Points that realize max_i ‖x − p_i‖ for every x: convex hull vertices, thinned to ``most``.

    The farthest point of a cloud from any x is a hull vertex. Hulls of curved clouds have thousands of
    vertices, so a farthest-point subsample of ``most`` of them is kept: σ_x (Eq. 5.7) is then
    underestimated by at most the covering radius of the subsample, a few per cent of the cloud's size,
    which only rescales λ_x slightly.
    """
    try:
        from scipy.spatial import ConvexHull

        H = P[ConvexHull(P).vertices]
    except Exception:  # flat or degenerate cloud: qhull refuses
        H = P
    if len(H) > most:
        sel = [int(np.argmax(np.linalg.norm(H - H.mean(0), axis=1)))]
        d = np.linalg.norm(H - H[sel[0]], axis=1)
        for _ in range(most - 1):
            j = int(np.argmax(d))
            sel.append(j)
            d = np.minimum(d, np.linalg.norm(H - H[j], axis=1))
        H = H[sel]
    return np.ascontiguousarray(H)


class NeighbourBlend:
    """Neighbour search (:class:`PointKNN`), hull and chunked queries shared by PAT and the baselines.

    Parameters
    ----------
    P : (n, 3) float64
        Validated points.
    C : float
        Screening constant of Eq. 5.7 (λ_x = C / σ_x).
    r_eval : float or None
        Summation radius R_eval; None: twice the median distance from a point to its 32nd neighbour.
    k_eval : int
        Most candidates considered per query (neighbour query size).
    k_fallback : int
        Points summed when fewer than this many lie within R_eval (32 in §5.1.3).
    kd_eps : float
        Approximate search far from the cloud (the k_fallback-nearest tree walk): boxes farther than the current
        k-th distance / (1 + kd_eps) are skipped, so every returned distance is within (1 + kd_eps) of the true
        one. 0 = exact. Queries with k_fallback points within R_eval are always exact.
    """

    def __init__(self, P, C=64.0, r_eval=None, k_eval=64, k_fallback=32, tree=None, kd_eps=0.0):
        self.P = P
        self.knn = PointKNN(P) if tree is None else tree
        self.hull = hull_vertices(P)
        self.C = float(C)
        self.kd_eps = float(kd_eps)
        self.k_eval = int(min(k_eval, len(P)))
        self.k_fallback = int(min(k_fallback, self.k_eval))
        if r_eval is None:
            kk = min(32, len(P) - 1)
            d, _ = self.knn.query(P[:: max(1, len(P) // 4096)], k=kk + 1)
            r_eval = 2.0 * float(np.median(d[:, -1])) if kk > 0 else np.inf
        self.r_eval = float(r_eval)
        # fixed-radius grid for the points within R_eval; not worth it when a cell holds a large part of the cloud
        g = build_radius_grid(P, self.r_eval)
        self.grid = g if g is not None and len(g.keys) * 64 >= len(P) else None

    def neighbours(self, Q: np.ndarray):
        """(d, i), each (q, k_eval): the k_eval nearest within R_eval when at least k_fallback lie there,
        else the k_fallback nearest; ascending, padded with (inf, 0)."""
        Q = np.ascontiguousarray(Q, dtype=np.float64)
        k, k_min = self.k_eval, self.k_fallback
        d, i = np.empty((len(Q), k)), np.empty((len(Q), k), np.int64)
        t, g = self.knn.t, self.grid
        if g is None:
            z3, z1 = np.zeros(3), np.zeros(1, np.int64)
            z2 = np.zeros(2, np.int64)
            gargs = (z3, 1.0, np.ones(3, np.int64), z1, z2, z2, np.zeros((1, 3)), z1, False)
        else:
            gargs = (g.origin, g.cell, g.dims, g.keys, g.start, g.row_start, g.points, g.order, True)
        _blend_kernel(Q, self.knn.Ps, t.order, t.lo, t.hi, t.right, t.start, t.end, *gargs, k, k_min,
                      self.r_eval ** 2, (1.0 + self.kd_eps) ** 2, d, i)
        return d, i

    def map(self, Q, fn, width: int = 0, name: str = "Q"):
        """Validate ``Q`` and call ``fn(q, d, i, out)`` chunk by chunk; ``out`` is (q,) or (q, width)."""
        from gsdf.spatial._morton import morton_order

        Q = as_points(Q, name, seconds_per_row=SECONDS_PER_QUERY)
        out = np.empty((len(Q), width) if width else len(Q))
        # neighbour blocks are (chunk, k_eval) distances and indices: keep one block within ~64 MB
        chunk = max(1, min(CHUNK, (64 << 20) // (16 * self.k_eval + 64)))
        for s in range(0, len(Q), chunk):
            q = Q[s: s + chunk]
            if len(q) > 4096:  # Z-order: neighbouring queries share tree nodes and tori in cache
                o = morton_order(q)
                q = np.ascontiguousarray(q[o])
                d, i = self.neighbours(q)
                tmp = np.empty((len(q), width) if width else len(q))
                fn(q, d, i, tmp)
                out[s: s + len(q)][o] = tmp
            else:
                d, i = self.neighbours(q)
                fn(q, d, i, out[s: s + chunk])
        return out
