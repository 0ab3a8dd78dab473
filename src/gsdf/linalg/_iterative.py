"""Iterative SPD solves: conjugate gradients with Jacobi, smoothed-aggregation AMG (pyamg, optional) or a
caller's preconditioner; falls back to a factorization (:mod:`.direct`) when CG does not converge.

Example
-------
>>> import numpy as np, scipy.sparse as sp
>>> A = sp.diags([np.full(99, -1.0), np.full(100, 2.5), np.full(99, -1.0)], [-1, 0, 1]).tocsr()
>>> x = SPDSolver(A, direct_max=10).solve(np.ones(100))
>>> bool(np.abs(A @ x - 1).max() < 1e-8)
True
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp

from gsdf.linalg._direct import cholesky

__all__ = ["SPDSolver", "pcg", "cg_loop", "amg_preconditioner"]


def amg_preconditioner(A):
    """pyamg's smoothed-aggregation preconditioner of SPD ``A`` when pyamg is installed, else Jacobi."""
    try:
        import pyamg

        return pyamg.smoothed_aggregation_solver(A, symmetry="symmetric").aspreconditioner()
    except ImportError:
        d = A.diagonal()
        return sp.diags(1.0 / np.where(d > 0, d, 1.0))


def pcg(A, b, M=None, x0=None, rtol: float = 1e-8, maxiter: int = 500, warn: str | None = None):
    """Preconditioned conjugate gradients (scipy); returns ``(x, converged)``. ``M`` a matrix, LinearOperator or
    callable ``r -> z``; ``warn``: a message prefix to warn with when CG stops above ``rtol``."""
    from scipy.sparse.linalg import LinearOperator, cg

    n = A.shape[0]
    if callable(M) and not hasattr(M, "matvec") and not sp.issparse(M):
        M = LinearOperator((n, n), matvec=M)
    x, info = cg(A, b, x0=x0, M=M, rtol=rtol, atol=0.0, maxiter=maxiter)
    if info > 0 and warn:
        warnings.warn(f"{warn}: conjugate gradients stopped after {maxiter} iterations above rtol={rtol:g}")
    return x, info == 0


def cg_loop(matvec, psolve, b, x0, rtol: float = 1e-8, maxiter: int = 500, warn: str | None = None):
    """Preconditioned conjugate gradients on plain callables ``matvec(x)`` = A x and ``psolve(r)`` = M r: SciPy's
    ``cg`` iteration step for step (same stopping rule, ‖r‖ < rtol ‖b‖; same updates), without its
    LinearOperator wrapping — for solvers whose operators are a few numba kernels, where that wrapping was a
    visible part of an iteration. Returns ``(x, converged)``; ``x0`` is updated in place."""
    b = np.asarray(b, dtype=np.float64)
    bnrm2 = float(np.linalg.norm(b))
    if bnrm2 == 0.0:
        return b.copy(), True
    atol = rtol * bnrm2
    x = x0
    r = b - matvec(x) if x.any() else b.copy()
    rho_prev, p = 0.0, None
    for it in range(maxiter):
        if np.linalg.norm(r) < atol:
            return x, True
        z = psolve(r)
        rho = float(np.dot(r, z))
        if it > 0:
            p *= rho / rho_prev
            p += z
        else:
            p = z.copy()
        q = matvec(p)
        alpha = rho / float(np.dot(p, q))
        x += alpha * p
        r -= alpha * q
        rho_prev = rho
    if warn:
        warnings.warn(f"{warn}: conjugate gradients stopped after {maxiter} iterations above rtol={rtol:g}")
    return x, False


class SPDSolver:
    """Solve with a sparse symmetric positive definite matrix, set up once for many right-hand sides.

    Small systems (n ≤ ``direct_max``) are factorized: CHOLMOD via cholespy (SuperLU if it is missing or the
    matrix is numerically not PD). Larger ones use preconditioned conjugate gradients (the graded tet
    Laplacians are well conditioned): pyamg's smoothed aggregation preconditions when installed, Jacobi
    otherwise. If CG does not converge the matrix is factorized after all.
    """

    def __init__(self, A, direct_max: int = 5000, rtol: float = 1e-10):
        A = sp.csr_matrix(A)
        A.sum_duplicates()
        self.A, self.n, self.rtol = A, A.shape[0], rtol
        self._fact = self._M = None
        if self.n <= direct_max:
            self._factorize()
            return
        self._M = amg_preconditioner(A)

    def _factorize(self):
        from gsdf.linalg._direct import Factorization

        self._fact = cholesky(self.A)
        if self._fact is None:
            self._fact = Factorization(sp.csc_matrix(self.A), symmetric=False)

    @property
    def direct(self) -> bool:
        return self._fact is not None

    def _solve_vector(self, b):
        if self.direct:  # a previous right-hand side defeated CG
            return self._fact.solve(np.ascontiguousarray(b))
        x, ok = pcg(self.A, b, M=self._M, rtol=self.rtol, maxiter=20 * int(np.sqrt(self.n)) + 500)
        if ok:
            return x
        self._factorize()
        return self._fact.solve(np.ascontiguousarray(b))

    def solve(self, b):
        b = np.ascontiguousarray(b, dtype=np.float64)
        if self.direct:
            return self._fact.solve(b)
        if b.ndim == 1:
            return self._solve_vector(b)
        return np.column_stack([self._solve_vector(b[:, j]) for j in range(b.shape[1])])
