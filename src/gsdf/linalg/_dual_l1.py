"""The L1 linear program on a dual graph (HiGHS): least weighted L1 jump between per-cell shifts.

Cells (faces of a triangle mesh, tets of a tet mesh, components of a cut surface…) each get an unknown shift
``x_c``. Every dual edge ``k`` joins cell ``A_k`` to cell ``B_k`` and carries a known offset ``d_k``; the jump
across it is ``J_k = d_k + x_A - x_B``. The program

    minimise  Σ_k w_k |J_k|   subject to   lo_k ≤ J_k ≤ hi_k   (optional bounds)

is the integration step shared by L1 integration of the signed heat method (Feng & Crane 2024 §7.2, Eq. 16),
the residual of surface winding numbers (Feng 2026 thesis §6.1.2, step ④ of the spec notes, with the
"no extra loops" bounds) and its reduced form (§6.3, one cell per component). Written as an LP with the jump
split into positive and negative parts ``J = s⁺ - s⁻``, ``s± ≥ 0``:

    min Σ w (s⁺ + s⁻)   s.t.   x_A - x_B - s⁺ + s⁻ = -d,

a network matrix with two nonzeros per column block. Bounds on J become bounds on s± (no extra rows): with
``lo ≥ 0`` the negative part is fixed at 0 and ``s⁺ ∈ [lo, hi]``; mirrored for ``hi ≤ 0``; otherwise
``s⁺ ≤ hi`` and ``s⁻ ≤ -lo``. One shift per connected component of the dual graph is fixed at 0 (the gauge),
so the answer is deterministic up to LP ties. HiGHS failure, infeasibility or its time limit raise ValueError.
The same program is also solved through its LP dual, a pure min-cost circulation (:mod:`gsdf.linalg._netflow`),
and on a proven band of cells (:mod:`gsdf.linalg._band_lp`).

Example
-------
>>> import numpy as np
>>> pairs = np.array([[0, 1], [1, 2], [2, 0]])            # a cycle of three cells
>>> res = dual_graph_l1(3, pairs, offsets=np.array([1.0, 0.0, 0.0]), weights=np.array([1.0, 1.0, 5.0]))
>>> np.round(res.jumps, 6).tolist()                        # the total 1 goes to the cheapest edge
[0.0, 1.0, 0.0]
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from gsdf.linalg._l1_terms import DualL1Result, _checked_terms

__all__ = ["DualL1Result", "dual_graph_l1", "ALGORITHMS"]

ALGORITHMS = ("highs", "highs-ds", "highs-ipm")


def solve_highs(cost, A_eq, b_eq, bounds, algorithm: str, time_limit: float):
    """``scipy.optimize.linprog`` (HiGHS) of min cost·x, A_eq x = b_eq, bounds; returns (result, seconds).
    A time limit hit, infeasible bounds or any other HiGHS failure is a ValueError saying which."""
    from scipy.optimize import linprog

    t0 = time.perf_counter()
    try:
        res = linprog(cost, A_eq=A_eq, b_eq=b_eq, bounds=bounds, method=algorithm,
                      options={"time_limit": float(time_limit)})
    except Exception as exc:  # pragma: no cover - HiGHS raising instead of reporting
        raise ValueError(f"linear program: HiGHS failed ({exc})") from exc
    secs = time.perf_counter() - t0
    if res.status == 1:
        raise ValueError(f"linear program: HiGHS hit its limit after {secs:.1f} s (time_limit={time_limit}): "
                         f"{res.message}")
    if res.status == 2:
        raise ValueError(f"linear program: infeasible jump bounds ({res.message})")
    if res.status != 0 or res.x is None:
        raise ValueError(f"linear program: HiGHS failed with status {res.status}: {res.message}")
    return res, secs


def dual_graph_l1(n_cells: int, pairs, offsets, weights, bounds=None, time_limit: float = 300.0,
                  gauge: str = "component", algorithm: str = "highs") -> DualL1Result:
    """Minimise ``Σ_k w_k |d_k + x_{A_k} - x_{B_k}|`` over per-cell shifts x with HiGHS.

    Parameters
    ----------
    n_cells : int
        Number of cells (unknown shifts).
    pairs : (k, 2) int
        ``(A_k, B_k)`` cells of each dual edge.
    offsets : (k,) float
        ``d_k``, the jump when both shifts are 0.
    weights : (k,) float, ≥ 0
    bounds : (k, 2) float, optional
        ``[lo_k, hi_k]`` bounds on the jump ``J_k`` (±inf allowed); ``lo ≤ hi``.
    time_limit : float
        Seconds HiGHS may use; reaching it raises ValueError.
    gauge : "component" | "none"
        Fix one shift per connected component of the dual graph at 0 (default), or leave all free.
    algorithm : "highs" (HiGHS picks), "highs-ds" (dual simplex) or "highs-ipm" (interior point + crossover)

    Returns
    -------
    DualL1Result

    Example
    -------
    >>> r = dual_graph_l1(2, [[0, 1]], [0.5], [1.0], bounds=[[1.0, 2.0]])
    >>> round(float(r.jumps[0]), 6), round(float(r.objective), 6)
    (1.0, 1.0)
    """
    if algorithm not in ALGORITHMS:
        raise ValueError(f"algorithm: expected one of {ALGORITHMS}, got {algorithm!r}")
    n, P, d, w, lo, hi, first, _ = _checked_terms(n_cells, pairs, offsets, weights, bounds, time_limit, gauge)
    k = len(P)
    # bounds of s+ and s-
    sp_lo = np.where(lo > 0, lo, 0.0)
    sp_hi = np.where(hi < 0, 0.0, hi)
    sm_lo = np.where(hi < 0, -hi, 0.0)
    sm_hi = np.where(lo > 0, 0.0, -lo)
    x_lo, x_hi = np.full(n, -np.inf), np.full(n, np.inf)
    if first is not None:
        x_lo[first] = 0.0
        x_hi[first] = 0.0
    if k == 0:
        return DualL1Result(np.zeros(n), np.zeros(0), 0.0, 0.0)
    r = np.arange(k)
    rows = np.concatenate([r, r, r, r])
    cols = np.concatenate([P[:, 0], P[:, 1], n + r, n + k + r])
    vals = np.concatenate([np.ones(k), -np.ones(k), -np.ones(k), np.ones(k)])
    A = sp.csr_matrix((vals, (rows, cols)), shape=(k, n + 2 * k))   # duplicates (A == B) sum to 0
    cost = np.concatenate([np.zeros(n), w, w])
    bnds = np.column_stack([np.concatenate([x_lo, sp_lo, sm_lo]), np.concatenate([x_hi, sp_hi, sm_hi])])
    res, secs = solve_highs(cost, A, -d, bnds, algorithm, time_limit)
    x = res.x[:n]
    J = d + x[P[:, 0]] - x[P[:, 1]]
    return DualL1Result(x, J, float(np.dot(w, np.abs(J))), secs)
