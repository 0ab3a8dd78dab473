"""Tet domain (§8.1, App. B): TetField evaluation, marching tetrahedra, the graded mesh, the signed heat solve
against the exact signed distance, and the level-set constraints "zero", "multiple", "none"."""

import numpy as np
import pytest
from scipy.spatial import Delaunay

import gsdf
from gsdf.field import TetField
from gsdf.contour._tets import locate_in_tets, marching_tetrahedra
from gsdf.heat.volume import VolumeHeatOptions, signed_heat_volume
from gsdf.heat.tet._mesh import graded_lattice, surface_samples, tet_quality

from tests.shapes import uv_sphere


def test_tetfield_interpolates_linear_functions_and_contours_closed():
    rng = np.random.default_rng(0)
    X = rng.uniform(-1, 1, (3000, 3))
    D = Delaunay(X)
    lin = X @ [0.3, -0.2, 0.5] + 0.1
    f = TetField(X, D.simplices, lin, D)
    Q = rng.uniform(-0.5, 0.5, (200, 3))
    np.testing.assert_allclose(f(Q), Q @ [0.3, -0.2, 0.5] + 0.1, atol=1e-12)
    g = TetField(X, D.simplices, np.linalg.norm(X, axis=1) - 0.6)
    V, F = g.isosurface(0.0)
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    assert np.all(np.unique(E, axis=0, return_counts=True)[1] == 2)  # closed, edge-manifold
    assert abs(gsdf.winding_number(V, F, [[0, 0, 0]])[0] - 1) < 1e-6  # oriented outward
    assert abs(np.linalg.norm(V, axis=1).mean() - 0.6) < 0.02
    with pytest.raises(ValueError, match="outside"):
        marching_tetrahedra(X, D.simplices, lin, 10.0)
    with pytest.raises(ValueError, match="tets"):
        TetField(X, np.zeros((0, 4), int), lin)


def test_locate_in_arbitrary_tets_without_delaunay():
    rng = np.random.default_rng(1)
    X = rng.uniform(-1, 1, (500, 3))
    T = Delaunay(X).simplices
    Q = rng.uniform(-0.4, 0.4, (300, 3))
    s, b = locate_in_tets(X, T, Q)
    assert np.all(s >= 0) and np.all(b.min(axis=1) > -1e-9)
    np.testing.assert_allclose(np.einsum("qk,qkd->qd", b, X[T[s]]), Q, atol=1e-10)
    f = TetField(X, T, X[:, 0] * 2 - X[:, 2])  # no locator given: located among its own tets
    np.testing.assert_allclose(f(Q), Q[:, 0] * 2 - Q[:, 2], atol=1e-10)


def test_graded_lattice_and_surface_samples():
    Z = np.array([[0.0, 0.0, 0.0]])
    lo, hi, h = np.array([-1.0] * 3), np.array([1.0] * 3), 0.1
    L = graded_lattice(Z, lo, hi, h, levels=3)
    d = np.linalg.norm(L, axis=1)
    assert d.min() >= 0.35 * h - 1e-6  # nothing too close to the input
    assert np.all(L >= lo - 1e-12) and np.all(L <= hi + 1e-12)
    for c in ([-1, -1, -1], [1, 1, 1], [1, -1, 1]):  # box corners included
        assert np.min(np.linalg.norm(L - c, axis=1)) < 1e-9
    near = (d < 0.15).sum() / (4 / 3 * np.pi * 0.15 ** 3)
    far = ((d > 0.6) & (d < 0.8)).sum() / (4 / 3 * np.pi * (0.8 ** 3 - 0.6 ** 3))
    assert near > 3 * far  # graded: denser near the input
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    S, owner = surface_samples(V, np.array([[0, 1, 2]]), 0.25)
    assert len(S) > 10 and np.all(owner == 0) and np.allclose(S[:, 2], 0) and np.all(S[:, :2].sum(1) <= 1 + 1e-12)
    allp = np.concatenate([V, S])
    gaps = np.sort(np.linalg.norm(allp[:, None] - allp[None], axis=2), axis=1)[:, 1]
    assert gaps.max() <= 0.25 + 1e-9


@pytest.fixture(scope="module")
def sphere():
    return uv_sphere(12, 24)


def test_tet_sphere_sdf_close_to_exact_and_zero_on_input(sphere, tmp_path):
    V, F = sphere
    f = signed_heat_volume(mesh=(V, F), domain="tet", resolution=12)
    assert np.abs(f(V)).max() < 1e-12  # exactly zero on the input vertices
    rng = np.random.default_rng(0)
    Q = rng.uniform(-1.25, 1.25, (2000, 3))
    err = np.abs(f(Q) - gsdf.signed_distance(V, F, Q))
    h = f.meta["h"]
    assert err.mean() < 0.08 * h and np.quantile(err, 0.99) < 0.6 * h
    tets = f.tets
    q = tet_quality(f.vertices, tets)
    assert f.meta["n_dropped_tets"] == int((q < 0.02).sum())
    Vi, Fi = f.isosurface(0.0)
    assert abs(np.linalg.norm(Vi, axis=1).mean() - 0.98) < 0.02
    f.save(tmp_path / "t.npz")
    np.testing.assert_allclose(TetField.load(tmp_path / "t.npz").values, f.values)


def test_tet_multiple_constant_per_component_and_none():
    V1, F1 = uv_sphere(10, 20)
    V = np.vstack([0.45 * V1 - [0.6, 0, 0], 0.45 * V1 + [0.6, 0, 0]])
    F = np.vstack([F1, F1 + len(V1)])
    f = signed_heat_volume(mesh=(V, F), domain="tet", resolution=11,
                           options=VolumeHeatOptions(level_set_constraint="multiple"))
    assert f.meta["n_components"] == 2
    a, b = f(V[: len(V1)]), f(V[len(V1):])
    assert np.ptp(a) < 1e-10 and np.ptp(b) < 1e-10  # one constant per component
    assert abs(a[0]) < 0.05 and abs(b[0]) < 0.05
    d = f([[-0.6, 0, 0], [0.6, 0, 0], [0, 0, 0]])
    assert d[0] < -0.3 and d[1] < -0.3 and d[2] > 0.0  # the gap between them is outside
    g = signed_heat_volume(mesh=(V, F), domain="tet", resolution=11,
                           options=VolumeHeatOptions(level_set_constraint="none"))
    assert np.ptp(g(V[: len(V1)])) > 1e-6  # unconstrained: not constant on the input
    assert abs(np.mean(g(V))) < 0.02


def test_tet_point_cloud():
    i = np.arange(500) + 0.5
    phi, th = np.arccos(1 - 2 * i / 500), np.pi * (1 + 5 ** 0.5) * i
    P = np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])
    f = signed_heat_volume(points=(P, P), domain="tet", resolution=10)
    assert np.abs(f(P)).max() < 1e-12
    Q = np.array([[0, 0, 0.0], [0.5, 0, 0], [1.2, 0, 0]])
    assert np.all(np.abs(f(Q) - [-1.0, -0.5, 0.2]) < [0.2, 0.05, 0.03])  # the centre is a cusp of |x|


def test_tet_soft_weight_tends_to_the_hard_constraint(sphere):
    """The penalty λ Σ (φ(z_i) − φ(z_0))² on tets (the Poisson system pins one vertex: its constants are free)."""
    V, F = sphere
    hard = signed_heat_volume(mesh=(V, F), domain="tet", resolution=10)
    spread = []
    for lam in (1.0, 1e3):
        f = signed_heat_volume(mesh=(V, F), domain="tet", resolution=10, options=VolumeHeatOptions(soft_weight=lam))
        assert f.meta["soft_weight"] == lam and np.isfinite(f.values).all()
        spread.append(np.ptp(f(V)))
    assert spread[1] < 1e-2 * spread[0] and np.abs(f(V)).max() < 1e-4   # measured 0.0072, 2.5e-5
    Q = np.random.default_rng(0).uniform(-1.2, 1.2, (500, 3))
    assert np.abs(f(Q) - hard(Q)).max() < 1e-3


def test_tet_bad_options(sphere):
    V, F = sphere
    for opts, match in [(dict(mesher="gmsh"), "mesher"), (dict(max_memory=1000), "allowed"),
                        (dict(soft_weight=-1.0), "soft_weight"), (dict(theta=-1.0), "theta")]:
        with pytest.raises(ValueError, match=match):
            signed_heat_volume(mesh=(V, F), domain="tet", resolution=8, options=VolumeHeatOptions(**opts))
    try:
        import tetgen  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="pip install tetgen"):
            signed_heat_volume(mesh=(V, F), domain="tet", resolution=8, options=VolumeHeatOptions(mesher="tetgen"))


def test_tet_tetgen_conforming_mesher(sphere):
    pytest.importorskip("tetgen")
    V, F = sphere
    f = signed_heat_volume(mesh=(V, F), domain="tet", resolution=12, options=VolumeHeatOptions(mesher="tetgen"))
    assert f.meta["mesher"] == "tetgen"
    # the mesh conforms to the input, so φ = 0 on the whole input triangles, not only at their vertices
    assert np.abs(f(V)).max() < 1e-10 and np.abs(f(V[F].mean(axis=1))).max() < 1e-10
    rng = np.random.default_rng(0)
    Q = rng.uniform(-1.2, 1.2, (1000, 3))
    assert np.abs(f(Q) - gsdf.signed_distance(V, F, Q)).mean() < 0.15 * f.meta["h"]


def test_spd_solver_iterative_and_direct_agree():
    """Above ``direct_max`` the solver runs preconditioned CG; it must match the factorization."""
    import scipy.sparse as sp

    from gsdf.linalg import SPDSolver

    n = 40
    K1 = sp.diags([2.0 * np.ones(n), -np.ones(n - 1), -np.ones(n - 1)], [0, -1, 1])
    I1 = sp.identity(n)
    A = (sp.kron(K1, I1) + sp.kron(I1, K1) + 0.01 * sp.identity(n * n)).tocsr()
    rng = np.random.default_rng(0)
    b = rng.standard_normal((n * n, 3))
    direct = SPDSolver(A)
    iterative = SPDSolver(A, direct_max=10)
    assert direct.direct and not iterative.direct
    x = iterative.solve(b)
    np.testing.assert_allclose(x, direct.solve(b), rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(iterative.solve(b[:, 0]), x[:, 0])
    # an indefinite matrix defeats CG: the solver must fall back to the factorization, not return garbage
    B = (A - 4.0 * sp.identity(n * n)).tocsr()
    y = SPDSolver(B, direct_max=10).solve(b[:, 0])
    np.testing.assert_allclose(B @ y, b[:, 0], atol=1e-8)
