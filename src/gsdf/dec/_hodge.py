"""Hodge decomposition of a discrete 1-form on any cell complex (triangle or tet meshes alike).

Given the coboundaries d0 (edges × vertices), d1 (2-cells × edges) and a positive diagonal ⋆1, a 1-form ω
splits ⋆1-orthogonally (thesis §2.3, Eq. 2.1) into

    ω = d0 α  +  ⋆1⁻¹ d1ᵀ β  +  h,

- exact part ``d0 α``:      ``(d0ᵀ ⋆1 d0) α = d0ᵀ ⋆1 ω``   (a vertex Laplacian),
- coexact part ``⋆1⁻¹ d1ᵀ β``: ``(d1 ⋆1⁻¹ d1ᵀ) β = d1 ω``  (a 2-cell Laplacian; β is ⋆2 of the 2-form),
- harmonic part h = the rest: ``d1 h = 0`` and ``d0ᵀ ⋆1 h = 0``.

No boundary condition is imposed at boundary vertices or boundary 2-cells (the natural, "Neumann" one): on a
surface with boundary the harmonic forms are then tangent to the boundary and pair with the absolute homology —
a loop around a hole of an annulus carries the harmonic form, an arc joining two boundary circles is detected
by it (spec §1(e).5). ⋆0 and ⋆2 do not change the split; they are accepted so that the same object also
builds the Hodge Laplacians. The harmonic space has dimension b1 (2g on a closed genus-g surface);
:meth:`HodgeDecomposition.harmonic_basis` finds it by projecting random 1-forms (rank-revealing), so it needs
no topology of the complex.

Both Laplacians get ``1e-8 × mean diagonal`` added (their null spaces are the constants per component; the
right-hand sides are orthogonal to them) and are factorized once, lazily; two steps of iterative refinement
against the unregularised matrix remove the bias this adds.

Example
-------
>>> import numpy as np, scipy.sparse as sp
>>> d0 = sp.csr_matrix(np.array([[-1., 1, 0], [0, -1, 1], [1, 0, -1]]))     # a triangle's boundary cycle,
>>> d1 = sp.csr_matrix((0, 3))                                             # no 2-cells: b1 = 1
>>> H = HodgeDecomposition(d0, d1, np.ones(3))
>>> H.harmonic_basis().shape
(3, 1)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from gsdf.linalg import Factorization

__all__ = ["HodgeDecomposition", "HodgeParts"]


@dataclass
class HodgeParts:
    """``omega = exact + coexact + harmonic``; ``alpha`` (vertices) and ``beta`` (2-cells) the potentials."""

    exact: np.ndarray
    coexact: np.ndarray
    harmonic: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray


def _diag(x, n, name, required=True):
    if x is None:
        if required:
            raise ValueError(f"{name}: required")
        return None
    A = np.asarray(x)
    if A.dtype == bool or not np.issubdtype(A.dtype, np.number):
        raise ValueError(f"{name}: expected a numeric diagonal, got dtype {A.dtype}")
    if sp.issparse(x):
        A = x.diagonal()
    A = np.asarray(A, dtype=np.float64).ravel()
    if A.shape != (n,):
        raise ValueError(f"{name}: expected {n} diagonal entries, got {A.shape}")
    if not np.isfinite(A).all() or (A <= 0).any():
        raise ValueError(f"{name}: Hodge star entries must be finite and positive")
    return A


class HodgeDecomposition:
    """Factorize-once Hodge decomposition of 1-forms on a cell complex.

    Parameters
    ----------
    d0 : (nE, nV) sparse, vertex -> edge coboundary
    d1 : (nF, nE) sparse, edge -> 2-cell coboundary (``d1 @ d0 == 0`` is checked)
    star1 : (nE,) positive diagonal ⋆1
    star0 : (nV,), star2 : (nF,), optional positive diagonals (only for :meth:`hodge_laplacian1`)
    reg : float, relative diagonal regularisation

    Example
    -------
    >>> import numpy as np, scipy.sparse as sp
    >>> d0 = sp.csr_matrix(np.array([[-1., 1, 0], [0, -1, 1], [1, 0, -1]]))
    >>> d1 = sp.csr_matrix(np.array([[1., 1, 1]]))                           # the triangle filled in: b1 = 0
    >>> H = HodgeDecomposition(d0, d1, np.ones(3))
    >>> p = H.decompose(np.array([1.0, 2.0, 0.0]))
    >>> bool(np.allclose(p.exact + p.coexact, [1, 2, 0])), bool(np.allclose(p.harmonic, 0))
    (True, True)
    """

    def __init__(self, d0, d1, star1, star0=None, star2=None, reg: float = 1e-8):
        if not (sp.issparse(d0) and sp.issparse(d1)):
            raise ValueError("d0, d1: expected scipy.sparse matrices")
        d0, d1 = sp.csr_matrix(d0, dtype=np.float64), sp.csr_matrix(d1, dtype=np.float64)
        nE, nV = d0.shape
        if d1.shape[1] != nE:
            raise ValueError(f"d1: expected {nE} columns (one per edge of d0), got shape {d1.shape}")
        if d1.shape[0] and nV and abs(d1 @ d0).max() > 1e-12:
            raise ValueError("d0, d1: d1 @ d0 is not zero (inconsistent orientations)")
        self.d0, self.d1 = d0, d1
        self.nV, self.nE, self.nF = nV, nE, d1.shape[0]
        self.star1 = _diag(star1, nE, "star1")
        self.star0 = _diag(star0, nV, "star0", required=False)
        self.star2 = _diag(star2, self.nF, "star2", required=False)
        self.reg = float(reg)
        self._f0 = self._f1 = None

    @staticmethod
    def _refined(fact, K, b, steps: int = 2):
        """Solve with the regularised factorization, then iterative refinement against the unregularised K
        (removes the O(reg) bias off the null space; the null-space component of b is zero)."""
        x = fact.solve(b)
        for _ in range(steps):
            x = x + fact.solve(b - K @ x)
        return x

    def _fact0(self):
        if self._f0 is None:
            K = (self.d0.T @ sp.diags(self.star1) @ self.d0).tocsc()
            s = K.diagonal().mean() if self.nV else 1.0
            self._K0 = K
            self._f0 = Factorization((K + self.reg * max(s, 1e-300) * sp.identity(self.nV)).tocsc())
        return self._f0

    def _fact1(self):
        if self._f1 is None:
            K = (self.d1 @ sp.diags(1.0 / self.star1) @ self.d1.T).tocsc()
            s = K.diagonal().mean() if self.nF else 1.0
            self._K1 = K
            self._f1 = Factorization((K + self.reg * max(s, 1e-300) * sp.identity(self.nF)).tocsc())
        return self._f1

    def _check_form(self, omega):
        A = np.asarray(omega)
        if A.dtype == bool or not np.issubdtype(A.dtype, np.number):
            raise ValueError(f"omega: expected a numeric 1-form, got dtype {A.dtype}")
        A = A.astype(np.float64)
        if A.shape[0] != self.nE or A.ndim > 2:
            raise ValueError(f"omega: expected shape ({self.nE},) or ({self.nE}, k), got {A.shape}")
        if not np.isfinite(A).all():
            raise ValueError("omega: contains NaN or infinite values")
        return A

    def exact_part(self, omega) -> tuple[np.ndarray, np.ndarray]:
        """``(d0 α, α)``: the ⋆1-orthogonal projection of ω on exact forms."""
        w = self._check_form(omega)
        if self.nV == 0:
            return np.zeros_like(w), np.zeros((0,) + w.shape[1:])
        s1 = self.star1 if w.ndim == 1 else self.star1[:, None]
        alpha = self._refined(self._fact0(), self._K0, self.d0.T @ (s1 * w))
        return self.d0 @ alpha, alpha

    def coexact_part(self, omega) -> tuple[np.ndarray, np.ndarray]:
        """``(⋆1⁻¹ d1ᵀ β, β)``: the ⋆1-orthogonal projection of ω on coexact forms."""
        w = self._check_form(omega)
        if self.nF == 0:
            return np.zeros_like(w), np.zeros((0,) + w.shape[1:])
        beta = self._refined(self._fact1(), self._K1, self.d1 @ w)
        s1 = self.star1 if w.ndim == 1 else self.star1[:, None]
        return (self.d1.T @ beta) / s1, beta

    def decompose(self, omega) -> HodgeParts:
        """Split ``omega`` (nE,) or (nE, k) into exact, coexact and harmonic parts."""
        w = self._check_form(omega)
        ex, alpha = self.exact_part(w)
        co, beta = self.coexact_part(w)
        return HodgeParts(ex, co, w - ex - co, alpha, beta)

    def harmonic_basis(self, max_dim: int = 4096, seed: int = 0, tol: float = 1e-6) -> np.ndarray:
        """A ⋆1-orthonormal basis (nE, b1) of the harmonic 1-forms.

        Projects k random 1-forms (k doubling until the rank stays below k/2) and keeps the directions whose
        ⋆1-Gram eigenvalue exceeds ``tol`` times the largest (and a noise floor), so the dimension equals the
        first Betti number of the complex without any knowledge of its topology.
        """
        rng = np.random.default_rng(seed)
        k = 8
        while True:
            R = rng.standard_normal((self.nE, k))
            H = self.decompose(R).harmonic
            G = H.T @ (self.star1[:, None] * H)
            lam, Q = np.linalg.eigh(0.5 * (G + G.T))
            floor = 1e-9 * float(np.einsum("ij,i,ij->", R, self.star1, R)) / k
            keep = lam > max(tol * max(lam.max(), 0.0), floor)
            r = int(keep.sum())
            if r <= k // 2 or k >= max_dim:
                break
            k *= 2
        B = H @ (Q[:, keep] / np.sqrt(lam[keep]))
        # one more projection cleans the solver residue
        return self.decompose(B).harmonic if r else B

    def hodge_laplacian1(self) -> sp.csr_matrix:
        """The (symmetrised) Hodge Laplacian on 1-forms, ``⋆1 d0 ⋆0⁻¹ d0ᵀ ⋆1 + d1ᵀ ⋆2 d1`` (needs star0, star2);
        its kernel is the harmonic space."""
        if self.star0 is None or self.star2 is None:
            raise ValueError("star0, star2: required for the Hodge Laplacian")
        S1 = sp.diags(self.star1)
        return (S1 @ self.d0 @ sp.diags(1.0 / self.star0) @ self.d0.T @ S1
                + self.d1.T @ sp.diags(self.star2) @ self.d1).tocsr()
