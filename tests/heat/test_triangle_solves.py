"""gsdf.linalg: factorize once / solve many, Hermitian systems, saddle points, linear programs."""

import numpy as np
import pytest
import scipy.sparse as sp

from gsdf.data._shapes import grid_mesh
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.linalg import Factorization, HermitianFactorization, saddle_matrix, solve_lp


def test_hermitian_backends_agree():
    V, F = grid_mesh(10, jitter=0.2, delaunay=True)
    ops = TriangleMeshOperators(V, F)
    A = ops.cr_mass() + ops.h ** 2 * ops.cr_connection_laplacian()
    assert abs(A - A.conj().T).max() < 1e-14                       # Hermitian (Eq. 9)
    b = np.random.default_rng(0).normal(size=A.shape[0]) * (1 + 1j)
    x1 = HermitianFactorization(A, backend="superlu").solve(b)
    x2 = HermitianFactorization(A, backend="cholmod").solve(b)
    x3 = HermitianFactorization(A, backend="ldl").solve(b)
    # the default: LDLᴴ below LDL_MAX_UNKNOWNS, SuperLU above (measured, gsdf.linalg._direct)
    assert HermitianFactorization(A).backend == "ldl"
    np.testing.assert_allclose(A @ x1, b, atol=1e-10)
    np.testing.assert_allclose(x1, x2, atol=1e-10)
    np.testing.assert_allclose(x1, x3, atol=1e-10)
    with pytest.raises(ValueError, match="backend"):
        HermitianFactorization(A, backend="mumps")


def test_connection_laplacian_is_psd_and_kills_parallel_fields():
    V, F = grid_mesh(6, jitter=0.2, delaunay=True)
    ops = TriangleMeshOperators(V, F)
    L = ops.cr_connection_laplacian().toarray()
    assert np.linalg.eigvalsh(L).min() > -1e-10
    # a constant vector field (1, 0) in the plane expressed in every edge basis is in the kernel
    u = np.zeros(ops.n_edges, complex)
    u[ops.face_edges.ravel()] = (ops.slot_u[..., 0] + 1j * ops.slot_w[..., 0]).ravel()
    assert np.abs(L @ u).max() < 1e-10


def test_saddle_and_lp():
    C = sp.diags([2.0, 2.0, 2.0]).tocsr()
    A = sp.csr_matrix(np.array([[1.0, -1.0, 0.0]]))
    K = saddle_matrix(C, A)
    x = Factorization(K, symmetric=False).solve(np.array([1.0, 3.0, 0.0, 0.0]))
    np.testing.assert_allclose(x[:3], [1.0, 1.0, 0.0])
    sol = solve_lp(np.array([1.0, 1.0]), A_eq=np.array([[1.0, 1.0]]), b_eq=np.array([2.0]))
    assert abs(sol.sum() - 2) < 1e-9
    with pytest.raises(ValueError, match="linear program failed"):
        solve_lp(np.array([1.0]), A_eq=np.array([[1.0]]), b_eq=np.array([-1.0]))
    with pytest.raises(ValueError, match="square"):
        Factorization(sp.csr_matrix(np.ones((2, 3))))
