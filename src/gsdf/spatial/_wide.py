"""Wide (4- or 8-child) view of a binary :class:`gsdf.spatial._bvh.BVH`, for walks that test several children
at once.

A wide node is an internal node of the binary tree; its children are found by repeatedly replacing the
largest internal child (most elements) by its two children until there are ``width`` of them or only leaves
are left. Every child is a node of the binary tree, so data computed per binary node (boxes, Taylor
moments) is gathered per wide node by indexing with :attr:`WideBVH.kids`. Wide nodes are numbered in
depth-first preorder, so a walk that pushes children in order reads memory mostly forwards.

Cost: O(k) for k binary nodes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from gsdf.spatial._bvh import BVH


@dataclass(frozen=True)
class WideBVH:
    """Wide tree over the nodes of a binary BVH.

    Attributes
    ----------
    kids : (w, width) int64
        Binary node id of each child slot, ``-1`` for an empty slot.
    child : (w, width) int64
        Wide node id of each child that is itself a wide node (an internal binary node); ``-1`` for a child
        that is a binary leaf, ``-2`` for an empty slot.
    depth : int
        Number of wide levels (bounds the walk's stack: ``depth * (width - 1) + 1`` entries).
    """

    kids: np.ndarray
    child: np.ndarray
    depth: int

    @property
    def width(self) -> int:
        return int(self.kids.shape[1])

    @property
    def n_nodes(self) -> int:
        return int(self.kids.shape[0])


def widen(tree: BVH, width: int = 4) -> WideBVH:
    """Collapse a binary BVH into a ``width``-ary one (width ≥ 2).

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.spatial._bvh import build_point_bvh
    >>> w = widen(build_point_bvh(np.random.default_rng(0).random((100, 3)), leaf_size=4), 4)
    >>> w.kids.shape[1], bool((w.child[0] >= -1).all())
    (4, True)
    """
    if width < 2:
        raise ValueError(f"width must be >= 2, got {width}")
    kids, child, depth = _collapse(tree.right, tree.start, tree.end, int(width))
    return WideBVH(kids, child, int(depth))


@njit(cache=True, nogil=True)  # nogil: the triangle winding build runs it beside the moments' threads
def _collapse(right, start, end, width):
    k = right.shape[0]
    cap = max(1, k)
    kids = np.full((cap, width), -1, np.int64)
    wide_of = np.full(k, -1, np.int64)
    level = np.zeros(k, np.int64)
    stack = np.empty(k + 1, np.int64)
    buf = np.empty(width, np.int64)
    stack[0] = 0
    sp = 1
    count = 0
    depth = 0
    while sp > 0:
        sp -= 1
        b = stack[sp]
        n = count
        count += 1
        wide_of[b] = n
        depth = max(depth, level[b] + 1)
        if right[b] < 0:  # a root that is a leaf: one wide node with that leaf as its only child
            buf[0] = b
            m = 1
        else:
            buf[0] = b + 1
            buf[1] = right[b]
            m = 2
            while m < width:
                best = -1
                most = 0
                for j in range(m):
                    c = buf[j]
                    if right[c] >= 0 and end[c] - start[c] > most:
                        most = end[c] - start[c]
                        best = j
                if best < 0:
                    break
                c = buf[best]
                # keep the slots in tree order: the two children take the place of their parent
                for j in range(m, best + 1, -1):
                    buf[j] = buf[j - 1]
                buf[best] = c + 1
                buf[best + 1] = right[c]
                m += 1
        for j in range(m):
            kids[n, j] = buf[j]
        for j in range(m - 1, -1, -1):  # reverse, so the first child is popped (numbered) next
            c = buf[j]
            if c != b and right[c] >= 0:
                level[c] = level[b] + 1
                stack[sp] = c
                sp += 1
    kids = kids[:count].copy()
    child = np.full((count, width), -2, np.int64)
    for n in range(count):
        for j in range(width):
            c = kids[n, j]
            if c >= 0:
                child[n, j] = wide_of[c] if right[c] >= 0 else -1  # the root is a kid only when it is a leaf
    return kids, child, depth
