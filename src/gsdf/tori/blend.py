"""Shared machinery of the self-normalized and LogSumExp convolutional formulas (thesis §3.2, §5.1.3).

Per query x (Eq. 5.7): σ_x = ½ max_i ‖x − p_i‖ (the farthest point of a cloud is a vertex of its convex hull,
so only hull vertices are scanned) and λ_x = C/σ_x with C = 64. The sums of Eqs. 5.6, 5.8, 5.9 run over the
points within R_eval of x, falling back to the 32 nearest when fewer lie within R_eval (§5.1.3); candidates
come from one tree query (:class:`PointKNN`, a BVH walked nearest-child first) of the ``k_eval`` (default 64) nearest points, which caps the work per query.
Exponents are shifted by the nearest distance d_min instead of σ_x: the self-normalized ratios are unchanged
and the shift is exact in the LogSumExp formulas (we add d_min back), while no weight can underflow.
"""

from __future__ import annotations

import numpy as np

from numba import njit, prange

from .._checks import as_points
from ..spatial.bvh import build_bvh

CHUNK = 1 << 16


@njit(cache=True, inline="always")
def _box_d2(lo, hi, i, x0, x1, x2):
    a = max(lo[i, 0] - x0, 0.0, x0 - hi[i, 0])
    b = max(lo[i, 1] - x1, 0.0, x1 - hi[i, 1])
    c = max(lo[i, 2] - x2, 0.0, x2 - hi[i, 2])
    return a * a + b * b + c * c


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
                        m = k - 1
                        while m > 0 and bd[m - 1] > d2:
                            bd[m] = bd[m - 1]
                            bi[m] = bi[m - 1]
                            m -= 1
                        bd[m] = d2
                        bi[m] = e
            else:
                l = node + 1
                dl = _box_d2(lo, hi, l, x0, x1, x2)
                dr = _box_d2(lo, hi, r, x0, x1, x2)
                if dl <= dr:
                    stack[sp] = r
                    stack[sp + 1] = l
                else:
                    stack[sp] = l
                    stack[sp + 1] = r
                sp += 2
        for m in range(k):
            out_d[j, m] = np.sqrt(bd[m])
            out_i[j, m] = order[bi[m]]


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
        Approximate neighbour search: tree boxes farther than the current k-th distance / (1 + kd_eps) are
        skipped, so every returned distance is within (1 + kd_eps) of the true one. 0 = exact.
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

    def neighbours(self, Q: np.ndarray):
        return self.knn.query(Q, self.k_eval, self.kd_eps, k_min=self.k_fallback, radius=self.r_eval)

    def map(self, Q, fn, width: int = 0, name: str = "Q"):
        """Validate ``Q`` and call ``fn(q, d, i, out)`` chunk by chunk; ``out`` is (q,) or (q, width)."""
        from ..spatial.morton import morton_order

        Q = as_points(Q, name)
        out = np.empty((len(Q), width) if width else len(Q))
        for s in range(0, len(Q), CHUNK):
            q = Q[s: s + CHUNK]
            if len(q) > 4096:  # Z-order: neighbouring queries share tree nodes and tori in cache
                o = morton_order(q)
                q = np.ascontiguousarray(q[o])
                d, i = self.neighbours(q)
                tmp = np.empty((len(q), width) if width else len(q))
                fn(q, d, i, tmp)
                out[s: s + len(q)][o] = tmp
            else:
                d, i = self.neighbours(q)
                fn(q, d, i, out[s: s + CHUNK])
        return out
