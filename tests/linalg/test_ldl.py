"""gsdf.linalg._ldl: nested-dissection LDLᴴ against dense solves and SuperLU; orderings; non-PD input."""

import numpy as np
import pytest
import scipy.sparse as sp

from gsdf.data._shapes import grid_mesh, sphere_mesh
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.linalg import Factorization, HermitianFactorization, LDLFactorization, spd_factorization
from gsdf.linalg._ldl import nested_dissection


def _ops():
    V, F = sphere_mesh(2)
    return TriangleMeshOperators(V, F)


def test_complex_hermitian_matches_dense_solve():
    ops = _ops()
    A = (ops.cr_mass() + ops.h ** 2 * ops.cr_connection_laplacian()).tocsr()
    b = np.random.default_rng(1).normal(size=(A.shape[0], 2)) @ np.array([1.0, 1j])
    f = LDLFactorization(A)
    x = f.solve(b)
    np.testing.assert_allclose(x, np.linalg.solve(A.toarray(), b), rtol=1e-10, atol=1e-12)
    # the same from the CSC arrays (read as Aᵀ = conj(A)), and several right-hand sides at once
    np.testing.assert_allclose(LDLFactorization(A.tocsc()).solve(b), x, rtol=1e-12, atol=1e-14)
    B = np.stack([b, 2 * b], axis=1)
    np.testing.assert_allclose(f.solve(B)[:, 1], 2 * x, rtol=1e-12, atol=1e-14)


def test_real_spd_matches_superlu_and_complex_rhs():
    ops = _ops()
    C = ops.cotan_laplacian()
    free = np.arange(5, C.shape[0])
    A = (C[free][:, free]).tocsr()                                # Dirichlet-reduced: SPD
    b = np.random.default_rng(2).normal(size=A.shape[0])
    x = LDLFactorization(A).solve(b)
    np.testing.assert_allclose(x, Factorization(A.tocsc()).solve(b), rtol=1e-10, atol=1e-12)
    z = LDLFactorization(A).solve(b + 2j * b)                     # complex b of a real matrix: two solves
    np.testing.assert_allclose(z, x + 2j * x, rtol=1e-12, atol=1e-13)
    assert type(spd_factorization(A)).__name__ == "LDLFactorization"


def test_nested_dissection_is_a_permutation_with_less_fill_than_natural():
    V, F = grid_mesh(30)
    L = TriangleMeshOperators(V, F).cotan_laplacian().tocsr()
    p = nested_dissection(L)
    assert sorted(p.tolist()) == list(range(L.shape[0]))
    A = (L + sp.identity(L.shape[0])).tocsr()
    f = LDLFactorization(A)
    natural = np.linalg.cholesky(A.toarray())                    # grid numbering: banded fill
    assert f.nnz < 0.6 * (np.count_nonzero(np.abs(natural) > 1e-14) - A.shape[0])
    # disconnected graphs (two blocks) and a path (separator = middle node)
    D = sp.block_diag([A, A]).tocsr()
    np.testing.assert_allclose(LDLFactorization(D).solve(np.ones(D.shape[0])), np.tile(f.solve(np.ones(A.shape[0])), 2),
                               rtol=1e-12)
    P = sp.diags([1, 1, 1], [-1, 0, 1], shape=(7, 7), dtype=float).tocsr()
    assert int(nested_dissection(P, leaf=1)[-1]) == 3


def test_not_positive_definite_raises_and_callers_fall_back():
    A = sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]]))         # indefinite
    with pytest.raises(ValueError, match="positive definite"):
        LDLFactorization(A)
    x = spd_factorization(A).solve(np.array([3.0, 3.0]))          # SuperLU instead
    np.testing.assert_allclose(x, [1.0, 1.0])
    Ac = sp.csr_matrix(np.array([[1.0, 2j], [-2j, 1.0]]))
    assert HermitianFactorization(Ac).backend == "superlu"
    with pytest.raises(ValueError, match="square"):
        LDLFactorization(sp.csr_matrix(np.ones((2, 3))))
    with pytest.raises(ValueError, match="shape"):
        LDLFactorization(sp.identity(3, format="csr")).solve(np.ones(4))


def test_coo_to_csr_matches_scipy_real_and_complex():
    from gsdf.linalg._assembly import coo_to_csr

    rng = np.random.default_rng(3)
    r, c = rng.integers(0, 40, 500), rng.integers(0, 30, 500)
    for v in (rng.normal(size=500), rng.normal(size=500) + 1j * rng.normal(size=500)):
        A = coo_to_csr(r, c, v, (40, 30))
        B = sp.csr_matrix((v, (r, c)), shape=(40, 30))
        assert A.has_canonical_format and np.all(np.diff(A.indices[A.indptr[0]:A.indptr[1]]) > 0)
        np.testing.assert_allclose(A.toarray(), B.toarray(), rtol=1e-13, atol=1e-14)
    ops = _ops()
    np.testing.assert_allclose(ops.cr_vector_heat_matrix(0.1).toarray(),
                               (ops.cr_mass() + 0.1 * ops.cr_connection_laplacian()).toarray(), atol=1e-15)


def test_principal_submatrix_equals_scipy_bit_for_bit():
    """scale · A[keep][:, keep] + diag(d) in one pass: the same arrays as scipy's indexing, scaling and
    addition (CSR and CSC, real and complex; sums that cancel exactly are dropped as scipy drops them, a
    missing diagonal is inserted, explicit zeros are kept without a diagonal); bad input raises."""
    from gsdf.linalg._assembly import principal_submatrix

    rng = np.random.default_rng(5)
    for trial in range(120):
        n = int(rng.integers(1, 25))
        D = (rng.random((n, n)) < 0.3) * rng.integers(-2, 3, (n, n)).astype(float)
        D = D + D.T
        if trial % 3 == 0:
            D = D * (1 + 1j * rng.random((n, n)))
        A = sp.csr_matrix(D) if trial % 2 else sp.csc_matrix(D)
        A.data[::4] = 0.0                                         # explicit zeros
        keep = np.flatnonzero(rng.random(n) < 0.7)
        d = rng.integers(-1, 2, len(keep)).astype(float)         # zeros and exact cancellations
        t = float(rng.choice([1.0, 0.5, 2.0]))
        for got, ref in ((principal_submatrix(A, keep, t, d), t * A[keep][:, keep] + sp.diags(d)),
                         (principal_submatrix(A, keep), A[keep][:, keep])):
            ref = ref.asformat(A.format)
            ref.sort_indices()
            assert got.format == A.format and got.dtype == A.dtype
            for k in ("indptr", "indices", "data"):
                assert np.array_equal(getattr(got, k), getattr(ref, k)), (trial, k)
    with pytest.raises(ValueError, match="diag"):
        principal_submatrix(sp.identity(3, format="csr"), np.array([0, 1]), 1.0, np.ones(3))
    with pytest.raises(ValueError, match="CSR or CSC"):
        principal_submatrix(sp.identity(3, format="coo"))
    I3 = sp.identity(3, format="csr")
    for keep in (np.array([2, 0]), np.array([0, 0, 2]), np.array([0, 3]), np.array([-1, 1]), np.array([[0, 1]]),
                 np.array([0.0, 1.0])):
        with pytest.raises(ValueError, match="keep"):
            principal_submatrix(I3, keep)
    with pytest.raises(ValueError, match="square"):
        principal_submatrix(sp.csr_matrix(np.ones((2, 3))))
    assert principal_submatrix(I3, np.array([], np.int64)).shape == (0, 0)


def test_ordering_hint_taken_unless_flop_heavy_then_fewer_flops_kept():
    """``hint`` is taken as it is when its factor is not flop-heavy (HINT_AMD_FLOPS); a flop-heavy hint
    competes with AMD on flops: a good hint (nested dissection on a grid) or AMD is kept, whichever is
    cheaper; the natural order (a banded, flop-heavy one) never beats AMD; bad hints raise."""
    from gsdf.linalg import _ldl as ldl
    from gsdf.linalg._ldl import _flops, _pattern
    from gsdf.linalg._ordering import approximate_minimum_degree

    V, F = grid_mesh(24)
    ops = TriangleMeshOperators(V, F)
    A = (ops.cotan_laplacian() + sp.diags(ops.vertex_mass())).tocsr()
    n = A.shape[0]
    ip, ix = A.indptr.astype(np.int64), A.indices.astype(np.int64)
    amd = approximate_minimum_degree(A)
    nd = nested_dissection(A)
    fl = {k: _flops(_pattern(ip, ix, n, p)[4]) for k, p in (("amd", amd), ("nd", nd))}
    natural = np.arange(n)
    f_nat = _flops(_pattern(ip, ix, n, natural)[4])
    assert f_nat > fl["amd"]
    heavy = ldl.HINT_AMD_FLOPS * len(ix) * np.log2(n)
    assert max(fl["nd"], f_nat) < heavy                       # both light: taken as given, no AMD pass
    assert np.array_equal(LDLFactorization(A, hint=nd).perm, nd)
    assert np.array_equal(LDLFactorization(A, hint=natural).perm, natural)
    # with a lower threshold both are flop-heavy and compete with AMD
    old = ldl.HINT_AMD_FLOPS
    try:
        ldl.HINT_AMD_FLOPS = 0.5 * min(fl["nd"], f_nat) / (len(ix) * np.log2(n))
        f = LDLFactorization(A, hint=nd)
        assert np.array_equal(f.perm, nd if fl["nd"] <= fl["amd"] else amd)
        g = LDLFactorization(A, hint=natural)
        assert np.array_equal(g.perm, amd)
    finally:
        ldl.HINT_AMD_FLOPS = old
    b = np.random.default_rng(0).normal(size=n)
    np.testing.assert_allclose(A @ f.solve(b), b, atol=1e-10)
    np.testing.assert_allclose(spd_factorization(A, hint=nd).solve(b), LDLFactorization(A, hint=nd).solve(b),
                               rtol=0, atol=0)
    with pytest.raises(ValueError, match="ordering"):
        LDLFactorization(A, hint=np.zeros(n, np.int64))
    with pytest.raises(ValueError, match="ordering"):
        LDLFactorization(A, hint=np.arange(n - 1))


def _quad_connection_laplacian(nx=40, ny=30):
    """A complex Hermitian PD operator on a quad grid (mass + Laplacian with unit-modulus off-diagonal phases):
    the polygon meshes' kind of system, whose AMD factor has wide supernodes."""
    from gsdf.heat.polygon._domain import PolygonDomain

    x, y = np.meshgrid(np.linspace(0, 1, nx), np.linspace(0, 1, ny), indexing="ij")
    V = np.stack([x.ravel(), y.ravel(), 0.1 * np.sin(3 * x.ravel()) * np.cos(2 * y.ravel())], 1)
    idx = np.arange(nx * ny).reshape(nx, ny)
    Q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    D = PolygonDomain(V, Q)
    return D.vector_heat_matrix().tocsr()


def test_supernodal_kernel_matches_up_looking_and_dense_solve(monkeypatch):
    import gsdf.linalg._ldl as ldl

    A = _quad_connection_laplacian()
    b = np.random.default_rng(3).normal(size=A.shape[0]) * (1 + 0.5j)
    monkeypatch.setattr(ldl, "SUPERNODAL_FLOPS", np.inf)          # up-looking
    f0 = LDLFactorization(A, ordering="amd")
    monkeypatch.setattr(ldl, "SUPERNODAL_FLOPS", 0.0)             # supernodal whenever the widths allow
    monkeypatch.setattr(ldl, "SUPERNODAL_WIDTH", 1)
    monkeypatch.setattr(ldl, "SUPERNODAL_MEAN", 1.0)
    calls = []
    kernel = ldl._supernodal_numeric
    monkeypatch.setattr(ldl, "_supernodal_numeric", lambda *a: calls.append(1) or kernel(*a))
    f1 = LDLFactorization(A, ordering="amd")
    assert calls and np.array_equal(f1._lp, f0._lp) and np.array_equal(f1._li, f0._li)
    assert ldl._supernode_widths(*ldl._pattern(A.indptr.astype(np.int64), A.indices.astype(np.int64),
                                               A.shape[0], f1.perm)[3:])[0] > 8
    np.testing.assert_allclose(f1._lx, f0._lx, rtol=0, atol=1e-12 * np.abs(f0._lx).max())
    np.testing.assert_allclose(f1._d, f0._d, rtol=1e-12)
    x = f1.solve(b)
    np.testing.assert_allclose(x, np.linalg.solve(A.toarray(), b), rtol=1e-10, atol=1e-12)
    # not positive definite: the supernodal kernel reports the pivot, the constructor raises
    with pytest.raises(ValueError, match="not positive definite"):
        LDLFactorization((A - 10 * sp.identity(A.shape[0])).tocsr(), ordering="amd")


def test_supernodal_rule_picks_complex_polygon_systems_only():
    import gsdf.linalg._ldl as ldl

    A = _quad_connection_laplacian(90, 90)
    pat = ldl._pattern(A.indptr.astype(np.int64), A.indices.astype(np.int64), A.shape[0],
                       ldl.order_csr(A.indptr.astype(np.int64), A.indices.astype(np.int64), A.shape[0], "amd"))
    assert ldl._use_supernodal(True, pat[3], pat[4])
    assert not ldl._use_supernodal(False, pat[3], pat[4])          # real systems stay up-looking


def test_int32_indices_same_solve_as_int64():
    """L's indices are int32 (less memory traffic in the solves); the solve is bit-identical to one over
    int64 copies of the same factor (real and complex Hermitian)."""
    import scipy.sparse as sp

    from gsdf.linalg import _ldl as ldl

    rng = np.random.default_rng(3)
    n = 400
    B = sp.random(n, n, density=0.02, random_state=4, format="csr")
    A = (B @ B.T + sp.identity(n) * 5).tocsr()
    Ac = (A + 1j * sp.triu(B, 1) - 1j * sp.triu(B, 1).T).tocsr()
    Ac = (Ac + Ac.conj().T) * 0.5 + sp.identity(n) * float(abs(Ac).sum(axis=1).max())
    for M in (A, Ac.tocsr()):
        f = ldl.LDLFactorization(M)
        assert f._li.dtype == np.int32 and f._lp.dtype == np.int32
        b = rng.standard_normal(n) + (1j * rng.standard_normal(n) if np.iscomplexobj(M.data) else 0)
        bp = np.ascontiguousarray(b[f.perm], f.dtype)
        x32 = ldl._solve(f._lp, f._li, f._lx, f._d, bp)
        x64 = ldl._solve(f._lp.astype(np.int64), f._li.astype(np.int64), f._lx, f._d, bp)
        assert np.array_equal(x32, x64)
        assert np.linalg.norm(M @ f.solve(b) - b) <= 1e-10 * np.linalg.norm(b)


def test_too_many_entries_for_int32_raises(monkeypatch):
    import scipy.sparse as sp

    from gsdf.linalg import _ldl as ldl

    monkeypatch.setattr(ldl, "INDEX_MAX", 2)
    A = sp.csr_matrix(np.array([[4.0, 1, 1], [1, 3, 1], [1, 1, 2]]))
    with pytest.raises(ValueError, match="int32"):
        ldl.LDLFactorization(A)
