"""Linear programs by HiGHS (scipy.optimize.linprog)."""

from __future__ import annotations

__all__ = ["solve_lp"]


def solve_lp(c, A_ub=None, b_ub=None, A_eq=None, b_eq=None, bounds=(0, None)):
    """Solve ``min cᵀx`` s.t. ``A_ub x <= b_ub``, ``A_eq x = b_eq``, ``bounds`` with HiGHS (scipy.optimize.linprog).

    Raises ValueError when HiGHS reports failure.
    """
    from scipy.optimize import linprog

    res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds, method="highs")
    if res.status != 0:
        raise ValueError(f"linear program failed: {res.message}")
    return res.x
