"""Volumetric signed heat method on grids (Feng & Crane 2024, §8.2): analytic answers, the tree Yukawa sum
against the direct sum, the fast Poisson solve, and bad input."""

import numpy as np
import pytest

import gsdf
from gsdf.heat.volume import VolumeHeatOptions, YukawaTree, mesh_sources, signed_heat_volume
from gsdf.heat.grid._poisson import dct_poisson, divergence_rhs, neumann_laplacian

from tests.shapes import cube, fibonacci_sphere, uv_sphere


def _edges_manifold_closed(F):
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, counts = np.unique(E, axis=0, return_counts=True)
    return bool(np.all(counts == 2))


@pytest.fixture(scope="module")
def sphere():
    return uv_sphere(30, 60)


def test_sphere_mesh_converges_to_exact_sdf(sphere):
    V, F = sphere
    errs = []
    for res in (16, 32):
        f = signed_heat_volume(mesh=(V, F), resolution=res)
        Q = f.grid_points()
        exact = gsdf.signed_distance(V, F, Q)
        errs.append(np.abs(f.values.ravel() - exact).mean())
        assert f.values.min() < -0.8 and f.values.max() > 0.1  # negative inside
    h32 = 2.4 / 31
    assert errs[1] < errs[0]
    assert errs[1] < 0.1 * h32


def test_sphere_cloud_matches_analytic():
    P = fibonacci_sphere(3000)
    f = signed_heat_volume(points=(P, P * 2.0), resolution=32)  # normals need not be unit
    Q = f.grid_points()
    err = np.abs(f.values.ravel() - (np.linalg.norm(Q, axis=1) - 1.0))
    assert err.mean() < 0.01
    d = f([[0, 0, 0], [1.2, 0, 0], [0, 0.5, 0]])
    assert np.all(np.abs(d - [-1.0, 0.2, -0.5]) < [0.1, 0.02, 0.02])  # the centre is a cusp of |x|


def test_zero_constraint_and_explicit_box_and_shape(sphere):
    V, F = sphere
    f = signed_heat_volume(mesh=(V, F), resolution=(20, 22, 24), bbox_min=[-1.3] * 3, bbox_max=[1.3, 1.4, 1.5])
    assert f.shape == (20, 22, 24)
    np.testing.assert_allclose(f.bbox_max, [1.3, 1.4, 1.5])
    assert np.abs(f(V)).mean() < 0.02


def test_grid_exact_constraint_zero_at_sources(sphere):
    from gsdf.heat.grid._poisson import cell_constraint_matrix

    V, F = sphere
    src = mesh_sources(V, F)
    f = signed_heat_volume(mesh=(V, F), resolution=20, options=VolumeHeatOptions(soft_weight=None))
    C, w = cell_constraint_matrix(src.B, src.a, f.bbox_min, f.spacing, f.shape)
    h = f.spacing.max()
    assert np.abs(C @ f.values.ravel()).max() < 1e-3 * h  # exact: every cell's fitted zero level
    assert f.meta["constraint_residual"] < 1e-3 * h and f.meta["constraint_rows"] == C.shape[0]
    assert np.abs(f(src.B)).mean() < 0.01 * h  # the trilinear interpolant ≈ 0 at the sources
    exact = gsdf.signed_distance(V, F, f.grid_points())
    assert np.abs(f.values.ravel() - exact).mean() < 0.15 * h


def test_isosurfaces_closed_manifold(sphere):
    V, F = sphere
    f = signed_heat_volume(mesh=(V, F), resolution=32)
    for level in (-0.3, 0.0, 0.2):
        Vc, Fc = f.isosurface(level)
        assert _edges_manifold_closed(Fc)
        r = np.linalg.norm(Vc, axis=1)
        assert abs(r.mean() - (1 + level)) < 0.03


def test_tree_yukawa_matches_direct_sum():
    rng = np.random.default_rng(3)
    V, F = uv_sphere(20, 40)
    V = V + 0.05 * rng.normal(size=V.shape)  # a bumpy, non-convex surface
    src = mesh_sources(V, F)
    Q = rng.uniform(-1.6, 1.6, size=(1500, 3))
    for t in (0.05 ** 2, 0.2 ** 2):
        exact = YukawaTree(src.B, src.W, t, theta=0.0).direct(Q)
        same = YukawaTree(src.B, src.W, t, theta=0.0)(Q)  # no clusters: only pruning, at ε = 1e-6
        rel = np.linalg.norm(same - exact, axis=1) / np.linalg.norm(exact, axis=1)
        assert np.median(rel) < 1e-5 and rel.max() < 1e-4
        for theta, tol_deg in ((0.5, 0.25), (1.5, 5.0)):
            X = YukawaTree(src.B, src.W, t, theta=theta)(Q)
            cos = (X * exact).sum(1) / np.linalg.norm(X, axis=1) / np.linalg.norm(exact, axis=1)
            assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < tol_deg


def test_tree_yukawa_scaled_against_raw_kernel():
    B = np.array([[0.0, 0, 0], [0.3, 0.1, 0]])
    W = np.array([[0.0, 0, 1], [0.2, 0, 0.5]])
    q = np.array([[0.1, 0.2, 0.3]])
    t = 0.01
    lam = 1 / np.sqrt(t)
    r = np.linalg.norm(B - q, axis=1)
    raw = (W * (np.exp(-lam * r) / (4 * np.pi * r))[:, None]).sum(0)
    X = YukawaTree(B, W, t, theta=0.0)(q)[0]
    np.testing.assert_allclose(X * np.exp(-lam * r.min()), raw, rtol=1e-12)


def test_dct_poisson_solves_neumann_laplacian():
    rng = np.random.default_rng(0)
    shape, h = (9, 12, 7), np.array([0.1, 0.2, 0.15])
    L = neumann_laplacian(shape, h)
    b = rng.normal(size=np.prod(shape))
    b -= b.mean()
    x = dct_poisson(b, shape, h)
    np.testing.assert_allclose(L @ x, b, atol=1e-9)
    # the divergence right-hand side is orthogonal to constants (compatible Neumann problem)
    Y = rng.normal(size=shape + (3,))
    assert abs(divergence_rhs(Y, h).sum()) < 1e-9


def test_polygon_soup_with_hole_still_signed():
    V2, F2 = uv_sphere(16, 32)
    F2 = F2[np.abs(V2[F2].mean(1)[:, 2]) < 0.8]  # open both caps
    f = signed_heat_volume(mesh=(V2 * 0.5, F2), resolution=24)
    d = f([[0, 0, 0], [0.6, 0, 0], [0.4, 0, 0]])
    assert d[0] < -0.3 and d[1] > 0.05 and d[2] < -0.05


def test_input_spacing_and_t_scale_input():
    from gsdf.heat.volume import input_spacing

    V, F = cube()  # unit cube: 12 axis edges of length 1 and 6 face diagonals of length √2
    assert abs(input_spacing(V, F) - (12 + 6 * 2 ** 0.5) / 18) < 1e-12
    P = np.array([[0, 0, 0], [0.1, 0, 0], [0.3, 0, 0]], float)
    k2 = np.mean([0.1, 0.3, 0.1, 0.2, 0.2, 0.3])  # mean distance to the other two points
    assert abs(input_spacing(P) - k2) < 1e-12
    with pytest.raises(ValueError, match="coincide"):
        input_spacing(np.zeros((5, 3)))
    # a fine sphere mesh with a hole on a coarse grid: the input's own spacing gives a shorter t and a field
    # closer to the exact SDF (with the soft penalty: the grid default, and gsdf heat's)
    V2, F2 = uv_sphere(40, 80)
    F2 = F2[V2[F2].mean(1)[:, 2] < 0.9]
    f_grid = signed_heat_volume(mesh=(V2, F2), resolution=20, options=VolumeHeatOptions(soft_weight=10.0))
    f_in = signed_heat_volume(mesh=(V2, F2), resolution=20,
                              options=VolumeHeatOptions(t_scale="input", soft_weight=10.0))
    Q = f_grid.grid_points()
    exact = np.linalg.norm(Q, axis=1) - 1.0
    e_grid = np.abs(f_grid.values.ravel() - exact).mean()
    e_in = np.abs(f_in.values.ravel() - exact).mean()
    assert e_in < 0.9 * e_grid  # measured 0.0036 vs 0.0042
    # t = t_coef · (input spacing)²: the same field as t_coef scaled by (input spacing / grid spacing)²
    h = float(f_grid.spacing.max())
    np.testing.assert_allclose(f_in.meta["t"], input_spacing(V2, F2) ** 2, rtol=1e-12)
    np.testing.assert_allclose(f_grid.meta["t"], h ** 2, rtol=1e-12)


@pytest.mark.parametrize("kwargs, msg", [
    (dict(mesh=cube(), options=dict(t_scale="mesh")), "t_scale"),
    (dict(mesh=(np.zeros((0, 3)), np.zeros((0, 3), int))), "empty"),
    (dict(mesh=(np.zeros((3, 3)), np.array([[0, 1, 2]]))), "zero area"),
    (dict(points=(np.eye(3), np.zeros((3, 3)))), "all normals are zero"),
    (dict(points=(np.eye(3), None)), "normals"),
    (dict(), "exactly one"),
    (dict(mesh=cube(), resolution=1), "resolution"),
    (dict(mesh=cube(), resolution=10**6), "absurd"),
    (dict(mesh=cube(), resolution=2000), "allowed"),
    (dict(mesh=cube(), resolution=64, options=dict(max_memory=10**6)), "allowed"),
    (dict(mesh=cube(), options=dict(max_memory=0)), "max_memory"),
    (dict(mesh=cube(), options=dict(progress=3)), "progress"),
    (dict(mesh=cube(), bbox_min=[0, 0, 0], bbox_max=[1, 1, 1]), "does not contain"),
    (dict(mesh=cube(), bbox_min=[1, 1, 1], bbox_max=[0, 0, 0]), "must exceed"),
    (dict(mesh=cube(), domain="octree"), "domain"),
    (dict(mesh=cube(), t_coef=-1), "t_coef"),
    (dict(mesh=cube(), options=dict(level_set_constraint="two")), "level_set_constraint"),
    (dict(mesh=cube(), resolution=2.5), "resolution"),
])
def test_bad_input(kwargs, msg):
    """Bad options are refused by VolumeHeatOptions itself (at construction) or by signed_heat_volume."""
    with pytest.raises(ValueError, match=msg):
        if "options" in kwargs:
            kwargs = {**kwargs, "options": VolumeHeatOptions(**kwargs["options"])}
        signed_heat_volume(**kwargs)


def test_box_refusal_names_the_boxes_in_the_callers_units():
    """A box that does not contain the input is refused, and the message gives both boxes in the caller's
    coordinates (not the internal frame's: ±0.5 for the caller's ±1)."""
    import gsdf
    from gsdf.data._shapes import sphere_mesh

    V, F = sphere_mesh(2)
    V = V * [1.5, 1.0, 1.0] + [10.0, 0, 0]  # x from 8.5 to 11.5
    with pytest.raises(ValueError) as e:
        gsdf.signed_heat_volume(mesh=(V, F), bbox_min=[9, -2, -2], bbox_max=[11, 2, 2], resolution=8)
    msg = str(e.value)
    assert "9." in msg and "11." in msg and "8.5" in msg and "11.5" in msg


@pytest.mark.parametrize("Q,why", [([[0.0, np.nan, 0.0]], "NaN"), ([[1j, 0, 0]], "complex"),
                                   (np.zeros((1, 4, 3)), r"expected shape \(n, 3\)"), ("abc", "string")])
def test_yukawa_nearest_distance_checks_queries(Q, why):
    """nearest_distance checks its queries as the tree's other methods do (they were handed to the k-d tree)."""
    tree = YukawaTree(np.eye(3), np.eye(3), t=0.01)
    with pytest.raises(ValueError, match="Q: .*" + why):
        tree.nearest_distance(Q)
    assert tree.nearest_distance(np.zeros((0, 3))).shape == (0,)


@pytest.mark.parametrize("leaf_size", [2.5, float("nan"), "8", True, 1j, 0, 2 ** 64])
def test_yukawa_tree_checks_its_leaf_size(leaf_size):
    """leaf_size went unchecked to the tree build (a numba TypingError, NaN to int, fractions accepted)."""
    with pytest.raises(ValueError, match="leaf_size"):
        YukawaTree(np.eye(3), np.eye(3), t=0.01, leaf_size=leaf_size)
    assert YukawaTree(np.eye(3), np.eye(3), t=0.01, leaf_size=np.int32(1)).m == 3
