"""gsdf.linalg._eig3.jacobi_eig3 against numpy's LAPACK eigh (an independent implementation)."""

import numpy as np
import pytest

from gsdf.linalg._eig3 import jacobi_eig3


def _check(S):
    A = S.copy()
    U = np.empty((3, 3))
    jacobi_eig3(A, U)
    lam = np.diag(A).copy()
    scale = max(1.0, np.abs(S).max())
    assert np.abs(A - np.diag(lam)).max() <= 1e-12 * scale                  # diagonalised
    assert np.allclose(U.T @ U, np.eye(3), atol=1e-12)                     # orthonormal
    assert np.allclose(U @ np.diag(lam) @ U.T, S, atol=1e-11 * scale)     # reconstructs the input
    assert np.allclose(np.sort(lam), np.linalg.eigvalsh(S), atol=1e-11 * scale)


@pytest.mark.parametrize("seed", range(20))
def test_random_symmetric(seed):
    M = np.random.default_rng(seed).standard_normal((3, 3)) * 10.0 ** (seed % 5 - 2)
    _check(M + M.T)


@pytest.mark.parametrize("S", [np.zeros((3, 3)), np.eye(3), np.diag([2.0, 2.0, -1.0]),
                               np.outer([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]),        # rank one, two zero eigenvalues
                               np.array([[1.0, 1e-9, 0.0], [1e-9, 1.0, 0.0], [0.0, 0.0, 1.0]])])
def test_repeated_and_zero_eigenvalues(S):
    _check(S)
