"""Tet domain (§8.1, App. B): TetField evaluation, marching tetrahedra, and the signed heat solve's sign."""

import numpy as np
import pytest
from scipy.spatial import Delaunay

import gsdf
from gsdf.field import TetField, marching_tetrahedra
from gsdf.heat.volume import signed_heat_volume

from .shapes import uv_sphere


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


def test_tet_signed_heat_sign_and_rough_distance(tmp_path):
    V, F = uv_sphere(12, 24)
    f = signed_heat_volume(mesh=(V, F), domain="tet", resolution=7)
    d = f([[0, 0, 0], [0.5, 0, 0], [1.2, 0, 0]])
    assert d[0] < -0.6 and d[1] < -0.2 and d[2] > 0.05
    f.save(tmp_path / "t.vtu")
    f.save(tmp_path / "t.npz")
    g = TetField.load(tmp_path / "t.npz")
    np.testing.assert_allclose(g.values, f.values)
    with pytest.raises(ValueError, match="multiple"):
        signed_heat_volume(mesh=(V, F), domain="tet", resolution=7, level_set_constraint="multiple")
