"""Regularized saddle-point matrices of equality-constrained least squares (Feng & Crane 2024, Eq. 14)."""

from __future__ import annotations

import scipy.sparse as sp

__all__ = ["saddle_matrix"]


def saddle_matrix(C, A, delta: float = 0.0):
    """The (regularized) saddle-point matrix ``[[C, Aᵀ], [A, -δ I]]`` of an equality-constrained least-squares
    problem (Feng & Crane 2024, Eq. 14). A small ``δ > 0`` keeps it nonsingular when constraint rows repeat."""
    A = sp.csr_matrix(A)
    m = A.shape[0]
    D = sp.identity(m, format="csr") * (-float(delta)) if delta else sp.csr_matrix((m, m))
    return sp.bmat([[sp.csr_matrix(C), A.T], [A, D]], format="csc")
