"""The signed heat method with a point cloud as the domain (§8.4, local-triangulation cover)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from gsdf.heat import PointCloudSignedHeatSolver
from gsdf.heat.surface.meshes import sphere_mesh


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


def test_pointcloud_bad_input():
    P = np.random.default_rng(1).uniform(size=(50, 3))
    solver = PointCloudSignedHeatSolver(P, k=8)
    with pytest.raises(ValueError, match="out of range"):
        solver.compute_distance([np.array([0, 1, 500])])
    with pytest.raises(ValueError, match="no sources"):
        solver.compute_distance([])
    with pytest.raises(ValueError, match="at least 2"):
        solver.compute_distance([np.array([3])])
    with pytest.raises(ValueError, match="at least 4 points"):
        PointCloudSignedHeatSolver(P[:3])
