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
``algorithm="network"`` solves the LP dual instead, a pure min-cost circulation (:mod:`gsdf.dec.netflow`).

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

from .l1_terms import DualL1Result, _checked_terms

__all__ = ["DualL1Result", "dual_graph_l1", "decomposition_l1", "ALGORITHMS"]

ALGORITHMS = ("highs", "highs-ds", "highs-ipm", "network")


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
    algorithm : "highs" (HiGHS picks), "highs-ds" (dual simplex), "highs-ipm" (interior point + crossover) or
        "network" (the dual min-cost circulation by a network simplex, :mod:`gsdf.dec.netflow`; same optimum)

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
    if algorithm == "network":
        from .netflow import dual_graph_l1_network

        return dual_graph_l1_network(n_cells, pairs, offsets, weights, bounds=bounds, time_limit=time_limit,
                                     gauge=gauge)
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


def decomposition_l1(n_cells: int, pairs, offsets, weights, on_input, target, fill_weights, bounds=None,
                     time_limit: float = 300.0, algorithm: str = "highs-ds"):
    """Two-layer L1 program: a residual ``J = d + x_A - x_B`` and a labeling jump ``K = y_A - y_B`` together.

    Minimises ``Σ_k w_k |J_k|`` (the residual's completion, as :func:`dual_graph_l1`) plus, with the fill weights
    f, ``Σ_{k off input} f_k |K_k| + Σ_{k on input} f_k |target_k - J_k - K_k|``: the labeling y must jump by
    what the residual leaves of the input (``target - J`` on the input dual edges) and pays for every jump off
    the input (the completion of the bounding part) and for every bit of the input it leaves unexplained.
    Used by surface winding numbers (``objective="decomposition"``): the cost of a decomposition is the length
    of *both* completions, the nonbounding one (J) and the bounding one (K).

    Parameters
    ----------
    n_cells, pairs, offsets, weights, bounds, time_limit : as :func:`dual_graph_l1` (bounds act on J)
    on_input : (k,) bool, the dual edges of the input
    target : (k,) float, the input's jump on each dual edge (ignored off the input)
    fill_weights : (k,) float ≥ 0
    algorithm : "highs", "highs-ds" or "highs-ipm"

    Returns
    -------
    (J (k,), K (k,), objective, seconds)

    Example
    -------
    >>> J, K, obj, _ = decomposition_l1(2, [[0, 1]], [0.0], [1.0], [True], [1.0], [1.0])
    >>> round(float(K[0]), 6), round(float(obj), 6)       # the labeling explains the input for free
    (1.0, 0.0)
    """
    if algorithm not in ("highs", "highs-ds", "highs-ipm"):
        raise ValueError(f"algorithm: expected 'highs', 'highs-ds' or 'highs-ipm', got {algorithm!r}")
    n, P, d, w, lo, hi, first, _ = _checked_terms(n_cells, pairs, offsets, weights, bounds, time_limit,
                                                   "component")
    k = len(P)
    on = np.asarray(on_input, dtype=bool).reshape(-1)
    tg = np.asarray(target, dtype=float).reshape(-1)
    f = np.asarray(fill_weights, dtype=float).reshape(-1)
    for name, a in (("on_input", on), ("target", tg), ("fill_weights", f)):
        if a.shape != (k,):
            raise ValueError(f"{name}: expected shape ({k},), got {a.shape}")
    if not np.all(np.isfinite(tg)):
        raise ValueError("target: expected finite values")
    if not (np.all(np.isfinite(f)) and np.all(f >= 0)):
        raise ValueError("fill_weights: expected finite values >= 0")
    if k == 0:
        return np.zeros(0), np.zeros(0), 0.0, 0.0
    sp_lo = np.where(lo > 0, lo, 0.0)
    sp_hi = np.where(hi < 0, 0.0, hi)
    sm_lo = np.where(hi < 0, -hi, 0.0)
    sm_hi = np.where(lo > 0, 0.0, -lo)
    fx = np.full(n, -np.inf), np.full(n, np.inf)
    if first is not None:
        fx[0][first] = 0.0
        fx[1][first] = 0.0
    # columns: x (n), y (n), s+ s- (J's parts), t+ t- (K off the input; the unexplained input on it)
    r = np.arange(k)
    one = np.ones(k)
    A, B = P[:, 0], P[:, 1]
    ix = np.flatnonzero(on)
    # rows 0..k-1:  x_A - x_B - s+ + s- = -d
    rows = [r, r, r, r]
    cols = [A, B, 2 * n + r, 2 * n + k + r]
    vals = [one, -one, -one, one]
    # rows k..2k-1: y_A - y_B (+ x_A - x_B on the input) - t+ + t- = 0 off the input, target - d on it
    rows += [k + r, k + r, k + r, k + r, k + ix, k + ix]
    cols += [n + A, n + B, 2 * n + 2 * k + r, 2 * n + 3 * k + r, A[ix], B[ix]]
    vals += [one, -one, -one, one, np.ones(len(ix)), -np.ones(len(ix))]
    M = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(2 * k, 2 * n + 4 * k))
    rhs = np.concatenate([-d, np.where(on, tg - d, 0.0)])
    cost = np.concatenate([np.zeros(2 * n), w, w, f, f])
    lo_all = np.concatenate([fx[0], fx[0], sp_lo, sm_lo, np.zeros(2 * k)])
    hi_all = np.concatenate([fx[1], fx[1], sp_hi, sm_hi, np.full(2 * k, np.inf)])
    res, secs = solve_highs(cost, M, rhs, np.column_stack([lo_all, hi_all]), algorithm, time_limit)
    x, y = res.x[:n], res.x[n:2 * n]
    J = d + x[A] - x[B]
    K = y[A] - y[B]
    t = np.where(on, tg - J - K, K)
    return J, K, float(np.dot(w, np.abs(J)) + np.dot(f, np.abs(t))), secs
