"""The signed heat method on polygon meshes (§8.3, virtual-vertex refinement)."""

import numpy as np
import pytest

from gsdf.heat import PolygonMeshSignedHeatSolver, SurfaceSignedHeatSolver, region_boundary_curves
from gsdf.heat.surface.polygon import virtual_vertex_refinement


def _quads(n, bump=0.0):
    x = np.linspace(-1, 1, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), bump * np.sin(3 * X.ravel()) * np.cos(2 * Y.ravel())], 1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    Q = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()], 1)
    return V, Q


def _square_loop(V, Q):
    inside = (np.abs(V[Q].mean(1)[:, :2]) < 0.5).all(1)
    tri = np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    return region_boundary_curves(tri, np.concatenate([inside, inside]))


def test_quad_mesh_square_loop():
    V, Q = _quads(20)
    solver = PolygonMeshSignedHeatSolver(V, Q)
    phi = solver.compute_distance(_square_loop(V, Q))
    assert phi.shape == (len(V),)
    exact = np.abs(V[:, :2]).max(1) - 0.5
    axis = (np.abs(V[:, 0]) < 1e-9) | (np.abs(V[:, 1]) < 1e-9)
    assert np.abs(phi - exact)[axis].max() < 0.05


def test_nonplanar_mixed_polygons_agree_with_triangulation():
    V, Q = _quads(16, bump=0.1)
    polys = [list(q) for q in Q[:-2]] + [[Q[-2][0], Q[-2][1], Q[-2][2]], [Q[-2][0], Q[-2][2], Q[-2][3]]] + [Q[-1]]
    loop = _square_loop(V, Q)
    phi = PolygonMeshSignedHeatSolver(V, polys).compute_distance(loop)
    tri = np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    ref = SurfaceSignedHeatSolver(V, tri).compute_distance(loop)
    assert np.abs(phi - ref).max() < 0.05


def test_virtual_vertex_of_regular_hexagon_is_centre():
    t = np.linspace(0, 2 * np.pi, 6, endpoint=False)
    V = np.stack([np.cos(t) + 2, np.sin(t), 0 * t], 1)
    Vr, Fr = virtual_vertex_refinement(V, [np.arange(6)])
    np.testing.assert_allclose(Vr[6], [2, 0, 0], atol=1e-12)
    assert len(Fr) == 6


def test_polygon_bad_input():
    V, Q = _quads(4)
    with pytest.raises(ValueError, match="at least 3"):
        PolygonMeshSignedHeatSolver(V, [[0, 1]])
    with pytest.raises(ValueError, match="out of range"):
        PolygonMeshSignedHeatSolver(V, [[0, 1, 99]])
    solver = PolygonMeshSignedHeatSolver(V, Q)
    with pytest.raises(ValueError, match="out of range"):
        solver.compute_distance([np.array([0, 1, 30])])
