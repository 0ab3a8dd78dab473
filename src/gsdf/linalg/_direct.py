"""Direct sparse solvers: factorize once, solve many (SuperLU in symmetric mode; CHOLMOD via cholespy).

The only module of gsdf that wraps a sparse factorization (with :mod:`.iterative`, which falls back to it).

* :class:`Factorization` — SuperLU LU of a square real or complex matrix (symmetric mode first);
* :class:`HermitianFactorization` — complex Hermitian positive definite (numba LDLᴴ up to ``LDL_MAX_UNKNOWNS`` / 2
  unknowns, else SuperLU; or CHOLMOD on the 2n real form);
* :func:`spd_factorization` — real SPD: numba LDLᵀ up to ``LDL_MAX_UNKNOWNS``, else :class:`Factorization`;
* :class:`BlockHermitianFactorization` — a complex operator given as its real 2n×2n SPD block matrix
  (``[[Re, -Im], [Im, Re]]`` per entry, or any real 2×2 blocks such as reflections): CHOLMOD, SuperLU fallback;
  solves take and return complex vectors;
* :func:`cholesky` — CHOLMOD of a real SPD matrix (None when cholespy is missing or the matrix is not PD);
* :func:`cached_factorization` — a small keyed cache of factorizations (constraint sets).

Example
-------
>>> import numpy as np, scipy.sparse as sp
>>> Factorization(sp.diags([2.0, 4.0]).tocsc()).solve(np.array([2.0, 2.0]))
array([1. , 0.5])
"""

from __future__ import annotations

import functools

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import reverse_cuthill_mckee

from gsdf.threads import blas_region


def _in_blas_region(method):
    """Run a factorization's method with BLAS limited by :func:`gsdf.threads.blas_region` (CHOLMOD's supernodes
    and SuperLU's blocks are small: BLAS threads only contend with numba's)."""
    @functools.wraps(method)
    def wrapper(*args, **kwargs):
        with blas_region():
            return method(*args, **kwargs)
    return wrapper

__all__ = ["Factorization", "HermitianFactorization", "BlockHermitianFactorization", "CholeskyFactorization",
           "cholesky", "cached_factorization", "spd_factorization", "LDL_MAX_UNKNOWNS"]

#: Size rule of the factorization backend, in real unknowns (a complex unknown counts 2): up to this size the
#: numba LDLᴴ of :mod:`gsdf.linalg._ldl` (approximate minimum degree ordering), above it SuperLU.
LDL_MAX_UNKNOWNS = 300_000


def _ldl_size(A) -> int:
    """Size of ``A`` in real unknowns for :data:`LDL_MAX_UNKNOWNS` (complex unknowns count 2)."""
    return A.shape[0] * (2 if np.iscomplexobj(A.data if sp.issparse(A) else A) else 1)


def _ldl_or_none(A, hint=None, ordering="auto"):
    """:class:`~gsdf.linalg._ldl.LDLFactorization` of ``A`` (``ordering``, ``hint``: its ordering options), or
    None when it is not positive definite."""
    from gsdf.linalg._ldl import LDLFactorization

    try:
        return LDLFactorization(A, ordering=ordering, hint=hint)
    except ValueError:
        return None


def spd_factorization(A, reorder: bool = True, hint=None):
    """A factorization of the real symmetric positive definite ``A`` with ``solve(b)``: LDLᵀ (numba, AMD
    ordered) up to :data:`LDL_MAX_UNKNOWNS` (real) unknowns, else (or when a pivot is not positive) SuperLU's
    :class:`Factorization` (``reorder`` = its RCM renumbering). ``hint``: a permutation (n,) the LDLᵀ's
    ordering rule also tries (:class:`~gsdf.linalg._ldl.LDLFactorization`); SuperLU orders by itself.

    Example
    -------
    >>> import numpy as np, scipy.sparse as sp
    >>> spd_factorization(sp.diags([2.0, 4.0]).tocsr()).solve(np.array([2.0, 2.0]))
    array([1. , 0.5])
    """
    if _ldl_size(A) <= LDL_MAX_UNKNOWNS:
        f = _ldl_or_none(A, hint)
        if f is not None:
            return f
    return Factorization(sp.csc_matrix(A), reorder=reorder)


class Factorization:
    """A sparse LU factorization of a square (typically symmetric / Hermitian) matrix, reused across solves.

    Parameters
    ----------
    A : scipy.sparse matrix, shape (n, n), real or complex
    symmetric : bool
        Use the symmetric mode of SuperLU (ordering of A + Aᵀ, diagonal pivots first): several times less fill
        for the Laplacian-like matrices of the heat method. Falls back to the general LU below when a pivot
        vanishes.
    ordering, pivot : str, float
        Column ordering (``permc_spec``) and partial-pivoting threshold of the general LU.
    reorder : bool
        Renumber the unknowns by reverse Cuthill–McKee before SuperLU's minimum-degree ordering (same fill; the
        ordering step is much faster on badly numbered inputs).
        Rounding then differs from the unreordered factorization (≈ 1e-15 relative on well-conditioned
        systems, so it is used for the vector heat and Dirichlet systems, not for the ε-regularized ones).
    """

    def __init__(self, A, symmetric: bool = True, ordering: str = "MMD_AT_PLUS_A", pivot: float = 0.1,
                 reorder: bool = False):
        A = sp.csc_matrix(A)
        if A.shape[0] != A.shape[1]:
            raise ValueError(f"matrix: expected a square matrix, got shape {A.shape}")
        self.shape = A.shape
        self.dtype = A.dtype
        self._perm = None
        with blas_region():                            # SuperLU's tiny BLAS calls: threads only cost
            if symmetric:
                # SuperLU's minimum degree ordering is slow on some input numberings (CAD meshes, edges
                # numbered by vertex pairs) for the same fill; a reverse Cuthill–McKee numbering first
                # (O(nnz), milliseconds) removes that
                p = reverse_cuthill_mckee(A.tocsr(), symmetric_mode=True) if reorder and A.shape[0] > 1 else None
                Ap = sp.csc_matrix(A[p][:, p]) if p is not None else A
                try:
                    self._lu = spla.splu(Ap, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                         options={"SymmetricMode": True})
                    self._perm = p
                    return
                except RuntimeError:                          # a zero pivot without pivoting (saddle systems)
                    pass
            try:
                self._lu = spla.splu(A, permc_spec=ordering, diag_pivot_thresh=pivot)
            except RuntimeError as exc:
                raise ValueError(f"matrix: the sparse system is singular ({exc})") from exc

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for one right-hand side (n,) or several (n, k)."""
        b = np.asarray(b)
        p = self._perm
        if p is not None:
            b = b[p]
        with blas_region():
            if np.iscomplexobj(b) and not np.iscomplexobj(np.zeros(0, self.dtype)):
                x = self._lu.solve(np.ascontiguousarray(b.real)) + 1j * self._lu.solve(np.ascontiguousarray(b.imag))
            else:
                x = self._lu.solve(np.ascontiguousarray(b, dtype=np.result_type(b, self.dtype)))
        if p is None:
            return x
        out = np.empty_like(x)
        out[p] = x
        return out


class HermitianFactorization:
    """Factorization of a sparse Hermitian positive definite complex matrix, reused across solves.

    ``backend="auto"`` (the default): ``"ldl"`` up to :data:`LDL_MAX_UNKNOWNS` / 2 complex unknowns, else
    ``"superlu"``.
    ``backend="ldl"``: the numba LDLᴴ of :mod:`gsdf.linalg._ldl` (SuperLU when a pivot is not positive).
    ``backend="superlu"``: SciPy's SuperLU on the complex matrix in symmetric mode.
    ``backend="cholmod"``: CHOLMOD through ``cholespy`` on the equivalent real symmetric system of size 2n (the
    2×2 blocks ``[[Re, -Im], [Im, Re]]`` interleaved).
    ``reorder``: the reverse Cuthill–McKee renumbering of :class:`Factorization` (default True).
    ``ordering``: the LDLᴴ backend's fill-reducing ordering (:class:`~gsdf.linalg._ldl.LDLFactorization`).

    Example
    -------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.csr_matrix(np.array([[2.0, 1j], [-1j, 2.0]]))
    >>> x = HermitianFactorization(A).solve(np.array([1.0, 0.0]))
    >>> bool(np.allclose(A @ x, [1.0, 0.0]))
    True
    """

    @_in_blas_region
    def __init__(self, A, backend: str = "auto", reorder: bool = True, ordering="auto"):
        n = A.shape[0]
        self.n = n
        self._chol = self._ldl = None
        if backend not in ("auto", "superlu", "cholmod", "ldl"):
            raise ValueError(f"backend: expected 'auto', 'ldl', 'superlu' or 'cholmod', got {backend!r}")
        if backend == "ldl" or (backend == "auto" and 2 * n <= LDL_MAX_UNKNOWNS):
            self._ldl = _ldl_or_none(sp.csr_matrix(A, dtype=np.complex128), ordering=ordering)
            if self._ldl is not None:
                self.backend = "ldl"
                return
        A = sp.coo_matrix(A)
        if backend == "cholmod":
            from cholespy import CholeskySolverD, MatrixType

            r, c, v = A.row, A.col, A.data.astype(np.complex128)
            rows = np.concatenate([2 * r, 2 * r, 2 * r + 1, 2 * r + 1])
            cols = np.concatenate([2 * c, 2 * c + 1, 2 * c, 2 * c + 1])
            vals = np.concatenate([v.real, -v.imag, v.imag, v.real])
            R = sp.csr_matrix((vals, (rows, cols)), shape=(2 * n, 2 * n))
            R.sum_duplicates()
            self._chol = CholeskySolverD(2 * n, R.indptr.astype(np.int32), R.indices.astype(np.int32),
                                         np.ascontiguousarray(R.data), MatrixType.CSR)
            self.backend = "cholmod"
            return
        self._lu = Factorization(A.astype(np.complex128), reorder=bool(reorder))
        self.backend = "superlu"

    @property
    def ordering(self):
        """The fill-reducing permutation (n,) of the LDLᴴ backend (``perm[k]`` = the unknown eliminated k-th),
        None for the other backends (they order internally)."""
        return None if self._ldl is None else self._ldl.perm

    @_in_blas_region
    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for a complex right-hand side (n,)."""
        b = np.asarray(b, dtype=np.complex128)
        if self._ldl is not None:
            return self._ldl.solve(b)
        if self._chol is None:
            return self._lu.solve(b)
        rb = np.empty(2 * self.n)
        rb[0::2], rb[1::2] = b.real, b.imag
        x = np.zeros_like(rb)
        self._chol.solve(rb, x)
        return x[0::2] + 1j * x[1::2]



class CholeskyFactorization:
    """CHOLMOD (cholespy) factorization of a real SPD matrix; ``solve`` for (n,) or (n, k) right-hand sides."""

    @_in_blas_region
    def __init__(self, A):
        from cholespy import CholeskySolverD, MatrixType

        A = sp.csr_matrix(A)
        A.sum_duplicates()
        self.n = A.shape[0]
        self._chol = CholeskySolverD(self.n, A.indptr.astype(np.int32), A.indices.astype(np.int32),
                                     np.ascontiguousarray(A.data, dtype=np.float64), MatrixType.CSR)

    @_in_blas_region
    def solve(self, b):
        b = np.ascontiguousarray(b, dtype=np.float64)
        x = np.zeros_like(b)
        self._chol.solve(b, x)
        return x


def cholesky(A):
    """A :class:`CholeskyFactorization` of the real SPD ``A``, or None when cholespy is not installed or CHOLMOD
    finds ``A`` not positive definite (callers then use :class:`Factorization`)."""
    try:
        return CholeskyFactorization(A)
    except (ImportError, ValueError, RuntimeError):
        return None


class BlockHermitianFactorization:
    """Factorization of a complex linear operator given in real form: the 2n×2n SPD matrix whose 2×2 block
    (i, j) maps (Re, Im) of unknown j to row i (e.g. the vector heat operator ``M ⊗ I₂ + t L∇`` on meshes whose
    face orientations disagree, where transport is a reflection). CHOLMOD via cholespy, SuperLU without it.
    ``solve`` takes and returns complex vectors (n,).

    Example
    -------
    >>> import numpy as np, scipy.sparse as sp
    >>> f = BlockHermitianFactorization(sp.diags([2.0, 2.0]))
    >>> complex(f.solve(np.array([2.0 + 4.0j]))[0])
    (1+2j)
    """

    @_in_blas_region
    def __init__(self, A):
        A = sp.csr_matrix(A)
        A.sum_duplicates()
        self.n = A.shape[0] // 2
        self._chol = None
        try:
            from cholespy import CholeskySolverD, MatrixType
        except ImportError:
            self._lu = Factorization(A.tocsc())
            self.backend = "superlu"
        else:
            self._chol = CholeskySolverD(A.shape[0], A.indptr.astype(np.int32), A.indices.astype(np.int32),
                                         np.ascontiguousarray(A.data, dtype=np.float64), MatrixType.CSR)
            self.backend = "cholmod"

    @_in_blas_region
    def solve(self, b):
        b = np.asarray(b, np.complex128)
        r = np.empty(2 * self.n)
        r[0::2], r[1::2] = b.real, b.imag
        if self._chol is not None:
            x = np.zeros_like(r)
            self._chol.solve(r, x)
        else:
            x = self._lu.solve(r)
        return x[0::2] + 1j * x[1::2]


def cached_factorization(cache: dict, key, build, most: int = 8):
    """``cache[key]``, building it with ``build()`` on a miss; the oldest entry is dropped beyond ``most``."""
    fact = cache.get(key)
    if fact is None:
        if len(cache) >= most:
            cache.pop(next(iter(cache)))
        fact = cache[key] = build()
    return fact
