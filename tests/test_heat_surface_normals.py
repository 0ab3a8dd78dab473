"""Explicit curve normals (``curve_normals=``) of the surface signed heat method, e.g. on nonorientable domains."""

import numpy as np
import pytest

from gsdf.heat import SurfaceSignedHeatSolver
from gsdf.heat.surface.curves import level_set_curves, region_boundary_curves
from gsdf.heat.surface.meshes import grid_mesh


def mobius(nu=120, nv=12, w=0.4):
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    v = np.linspace(-w, w, nv + 1)
    U, W = np.meshgrid(u, v, indexing="ij")
    X = np.stack([(1 + W / 2 * np.cos(U / 2)) * np.cos(U), (1 + W / 2 * np.cos(U / 2)) * np.sin(U),
                  W / 2 * np.sin(U / 2)], -1).reshape(-1, 3)
    idx = np.arange(nu * (nv + 1)).reshape(nu, nv + 1)
    nxt = np.roll(idx, -1, axis=0)
    nxt[-1] = idx[0, ::-1]                                     # the half twist
    a, b, c, d = idx[:, :-1].ravel(), nxt[:, :-1].ravel(), nxt[:, 1:].ravel(), idx[:, 1:].ravel()
    return X, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


def test_planar_normals_match_face_normals_and_flip():
    V, F = grid_mesh(16, jitter=0.2, delaunay=True)
    s = SurfaceSignedHeatSolver(V, F)
    bary = level_set_curves(V, F, np.linalg.norm(V[:, :2], axis=1) - 0.5)
    (loop,) = region_boundary_curves(F, np.linalg.norm(V[F].mean(1)[:, :2], axis=1) < 0.5)
    for curves in (bary, [loop]):
        ref = s.compute_distance(curves)
        up = s.compute_distance(curves, curve_normals=np.array([0.0, 0, 1]))
        np.testing.assert_allclose(up, ref, atol=1e-10)
        per_node = [np.tile([0.0, 0, -2.0], (len(c), 1)) for c in curves]     # unnormalized is fine
        np.testing.assert_allclose(s.compute_distance(curves, curve_normals=per_node), -ref, atol=1e-10)


def test_mobius_given_normals_finite_and_flip_sign():
    V, F = mobius()
    s = SurfaceSignedHeatSolver(V, F)
    c = V[np.argmin(np.linalg.norm(V - [-1.0, 0, 0], axis=1))]    # away from the seam at u = 0
    d = np.linalg.norm(V - c, axis=1)
    curves = level_set_curves(V, F, d - 0.25)
    n = s.ops.normals[np.argmin(np.linalg.norm(V[F].mean(1) - c, axis=1))]
    p1 = s.compute_distance(curves, curve_normals=n)
    p2 = s.compute_distance(curves, curve_normals=[-n] * len(curves))
    assert np.isfinite(p1).all() and np.isfinite(p2).all()
    near = d < 0.4
    assert np.abs(p1 - (d - 0.25))[near].max() < 0.06                 # inside negative with the local normal
    assert np.abs(p2 + (d - 0.25))[near].max() < 0.06                 # flipped normals: flipped sign
    np.testing.assert_allclose(p2, -p1, atol=1e-9)


def test_curve_normals_bad_input():
    V, F = grid_mesh(8)
    s = SurfaceSignedHeatSolver(V, F)
    curves = level_set_curves(V, F, np.linalg.norm(V[:, :2], axis=1) - 0.5)
    with pytest.raises(ValueError, match="curve_normals"):
        s.compute_distance(curves, curve_normals=[np.zeros(3)])
    with pytest.raises(ValueError, match="curve_normals"):
        s.compute_distance(curves, curve_normals=[np.ones((2, 3))])
    with pytest.raises(ValueError, match="curve_normals"):
        s.compute_distance(curves, curve_normals=[None, None])
    with pytest.raises(ValueError, match="curve_normals"):
        SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=True).compute_distance(
            [np.array([0, 1, 10, 0])], curve_normals=[np.array([0, 0, 1.0])])
