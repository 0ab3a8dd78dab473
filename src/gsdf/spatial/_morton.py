"""Morton (Z-order) sorting of query points, so consecutive queries walk similar tree paths (cache reuse)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _spread(x):
    # spread the low 21 bits of x so that there are two zero bits between each
    x &= 0x1FFFFF
    x = (x | (x << 32)) & 0x1F00000000FFFF
    x = (x | (x << 16)) & 0x1F0000FF0000FF
    x = (x | (x << 8)) & 0x100F00F00F00F00F
    x = (x | (x << 4)) & 0x10C30C30C30C30C3
    x = (x | (x << 2)) & 0x1249249249249249
    return x


def morton_codes(Q):
    """63-bit Morton codes of points Q (n, 3), quantized on their own bounding box."""
    return _codes(Q, Q.min(axis=0), Q.max(axis=0))


@njit(cache=True)  # serial: ~10 ns per point, a parallel loop would only add ~1 s of compilation
def _codes(Q, lo, hi):
    n = Q.shape[0]
    codes = np.empty(n, np.int64)
    scale = np.empty(3)
    for d in range(3):
        ext = hi[d] - lo[d]
        scale[d] = (2**21 - 1) / ext if ext > 0 else 0.0
    for i in range(n):
        c = 0
        for d in range(3):
            g = np.int64((Q[i, d] - lo[d]) * scale[d])
            c |= _spread(g) << d
        codes[i] = c
    return codes


def morton_order(Q: np.ndarray) -> np.ndarray:
    """Permutation that sorts points ``Q`` (n, 3) along the Z-order curve."""
    if Q.shape[0] < 2:
        return np.arange(Q.shape[0])
    return np.argsort(morton_codes(Q), kind="stable")


def cell_order(Q: np.ndarray) -> np.ndarray:
    """Permutation grouping points ``Q`` (n, 3) by cells of a coarse Morton grid (at most 2^15 cells, so the
    counts stay in cache; about 4 points per cell for small n), cells in Z-order: the locality of :func:`morton_order` for tree walks at O(n) cost (one counting sort,
    no comparison sort). Points inside one cell keep their input order.

    Example
    -------
    >>> import numpy as np
    >>> Q = np.random.default_rng(0).random((1000, 3))
    >>> o = cell_order(Q)
    >>> bool((np.sort(o) == np.arange(1000)).all())
    True
    """
    n = Q.shape[0]
    if n < 2:
        return np.arange(n)
    # 2^(3 bits) cells, at most 2^15 (the histogram stays in the L2 cache)
    bits = int(min(5, max(1, round(np.log2(max(n / 4, 2)) / 3))))
    lo, hi = _bounds(Q)
    return _counting_order(Q, lo, hi, bits)


def gather_rows(Q: np.ndarray, order: np.ndarray) -> np.ndarray:
    """``Q[order]`` as a new C-contiguous (n, 3) float64 array (one compiled pass)."""
    return _gather(Q, order)


@njit(cache=True)
def _gather(Q, order):
    out = np.empty((order.shape[0], 3))
    for i in range(order.shape[0]):
        j = order[i]
        out[i, 0] = Q[j, 0]
        out[i, 1] = Q[j, 1]
        out[i, 2] = Q[j, 2]
    return out


@njit(cache=True)
def _bounds(Q):  # one pass; numpy's axis-0 min/max on (n, 3) rows is several times slower
    lo = Q[0].copy()
    hi = Q[0].copy()
    for i in range(1, Q.shape[0]):
        for d in range(3):
            x = Q[i, d]
            if x < lo[d]:
                lo[d] = x
            elif x > hi[d]:
                hi[d] = x
    return lo, hi


@njit(cache=True)  # serial: ~10 ns per point; a parallel launch costs more than that under load
def _counting_order(Q, lo, hi, bits):
    n = Q.shape[0]
    cells = 1 << (3 * bits)
    top = (1 << bits) - 1
    scale = np.empty(3)
    for d in range(3):
        ext = hi[d] - lo[d]
        scale[d] = (top + 1) / ext if ext > 0 else 0.0
    code = np.empty(n, np.int64)
    count = np.zeros(cells + 1, np.int64)
    for i in range(n):
        c = 0
        for d in range(3):
            g = min(top, np.int64((Q[i, d] - lo[d]) * scale[d]))
            c |= _spread(g) << d
        code[i] = c
    for i in range(n):
        count[code[i] + 1] += 1
    for c in range(cells):
        count[c + 1] += count[c]
    order = np.empty(n, np.int64)
    for i in range(n):
        c = code[i]
        order[count[c]] = i
        count[c] += 1
    return order
