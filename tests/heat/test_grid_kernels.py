"""Fast building blocks of the grid signed heat method against independent implementations: the dense-matrix
DCT against scipy.fft, the 3×3 Jacobi PCA against LAPACK, the grid-operator cache against a fresh build, the
Yukawa tree against the direct sum, and the cloud-area candidate search against the k-d tree."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.fft import dctn, idctn
from scipy.spatial import cKDTree

from gsdf.heat.grid import _poisson as G
from gsdf.heat.volume._sources import point_sources
from gsdf.heat._yukawa import YukawaTree
from gsdf.winding._point_areas import _candidate_search, _smallest_eigenvector3


@pytest.mark.parametrize("shape", [(2, 2, 2), (5, 1, 3), (23, 32, 27), (40, 40, 21), (50, 30, 30)])
def test_dct3_matches_scipy(shape):
    X = np.random.default_rng(sum(shape)).standard_normal(shape)
    assert np.abs(G.dct3(X) - dctn(X, type=2, norm="ortho")).max() < 1e-12
    assert np.abs(G.dct3(X, inverse=True) - idctn(X, type=2, norm="ortho")).max() < 1e-12
    assert np.abs(G.dct3(G.dct3(X), inverse=True) - X).max() < 1e-12


def test_dct_poisson_solves_the_neumann_laplacian():
    shape, h = (13, 9, 11), np.array([0.1, 0.2, 0.15])
    rhs = np.random.default_rng(0).standard_normal(int(np.prod(shape)))
    rhs -= rhs.mean()
    phi = G.dct_poisson(rhs, shape, h)
    L = G.neumann_laplacian(shape, h)
    assert np.abs(L @ phi - rhs).max() < 1e-9 * np.abs(rhs).max()
    assert abs(phi.mean()) < 1e-12


def test_smallest_eigenvector3_matches_lapack():
    rng = np.random.default_rng(3)
    for trial in range(300):
        X = rng.standard_normal((25, 3)) * rng.random(3) ** (3 * (trial % 4))
        X *= 10.0 ** rng.uniform(-4, 4)
        C = (X - X.mean(0)).T @ (X - X.mean(0))
        w, U = np.linalg.eigh(C)
        wmid, wmax, vx, vy, vz = _smallest_eigenvector3(C.copy())
        assert abs(wmid - w[1]) <= 1e-12 * w[2] and abs(wmax - w[2]) <= 1e-12 * w[2]
        if w[1] - w[0] > 1e-6 * w[2]:
            assert 1 - abs(np.dot([vx, vy, vz], U[:, 0])) < 1e-12
    # a diagonal matrix is already converged; collinear points have two zero eigenvalues
    assert _smallest_eigenvector3(np.diag([3.0, 1.0, 2.0]))[2:] == (0.0, 1.0, 0.0)
    X = np.outer(np.arange(5.0), [1.0, 2.0, 3.0])
    wmid, wmax = _smallest_eigenvector3((X - X.mean(0)).T @ (X - X.mean(0)))[:2]
    assert wmid <= 1e-12 * wmax


def test_kron_laplacian_equals_the_direct_assembly():
    shape, h = (10, 7, 9), (0.1, 0.1, 0.1)
    ref = (G._neumann_laplacian_kron(shape, h) - G.neumann_laplacian(shape, h)).tocsr()
    assert abs(ref).max() < 1e-9


def test_cg_loop_matches_scipy_cg():
    """gsdf.linalg._iterative.cg_loop is SciPy's cg on callables: the same iterates, the same stopping rule."""
    from scipy.sparse.linalg import LinearOperator, cg

    from gsdf.linalg._iterative import cg_loop

    rng = np.random.default_rng(4)
    A = sp.random(300, 300, 0.02, random_state=4)
    A = (A @ A.T + sp.identity(300)).tocsr()
    d = 1.0 / A.diagonal()
    b = rng.standard_normal(300)
    for maxiter in (3, 200):
        ref, info = cg(A, b, x0=np.zeros(300), M=LinearOperator(A.shape, matvec=lambda r: d * r), rtol=1e-8,
                       atol=0.0, maxiter=maxiter)
        x, ok = cg_loop(lambda v: A @ v, lambda r: d * r, b, np.zeros(300), rtol=1e-8, maxiter=maxiter)
        assert ok == (info == 0)
        assert np.abs(x - ref).max() <= 1e-12 * np.abs(ref).max()
    assert cg_loop(lambda v: A @ v, lambda r: r, np.zeros(300), np.ones(300))[0].any() == 0


def test_solve_poisson_penalized_against_a_direct_solve():
    shape, h = (12, 10, 8), np.full(3, 0.1)
    n = int(np.prod(shape))
    rng = np.random.default_rng(5)
    P = rng.random((40, 3)) * (np.array(shape) - 1) * h
    T = G.trilinear_matrix(P, np.zeros(3), h, shape)
    pen = (T.T @ sp.diags(np.full(40, 1e3)) @ T).tocsr()
    rhs = rng.standard_normal(n)
    x = G.solve_poisson(rhs, shape, h, pen, tol=1e-10)
    A = (G.neumann_laplacian(shape, h) + pen).tocsc()
    xd = sp.linalg.spsolve(A, rhs)
    assert np.abs(x - xd).max() < 1e-6 * np.abs(xd).max()


def test_yukawa_tree_matches_direct_sum():
    rng = np.random.default_rng(2)
    B = rng.standard_normal((600, 3))
    B /= np.linalg.norm(B, axis=1, keepdims=True)
    W = B * 0.01
    Q = rng.uniform(-1.5, 1.5, (300, 3))
    tree = YukawaTree(B, W, t=0.01, theta=0.5, eps=1e-8)
    X, Xd = tree(Q), tree.direct(Q)
    rel = np.linalg.norm(X - Xd, axis=1) / np.linalg.norm(Xd, axis=1)
    assert np.median(rel) < 1e-3 and rel.max() < 0.05
    exact = YukawaTree(B, W, t=0.01, theta=0.0, eps=1e-8)(Q)     # no clusters: the direct sum, pruned at 1e-8
    assert (np.linalg.norm(exact - Xd, axis=1) / np.linalg.norm(Xd, axis=1)).max() < 1e-6


def test_yukawa_tree_refuses_a_progress_that_is_not_callable():
    tree = YukawaTree(np.eye(3), np.eye(3), t=0.01)
    with pytest.raises(ValueError, match="progress: expected a callable"):
        tree([[0.5, 0.0, 0.2]], progress=3)
    seen = []
    tree([[0.5, 0.0, 0.2]], progress=lambda stage, f: seen.append(f))
    assert seen == [1.0]


@pytest.mark.parametrize("k", [5, 41, 161])
def test_candidate_search_same_sets_as_kd_tree(k):
    P = np.random.default_rng(k).random((700, 3))
    rows = _candidate_search(P, k).rows(0, 700)
    ref = cKDTree(P).query(P, k)[1]
    assert np.array_equal(np.sort(rows, axis=1), np.sort(ref, axis=1))


def test_point_sources_candidates():
    i = np.arange(500) + 0.5
    ph, th = np.arccos(1 - 2 * i / 500), np.pi * (1 + 5 ** 0.5) * i
    P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    for c in (1, 2, 8):
        s = point_sources(P, P, candidates=c)
        assert abs(s.a.sum() / (4 * np.pi) - 1) < 0.03           # the areas of a sphere sum to 4π
    with pytest.raises(ValueError, match="candidates"):
        point_sources(P, P, candidates=0)
    with pytest.raises(ValueError, match="candidates"):
        point_sources(P, P, candidates=True)


def test_yukawa_tree_validates_sources_weights_and_queries():
    """NaN weights gave NaN fields; a (m, 2) W was accepted; NaN sources/queries leaked SciPy's text."""
    B = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    W = np.array([[0, 0, 1.0], [0, 0, 1.0]])
    for args, why in (((B, W * np.nan), "W: contains NaN"), ((B * np.nan, W), "B: contains NaN"),
                      ((B, W[:, :2]), r"W: expected shape \(n, 3\)"), ((B, W[:1]), "W: has 1 rows but there are 2"),
                      ((B, W + 1j), "W: expected numeric coordinates, got complex")):
        with pytest.raises(ValueError, match=why):
            YukawaTree(*args, t=0.01)
    tree = YukawaTree(B, W, t=0.01)
    with pytest.raises(ValueError, match="Q: contains NaN"):
        tree([[np.nan, 0, 0.2]])
    with pytest.raises(ValueError, match=r"dref: expected shape \(1,\)"):
        tree([[0.5, 0, 0.2]], dref=[1.0, 2.0])
    assert np.isfinite(tree([[0.5, 0, 0.2]])).all()
