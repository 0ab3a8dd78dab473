"""The k nearest neighbours of every point of a cloud among the cloud itself, on a uniform cell grid.

What :func:`gsdf.winding._point_areas` needs (its 21-161 candidates per point; a k-d tree query keeps a sorted heap
of k per query, so its cost grows with k). Here the points are bucketed in cubic cells of about the typical k-th
neighbour distance; each point scans the cubes of cells around its own (Chebyshev distance R = 1, 2, ...) keeping
the points closer than the nearest face of the scanned cube (faces on the border of the grid do not count: nothing
lies beyond them; cells wholly beyond that face are not read) until at least k are kept — every unseen point is
farther, so those k are exact. The k-th smallest squared distance is found by a histogram of the kept ones
(:func:`_kth_smallest`) and the points up to it are kept; ties at the threshold go to the smallest indices. A
point whose block keeps fewer than k rescans the next cube out to the k-th distance among its block's points, an
upper bound of its own k-th.

Rows come out in no particular order unless ``ordered`` (sorted by distance, ties by index: the rows of
``cKDTree.query``, so a caller gets bit-identical results from either; the sort costs ~15 % at k = 41).
Cost: O(n log n) bucketing plus O(n m) for m ≈ 1.5-2 k candidates per point on a surface sample, on the calling
thread below :data:`PARALLEL_POINTS` points and on gsdf's threads from it.

Example
-------
>>> import numpy as np
>>> from gsdf.spatial._knn import knn_self
>>> P = np.random.default_rng(0).random((500, 3))
>>> idx = knn_self(P, 8)
>>> from scipy.spatial import cKDTree
>>> bool(np.array_equal(np.sort(idx, axis=1), np.sort(cKDTree(P).query(P, 8)[1], axis=1)))
True
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gsdf.threads import run_tasks

__all__ = ["SelfKNN", "knn_self"]

MAX_CELLS = 1 << 22  # dense cell table; coarser cells above this
NBUCKET = 64  # buckets of the selection histogram (:func:`_kth_smallest`)
CELL_FACTOR = 1.0  # cell / median k-th neighbour distance


class SelfKNN:
    """The cell grid of a cloud ``P`` (n, 3) for its ``k`` nearest neighbours, queried in row ranges.

    ``rows(s, e)`` gives (e − s, k) int64: the same sets as ``cKDTree(P).query(P[s:e], k)[1]`` (ties at the
    k-th distance by smallest index), each row in no particular order, the point itself among them.
    ``k`` must be in [1, n]. ``ordered``: each row sorted by distance, ties by index. The kernel is serial and
    GIL-free (no numba parallel loop, which compiles 5× longer): ``rows()`` of the whole cloud runs ranges of
    cells on gsdf's persistent threads from :data:`PARALLEL_POINTS` points.
    """

    def __init__(self, P, k: int, ordered: bool = False):
        P = np.ascontiguousarray(P, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != 3:
            raise ValueError(f"P: expected an (n, 3) array, got shape {P.shape}")
        n = P.shape[0]
        if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)) or not 1 <= int(k) <= n:
            raise ValueError(f"k: must be an integer in [1, {n}] (the number of points), got {k!r}")
        if not np.isfinite(P).all():
            raise ValueError("P: contains NaN or inf")
        if not isinstance(ordered, (bool, np.bool_)):
            raise ValueError(f"ordered: expected True or False, got {ordered!r}")
        self.P, self.n, self.k, self.ordered = P, n, int(k), bool(ordered)
        lo = P.min(axis=0)
        ext = float((P.max(axis=0) - lo).max())
        self.degenerate = ext == 0.0  # all points coincide: the k smallest indices
        if self.degenerate:
            return
        # cell: the median k-th neighbour distance of ~32 sample points (brute force), bounded by the table size
        sample = np.ascontiguousarray(P[:: max(1, n // 32)])
        cell = max(CELL_FACTOR * _sample_kth(sample, P, self.k), ext / (MAX_CELLS ** (1.0 / 3.0) - 1.0), ext * 1e-12)
        dims = np.floor((P.max(axis=0) - lo) / cell).astype(np.int64) + 1
        c = np.minimum(np.floor((P - lo) / cell).astype(np.int64), dims - 1)
        key = (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]
        order = np.argsort(key, kind="stable").astype(np.int64)
        ncell = int(np.prod(dims))
        start = np.zeros(ncell + 1, np.int64)
        np.cumsum(np.bincount(key, minlength=ncell), out=start[1:])
        self._grid = (np.ascontiguousarray(P[order]), order, start, np.ascontiguousarray(c), dims, lo, float(cell))

    def rows(self, s: int = 0, e: int | None = None) -> np.ndarray:
        e = self.n if e is None else int(e)
        s = int(s)
        if not 0 <= s <= e <= self.n:
            raise ValueError(f"rows: expected 0 <= s <= e <= {self.n} (the number of points), got s={s}, e={e}")
        if self.degenerate:
            return np.tile(np.arange(self.k, dtype=np.int64), (e - s, 1))
        out = np.empty((e - s, self.k), np.int64)
        if s == 0 and e == self.n:  # every row: cell by cell, the candidates of a cell gathered once
            start = self._grid[2]
            ranges = _cell_ranges(start, self.n)
            run_tasks(lambda r: _knn_by_cell(self.P, *self._grid, self.k, self.ordered, r[0], r[1], out), ranges)
        else:
            _knn_kernel(self.P, *self._grid, self.k, int(s), self.ordered, out)
        return out


#: From this many points the cells are split into ranges of about equal point counts, run on the threads of
#: :func:`gsdf.threads.run_tasks` (4 per thread, taken in turn, so a descheduled worker delays one range); below,
#: one call on the calling thread.
PARALLEL_POINTS = 1024


def _cell_ranges(start, n: int) -> list:
    """[(c0, c1), ...] covering every cell: one range below PARALLEL_POINTS points or with one thread, else about
    4 per thread of equal point counts (cells split at the point-count quantiles)."""
    import numba

    threads = numba.get_num_threads()
    ncell = start.shape[0] - 1
    if n < PARALLEL_POINTS or threads <= 1:
        return [(0, ncell)]
    parts = 4 * threads
    cuts = np.searchsorted(start, (np.arange(1, parts) * n) // parts, side="right") - 1
    cuts = np.unique(np.concatenate([[0], np.clip(cuts, 0, ncell), [ncell]]))
    return [(int(a), int(b)) for a, b in zip(cuts[:-1], cuts[1:]) if b > a]


def knn_self(P, k: int) -> np.ndarray:
    """Indices (n, k) of the ``k`` nearest points of every row of ``P`` (n, 3) among ``P`` itself
    (:class:`SelfKNN`; the same sets as ``cKDTree(P).query(P, k)[1]``, rows unordered)."""
    return SelfKNN(P, k).rows()


@njit(cache=True)
def _sample_kth(S, P, k):
    """Median over the sample points S of the distance to their k-th nearest point of P (brute force)."""
    m, n = S.shape[0], P.shape[0]
    d = np.empty(n)
    tmp = np.empty(n)
    hist = np.empty(NBUCKET + 1, np.int64)
    kth = np.empty(m)
    for a in range(m):
        for j in range(n):
            u, v, w = P[j, 0] - S[a, 0], P[j, 1] - S[a, 1], P[j, 2] - S[a, 2]
            d[j] = u * u + v * v + w * w
        kth[a] = np.sqrt(_kth_smallest(d, np.int64(n), np.int64(k - 1), np.inf, tmp, hist))  # 2-3× a quickselect
    # the median by the same quickselect (np.median would compile numba's sort, ~1.5 s cold): after selecting
    # rank m // 2 the smaller half lies before it, so for even m the other middle value is that half's largest
    hi = _select(kth, m, m // 2)
    if m % 2 == 1:
        return hi
    lo = kth[0]
    for a in range(1, m // 2):
        lo = max(lo, kth[a])
    return (lo + hi) / 2.0


@njit(cache=True)
def _select(a, m, r):
    """The r-th smallest (0-based) of a[:m], by quickselect (median-of-three pivots); reorders a[:m]."""
    lo, hi = 0, m - 1
    while hi > lo:
        mid = (lo + hi) // 2
        x, y, z = a[lo], a[mid], a[hi]
        piv = max(min(x, y), min(max(x, y), z))
        i, j = lo, hi
        while i <= j:
            while a[i] < piv:
                i += 1
            while a[j] > piv:
                j -= 1
            if i <= j:
                a[i], a[j] = a[j], a[i]
                i += 1
                j -= 1
        if r <= j:
            hi = j
        elif r >= i:
            lo = i
        else:
            return a[r]
    return a[r]


@njit(cache=True, nogil=True)
def _knn_kernel(P, Ps, order, start, cells, dims, lo, cell, k, s, ordered, out):
    cap = 8 * k + 64
    cd = np.empty(cap)
    ci = np.empty(cap, np.int64)
    tmp = np.empty(cap)
    hist = np.empty(NBUCKET + 1, np.int64)
    for r in range(out.shape[0]):
        cd, ci, tmp = _knn_one(P, Ps, order, start, cells, dims, lo, cell, k, s + r, r, ordered, cd, ci, tmp, hist,
                               out)


@njit(cache=True)
def _knn_one(P, Ps, order, start, cells, dims, lo, cell, k, i, row, ordered, cd, ci, tmp, hist, out, R0=1,
             tau=np.inf):
    """The k nearest of point i into out[row] (sorted by (distance, index) when ``ordered``); returns the
    (possibly grown) scratch buffers.

    Scans the cube of cells at Chebyshev distance <= R of the point's own cell (R = R0, R0 + 1, ...), keeping
    only points closer than ``reach``, the distance to the nearest face of the cube that has cells beyond it (a
    point outside the cube is farther than that), and not farther than ``tau`` (squared; an upper bound of the
    k-th nearest distance known to the caller, or inf): once k are kept they are the k nearest. Cells wholly
    beyond that are not read. The kept points are the same, in the same order, as without ``tau`` once the
    ones beyond the k-th distance are dropped, so the row does not depend on ``tau``."""
    x, y, z = P[i, 0], P[i, 1], P[i, 2]
    cx, cy, cz = cells[i, 0], cells[i, 1], cells[i, 2]
    R = R0
    while True:
        x0, x1 = max(cx - R, 0), min(cx + R, dims[0] - 1)
        y0, y1 = max(cy - R, 0), min(cy + R, dims[1] - 1)
        z0, z1 = max(cz - R, 0), min(cz + R, dims[2] - 1)
        reach = _reach(x, y, z, x0, x1, y0, y1, z0, z1, dims, lo, cell)
        lim = min(reach * reach, tau)
        m = 0
        for ax in range(x0, x1 + 1):
            gx = max(0.0, max(lo[0] + ax * cell - x, x - (lo[0] + (ax + 1) * cell)))
            gx *= gx
            if gx > lim:
                continue
            for ay in range(y0, y1 + 1):
                gy = max(0.0, max(lo[1] + ay * cell - y, y - (lo[1] + (ay + 1) * cell)))
                gy = gx + gy * gy
                if gy > lim:
                    continue
                base = (ax * dims[1] + ay) * dims[2]
                for az in range(z0, z1 + 1):
                    gz = max(0.0, max(lo[2] + az * cell - z, z - (lo[2] + (az + 1) * cell)))
                    if gy + gz * gz > lim:
                        continue  # the whole cell lies beyond reach
                    s, e = start[base + az], start[base + az + 1]
                    if m + (e - s) > cd.shape[0]:  # grow the scratch buffers
                        cap = 2 * (m + e - s)
                        cd2, ci2 = np.empty(cap), np.empty(cap, np.int64)
                        for q in range(m):  # a loop, not a slice assignment (whose shape-mismatch error
                            cd2[q] = cd[q]  # path costs ~2 s of a cold compile)
                            ci2[q] = ci[q]
                        cd, ci, tmp = cd2, ci2, np.empty(cap)
                    for p in range(s, e):   # branch-free: written always, counted when kept
                        u, v, w = Ps[p, 0] - x, Ps[p, 1] - y, Ps[p, 2] - z
                        d = u * u + v * v + w * w
                        cd[m] = d
                        ci[m] = order[p]
                        m += d <= lim
        if m >= k:
            break
        R += 1
    _keep_k(cd, ci, tmp, hist, np.int64(m), k, ordered, out, row, lim)
    return cd, ci, tmp


@njit(cache=True)
def _kth_smallest(a, m, r, top, tmp, hist):
    """The r-th smallest (0-based) of a[:m] (values >= 0, m > r), a unchanged; tmp (>= m) and hist
    (NBUCKET + 1) are scratch.

    A histogram of NBUCKET equal buckets over [0, top] (``top``: a bound of most values, e.g. the squared
    reach they were kept within; inf or 0: their maximum is used; larger values share the last bucket) gives
    the bucket holding rank r, and the rank within that bucket is selected among its few values by
    :func:`_select`. Bucketing is monotone in the value (a product by a positive scale, then truncation), so
    every value of a lower bucket is <= every value of a higher one and the result is exactly the r-th value.
    On the 50-250 values of a neighbour search this is ~3× faster than a quickselect over all of them, whose
    comparisons are mispredicted branches."""
    if not (top > 0.0 and top < np.inf):
        top = 0.0
        for q in range(m):
            top = max(top, a[q])
        if top == 0.0:
            return 0.0
    scale = NBUCKET / top
    if not scale < np.inf:   # top subnormal
        for q in range(m):
            tmp[q] = a[q]
        return _select(tmp, np.int64(m), r)
    for b in range(NBUCKET + 1):
        hist[b] = 0
    for q in range(m):
        hist[int(min(a[q] * scale, float(NBUCKET)))] += 1
    below = 0
    B = 0
    while below + hist[B] <= r:
        below += hist[B]
        B += 1
    c = 0
    for q in range(m):   # the values of bucket B, branch-free
        tmp[c] = a[q]
        c += int(min(a[q] * scale, float(NBUCKET))) == B
    return _select(tmp, np.int64(c), r - below)


@njit(cache=True)
def _keep_k(cd, ci, tmp, hist, m, k, ordered, out, row, top):
    """out[row] = the indices of the k smallest (d², index) among cd[:m], ci[:m] (m >= k): the k-th smallest d²
    (:func:`_kth_smallest`, ``top`` its histogram's range) as threshold, then the ties at it by smallest index
    (sorted by (d², index) when ``ordered``)."""
    thr = _kth_smallest(cd, np.int64(m), np.int64(k - 1), top, tmp, hist)  # int64: one specialisation
    c = 0
    for q in range(m):
        if cd[q] <= thr:
            cd[c] = cd[q]
            ci[c] = ci[q]
            c += 1
    if ordered or c > k:
        # insertion sort by (d², index) of the c (about k) kept: ordered rows, and the ties at the threshold
        for a in range(1, c):
            dv, iv = cd[a], ci[a]
            b = a
            while b > 0 and (cd[b - 1] > dv or (cd[b - 1] == dv and ci[b - 1] > iv)):
                cd[b] = cd[b - 1]
                ci[b] = ci[b - 1]
                b -= 1
            cd[b] = dv
            ci[b] = iv
    for t in range(k):
        out[row, t] = ci[t]


@njit(cache=True)
def _gather(Ps, order, start, dims, x0, x1, y0, y1, z0, z1, bx, by, bz, bi):
    """The points of the cells [x0, x1] × [y0, y1] × [z0, z1] into bx, by, bz (coordinates) and bi (indices),
    cell by cell in (x, y, z) order as :func:`_knn_one` scans them; returns the count and the (possibly grown)
    buffers."""
    n1, n2 = dims[1], dims[2]
    M = 0
    for ax in range(x0, x1 + 1):
        for ay in range(y0, y1 + 1):
            base = (ax * n1 + ay) * n2
            a, b = start[base + z0], start[base + z1 + 1]   # the z-run of cells is contiguous
            if M + (b - a) > bx.shape[0]:
                c2 = 2 * (M + b - a)
                nx, ny, nz, ni = np.empty(c2), np.empty(c2), np.empty(c2), np.empty(c2, np.int64)
                for q in range(M):
                    nx[q], ny[q], nz[q], ni[q] = bx[q], by[q], bz[q], bi[q]
                bx, by, bz, bi = nx, ny, nz, ni
            for q in range(a, b):
                bx[M], by[M], bz[M], bi[M] = Ps[q, 0], Ps[q, 1], Ps[q, 2], order[q]
                M += 1
    return M, bx, by, bz, bi


@njit(cache=True)
def _reach(x, y, z, x0, x1, y0, y1, z0, z1, dims, lo, cell):
    """Distance from (x, y, z) to the nearest face of the cells [x0, x1] × [y0, y1] × [z0, z1] that has cells
    beyond it (inf when none has): every point outside those cells is at least this far."""
    reach = np.inf
    if x0 > 0:
        reach = min(reach, x - (lo[0] + x0 * cell))
    if x1 < dims[0] - 1:
        reach = min(reach, lo[0] + (x1 + 1) * cell - x)
    if y0 > 0:
        reach = min(reach, y - (lo[1] + y0 * cell))
    if y1 < dims[1] - 1:
        reach = min(reach, lo[1] + (y1 + 1) * cell - y)
    if z0 > 0:
        reach = min(reach, z - (lo[2] + z0 * cell))
    if z1 < dims[2] - 1:
        reach = min(reach, lo[2] + (z1 + 1) * cell - z)
    return reach


@njit(cache=True, nogil=True)
def _knn_by_cell(P, Ps, order, start, cells, dims, lo, cell, k, ordered, c0, c1, out):
    """The rows of out (original point order) of the points in cells c0 <= cell < c1 (GIL-free: ranges of cells
    run on threads, each writing its own rows): per nonempty cell, the points of its 3×3×3 block are gathered
    once (coordinates contiguous); each of the cell's points keeps those closer than its reach (the nearest
    face of the block with cells beyond it). A point keeping fewer than k falls back to the 5×5×5 cube (R = 2
    of :func:`_knn_one`, gathered once per cell that has such points), bounded by the k-th distance among the
    block's points (every one of them is a point of the cloud, so the true k-th nearest is no farther), and to
    :func:`_knn_one` from R = 3 if that is not enough either. On CGAL's hippo1 and oni a quarter to a third of
    the points fall back."""
    n0, n1, n2 = dims[0], dims[1], dims[2]
    cap = 8 * k + 64
    bx, by, bz = np.empty(cap), np.empty(cap), np.empty(cap)
    bi = np.empty(cap, np.int64)
    gx, gy, gz = np.empty(cap), np.empty(cap), np.empty(cap)
    gi = np.empty(cap, np.int64)
    cd = np.empty(cap)
    ci = np.empty(cap, np.int64)
    tmp = np.empty(cap)
    hist = np.empty(NBUCKET + 1, np.int64)
    fb = np.empty(64, np.int64)       # the cell's points that fall back, and their bounds
    fbt = np.empty(64)
    for cid in range(c0, c1):
        s, e = start[cid], start[cid + 1]
        if e == s:
            continue
        cx, cy, cz = cid // (n1 * n2), (cid // n2) % n1, cid % n2
        x0, x1 = max(cx - 1, 0), min(cx + 1, n0 - 1)
        y0, y1 = max(cy - 1, 0), min(cy + 1, n1 - 1)
        z0, z1 = max(cz - 1, 0), min(cz + 1, n2 - 1)
        M, bx, by, bz, bi = _gather(Ps, order, start, dims, x0, x1, y0, y1, z0, z1, bx, by, bz, bi)
        if cd.shape[0] < M:
            cd, ci, tmp = np.empty(M), np.empty(M, np.int64), np.empty(M)
        if fb.shape[0] < e - s:
            fb, fbt = np.empty(e - s, np.int64), np.empty(e - s)
        nf = 0
        for p in range(s, e):
            x, y, z = Ps[p, 0], Ps[p, 1], Ps[p, 2]
            reach = _reach(x, y, z, x0, x1, y0, y1, z0, z1, dims, lo, cell)
            lim = reach * reach
            m = 0
            for q in range(M):   # branch-free (about half are kept: a branch would mispredict)
                u, v, w = bx[q] - x, by[q] - y, bz[q] - z
                d = u * u + v * v + w * w
                cd[m] = d
                ci[m] = bi[q]
                m += d <= lim
            if m >= k:
                _keep_k(cd, ci, tmp, hist, np.int64(m), k, ordered, out, order[p], lim)
                continue
            tau = np.inf
            if M >= k:
                for q in range(M):
                    u, v, w = bx[q] - x, by[q] - y, bz[q] - z
                    cd[q] = u * u + v * v + w * w
                tau = _kth_smallest(cd, np.int64(M), np.int64(k - 1), np.inf, tmp, hist)
            fb[nf] = p
            fbt[nf] = tau
            nf += 1
        if nf == 0:
            continue
        X0, X1 = max(cx - 2, 0), min(cx + 2, n0 - 1)
        Y0, Y1 = max(cy - 2, 0), min(cy + 2, n1 - 1)
        Z0, Z1 = max(cz - 2, 0), min(cz + 2, n2 - 1)
        G, gx, gy, gz, gi = _gather(Ps, order, start, dims, X0, X1, Y0, Y1, Z0, Z1, gx, gy, gz, gi)
        if cd.shape[0] < G:
            cd, ci, tmp = np.empty(G), np.empty(G, np.int64), np.empty(G)
        for f in range(nf):
            p = fb[f]
            x, y, z = Ps[p, 0], Ps[p, 1], Ps[p, 2]
            # what _knn_one keeps at R = 2 (the same points in the same order: cells beyond lim hold none)
            reach = _reach(x, y, z, X0, X1, Y0, Y1, Z0, Z1, dims, lo, cell)
            lim = min(reach * reach, fbt[f])
            m = 0
            for q in range(G):
                u, v, w = gx[q] - x, gy[q] - y, gz[q] - z
                d = u * u + v * v + w * w
                cd[m] = d
                ci[m] = gi[q]
                m += d <= lim
            i = order[p]
            if m >= k:
                _keep_k(cd, ci, tmp, hist, np.int64(m), k, ordered, out, i, lim)
            else:
                cd, ci, tmp = _knn_one(P, Ps, order, start, cells, dims, lo, cell, k, i, i, ordered, cd, ci, tmp,
                                       hist, out, 3, fbt[f])
