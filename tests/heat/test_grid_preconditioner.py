"""Small-grid speed path of the volume signed heat method (issue 17 goal 6): the Step III preconditioner that
carries its residual through the stages, against a sparse direct solve and the stage-by-stage recomputation."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve


def _penalized_system(shape=(11, 9, 8), m=60, seed=4):
    """L + P of the soft level-set penalty for m random sources on a small grid, and a right-hand side."""
    from gsdf.heat.grid._poisson import neumann_laplacian, trilinear_matrix

    rng = np.random.default_rng(seed)
    spacing = np.array([0.1, 0.1, 0.1])
    lo = np.zeros(3)
    B = lo + rng.uniform(0.15, 0.65, (m, 3)) * (np.array(shape) - 1) * spacing
    T = trilinear_matrix(B, lo, spacing, shape)
    P = (T.T @ sp.diags(rng.uniform(1, 3, m) * 10 / 0.1 ** 4) @ T).tocsr()
    b = rng.normal(size=int(np.prod(shape)))
    L = neumann_laplacian(shape, spacing)
    return shape, spacing, L, P, b


def test_carried_residual_preconditioner_solves_the_penalized_system():
    from gsdf.heat.grid._poisson import solve_poisson

    shape, spacing, L, P, b = _penalized_system()
    A = (L + P).tocsc()
    ref = spsolve(A, b)
    for block in (3, 4):
        x = solve_poisson(b, shape, spacing, P, tol=1e-11, min_block=block)
        assert np.abs(x - ref).max() <= 1e-8 * np.abs(ref).max()
    x = solve_poisson(b, shape, spacing, P)  # default tolerance: relative residual 1e-5
    assert np.linalg.norm(A @ x - b) <= 1.1e-5 * np.linalg.norm(b)


def test_carried_residual_is_the_same_operator_as_recomputing_it():
    """One preconditioner application of the fast path (numba kernels, carried residual) equals the
    stage-by-stage r − A x version with SciPy matrices, and its A x equals (L + P) x."""
    from scipy.sparse.linalg import LinearOperator

    import gsdf.heat.grid._poisson as G

    shape, spacing, L, P, b = _penalized_system(seed=7)
    seen = {}
    real_pcg = G.pcg

    def capture(A, rhs, M=None, **kw):
        seen.setdefault("M", []).append(M)
        return real_pcg(A, rhs, M=M, **kw)

    G.pcg = capture
    try:
        G._solve_poisson_reference(b, shape, spacing, P, block=3)
    finally:
        G.pcg = real_pcg
    (slow,) = seen["M"]
    assert isinstance(slow, LinearOperator)
    fast = G.PenalizedPoisson(shape, spacing, P, min_block=3)
    assert fast.block == 3
    r = np.random.default_rng(1).normal(size=L.shape[0])
    zf, zs = fast.precondition(r), slow.matvec(r)
    assert np.abs(zf - zs).max() <= 1e-9 * np.abs(zs).max()
    assert np.abs(fast.matvec(r) - (L + P) @ r).max() <= 1e-12 * np.abs((L + P) @ r).max()
    # symmetric (CG needs it): <M r, s> = <r, M s>
    s = np.random.default_rng(2).normal(size=L.shape[0])
    assert abs(fast.precondition(r) @ s - r @ fast.precondition(s)) <= 1e-9 * abs(r @ fast.precondition(s))
    # the coarse matrix assembled on the grid is the Galerkin product R (L + P) Rᵀ
    R = G._aggregation(shape, 3)
    C = (R @ (L + P) @ R.T).toarray()
    x = np.random.default_rng(3).normal(size=C.shape[0])
    assert np.abs(fast.coarse.solve(C @ x) - x).max() <= 1e-8 * np.abs(x).max()


def test_penalty_matrix_equals_the_sparse_product():
    """P = Aᵀ diag(w) A: the cell kernel for trilinear rows (points on nodes, faces and corners of the box
    included), SciPy's product for rows spanning several cells."""
    import scipy.sparse as sp

    import gsdf.heat.grid._poisson as G

    rng = np.random.default_rng(0)
    shape, h = (12, 9, 7), np.full(3, 0.1)
    B = rng.random((300, 3)) * (np.array(shape) - 1) * h
    B[:4] = 0.0
    B[4] = (np.array(shape) - 1) * h
    B[5] = np.array([3, 4, 2]) * h                       # on a node
    T = G.trilinear_matrix(B, np.zeros(3), h, shape)
    assert T.has_canonical_format
    assert abs(T - sp.csr_matrix(T.toarray())).max() == 0
    w = rng.random(300)
    ref = (T.T @ sp.diags(w) @ T).tocsr()
    assert abs(G.penalty_matrix(T, w, shape) - ref).max() <= 1e-15 * abs(ref).max()
    D = sp.csr_matrix(np.vstack([T[:3].toarray(), T[10].toarray() - T[200].toarray()]))   # not in one cell
    assert abs(G.penalty_matrix(D, 2.0, shape) - 2.0 * (D.T @ D)).max() <= 1e-15 * abs(D.T @ D).max()
    # few entries that are not one cell although each is within one node of the row's first entry
    idx = lambda i, j, k: (i * shape[1] + j) * shape[2] + k
    E = sp.csr_matrix(([1.0, -2.0, 1.0], ([0, 0, 0], [idx(1, 1, 2), idx(1, 2, 1), idx(1, 2, 3)])),
                      shape=(1, T.shape[1]))
    assert abs(G.penalty_matrix(E, 1.0, shape) - E.T @ E).max() == 0
    with pytest.raises(ValueError, match="columns"):
        G.penalty_matrix(T[:, :-1], 1.0, shape)


def test_solve_poisson_penalty_without_constants():
    """A penalty of differences only (P·1 = 0) gives a finite answer; an all-zero penalty is refused."""
    import scipy.sparse as sp

    import gsdf.heat.grid._poisson as G

    shape, h = (6, 5, 4), np.full(3, 0.2)
    n = int(np.prod(shape))
    rhs = np.random.default_rng(0).normal(size=n)
    rhs -= rhs.mean()
    d = sp.csr_matrix(([1.0, -1.0], ([0, 0], [0, n - 1])), shape=(1, n))
    x = G.solve_poisson(rhs, shape, h, (d.T @ d).tocsr())
    assert np.isfinite(x).all()
    with pytest.raises(ValueError, match="penalty"):
        G.solve_poisson(rhs, shape, h, sp.csr_matrix((n, n)))


def test_small_cloud_volume_field_unchanged_by_the_fast_path(monkeypatch):
    """The whole soft-penalty grid run at 14³ against the reference preconditioner (same φ to CG tolerance);
    at the default tolerance (1e-3) φ moves by well under 1e-3 of its range."""
    import gsdf.heat.grid._poisson as G
    from gsdf.heat.grid._domain import GridPoisson
    from gsdf.heat.volume import signed_heat_volume

    i = np.arange(400) + 0.5
    ph, th = np.arccos(1 - 2 * i / 400), np.pi * (1 + 5 ** 0.5) * i
    S = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    default = signed_heat_volume(points=(S, S), resolution=14).values
    monkeypatch.setattr(GridPoisson, "penalty_tol", 1e-7)
    fast = signed_heat_volume(points=(S, S), resolution=14).values
    assert 0 < np.abs(default - fast).max() <= 1e-3 * np.abs(fast).max()
    real = G.solve_poisson
    G.solve_poisson = lambda rhs, shape, spacing, penalty=None, **kw: (
        real(rhs, shape, spacing) if penalty is None
        else G._solve_poisson_reference(rhs, shape, spacing, penalty, tol=1e-10))
    import gsdf.heat.grid._domain as D

    old_ref = D.solve_poisson
    D.solve_poisson = G.solve_poisson
    try:
        slow = signed_heat_volume(points=(S, S), resolution=14).values
    finally:
        G.solve_poisson = real
        D.solve_poisson = old_ref
    assert np.abs(fast - slow).max() <= 1e-6 * np.abs(slow).max()
    c = fast.shape[0] // 2
    assert fast[c, c, c] < -0.7  # the centre of the unit sphere


def test_self_knn_matches_the_kd_tree():
    """The cell-grid k nearest neighbours of point_areas: the k-d tree's sets (clustered cloud and an exact
    lattice full of ties, where the k-th distances must agree), row ranges, degenerate and bad input."""
    import pytest
    from scipy.spatial import cKDTree

    from gsdf.spatial._knn import SelfKNN, knn_self

    rng = np.random.default_rng(5)
    P = np.vstack([rng.normal(size=(400, 3)) * [1, 1, 0.01], rng.random((300, 3)) * 5 + 3])  # a sheet + a blob
    for k in (1, 7, 161, 700):
        ref = cKDTree(P).query(P, k)[1].reshape(len(P), k)
        got = knn_self(P, k)
        assert np.array_equal(np.sort(got, axis=1), np.sort(ref, axis=1))
    assert np.array_equal(SelfKNN(P, 9).rows(100, 130), knn_self(P, 9)[100:130])
    for s, e in ((-1, 5), (10, 5), (0, len(P) + 1)):
        with pytest.raises(ValueError, match="rows"):
            SelfKNN(P, 9).rows(s, e)
    with pytest.raises(ValueError, match="ordered"):
        SelfKNN(P, 9, ordered="no")
    for k in (1, 7, 41):   # ordered rows: sorted by distance, ties by index — the k-d tree's rows
        assert np.array_equal(SelfKNN(P, k, ordered=True).rows(), cKDTree(P).query(P, k)[1].reshape(len(P), k))
    g = np.arange(7) * 0.5
    G = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    d_ref = cKDTree(G).query(G, 19)[0]
    got = knn_self(G, 19)
    assert np.allclose(np.sort(np.linalg.norm(G[got] - G[:, None], axis=2), axis=1), d_ref)
    assert all(len(set(r)) == 19 for r in got.tolist())
    ordered = SelfKNN(G, 19, ordered=True).rows()   # a lattice: many ties at every distance, broken by index
    d = np.linalg.norm(G[ordered] - G[:, None], axis=2)
    assert np.allclose(d, d_ref) and np.all(np.diff(d, axis=1) >= -1e-12)
    tie = np.isclose(d[:, 1:], d[:, :-1])
    assert np.all(ordered[:, 1:][tie] > ordered[:, :-1][tie])
    assert np.array_equal(knn_self(np.ones((5, 3)), 3), np.tile([0, 1, 2], (5, 1)))
    for bad, k in ((P[:, :2], 3), (P, 0), (P, len(P) + 1), (P, True), (P, 2.5)):
        with pytest.raises(ValueError):
            knn_self(bad, k)
    Q = P.copy()
    Q[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        knn_self(Q, 3)



def test_grid_multiple_soft_rows_without_components_is_a_clear_error():
    """Sources without connected components (no node rows): "multiple" soft rows name the problem (was a
    TypeError from indexing None)."""
    from types import SimpleNamespace

    from gsdf.heat.grid._domain import GridDomain

    D = GridDomain(np.zeros(3), np.ones(3), (6, 6, 6), t=0.01)
    with pytest.raises(ValueError, match="multiple"):
        D.soft_rows(SimpleNamespace(node_rows=None), "multiple", 1.0)
