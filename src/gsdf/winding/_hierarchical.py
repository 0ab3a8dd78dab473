"""Exact generalized winding numbers of triangle soups by divide and conquer (Jacobson et al. 2013, §3.3).

For a patch S of triangles inside a box B and a query q outside B, S closed by any cap C with the same
boundary and lying inside B is a closed surface that does not enclose q, so w_S(q) = −w_C(q). With C the
fan of the boundary edges a→b of S to the box centre c (triangles (c, b, a)), w_S(q) = Σ w(c, a, b): a sum
over the O(√m) boundary edges instead of the m triangles. Boundary edges are the directed edges whose
multiplicities (a→b counts +1, b→a −1) do not cancel, so duplicated, flipped and nonmanifold faces are
handled exactly. A tree node is summed this way when q is outside its box, opened otherwise; leaves are
summed directly. The result equals the direct sum up to round-off, for any soup.

Cost: precompute O(m log² m) (sorting edges per node); a query outside most boxes visits O(log m) nodes.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from gsdf._checks import as_mesh, integer, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf._normalize import Frame
from gsdf.spatial._bvh import build_bvh
from gsdf.winding._query import map_queries
from gsdf.winding._solid_angle import solid_angle_w


@njit(cache=True)
def _node_boundary(F, order, s, e, nv, out_edges, write):
    """Directed boundary edges (with multiplicity) of triangles order[s:e]; returns their count."""
    m = 3 * (e - s)
    keys = np.empty(m, np.int64)
    sign = np.empty(m, np.int64)
    c = 0
    for j in range(s, e):
        t = order[j]
        for k in range(3):
            a = F[t, k]
            b = F[t, (k + 1) % 3]
            if a == b:
                keys[c] = -1  # degenerate edge, no contribution
                sign[c] = 0
            elif a < b:
                keys[c] = a * nv + b
                sign[c] = 1
            else:
                keys[c] = b * nv + a
                sign[c] = -1
            c += 1
    o = np.argsort(keys)
    count = 0
    i = 0
    while i < m:
        key = keys[o[i]]
        tot = 0
        while i < m and keys[o[i]] == key:
            tot += sign[o[i]]
            i += 1
        if key >= 0 and tot != 0:
            if write:
                u = key // nv
                v = key % nv
                if tot > 0:
                    out_edges[count, 0] = u
                    out_edges[count, 1] = v
                    out_edges[count, 2] = tot
                else:
                    out_edges[count, 0] = v
                    out_edges[count, 1] = u
                    out_edges[count, 2] = -tot
            count += 1
    return count


@njit(parallel=True, cache=True)
def _boundaries(F, order, start, end, nv):
    k = start.shape[0]
    counts = np.zeros(k, np.int64)
    dummy = np.empty((0, 3), np.int64)
    for i in prange(k):
        counts[i] = _node_boundary(F, order, start[i], end[i], nv, dummy, False)
    ptr = np.zeros(k + 1, np.int64)
    for i in range(k):
        ptr[i + 1] = ptr[i] + counts[i]
    E = np.empty((ptr[k], 3), np.int64)
    for i in prange(k):
        _node_boundary(F, order, start[i], end[i], nv, E[ptr[i]:ptr[i + 1]], True)
    return ptr, E


@njit(parallel=True, cache=True)
def _eval(Q, T, lo, hi, right, skip, start, end, ptr, EC, use_cap, out):
    k = lo.shape[0]
    for qi in prange(Q.shape[0]):
        qx, qy, qz = Q[qi, 0], Q[qi, 1], Q[qi, 2]
        acc = 0.0
        i = 0
        while i < k:
            outside = (qx < lo[i, 0] or qx > hi[i, 0] or qy < lo[i, 1] or qy > hi[i, 1]
                       or qz < lo[i, 2] or qz > hi[i, 2])
            if outside and use_cap[i]:
                cx = 0.5 * (lo[i, 0] + hi[i, 0]) - qx
                cy = 0.5 * (lo[i, 1] + hi[i, 1]) - qy
                cz = 0.5 * (lo[i, 2] + hi[i, 2]) - qz
                for j in range(ptr[i], ptr[i + 1]):
                    acc += EC[j, 6] * solid_angle_w(cx, cy, cz, EC[j, 0] - qx, EC[j, 1] - qy, EC[j, 2] - qz,
                                                    EC[j, 3] - qx, EC[j, 4] - qy, EC[j, 5] - qz)
                i = skip[i]
            elif outside or right[i] < 0:
                for t in range(start[i], end[i]):
                    acc += solid_angle_w(T[t, 0] - qx, T[t, 1] - qy, T[t, 2] - qz,
                                         T[t, 3] - qx, T[t, 4] - qy, T[t, 5] - qz,
                                         T[t, 6] - qx, T[t, 7] - qy, T[t, 8] - qz)
                i = skip[i]
            else:
                i += 1
        out[qi] = acc


class ExactWindingNumber:
    """Exact winding number of a triangle soup, hierarchical (build once, query many).

    Same values as :func:`gsdf.winding_number` (up to round-off), usually far faster for many queries: a node of
    the tree whose query lies outside its box contributes the solid angle of a small cap over its boundary edges
    instead of its triangles (the winding number depends only on the boundary there).

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles (a soup is fine).
    leaf_size : int, default 8
        Triangles per tree leaf (>= 1); changes speed only.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range.

    Notes
    -----
    Call the object with query points: ``ewn(Q, progress=None)`` takes ``Q`` (q, 3) and an optional
    ``progress(stage, fraction)`` callback and returns the (q,) float64 winding numbers.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> gsdf.ExactWindingNumber(V, F)([[0.1, 0.1, 0.1], [2, 2, 2]]).round(12)
    array([1., 0.])
    """

    _seconds_per_point = SECONDS_PER_QUERY  # cost of one query, for the size guard of contouring callers

    def __init__(self, V, F, leaf_size: int = 8):
        V, F = as_mesh(V, F)
        leaf_size = integer(leaf_size, "leaf_size", 1)
        self._frame = Frame.of_mesh(V, F)  # scale invariance (gsdf._normalize)
        V = self._frame.geometry(V)
        Tv = V[F]
        self.tree = t = build_bvh(Tv.mean(axis=1), Tv.min(axis=1), Tv.max(axis=1), leaf_size)
        self._T = np.ascontiguousarray(Tv[t.order].reshape(-1, 9))
        self._ptr, E = _boundaries(F, t.order, t.start, t.end, V.shape[0])
        # boundary edge coordinates and multiplicity, one row per edge: a (3), b (3), multiplicity
        self._EC = np.ascontiguousarray(np.column_stack([V[E[:, 0]], V[E[:, 1]], E[:, 2].astype(np.float64)]))
        # the cap pays off when it has fewer triangles than the node itself
        self._use_cap = np.diff(self._ptr) < (t.end - t.start)

    @query_shaped()
    def __call__(self, Q, progress=None) -> np.ndarray:
        """Exact winding numbers (q,) at the query points ``Q`` (q, 3); ``progress(stage, fraction)`` after each
        chunk."""
        return map_queries(self._kernel, Q, progress=progress, coherent=True, frame=self._frame)

    def _kernel(self, q, out):
        t = self.tree
        _eval(q, self._T, t.lo, t.hi, t.right, t.skip, t.start, t.end, self._ptr, self._EC, self._use_cap, out)
