"""A uniform grid of cell size r/2 over a point set, for "all points within r" queries.

Points are sorted by the linear index ``ix + nx (iy + ny iz)`` of their cell, so consecutive cells of one grid
row (fixed iy, iz) are one contiguous range of the sorted points. ``row_start`` (dense, one entry per row)
gives each row's range of nonempty cells. A query visits the 5 × 5 rows around it, skips rows farther than r
in (y, z), clips each row's x range to the chord of the ball, and scans that one point range. On a surface
cloud with r a few point spacings this touches about twice the points inside the ball, against a
k-nearest-neighbour tree walk that must also order them. Cost: O(n log n) build, O(n + ny nz) memory.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass(frozen=True)
class RadiusGrid:
    """Sorted-cell grid; see the module docstring.

    Attributes
    ----------
    origin : (3,) float64
        Low corner of cell (0, 0, 0).
    cell : float
        Cell size (half the query radius it was built for).
    dims : (3,) int64
        Cells per axis.
    keys : (c,) int64
        Sorted linear indices of the nonempty cells.
    start : (c + 1,) int64
        ``points[start[j]:start[j + 1]]`` lie in cell ``keys[j]``.
    row_start : (ny nz + 1,) int64
        Nonempty cells ``keys[row_start[t]:row_start[t + 1]]`` lie in row ``t = iy + ny iz``.
    points : (n, 3) float64
        The points in cell order.
    order : (n,) int64
        Original index of each sorted point.
    """

    origin: np.ndarray
    cell: float
    dims: np.ndarray
    keys: np.ndarray
    start: np.ndarray
    row_start: np.ndarray
    points: np.ndarray
    order: np.ndarray


def build_radius_grid(P: np.ndarray, r: float, max_rows: int = 1 << 24):
    """Grid for radius-``r`` queries over ``P`` (n, 3); None when it would need more than ``max_rows`` rows
    or ``r`` is not a positive finite number (callers then fall back to a tree)."""
    P = np.ascontiguousarray(P, dtype=np.float64)
    if not (np.isfinite(r) and r > 0) or len(P) == 0:
        return None
    h = 0.5 * r
    lo = P.min(0) - 0.5 * h
    dims = np.floor((P.max(0) + 0.5 * h - lo) / h).astype(np.int64) + 1
    if float(dims[1]) * float(dims[2]) > max_rows or float(np.prod(dims.astype(np.float64))) > 2.0 ** 62:
        return None
    c = np.minimum(np.floor((P - lo) / h).astype(np.int64), dims - 1)
    key = c[:, 0] + dims[0] * (c[:, 1] + dims[1] * c[:, 2])
    order = np.argsort(key, kind="stable")
    ks = key[order]
    keys, first = np.unique(ks, return_index=True)
    start = np.append(first, len(P)).astype(np.int64)
    row_start = np.searchsorted(keys // dims[0], np.arange(dims[1] * dims[2] + 1)).astype(np.int64)
    return RadiusGrid(lo, float(h), dims, keys, start, row_start, np.ascontiguousarray(P[order]),
                      order.astype(np.int64))


@njit(cache=True)
def gather_within(x0, x1, x2, origin, cell, dims, keys, start, row_start, pts, order, r2, cd, ci):
    """Points within sqrt(r2) (<= 2 cells) of x: squared distances into ``cd`` and indices into ``ci`` (only
    the first len(cd) are stored); returns how many there are."""
    cap = cd.shape[0]
    nin = 0
    fx, fy, fz = (x0 - origin[0]) / cell, (x1 - origin[1]) / cell, (x2 - origin[2]) / cell
    rc2 = r2 / (cell * cell)  # radius² in cell units
    rc = np.sqrt(rc2)
    if fx < -rc or fy < -rc or fz < -rc or fx > dims[0] + rc or fy > dims[1] + rc or fz > dims[2] + rc:
        return 0
    z0, z1 = max(int(np.floor(fz - rc)), 0), min(int(np.floor(fz + rc)), dims[2] - 1)
    y0, y1 = max(int(np.floor(fy - rc)), 0), min(int(np.floor(fy + rc)), dims[1] - 1)
    for iz in range(z0, z1 + 1):
        dz = max(iz - fz, 0.0, fz - (iz + 1))
        for iy in range(y0, y1 + 1):
            dy = max(iy - fy, 0.0, fy - (iy + 1))
            rest = rc2 - dy * dy - dz * dz
            if rest < 0.0:
                continue
            chord = np.sqrt(rest)
            xa, xb = max(int(np.floor(fx - chord)), 0), min(int(np.floor(fx + chord)), dims[0] - 1)
            if xa > xb:
                continue
            row = iy + dims[1] * iz
            ca, cb = row_start[row], row_start[row + 1]
            if ca == cb:
                continue
            base = dims[0] * row
            while ca < cb and keys[ca] < base + xa:
                ca += 1
            ce = ca
            while ce < cb and keys[ce] <= base + xb:
                ce += 1
            for e in range(start[ca], start[ce]):
                u, v, w = pts[e, 0] - x0, pts[e, 1] - x1, pts[e, 2] - x2
                d2 = u * u + v * v + w * w
                if d2 <= r2:
                    if nin < cap:
                        cd[nin] = d2
                        ci[nin] = order[e]
                    nin += 1
    return nin
