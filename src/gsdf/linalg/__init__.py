"""Sparse linear algebra — the only place in gsdf that factorizes: factorize once, solve many.

* :mod:`.direct` — SuperLU (symmetric mode) and CHOLMOD via cholespy: :class:`Factorization` (real/complex LU),
  :class:`HermitianFactorization`, :func:`spd_factorization`, :class:`BlockHermitianFactorization` (complex operators in real 2×2-block
  form), :class:`CholeskyFactorization` / :func:`cholesky`, :func:`cached_factorization`;
* :mod:`.ldl` — :class:`LDLFactorization`, numba LDLᴴ (SPD / HPD up to ``LDL_MAX_UNKNOWNS``);
* :mod:`.ordering` — fill-reducing orderings (approximate minimum degree, nested dissection);
* :mod:`.iterative` — :class:`SPDSolver` (factorize small, CG with AMG/Jacobi large), :func:`pcg`,
  :func:`amg_preconditioner`;
* :mod:`.saddle` — :func:`saddle_matrix` of equality-constrained least squares (Eq. 14);
* :mod:`.lp` — :func:`solve_lp` (HiGHS);
* BLAS threads around factorizations and solves: :func:`gsdf.threads.blas_region` (one thread unless set).

Example
-------
>>> import numpy as np, scipy.sparse as sp
>>> from gsdf.linalg import Factorization
>>> A = sp.diags([2.0, 3.0]).tocsc()
>>> Factorization(A).solve(np.array([2.0, 3.0]))
array([1., 1.])
"""

from gsdf.linalg._direct import (
    BlockHermitianFactorization,
    CholeskyFactorization,
    Factorization,
    HermitianFactorization,
    LDL_MAX_UNKNOWNS,
    cached_factorization,
    cholesky,
    spd_factorization,
)
from gsdf.linalg._ldl import LDLFactorization
from gsdf.linalg._iterative import SPDSolver, amg_preconditioner, pcg
from gsdf.linalg._lp import solve_lp
from gsdf.linalg._saddle import saddle_matrix

__all__ = ["Factorization", "HermitianFactorization", "BlockHermitianFactorization", "CholeskyFactorization",
           "cholesky", "cached_factorization", "saddle_matrix", "solve_lp", "SPDSolver", "pcg",
           "amg_preconditioner", "spd_factorization", "LDLFactorization", "LDL_MAX_UNKNOWNS"]
