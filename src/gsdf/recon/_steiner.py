"""Sparse octree-guided Steiner points for the Delaunay tetrahedralisation (seed 003 §5.1, notes 2(b)).

The bounding box, padded by 10 %, is the root cell of an octree; cells containing input points are split
until their size is about twice the median nearest-neighbour spacing.  The centres of the empty leaves
(coarse far away, fine next to the surface) become Steiner points, so surface faces have tets on both sides
and the outside is tetrahedralised with few, well-shaped tets.  Centres are jittered slightly because Qhull
degenerates on exactly regular grids.

Example
-------
>>> import numpy as np
>>> from gsdf.recon._steiner import octree_steiner_points
>>> P = np.random.default_rng(0).normal(size=(500, 3))
>>> S = octree_steiner_points(P, spacing=0.2)
>>> S.shape[1], bool(len(S) > 0)
(3, True)
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["octree_steiner_points"]


def octree_steiner_points(P: np.ndarray, spacing: float, pad: float = 0.1, leaf: float = 2.0, min_gap: float = 2.0,
                          seed: int = 0) -> np.ndarray:
    """Centres of the empty leaves of the point octree, farther than ``min_gap * spacing`` from ``P``.

    Parameters
    ----------
    P : (n, 3) float — input points.
    spacing : float — typical point spacing (median nearest-neighbour distance).
    pad : float — bounding-box padding, relative to its largest side.
    leaf : float — point-containing cells are split while larger than ``leaf * spacing``.
    min_gap, seed : float, int — Steiner points too close to P are dropped; jitter seed.

    Returns
    -------
    (s, 3) float64 Steiner points (levels are a loop of depth ~log2(size / spacing); no loop over cells).
    """
    lo, hi = P.min(axis=0), P.max(axis=0)
    size = float((hi - lo).max()) * (1.0 + 2.0 * pad)
    if size <= 0:
        return np.zeros((0, 3))
    centre = 0.5 * (lo + hi)
    origin = centre - 0.5 * size
    depth = max(1, int(np.ceil(np.log2(size / max(leaf * spacing, 1e-12)))))
    depth = min(depth, 12)
    out = []
    occupied = np.zeros((1, 3), dtype=np.int64)  # level-0 cell
    child_offsets = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=np.int64)
    for level in range(1, depth + 1):
        n = 1 << level
        cell = size / n
        keys = np.clip(np.floor((P - origin) / cell).astype(np.int64), 0, n - 1)
        occ = np.unique(keys, axis=0)
        children = (2 * occupied[:, None, :] + child_offsets[None]).reshape(-1, 3)
        code = lambda A: (A[:, 0] * n + A[:, 1]) * n + A[:, 2]  # noqa: E731
        empty = children[~np.isin(code(children), code(occ))]
        out.append(origin + (empty + 0.5) * cell)
        occupied = occ
    S = np.concatenate(out) if out else np.zeros((0, 3))
    if len(S):
        d, _ = cKDTree(P).query(S)
        S = S[d > min_gap * spacing]
        S = S + np.random.default_rng(seed).uniform(-1e-6, 1e-6, S.shape) * size
    return np.ascontiguousarray(S)
