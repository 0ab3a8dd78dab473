"""The data of the L1 dual-graph program shared by its solvers (:mod:`gsdf.linalg._dual_l1` on HiGHS,
:mod:`gsdf.linalg._netflow`, :mod:`gsdf.linalg._band_lp`): the result type and the checked inputs.

Example
-------
>>> n, P, d, w, lo, hi, first, lab = _checked_terms(2, [[0, 1]], [0.5], [1.0], None, 1.0, "component")
>>> P.tolist(), first.tolist()
([[0, 1]], [0])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

__all__ = ["DualL1Result"]


@dataclass
class DualL1Result:
    """Solution of :func:`dual_graph_l1`.

    Attributes
    ----------
    shifts : (n_cells,) the per-cell shifts x (0 at each component's gauge cell)
    jumps : (k,) J = d + x_A - x_B per dual edge
    objective : Σ w |J|
    seconds : wall time of HiGHS
    """

    shifts: np.ndarray
    jumps: np.ndarray
    objective: float
    seconds: float


def _check_1d(a, k, name, default=None):
    if a is None:
        return default
    A = np.asarray(a, dtype=np.float64) if not (np.asarray(a).dtype == bool) else None
    if A is None:
        raise ValueError(f"{name}: expected real numbers, got booleans")
    if A.shape != (k,):
        raise ValueError(f"{name}: expected shape ({k},), got {A.shape}")
    return A


def _checked_terms(n_cells, pairs, offsets, weights, bounds, time_limit, gauge):
    """Validated data of the L1 program: (n, pairs (k, 2), d, w, lo, hi, gauge cells or None, component label
    per cell or None). ValueError naming the argument otherwise."""
    if isinstance(n_cells, (bool, np.bool_)) or not isinstance(n_cells, (int, np.integer)) or n_cells < 1:
        raise ValueError(f"n_cells: expected a positive integer, got {n_cells!r}")
    n = int(n_cells)
    P = np.asarray(pairs)
    if P.dtype == bool or not (np.issubdtype(P.dtype, np.integer) or P.size == 0):
        raise ValueError(f"pairs: expected an integer (k, 2) array, got dtype {P.dtype}")
    P = P.reshape(-1, 2).astype(np.int64) if P.size else np.zeros((0, 2), np.int64)
    if P.size and (P.min() < 0 or P.max() >= n):
        raise ValueError(f"pairs: cell index out of range for {n} cells")
    k = len(P)
    d = _check_1d(offsets, k, "offsets")
    w = _check_1d(weights, k, "weights")
    if not (np.isfinite(d).all() and np.isfinite(w).all()):
        raise ValueError("offsets/weights: contain NaN or infinite values")
    if (w < 0).any():
        raise ValueError("weights: must be nonnegative")
    if bounds is None:
        lo, hi = np.full(k, -np.inf), np.full(k, np.inf)
    else:
        B = np.asarray(bounds, dtype=np.float64)
        if B.shape != (k, 2):
            raise ValueError(f"bounds: expected shape ({k}, 2), got {B.shape}")
        lo, hi = B[:, 0], B[:, 1]
        if np.isnan(B).any() or (lo > hi).any():
            raise ValueError("bounds: need lo <= hi without NaN")
    if gauge not in ("component", "none"):
        raise ValueError(f"gauge: expected 'component' or 'none', got {gauge!r}")
    if not isinstance(time_limit, (int, float)) or isinstance(time_limit, bool) or not time_limit > 0:
        raise ValueError(f"time_limit: expected a positive number of seconds, got {time_limit!r}")

    first = lab = None
    if gauge == "component":
        G = sp.coo_matrix((np.ones(k), (P[:, 0], P[:, 1])), shape=(n, n))
        nc, lab = connected_components(G, directed=False)
        first = np.full(nc, n, dtype=np.int64)
        np.minimum.at(first, lab, np.arange(n))
    return n, P, d, w, lo, hi, first, lab
