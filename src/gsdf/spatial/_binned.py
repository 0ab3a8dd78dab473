"""The volume-split build of :func:`gsdf.spatial._bvh.build_bvh` (``split="volume"``), O(n log n) with small
constants.

Each node is split where n_L·r_L³ + n_R·r_R³ is smallest (r = half-diagonal of the child's element box,
n = its element count); the tree layout is the flat preorder one of :mod:`gsdf.spatial._bvh`. What keeps the
build cheap:

* elements are *moved*, not indexed: a working array holds each element's centroid and box (9 numbers) in
  the current order, and a node's partition swaps these rows, so every pass over a node reads memory
  sequentially;
* one pass over a node bins its elements along the two longest axes of its centroid box at once (32 bins
  per axis over the node's centroid box), and the candidate planes are the 2 × 31 bin boundaries (the
  shortest axis, across a surface patch, rarely holds the best plane);
* the partition pass also collects the two children's centroid boxes, and the children's element boxes
  come out of the bins, so no node is read again for its bounds;
* a node of at most :data:`SMALL` elements instead tries every split of its elements sorted along each of
  the same two axes (stable, by ranks): there the bins cost more than the elements, and an exhaustive sweep
  never finds a worse split than the bins. Its prefix / suffix boxes are running bounds, each position's
  cost computed as the bound is extended.

Example
-------
>>> import numpy as np
>>> from gsdf.spatial._bvh import build_bvh
>>> P = np.random.default_rng(0).random((1000, 3))
>>> t = build_bvh(P, P, P, leaf_size=4, split="volume")
>>> bool(np.array_equal(np.sort(t.order), np.arange(1000))), bool((t.end - t.start <= 4)[t.right < 0].all())
(True, True)
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit

from gsdf._memory import scratch

NBINS = 32
#: Nodes with at most this many elements are split by an exhaustive sweep instead of bins (2 × 32 bins cost
#: about as much as sorting and sweeping 24 elements along 2 axes).
SMALL = 24
MINBINS = 8
BINDIV = 1
#: The shortest axis of a node's centroid box is skipped only when it is shorter than the next by more than
#: this fraction: near-ties (as in a symmetric shape) would be decided by rounding, and a translated or
#: scaled copy of the input would get another tree.
TIE = 1e-6
#: Trees over more elements grow their lower subtrees in parallel when numba has more than one thread.
PARALLEL_ELEMENTS = 20_000


@njit(cache=True, inline="always")
def _cube_half_diag(lx, ly, lz, hx, hy, hz):
    """r³ for the half-diagonal r of a box: the volume a far-field ball of the box scales with."""
    dx, dy, dz = hx - lx, hy - ly, hz - lz
    d2 = 0.25 * (dx * dx + dy * dy + dz * dz)
    return d2 * np.sqrt(d2)


@njit(cache=True, inline="always")
def _axes(dx, dy, dz):
    """(a0, a1, a2, na): the axes of a box with extents dx, dy, dz to bin or sweep, the first ``na`` of them:
    the two longest (ascending), or all three (0, 1, 2) when the shortest is within :data:`TIE` of the next."""
    lo = min(dx, min(dy, dz))
    mid = dx + dy + dz - lo - max(dx, max(dy, dz))
    if lo >= (1.0 - TIE) * mid:
        return 0, 1, 2, 3
    if dx == lo:
        return 1, 2, 0, 2
    return (0, 1, 2, 2) if dz == lo else (0, 2, 1, 2)


@njit(cache=True)
def _split_binned(E, order, s, e, b, nb, bins, run, cost, sc, out):
    """Split E[s:e] (rows: centroid, box lo, box hi) at the best of the 2 × 31 bin planes on the two longest
    axes of its centroid box (3 × 31 when its shortest axis is nearly as long, see :func:`_axes`); partitions
    the rows (and ``order``) in place and returns the split index, or −1 when the centroids all coincide.

    ``b`` holds the node's box lo, hi and centroid lo, hi (12); ``nb`` ≤ bins.shape[1] bins per axis. On return
    ``out`` holds the left child's box (6) and centroid box (6), then the right child's. Scratch: bins (3, NBINS,
    7) (one row per binned axis), run (14, NBINS), cost (NBINS,), sc (3,).
    """
    a0, a1, a2, na = _axes(b[9] - b[6], b[10] - b[7], b[11] - b[8])
    for t in range(na):
        a = a0 if t == 0 else (a1 if t == 1 else a2)
        ext = b[9 + a] - b[6 + a]
        sc[t] = nb / ext if ext > 0.0 else 0.0
        for k in range(nb):
            bins[t, k, 0] = 0.0
            for d in range(3):
                bins[t, k, 1 + d] = np.inf
                bins[t, k, 4 + d] = -np.inf
    c0, c1, c2 = b[6 + a0], b[6 + a1], b[6 + a2]
    s0, s1, s2 = sc[0], sc[1], sc[2]
    for j in range(s, e):  # one pass, all axes
        for t in range(na):
            k = min(nb - 1, int((E[j, a0] - c0) * s0) if t == 0 else
                    (int((E[j, a1] - c1) * s1) if t == 1 else int((E[j, a2] - c2) * s2)))
            bins[t, k, 0] += 1.0
            for d in range(3):
                bins[t, k, 1 + d] = min(bins[t, k, 1 + d], E[j, 3 + d])
                bins[t, k, 4 + d] = max(bins[t, k, 4 + d], E[j, 6 + d])
    best = np.inf
    best_t = -1
    best_bin = -1
    for t in range(na):  # the row of bins of axis a0, a1, a2
        if sc[t] == 0.0:
            continue
        # run[0:7, k]: count and box of bins 0..k (left of plane k + 1); run[7:14, k]: of bins k..nb−1
        for d in range(7):
            run[d, 0] = bins[t, 0, d]
            run[7 + d, nb - 1] = bins[t, nb - 1, d]
        for k in range(1, nb):
            run[0, k] = run[0, k - 1] + bins[t, k, 0]
            for d in range(3):
                run[1 + d, k] = min(run[1 + d, k - 1], bins[t, k, 1 + d])
                run[4 + d, k] = max(run[4 + d, k - 1], bins[t, k, 4 + d])
        for k in range(nb - 2, 0, -1):
            run[7, k] = run[7, k + 1] + bins[t, k, 0]
            for d in range(3):
                run[8 + d, k] = min(run[8 + d, k + 1], bins[t, k, 1 + d])
                run[11 + d, k] = max(run[11 + d, k + 1], bins[t, k, 4 + d])
        # cost of plane k (left = bins 0..k−1, right = bins k..nb−1): its own loop, so the roots vectorise
        for k in range(1, nb):
            cost[k] = (run[0, k - 1] * _cube_half_diag(run[1, k - 1], run[2, k - 1], run[3, k - 1],
                                                      run[4, k - 1], run[5, k - 1], run[6, k - 1])
                       + run[7, k] * _cube_half_diag(run[8, k], run[9, k], run[10, k],
                                                     run[11, k], run[12, k], run[13, k]))
        for k in range(nb - 1, 0, -1):
            if run[0, k - 1] == 0.0 or run[7, k] == 0.0:
                continue
            if cost[k] < best:
                best = cost[k]
                best_t = t
                best_bin = k
    if best_t < 0:
        return -1
    best_axis = a0 if best_t == 0 else (a1 if best_t == 1 else a2)
    # children's element boxes: unions of the bins on either side of the plane
    for d in range(3):
        out[d] = out[12 + d] = np.inf
        out[3 + d] = out[15 + d] = -np.inf
        out[6 + d] = out[18 + d] = np.inf
        out[9 + d] = out[21 + d] = -np.inf
    for k in range(nb):
        o = 0 if k < best_bin else 12
        for d in range(3):
            out[o + d] = min(out[o + d], bins[best_t, k, 1 + d])
            out[o + 3 + d] = max(out[o + 3 + d], bins[best_t, k, 4 + d])
    # partition (Hoare: advance from both ends, swap misplaced pairs) collecting the children's centroid boxes
    cmin = b[6 + best_axis]
    scale = sc[best_t]
    i = s
    j = e - 1
    while True:
        while i <= j and min(nb - 1, int((E[i, best_axis] - cmin) * scale)) < best_bin:
            for d in range(3):
                out[6 + d] = min(out[6 + d], E[i, d])
                out[9 + d] = max(out[9 + d], E[i, d])
            i += 1
        while i <= j and min(nb - 1, int((E[j, best_axis] - cmin) * scale)) >= best_bin:
            for d in range(3):
                out[18 + d] = min(out[18 + d], E[j, d])
                out[21 + d] = max(out[21 + d], E[j, d])
            j -= 1
        if i >= j:
            break
        for d in range(9):
            E[i, d], E[j, d] = E[j, d], E[i, d]
        order[i], order[j] = order[j], order[i]
    return i


@njit(cache=True)
def _split_sweep(E, order, s, e, perm, key, pre, tmp, tmpo, out):
    """Split E[s:e] (at most :data:`SMALL` rows) at the cheapest of all positions of its elements sorted by
    centroid along either of the two longest axes of their centroid box (as :func:`_split_binned`; sweeping
    the third as well cost half as much again for the same trees); reorders the rows and returns the split
    index. ``out`` gets the children's boxes (their centroid boxes are not needed: small nodes are split by
    this sweep again).

    Scratch: perm (3, SMALL) int64, key (SMALL,), pre (2, SMALL), tmp (SMALL, 9), tmpo (SMALL,)."""
    n = e - s
    best = np.inf
    best_axis = 0
    best_pos = n // 2
    l0 = l1 = l2 = np.inf
    h0 = h1 = h2 = -np.inf
    for j in range(s, e):
        l0, l1, l2 = min(l0, E[j, 0]), min(l1, E[j, 1]), min(l2, E[j, 2])
        h0, h1, h2 = max(h0, E[j, 0]), max(h1, E[j, 1]), max(h2, E[j, 2])
    a0, a1, a2, na = _axes(h0 - l0, h1 - l1, h2 - l2)
    for t in range(na):
        a = a0 if t == 0 else (a1 if t == 1 else a2)
        p = perm[a]
        key[0] = E[s, a]
        ordered = True  # rows already sorted along a (as a sweep's children are along its axis): identity
        for i in range(1, n):
            key[i] = E[s + i, a]
            ordered &= key[i - 1] <= key[i]
        # stable sort of the local indices by centroid, as ranks: element i goes after the smaller keys and
        # the equal keys before it (the order of an insertion sort, without its chain of dependent loads)
        for i in range(n):
            if ordered:
                p[i] = i
                continue
            v = key[i]
            r = 0
            for j in range(i):
                r += key[j] <= v
            for j in range(i + 1, n):
                r += key[j] < v
            p[r] = i
        # pre[0, i]: (i + 1) r³ of the box of the first i + 1 sorted elements (running bounds); pre[1, i]:
        # (n − i) r³ of the rest
        pl0 = pl1 = pl2 = np.inf
        ph0 = ph1 = ph2 = -np.inf
        for i in range(n - 1):
            r = s + p[i]
            pl0 = min(pl0, E[r, 3])
            pl1 = min(pl1, E[r, 4])
            pl2 = min(pl2, E[r, 5])
            ph0 = max(ph0, E[r, 6])
            ph1 = max(ph1, E[r, 7])
            ph2 = max(ph2, E[r, 8])
            pre[0, i] = (i + 1) * _cube_half_diag(pl0, pl1, pl2, ph0, ph1, ph2)
        pl0 = pl1 = pl2 = np.inf
        ph0 = ph1 = ph2 = -np.inf
        for i in range(n - 1, 0, -1):  # left = first i sorted, right = the rest
            r = s + p[i]
            pl0 = min(pl0, E[r, 3])
            pl1 = min(pl1, E[r, 4])
            pl2 = min(pl2, E[r, 5])
            ph0 = max(ph0, E[r, 6])
            ph1 = max(ph1, E[r, 7])
            ph2 = max(ph2, E[r, 8])
            pre[1, i] = (n - i) * _cube_half_diag(pl0, pl1, pl2, ph0, ph1, ph2)
        for i in range(1, n):
            c = pre[0, i - 1] + pre[1, i]
            # equal costs (coincident or flat elements): the more balanced split, so duplicates give no chains
            if c < best or (c == best and abs(2 * i - n) < abs(2 * best_pos - n)):
                best = c
                best_axis = a
                best_pos = i
    p = perm[best_axis]
    for i in range(n):
        r = s + p[i]
        for d in range(9):
            tmp[i, d] = E[r, d]
        tmpo[i] = order[r]
    for d in range(3):
        out[d] = out[12 + d] = np.inf
        out[3 + d] = out[15 + d] = -np.inf
    for i in range(n):
        for d in range(9):
            E[s + i, d] = tmp[i, d]
        order[s + i] = tmpo[i]
        o = 0 if i < best_pos else 12
        for d in range(3):
            out[o + d] = min(out[o + d], tmp[i, 3 + d])
            out[o + 3 + d] = max(out[o + 3 + d], tmp[i, 6 + d])
    return s + best_pos


@njit(cache=True)
def _halves(E, s, m, e, out):
    """Element and centroid boxes of E[s:m] and E[m:e] into ``out`` (layout of :func:`_split_binned`)."""
    for h in range(2):
        o = 12 * h
        a, z = (s, m) if h == 0 else (m, e)
        for d in range(3):
            out[o + d] = out[o + 6 + d] = np.inf
            out[o + 3 + d] = out[o + 9 + d] = -np.inf
        for j in range(a, z):
            for d in range(3):
                out[o + d] = min(out[o + d], E[j, 3 + d])
                out[o + 3 + d] = max(out[o + 3 + d], E[j, 6 + d])
                out[o + 6 + d] = min(out[o + 6 + d], E[j, d])
                out[o + 9 + d] = max(out[o + 9 + d], E[j, d])


def build_volume(cent, elo, ehi, leaf_size):
    """Preorder arrays (order, start, end, right, skip, lo, hi) of the volume-split tree over elements with
    centroids ``cent`` and boxes ``elo``–``ehi`` (n, 3) (see :class:`gsdf.spatial._bvh.BVH`)."""
    E = np.empty((cent.shape[0], 9))
    E[:, 0:3] = cent
    E[:, 3:6] = elo
    E[:, 6:9] = ehi
    return build_volume_rows(E, leaf_size, numba.get_num_threads())


@njit(cache=True)
def _bigger(a, need):
    """The 2-d array ``a`` with its rows grown (doubled) to hold at least ``need`` rows.

    The copy is an explicit loop: a slice assignment would compile numba's shape-mismatch error path
    (message formatting, ~3 s of a cold build)."""
    cap = a.shape[0]
    while cap < need:
        cap *= 2
    if cap == a.shape[0]:
        return a
    out = np.empty((cap, a.shape[1]), a.dtype)
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            out[i, j] = a[i, j]
    return out


@njit(cache=True, inline="always")
def _put(dst, i, src, o, n):
    """dst[i, 0:n] = src[o:o + n] as a loop (no slice assignment, see :func:`_bigger`)."""
    for d in range(n):
        dst[i, d] = src[o + d]


@njit(cache=True, nogil=True)  # nogil: build_volume_rows grows subtrees on Python threads
def _grow(E, order, s0, e0, b0, leaf_size, cutoff, node_i, node_b, base):
    """Split rows s0:e0 of E (node bounds ``b0``: box lo, hi, centroid lo, hi) top-down into a preorder
    subtree with local node ids 0, 1, ... . A node of at most ``cutoff`` elements (cutoff > leaf_size; 0: none)
    is not split but listed as a task (its subtree is grown later, possibly on another thread).

    Node ``j`` is written to row ``base + j`` of ``node_i`` (int64 [start, end, right, task or −1]) and
    ``node_b`` (box); both are grown (copies returned) if too short. A subtree over n elements has at most
    2n − 1 nodes, so rows base .. base + 2n − 1 always suffice and a task grown into them never reallocates.

    Returns (count, node_i, node_b, ntask, task_i (ntask, 3) [start, end, node], task_b (ntask, 12) bounds).
    """
    task_i = np.empty((16, 3), np.int64)
    task_b = np.empty((16, 12))
    ntask = 0
    # stack of pending nodes: (start, end, parent that takes it as right child) and its 12 bounds
    st_i = np.empty((64, 3), np.int64)
    st_b = np.empty((64, 12))
    st_i[0, 0], st_i[0, 1], st_i[0, 2] = s0, e0, -1
    _put(st_b, 0, b0, 0, 12)
    sp = 1
    count = 0
    bins = np.empty((3, NBINS, 7))
    run_b = np.empty((14, NBINS))
    cost = np.empty(NBINS)
    sc = np.empty(3)
    out = np.empty(24)
    b = np.empty(12)
    perm = np.empty((3, SMALL), np.int64)
    key = np.empty(SMALL)
    pre = np.empty((2, SMALL))
    tmp = np.empty((SMALL, 9))
    tmpo = np.empty(SMALL, np.int64)
    while sp > 0:
        sp -= 1
        s, e, parent = st_i[sp, 0], st_i[sp, 1], st_i[sp, 2]
        for d in range(12):
            b[d] = st_b[sp, d]
        node = count
        count += 1
        row = base + node
        if row >= node_i.shape[0]:
            node_i = _bigger(node_i, row + 1)
            node_b = _bigger(node_b, row + 1)
        node_i[row, 0] = s
        node_i[row, 1] = e
        node_i[row, 2] = -1
        node_i[row, 3] = -1
        for d in range(6):
            node_b[row, d] = b[d]
        if parent >= 0:
            node_i[base + parent, 2] = node
        if e - s <= leaf_size:
            continue
        if e - s <= cutoff:
            if ntask == task_i.shape[0]:
                task_i = _bigger(task_i, ntask + 1)
                task_b = _bigger(task_b, ntask + 1)
            task_i[ntask, 0], task_i[ntask, 1], task_i[ntask, 2] = s, e, node
            _put(task_b, ntask, b, 0, 12)
            node_i[row, 3] = ntask
            ntask += 1
            continue
        if e - s <= SMALL:
            m = _split_sweep(E, order, s, e, perm, key, pre, tmp, tmpo, out)
        else:
            m = _split_binned(E, order, s, e, b, min(NBINS, max(MINBINS, (e - s) // BINDIV)), bins, run_b, cost, sc, out)
            if m < 0:  # every centroid in one point: halve (any order is as good as another)
                m = (s + e) // 2
                _halves(E, s, m, e, out)
        if sp + 2 > st_i.shape[0]:
            st_i = _bigger(st_i, sp + 2)
            st_b = _bigger(st_b, sp + 2)
        # push right first so the left child is popped next and gets id node + 1 (preorder)
        st_i[sp, 0], st_i[sp, 1], st_i[sp, 2] = m, e, node
        _put(st_b, sp, out, 12, 12)
        sp += 1
        st_i[sp, 0], st_i[sp, 1], st_i[sp, 2] = s, m, -1
        _put(st_b, sp, out, 0, 12)
        sp += 1
    return count, node_i, node_b, ntask, task_i, task_b


def build_volume_rows(E, leaf_size, threads=1, root=None):
    """:func:`build_volume` on one (n, 9) float64 array of rows [centroid, box lo, box hi], which it reorders
    in place (to tree order: row j is then element ``order[j]``). ``root``: the rows' bounds (12: box lo, hi,
    centroid lo, hi), or None to compute them.

    With ``threads`` > 1 (numba's current thread count) and more than :data:`PARALLEL_ELEMENTS` rows, the top
    of the tree is split down to nodes of about n/64 elements (the root on the calling thread, then its two
    halves at once), whose subtrees are grown on ``threads`` Python threads as soon as their half is done
    (:func:`_parallel_grow`; :func:`_grow` releases the GIL; the subtrees own disjoint rows) and
    spliced into the preorder arrays by :func:`_splice` (the same tree as the serial build). Both builds are
    the one compiled kernel :func:`_grow` driven from here: no parallel numba kernel (a parfor over the tasks
    would compile for seconds on a cold start, for a build of 0.05-0.3 s)."""
    n = E.shape[0]
    order = np.arange(n, dtype=np.int64)
    root = _root_bounds(E) if root is None else np.ascontiguousarray(root, dtype=np.float64)
    if threads > 1 and n > PARALLEL_ELEMENTS:
        cutoff = max(leaf_size + 1, n // 64)
        # task t's subtree goes to rows 2 s .. 2 e − 1 (s:e its elements): disjoint, and never too short
        sub_i = scratch("tree.node_i", (2 * n, 4), np.int64)
        sub_b = scratch("tree.node_b", (2 * n, 6))
        kt, top_i, top_b, ntask, task_i, counts = _parallel_grow(E, order, root, leaf_size, cutoff, threads,
                                                                 sub_i, sub_b)
        start, end, right, lo, hi = _splice(kt, top_i, top_b, task_i[:ntask], counts, sub_i, sub_b)
    else:
        node_i = scratch("tree.node_i", (2 * n, 4), np.int64)  # temporaries: the columns are copied out
        node_b = scratch("tree.node_b", (2 * n, 6))
        k, node_i, node_b, _, _, _ = _grow(E, order, 0, n, root, leaf_size, 0, node_i, node_b, 0)
        start, end, right = (node_i[:k, c].copy() for c in range(3))
        lo, hi = node_b[:k, 0:3].copy(), node_b[:k, 3:6].copy()
    return order, start, end, right, _skips(right), lo, hi


def _parallel_grow(E, order, root, leaf_size, cutoff, threads, sub_i, sub_b):
    """The tree on ``threads`` Python threads: the top down to nodes of at most ``cutoff`` elements (the
    tasks), as :func:`_grow` with that cutoff returns it, and every task's subtree, grown into rows
    2·start .. of ``sub_i`` / ``sub_b``. Returns (kt, top_i, top_b, ntask, task_i, counts) for :func:`_splice`.

    The root is split on the calling thread; then the two halves below it are grown at the same time, and a thread
    whose half is done takes the largest task published so far (its own half's or the other's) instead of
    waiting for the other half (the halves can differ much in size). One :func:`_grow` kernel throughout, so the
    same tree as the serial build: the root's split, then each child's subtree, numbered root, left's nodes,
    right's."""
    n = E.shape[0]
    # the root alone: nodes of at most n − 1 elements (its two children) become tasks
    k0, i0, b0, nt0, ti0, tb0 = _grow(E, order, 0, n, root, leaf_size, n - 1, np.empty((4, 4), np.int64),
                                      np.empty((4, 6)), 0)
    import heapq
    import threading

    from gsdf.threads import run_tasks

    if k0 != 3 or nt0 != 2:  # root is a leaf (cannot happen above PARALLEL_ELEMENTS), or not split in two
        kt, top_i, top_b, ntask, task_i, task_b = _grow(E, order, 0, n, root, leaf_size, cutoff,
                                                        np.empty((256, 4), np.int64), np.empty((256, 6)), 0)
        counts = np.empty(ntask, np.int64)

        def grow_task(t):
            s, e = task_i[t, 0], task_i[t, 1]
            counts[t] = _grow(E, order, s, e, task_b[t], leaf_size, 0, sub_i, sub_b, 2 * s)[0]

        run_tasks(grow_task, np.argsort(task_i[:ntask, 0] - task_i[:ntask, 1], kind="stable"), threads)
        return kt, top_i, top_b, ntask, task_i, counts
    halves = [None, None]
    counts_h = [None, None]
    pending = []  # heap of (−elements, half, task): the largest published task first
    cond = threading.Condition()
    state = [0, 0]  # halves claimed, halves published

    def worker(_):
        with cond:
            h = state[0]
            state[0] += 1
        if h < 2:
            res = _grow(E, order, ti0[h, 0], ti0[h, 1], tb0[h], leaf_size, cutoff, np.empty((128, 4), np.int64),
                        np.empty((128, 6)), 0)
            halves[h] = res
            nt, ti = res[3], res[4]
            counts_h[h] = np.empty(nt, np.int64)
            with cond:
                for t in range(nt):
                    heapq.heappush(pending, (int(ti[t, 0] - ti[t, 1]), h, t))
                state[1] += 1
                cond.notify_all()
        while True:
            with cond:
                # a thread only waits for a half that a running thread has claimed: no deadlock
                while not pending and state[1] < 2:
                    cond.wait()
                if not pending:
                    return
                _, h, t = heapq.heappop(pending)
            ti, tb = halves[h][4], halves[h][5]
            s = ti[t, 0]
            counts_h[h][t] = _grow(E, order, s, ti[t, 1], tb[t], leaf_size, 0, sub_i, sub_b, 2 * s)[0]

    run_tasks(worker, range(threads), threads)
    (kl, il, bl, ntl, tl, _), (kr, ir, br, ntr, tr, _) = halves
    kt = 1 + kl + kr
    top_i = np.empty((kt, 4), np.int64)
    top_b = np.empty((kt, 6))
    top_i[0] = (0, n, 1 + kl, -1)
    top_b[0] = b0[0]
    for off, k, ih, bh, toff in ((1, kl, il, bl, 0), (1 + kl, kr, ir, br, ntl)):
        rows = top_i[off:off + k]
        rows[:, 0:2] = ih[:k, 0:2]
        rows[:, 2] = np.where(ih[:k, 2] >= 0, ih[:k, 2] + off, -1)
        rows[:, 3] = np.where(ih[:k, 3] >= 0, ih[:k, 3] + toff, -1)
        top_b[off:off + k] = bh[:k]
    task_i = np.concatenate((tl[:ntl], tr[:ntr]))
    task_i[:ntl, 2] += 1
    task_i[ntl:, 2] += 1 + kl
    return kt, top_i, top_b, ntl + ntr, task_i, np.concatenate(counts_h)


@njit(cache=True)
def _root_bounds(E):
    """Box lo, hi and centroid lo, hi (12) of all rows of E."""
    # running bounds in scalars (not in ``root``: its stores and reloads chained every row, 0.85 ms at 89k)
    lx = ly = lz = cx0 = cy0 = cz0 = np.inf
    hx = hy = hz = cx1 = cy1 = cz1 = -np.inf
    for i in range(E.shape[0]):
        lx, ly, lz = min(lx, E[i, 3]), min(ly, E[i, 4]), min(lz, E[i, 5])
        hx, hy, hz = max(hx, E[i, 6]), max(hy, E[i, 7]), max(hz, E[i, 8])
        cx0, cy0, cz0 = min(cx0, E[i, 0]), min(cy0, E[i, 1]), min(cz0, E[i, 2])
        cx1, cy1, cz1 = max(cx1, E[i, 0]), max(cy1, E[i, 1]), max(cz1, E[i, 2])
    root = np.empty(12)
    root[0], root[1], root[2], root[3], root[4], root[5] = lx, ly, lz, hx, hy, hz
    root[6], root[7], root[8], root[9], root[10], root[11] = cx0, cy0, cz0, cx1, cy1, cz1
    return root


@njit(cache=True)
def _skips(right):
    """Preorder skip pointers: the node after node i's subtree. A leaf's is i + 1; an internal node's subtree
    ends where its right child's does, so one backward pass gives them all (O(k))."""
    k = right.shape[0]
    skip = np.empty(k, np.int64)
    for i in range(k - 1, -1, -1):
        r = right[i]
        skip[i] = i + 1 if r < 0 else skip[r]
    return skip


@njit(cache=True)
def _splice(kt, top_i, top_b, task_i, counts, sub_i, sub_b):
    """Final preorder arrays (start, end, right, lo, hi): the top tree's ``kt`` nodes in order, each task
    node replaced by its subtree (task t's ``counts[t]`` nodes at rows 2·start_t … of sub_i / sub_b).
    One serial pass of row copies (~1 ms at 89k faces; numpy's fancy indexing took ~5)."""
    final = np.empty(kt, np.int64)  # where each top node's subtree starts
    k = 0
    for i in range(kt):
        final[i] = k
        t = top_i[i, 3]
        k += counts[t] if t >= 0 else 1
    start, end, right = np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k, np.int64)
    lo, hi = np.empty((k, 3)), np.empty((k, 3))
    for i in range(kt):
        f = final[i]
        t = top_i[i, 3]
        if t < 0:  # a top node that stays
            start[f], end[f] = top_i[i, 0], top_i[i, 1]
            r = top_i[i, 2]
            right[f] = final[r] if r >= 0 else -1
            for d in range(3):
                lo[f, d] = top_b[i, d]
                hi[f, d] = top_b[i, 3 + d]
            continue
        row = 2 * task_i[t, 0]  # node j of task t goes to f + j, from row 2·start_t + j
        for j in range(counts[t]):
            start[f + j], end[f + j] = sub_i[row + j, 0], sub_i[row + j, 1]
            r = sub_i[row + j, 2]
            right[f + j] = f + r if r >= 0 else -1
            for d in range(3):
                lo[f + j, d] = sub_b[row + j, d]
                hi[f + j, d] = sub_b[row + j, 3 + d]
    return start, end, right, lo, hi
