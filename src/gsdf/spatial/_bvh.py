"""A bounding volume hierarchy over boxed elements (triangles or points), built once and queried many times.

The tree is binary, split at the median centroid along the longest axis of the node's centroid box, and
stored flat in *preorder*: the left child of an internal node ``i`` is ``i + 1``, its right child is
``right[i]``, and ``skip[i]`` is the first node after the subtree of ``i``. Queries can therefore walk the
tree without a stack ("descend: i + 1, prune: skip[i]"), which is what the numba kernels in
:mod:`gsdf.winding` and :mod:`gsdf.distance` do.

Cost: O(n log n) to build (median by quickselect), O(n) memory.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numba import njit

from gsdf.spatial._binned import build_volume, build_volume_rows


@dataclass(frozen=True)
class BVH:
    """Flat preorder bounding volume hierarchy.

    Attributes
    ----------
    order : (n,) int64
        Element permutation; node ``i`` holds elements ``order[start[i]:end[i]]``.
    start, end : (k,) int64
        Element ranges of each node in ``order``.
    right : (k,) int64
        Right child of each node, ``-1`` for leaves (the left child is ``i + 1``).
    skip : (k,) int64
        Index of the first node after the subtree rooted at ``i``.
    lo, hi : (k, 3) float64
        Axis-aligned bounding box of each node's elements.
    """

    order: np.ndarray
    start: np.ndarray
    end: np.ndarray
    right: np.ndarray
    skip: np.ndarray
    lo: np.ndarray
    hi: np.ndarray

    @property
    def n_nodes(self) -> int:
        return int(self.start.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.order.shape[0])


def build_bvh(centroids: np.ndarray, elem_lo: np.ndarray, elem_hi: np.ndarray, leaf_size: int = 8,
              split: str = "median") -> BVH:
    """Build a BVH over elements with the given centroids and bounding boxes (all (n, 3) float64).

    ``split="median"`` halves each node at the median centroid of its longest centroid axis (balanced tree).
    ``split="volume"`` picks, among 2 × 32 binned centroid planes on the two longest axes of the node's
    centroid box (every position of the sorted elements in nodes of at most 24), the split minimising n_L·vol(box_L) + n_R·vol(box_R) (box = child's element
    bounding box, volume taken as the cube of its half-diagonal so flat boxes still count); built by
    :func:`gsdf.spatial._binned.build_volume`. A node is opened by a uniformly distributed query with
    probability ∝ the volume of its far-field ball, so this keeps the far-field walk short on thin or
    elongated shapes where median splits produce long, thin boxes.

    Example
    -------
    >>> import numpy as np
    >>> P = np.random.default_rng(0).random((100, 3))
    >>> t = build_bvh(P, P, P, leaf_size=4, split="volume")
    >>> t.n_elements, bool(t.skip[0] == t.n_nodes)
    (100, True)
    """
    if split not in ("median", "volume"):
        raise ValueError(f"split must be 'median' or 'volume', got {split!r}")
    n = centroids.shape[0]
    if n == 0:
        raise ValueError("cannot build a tree over zero elements")
    if leaf_size < 1:
        raise ValueError(f"leaf_size must be >= 1, got {leaf_size}")
    cent = np.ascontiguousarray(centroids, dtype=np.float64)
    elo = np.ascontiguousarray(elem_lo, dtype=np.float64)
    ehi = np.ascontiguousarray(elem_hi, dtype=np.float64)
    if split == "volume":
        arrays = build_volume(cent, elo, ehi, int(leaf_size))
    else:
        arrays = _build(cent, elo, ehi, int(leaf_size))
    return BVH(*arrays)


def build_volume_bvh(E: np.ndarray, leaf_size: int = 4, root: np.ndarray | None = None) -> BVH:
    """Volume-split BVH (as ``build_bvh(..., split="volume")``) over elements given as one (n, 9) float64
    C-contiguous array of rows [centroid, box lo, box hi]. ``E`` is reordered in place into tree order (row
    ``j`` becomes element ``order[j]``), which saves the callers a gather. ``root``: the rows' bounds (12:
    box lo, hi, centroid lo, hi) if the caller has them (saves a pass over the rows), else computed.

    Example
    -------
    >>> import numpy as np
    >>> P = np.random.default_rng(0).random((50, 3))
    >>> E = np.hstack([P, P, P])
    >>> t = build_volume_bvh(E, 4)
    >>> bool(np.array_equal(E[:, :3], P[t.order]))
    True
    """
    if E.ndim != 2 or E.shape[1] != 9 or E.dtype != np.float64 or not E.flags.c_contiguous:
        raise ValueError(f"E: expected a C-contiguous (n, 9) float64 array, got {E.dtype} {E.shape}")
    if E.shape[0] == 0:
        raise ValueError("cannot build a tree over zero elements")
    if leaf_size < 1:
        raise ValueError(f"leaf_size must be >= 1, got {leaf_size}")
    return BVH(*build_volume_rows(E, int(leaf_size), numba.get_num_threads(), root))


def build_point_bvh(P: np.ndarray, leaf_size: int = 8) -> BVH:
    """BVH over points (each point is its own box)."""
    P = np.ascontiguousarray(P, dtype=np.float64)
    return build_bvh(P, P, P, leaf_size)


def build_triangle_bvh(V: np.ndarray, F: np.ndarray, leaf_size: int = 8) -> BVH:
    """BVH over the triangles ``F`` of vertex array ``V``."""
    T = V[F]  # (m, 3, 3)
    return build_bvh(T.mean(axis=1), T.min(axis=1), T.max(axis=1), leaf_size)


@njit(cache=True)
def _select(order, key, lo, hi, k):
    """Reorder order[lo:hi] so that key[order[k]] is the k-th smallest and is partitioned around it."""
    while hi - lo > 1:
        # median of three pivot
        mid = (lo + hi - 1) // 2
        a, b, c = key[order[lo]], key[order[mid]], key[order[hi - 1]]
        if (a <= b <= c) or (c <= b <= a):
            pivot = b
        elif (b <= a <= c) or (c <= a <= b):
            pivot = a
        else:
            pivot = c
        # three-way partition (Dutch national flag) so equal keys cannot stall the loop
        lt, i, gt = lo, lo, hi - 1
        while i <= gt:
            v = key[order[i]]
            if v < pivot:
                order[lt], order[i] = order[i], order[lt]
                lt += 1
                i += 1
            elif v > pivot:
                order[gt], order[i] = order[i], order[gt]
                gt -= 1
            else:
                i += 1
        if k < lt:
            hi = lt
        elif k > gt:
            lo = gt + 1
        else:
            return


@njit(cache=True)
def _build(cent, elo, ehi, leaf_size):
    n = cent.shape[0]
    order = np.arange(n)
    cap = 2 * n + 1  # a binary tree whose leaves are nonempty has at most 2n - 1 nodes
    start = np.empty(cap, np.int64)
    end = np.empty(cap, np.int64)
    right = np.full(cap, -1, np.int64)
    # explicit stack of (start, end, parent-that-wants-this-as-right-child)
    st_s = np.empty(128, np.int64)
    st_e = np.empty(128, np.int64)
    st_p = np.empty(128, np.int64)
    sp = 0
    st_s[0] = 0
    st_e[0] = n
    st_p[0] = -1
    sp = 1
    count = 0
    key = np.empty(n, np.float64)
    while sp > 0:
        sp -= 1
        s = st_s[sp]
        e = st_e[sp]
        parent = st_p[sp]
        node = count
        count += 1
        start[node] = s
        end[node] = e
        if parent >= 0:
            right[parent] = node
        if e - s <= leaf_size:
            continue
        # longest axis of the centroid box
        cmin0 = cmin1 = cmin2 = np.inf
        cmax0 = cmax1 = cmax2 = -np.inf
        for j in range(s, e):
            t = order[j]
            x, y, z = cent[t, 0], cent[t, 1], cent[t, 2]
            cmin0 = min(cmin0, x)
            cmax0 = max(cmax0, x)
            cmin1 = min(cmin1, y)
            cmax1 = max(cmax1, y)
            cmin2 = min(cmin2, z)
            cmax2 = max(cmax2, z)
        ext0, ext1, ext2 = cmax0 - cmin0, cmax1 - cmin1, cmax2 - cmin2
        axis = 0
        if ext1 > ext0 and ext1 >= ext2:
            axis = 1
        elif ext2 > ext0 and ext2 > ext1:
            axis = 2
        for j in range(s, e):
            t = order[j]
            key[t] = cent[t, axis]
        m = (s + e) // 2
        _select(order, key, s, e, m)
        if sp + 2 > st_s.shape[0]:
            st_s = np.concatenate((st_s, np.empty(st_s.shape[0], np.int64)))
            st_e = np.concatenate((st_e, np.empty(st_e.shape[0], np.int64)))
            st_p = np.concatenate((st_p, np.empty(st_p.shape[0], np.int64)))
        # push right first so the left child is popped next and gets id node + 1 (preorder)
        st_s[sp] = m
        st_e[sp] = e
        st_p[sp] = node
        sp += 1
        st_s[sp] = s
        st_e[sp] = m
        st_p[sp] = -1
        sp += 1
    k = count
    start = start[:k].copy()
    end = end[:k].copy()
    right = right[:k].copy()
    size = np.ones(k, np.int64)
    lo = np.empty((k, 3), np.float64)
    hi = np.empty((k, 3), np.float64)
    for i in range(k - 1, -1, -1):
        r = right[i]
        if r < 0:
            for d in range(3):
                lo[i, d] = np.inf
                hi[i, d] = -np.inf
            for j in range(start[i], end[i]):
                t = order[j]
                for d in range(3):
                    lo[i, d] = min(lo[i, d], elo[t, d])
                    hi[i, d] = max(hi[i, d], ehi[t, d])
        else:
            size[i] = 1 + size[i + 1] + size[r]
            for d in range(3):
                lo[i, d] = min(lo[i + 1, d], lo[r, d])
                hi[i, d] = max(hi[i + 1, d], hi[r, d])
    skip = np.arange(k) + size
    return order, start, end, right, skip, lo, hi
