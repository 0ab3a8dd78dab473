"""The signed heat method with a point cloud as the domain (§8.4, tufted-cover Laplacian)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from gsdf.heat import PointCloudSignedHeatSolver
from gsdf.data._shapes import sphere_mesh
from tests.shapes import fibonacci_sphere


def _latitude_ring(P, z0, m):
    """Cloud points nearest to m samples of the circle z = z0, clockwise seen from +z (the cap below is left)."""
    th = -np.linspace(0, 2 * np.pi, m, endpoint=False)
    r0 = np.sqrt(1 - z0 ** 2)
    idx = cKDTree(P).query(np.stack([r0 * np.cos(th), r0 * np.sin(th), np.full_like(th, z0)], 1))[1]
    idx = idx[np.concatenate([[True], idx[1:] != idx[:-1]])]
    if idx[0] == idx[-1]:
        idx = idx[:-1]
    return np.concatenate([idx, idx[:1]])


def test_planar_cloud_circle():
    rng = np.random.default_rng(0)
    P = np.column_stack([rng.uniform(-1, 1, (4000, 2)), np.zeros(4000)])
    N = np.tile([0, 0, 1.0], (len(P), 1))
    th = np.linspace(0, 2 * np.pi, 100, endpoint=False)
    idx = cKDTree(P).query(np.stack([0.5 * np.cos(th), 0.5 * np.sin(th), 0 * th], 1))[1]
    idx = idx[np.concatenate([[True], idx[1:] != idx[:-1]])]
    loop = np.concatenate([idx, idx[:1]])                    # counter-clockwise: inside negative
    solver = PointCloudSignedHeatSolver(P, N)
    exact = np.linalg.norm(P[:, :2], axis=1) - 0.5
    for mode in ("zero", "none", "multiple"):
        phi = solver.compute_distance([loop], level_set_constraint=mode)
        assert np.isfinite(phi).all()
        assert np.sqrt(np.mean((phi - exact) ** 2)) < 0.03
        assert np.abs(phi - exact).max() < 0.1


def test_sphere_cloud_latitude_circle_with_pca_normals():
    V, _ = sphere_mesh(4)
    z0 = 0.3
    ring = np.flatnonzero(np.abs(V[:, 2] - z0) < 0.04)
    ring = ring[np.argsort(-np.arctan2(V[ring, 1], V[ring, 0]))]   # clockwise seen from +z: cap below is left
    solver = PointCloudSignedHeatSolver(V)                         # PCA normals, oriented outwards
    phi = solver.compute_distance([np.concatenate([ring, ring[:1]])])
    exact = np.arccos(z0) - np.arccos(np.clip(V[:, 2], -1, 1))
    assert np.sqrt(np.mean((phi - exact) ** 2)) < 0.04


def test_fibonacci_sphere_matches_geodesic_sdf_of_latitude():
    # 4000 points, the curve = the cloud points nearest to the circle z = 0.3 (a zig-zag through the cloud);
    # exact: the geodesic signed distance to the circle. Measured (mode "none"): RMS 5e-3, max 0.02.
    P = fibonacci_sphere(4000)
    z0 = 0.3
    loop = _latitude_ring(P, z0, 150)
    exact = np.arccos(z0) - np.arccos(np.clip(P[:, 2], -1, 1))
    solver = PointCloudSignedHeatSolver(P, P)
    for mode, rms_tol, max_tol in (("none", 0.012, 0.04), ("zero", 0.025, 0.06), ("multiple", 0.025, 0.06)):
        phi = solver.compute_distance([loop], level_set_constraint=mode)
        assert np.sqrt(np.mean((phi - exact) ** 2)) < rms_tol, mode
        assert np.abs(phi - exact).max() < max_tol, mode
    # reversing the curve negates φ; flipping the normals (the surface orientation) does too
    phi = solver.compute_distance([loop[::-1]], level_set_constraint="none")
    assert np.sqrt(np.mean((phi + exact) ** 2)) < 0.012
    phi = PointCloudSignedHeatSolver(P, -P).compute_distance([loop], level_set_constraint="none")
    assert np.sqrt(np.mean((phi + exact) ** 2)) < 0.012


def test_operators_symmetric_and_hermitian():
    P = fibonacci_sphere(400)
    s = PointCloudSignedHeatSolver(P, P)
    L = s.L.toarray()
    assert np.abs(L - L.T).max() < 1e-12
    assert np.abs(L.sum(1)).max() < 1e-10
    assert (L - np.diag(np.diag(L))).max() <= 0                  # tufted cover: intrinsic Delaunay weights
    np.testing.assert_allclose(s.M.sum(), 4 * np.pi, rtol=0.02)
    C = s.Lconn.toarray()
    assert np.abs(C - C.conj().T).max() < 1e-12
    assert np.linalg.eigvalsh(C).min() > -1e-10
    np.testing.assert_allclose(np.abs(C), np.abs(L), atol=1e-12)  # rotations only
    np.testing.assert_allclose(np.cross(s.e1, s.e2), s.N, atol=1e-12)


def test_point_source_on_cloud():
    P = fibonacci_sphere(3000)
    s = PointCloudSignedHeatSolver(P, P)
    src = 1500                                                    # on the equator (the Fibonacci poles are irregular)
    exact = np.arccos(np.clip(P @ P[src], -1, 1))
    for mode in ("none", "zero"):
        phi = s.compute_distance([], points=[src], level_set_constraint=mode)
        assert phi[src] == 0 and phi.min() >= -1e-12                # shifted to minimum zero (Alg. 13)
        assert np.abs(phi - exact).max() < 0.05            # measured 0.023


def test_pointcloud_bad_input():
    P = np.random.default_rng(1).uniform(size=(50, 3))
    solver = PointCloudSignedHeatSolver(P, k=8)
    with pytest.raises(ValueError, match="out of range"):
        solver.compute_distance([np.array([0, 1, 500])])
    with pytest.raises(ValueError, match="no sources"):
        solver.compute_distance([])
    with pytest.raises(ValueError, match="at least 2"):
        solver.compute_distance([np.array([3])])
    with pytest.raises(ValueError, match="level_set_constraint"):
        solver.compute_distance([np.array([0, 1, 2])], level_set_constraint="some")
    with pytest.raises(ValueError, match="curve_signs"):
        solver.compute_distance([np.array([0, 1, 2])], curve_signs=[True, True])
    with pytest.raises(ValueError, match="at least 4 points"):
        PointCloudSignedHeatSolver(P[:3])
    with pytest.raises(ValueError, match="N"):
        PointCloudSignedHeatSolver(P, np.ones((49, 3)))
    with pytest.raises(ValueError, match="zero normals"):
        PointCloudSignedHeatSolver(P, np.vstack([np.zeros((1, 3)), np.ones((49, 3))]))
    with pytest.raises(ValueError, match="k"):
        PointCloudSignedHeatSolver(P, k=2)
    with pytest.raises(ValueError, match="P"):
        PointCloudSignedHeatSolver(np.full((10, 3), np.nan))
