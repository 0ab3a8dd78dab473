"""gsdf.linalg._ordering: AMD and nested dissection are permutations; AMD's fill against nested dissection, RCM
and SuperLU's multiple minimum degree; the LDLᴴ factors do not depend on the ordering; bad input."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import reverse_cuthill_mckee
from scipy.spatial import Delaunay

from gsdf.data._shapes import grid_mesh
from gsdf.mesh._triangle_ops import TriangleOperators
from gsdf.linalg._ldl import LDLFactorization, fill_count
from gsdf.linalg._ordering import approximate_minimum_degree, fill_reducing_ordering, nested_dissection


def _delaunay_laplacian(n, seed):
    """Graph Laplacian + 10 I of the Delaunay triangulation of n random points (an irregular planar mesh)."""
    X = np.random.default_rng(seed).random((n, 2))
    T = Delaunay(X).simplices
    i, j = T.ravel(), T[:, [1, 2, 0]].ravel()
    W = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    W = ((W + W.T) > 0).astype(float)
    return (sp.diags(np.asarray(W.sum(1)).ravel() + 10.0) - W).tocsr()


def _mmd_perm(A):
    """SuperLU's multiple minimum degree on A + Aᵀ as an elimination order (perm_c[j] = position of column j)."""
    lu = spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    p = np.empty(A.shape[0], np.int64)
    p[lu.perm_c] = np.arange(A.shape[0])
    return p


def test_permutation_on_random_graphs():
    rng = np.random.default_rng(0)
    for n in [1, 2, 3, 7, 20, 60, 150]:
        for density in (0.0, 0.05, 0.3, 1.0):
            m = int(density * n * n)
            r, c = rng.integers(0, n, m), rng.integers(0, n, m)       # unsymmetric, duplicates, diagonal entries
            A = sp.csr_matrix((np.ones(m), (r, c)), shape=(n, n))
            for order in (approximate_minimum_degree, nested_dissection):
                p = order(A)
                assert p.dtype == np.int64 and np.array_equal(np.sort(p), np.arange(n))
    assert approximate_minimum_degree(sp.csr_matrix((0, 0))).shape == (0,)


def test_amd_on_trees_and_cliques_is_exact():
    n = 40
    path = sp.diags([1.0, 4.0, 1.0], [-1, 0, 1], shape=(n, n)).tocsr()
    assert fill_count(path, approximate_minimum_degree(path)) == n - 1           # a tree: no fill at all
    r = np.arange(1, n)
    star = sp.csr_matrix((np.ones(2 * (n - 1)), (np.r_[r, 0 * r], np.r_[0 * r, r])), shape=(n, n)) + sp.identity(n)
    p = approximate_minimum_degree(star)
    assert p[-1] == 0 or p[-2] == 0                                              # the hub among the last two
    assert fill_count(star, p) == n - 1
    K = sp.csr_matrix(np.ones((12, 12)))
    assert fill_count(K, approximate_minimum_degree(K)) == 12 * 11 // 2


def test_amd_fill_against_nested_dissection_rcm_and_superlu_mmd():
    for n, seed in ((600, 1), (2500, 2)):
        A = _delaunay_laplacian(n, seed)
        amd = fill_count(A, approximate_minimum_degree(A))
        nd = fill_count(A, nested_dissection(A))
        rcm = fill_count(A, reverse_cuthill_mckee(A, symmetric_mode=True))
        mmd = fill_count(A, _mmd_perm(A))
        assert amd < 0.75 * nd and amd < 0.3 * rcm
        assert amd <= 1.05 * mmd
    V, F = grid_mesh(40)                                                        # a regular grid: ND is strong
    A = (TriangleOperators(V, F).cotan_laplacian() + sp.identity(len(V))).tocsr()
    amd = fill_count(A, approximate_minimum_degree(A))
    assert amd <= 1.05 * fill_count(A, nested_dissection(A))
    assert amd <= 1.05 * fill_count(A, _mmd_perm(A))
    assert amd < 0.5 * fill_count(A, reverse_cuthill_mckee(A, symmetric_mode=True))


def test_factors_do_not_depend_on_the_ordering():
    A = _delaunay_laplacian(400, 3)
    Ac = (A + 1j * sp.triu(A, 1) * 0.1 - 1j * sp.tril(A, -1) * 0.1).tocsr()     # Hermitian, still PD
    rng = np.random.default_rng(4)
    for M in (A, Ac):
        b = rng.normal(size=M.shape[0]) + (1j * rng.normal(size=M.shape[0]) if M is Ac else 0)
        x_ref = np.linalg.solve(M.toarray(), b)
        for ordering in ("auto", "amd", "nd", np.arange(M.shape[0]), rng.permutation(M.shape[0])):
            f = LDLFactorization(M, ordering=ordering)
            np.testing.assert_allclose(f.solve(b), x_ref, rtol=1e-10, atol=1e-12)
        # the same D up to reordering: the product of the pivots is det(A) whatever the order
        d_amd = LDLFactorization(M, ordering="amd")._d
        d_nd = LDLFactorization(M, ordering="nd")._d
        assert np.isclose(np.sum(np.log(d_amd)), np.sum(np.log(d_nd)), rtol=1e-12)
    assert LDLFactorization(A, ordering="amd").nnz < LDLFactorization(A, ordering="nd").nnz


def test_bad_orderings_raise():
    A = _delaunay_laplacian(50, 5)
    for bad in ("metis", "", None, True, 3):
        with pytest.raises(ValueError, match="ordering"):
            LDLFactorization(A, ordering=bad)
    for bad in (np.zeros(50, np.int64), np.arange(49), np.arange(50) + 1, np.arange(50) * 1.0):
        with pytest.raises(ValueError, match="ordering"):
            LDLFactorization(A, ordering=bad)
    with pytest.raises(ValueError, match="ordering"):
        fill_reducing_ordering(A, "colamd")
    with pytest.raises(ValueError, match="square"):
        approximate_minimum_degree(sp.csr_matrix(np.ones((2, 3))))
    with pytest.raises(ValueError, match="ordering"):
        fill_count(A, np.arange(3))


def _flop_count(f):
    c = np.diff(f._lp).astype(float)
    return float(c @ c)


def test_auto_rule_keeps_the_cheaper_ordering():
    from gsdf.linalg._ldl import AUTO_ND_FLOPS, AUTO_ND_MAX_N

    def periodic(m):
        T = sp.diags([1.0, 1.0, 1.0], [-1, 0, 1], shape=(m, m)).tolil()
        T[0, m - 1] = T[m - 1, 0] = 1.0
        return T.tocsr()

    # a quad torus (9-point stencil, periodic) cut along two rings: a flop-heavy factor where ND has fewer flops
    a, b = 96, 48
    G = sp.kron(periodic(a), periodic(b)).tocsr()
    keep = np.ones(a * b, bool)
    keep[np.r_[(a // 4) * b:(a // 4 + 1) * b, (3 * a // 4) * b:(3 * a // 4 + 1) * b]] = False
    k = np.flatnonzero(keep)
    torus = (sp.diags(np.full(a * b, 20.0)) - 0.1 * G).tocsr()[k][:, k].tocsr()
    for A in (torus, _delaunay_laplacian(3000, 6)):
        assert A.shape[0] <= AUTO_ND_MAX_N
        f_auto, f_amd, f_nd = (LDLFactorization(A, ordering=o) for o in ("auto", "amd", "nd"))
        heavy = _flop_count(f_amd) >= AUTO_ND_FLOPS * A.nnz * np.log2(A.shape[0])
        expect = f_nd if heavy and _flop_count(f_nd) < 0.9 * _flop_count(f_amd) else f_amd
        assert np.array_equal(f_auto.perm, expect.perm)
        b_ = np.ones(A.shape[0])
        np.testing.assert_allclose(f_auto.solve(b_), f_amd.solve(b_), rtol=1e-12)
    assert np.array_equal(LDLFactorization(torus).perm, LDLFactorization(torus, ordering="nd").perm)
    D = _delaunay_laplacian(3000, 6)
    assert np.array_equal(LDLFactorization(D).perm, LDLFactorization(D, ordering="amd").perm)
