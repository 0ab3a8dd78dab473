"""Scale invariance of the signed heat front-ends: φ(s·X) = s·φ(X) and φ(X + c) = φ(X).

Every front-end maps its geometry into a frame (gsdf._normalize: centred, power-of-two scale, exact) and maps
the distance back, so the results at 1e-150, 1e150 and 1e8 away from the origin equal the unit-scale ones up to
rounding; at these scales the unnormalised numerics underflowed (zero face areas) or overflowed.
"""

import warnings

import numpy as np
import pytest

import gsdf
from tests.shapes import uv_sphere

SCALES = (1e-150, 1.0, 1e150)
OFFSET = np.array([1e8, 0.0, 0.0])


def _quiet(fn):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return fn()


def _close(phi, ref, tol=1e-9):
    assert np.isfinite(phi).all()
    assert np.abs(phi - ref).max() <= tol * np.abs(ref).max()


@pytest.fixture(scope="module")
def sphere():
    V, F = uv_sphere(12, 24)
    loop = np.arange(1 + 5 * 24, 1 + 6 * 24)
    return V, F, np.append(loop, loop[0])


def _offset(V):
    """V moved by 1e8 and the reference geometry it rounds to (the subtraction is exact)."""
    W = V + OFFSET
    return W, W - OFFSET


@pytest.mark.parametrize("scale", SCALES)
def test_triangle_mesh_scale(sphere, scale):
    V, F, loop = sphere
    ref = gsdf.SurfaceSignedHeatSolver(V, F).compute_distance([loop])
    phi = _quiet(lambda: gsdf.SurfaceSignedHeatSolver(V * scale, F).compute_distance([loop]))
    _close(phi / scale, ref)
    # sharpening (PDHG, §7.3) runs without warnings at every scale; its iterates are not scale-covariant (the
    # mass-weighted linear term), so only the converged answer agrees: loosely after 200 iterations
    s = _quiet(lambda: gsdf.SurfaceSignedHeatSolver(V * scale, F))
    sharp = _quiet(lambda: s.sharpen(phi, [loop], iterations=200))
    _close(sharp / scale, gsdf.SurfaceSignedHeatSolver(V, F).sharpen(ref, [loop], iterations=200), 0.05)


def test_triangle_mesh_offset(sphere):
    V, F, loop = sphere
    W, R = _offset(V)
    phi = _quiet(lambda: gsdf.SurfaceSignedHeatSolver(W, F).compute_distance([loop]))
    _close(phi, gsdf.SurfaceSignedHeatSolver(R, F).compute_distance([loop]))
    # unnormalised the offset would cost ~8 digits; in the frame it stays a unit sphere
    _close(phi, gsdf.SurfaceSignedHeatSolver(V, F).compute_distance([loop]), 1e-6)


def _quads():
    x = np.linspace(-1, 1, 9)
    V = np.array([[a, b, 0.3 * a * b] for a in x for b in x])
    i = np.arange(81).reshape(9, 9)
    Q = np.stack([i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel(), i[:-1, 1:].ravel()], 1)
    loop = np.concatenate([i[2, 2:6], i[2:6, 6], i[6, 6:2:-1], i[6:1:-1, 2]])
    return V, Q, loop


@pytest.mark.parametrize("scale", SCALES + ("offset",))
def test_polygon_mesh_scale(scale):
    V, Q, loop = _quads()
    if scale == "offset":
        W, R = _offset(V)
        ref, s = gsdf.PolygonMeshSignedHeatSolver(R, Q).compute_distance([loop]), 1.0
    else:
        W, s = V * scale, scale
        ref = gsdf.PolygonMeshSignedHeatSolver(V, Q).compute_distance([loop])
    phi = _quiet(lambda: gsdf.PolygonMeshSignedHeatSolver(W, Q).compute_distance([loop]))
    _close(phi / s, ref)


def _cloud():
    """A jittered Fibonacci sphere (a uv sphere's symmetric ties make the tufted cover rounding-sensitive)."""
    i = np.arange(300) + 0.5
    ph, th = np.arccos(1 - 2 * i / 300), np.pi * (1 + 5 ** 0.5) * i
    P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    P += np.random.default_rng(0).normal(scale=0.01, size=P.shape)
    ring = np.flatnonzero(np.abs(P[:, 2]) < 0.08)
    ring = ring[np.argsort(np.arctan2(P[ring, 1], P[ring, 0]))]
    return P, np.append(ring, ring[0])


@pytest.mark.parametrize("scale", SCALES + ("offset",))
def test_point_cloud_scale(scale):
    P, loop = _cloud()
    if scale == "offset":
        W, R = _offset(P)
        ref, s = gsdf.PointCloudSignedHeatSolver(R).compute_distance([loop]), 1.0
    else:
        W, s = P * scale, scale
        ref = gsdf.PointCloudSignedHeatSolver(P).compute_distance([loop])
    solver = _quiet(lambda: gsdf.PointCloudSignedHeatSolver(W))
    phi = _quiet(lambda: solver.compute_distance([loop]))
    _close(phi / s, ref)
    r = gsdf.PointCloudSignedHeatSolver(P if scale != "offset" else R)
    _close(solver.M / s ** 2, r.M)  # attributes in input units
    assert abs(solver.t / s ** 2 / r.t - 1) < 1e-12 and abs(solver.mean_edge / s / r.mean_edge - 1) < 1e-12
    assert phi[np.argmax(P[:, 2])] < 0 < phi[np.argmin(P[:, 2])]  # the ring splits the sphere (ccw from +z)


@pytest.mark.parametrize("P, what", [
    (np.ones((10, 3)), "identical"),
    (np.outer(np.linspace(0, 1, 20), [1.0, 2.0, 3.0]) + 5.0, "collinear"),
    (np.repeat(np.eye(3), 5, axis=0), "distinct"),
])
def test_point_cloud_degenerate(P, what):
    with pytest.raises(ValueError, match=f"P: .*{what}"):
        _quiet(lambda: gsdf.PointCloudSignedHeatSolver(P))


def test_point_cloud_flat_patch_is_fine():
    x = np.linspace(-1, 1, 12)
    P = np.array([[a, b, 0.0] for a in x for b in x]) + 1e-3 * np.random.default_rng(1).normal(size=(144, 3)) * [1, 1, 0]
    N = np.tile([0.0, 0.0, 1.0], (144, 1))
    phi = _quiet(lambda: gsdf.PointCloudSignedHeatSolver(P, N).compute_distance([], points=[0]))
    assert np.isfinite(phi).all() and phi.min() == 0


@pytest.mark.parametrize("scale", SCALES + ("offset",))
def test_volume_grid_scale(sphere, scale):
    V, F, _ = sphere
    # theta=0: the exact Yukawa sum (the tree's cluster choices are discrete)
    kw = dict(resolution=10, options=gsdf.VolumeHeatOptions(theta=0.0))
    if scale == "offset":
        W, R = _offset(V)
        f0, s, c = gsdf.signed_heat_volume(mesh=(R, F), **kw), 1.0, OFFSET
    else:
        W, s, c = V * scale, scale, 0.0
        f0 = gsdf.signed_heat_volume(mesh=(V, F), **kw)
    f = _quiet(lambda: gsdf.signed_heat_volume(mesh=(W, F), **kw))
    _close(f.values / s, f0.values)
    np.testing.assert_allclose((f.bbox_min - c) / s, f0.bbox_min, rtol=0, atol=1e-7 if scale == "offset" else 1e-14)
    np.testing.assert_allclose((f.bbox_max - c) / s, f0.bbox_max, rtol=0, atol=1e-7 if scale == "offset" else 1e-14)
    Q = np.array([[0.0, 0, 0], [0.5, 0.2, -0.1], [1.05, 0, 0]])
    _close(_quiet(lambda: f(Q * s + c)) / s, f0(Q), 1e-7)
    assert abs(f0(Q)[0] + 1) < 0.35 and abs(f0(Q)[2] - 0.05) < 0.2  # world-unit distances of a unit sphere
    Vi = _quiet(lambda: f.isosurface(0.0))[0]
    np.testing.assert_allclose(np.linalg.norm((Vi - c) / s, axis=1), 1.0, atol=0.1)


def test_volume_default_tree_power_of_two_bitwise(sphere):
    """With the default tree the result at a power-of-two scale is bitwise the unit one."""
    V, F, _ = sphere
    f0 = gsdf.signed_heat_volume(mesh=(V, F), resolution=10)
    f = _quiet(lambda: gsdf.signed_heat_volume(mesh=(V * 2.0 ** -500, F), resolution=10, bbox_min=f0.bbox_min *
                                               2.0 ** -500, bbox_max=f0.bbox_max * 2.0 ** -500))
    assert np.array_equal(f.values * 2.0 ** 500, f0.values)
    exact = gsdf.VolumeHeatOptions(theta=0.0)
    g = _quiet(lambda: gsdf.signed_heat_volume(mesh=(V * 1e150, F), resolution=10, t_coef=0.5, options=exact))
    g0 = gsdf.signed_heat_volume(mesh=(V, F), resolution=10, t_coef=0.5, options=exact)
    _close(g.values / 1e150, g0.values)
    assert abs(g.meta["t"] / 1e300 / g0.meta["t"] - 1) < 1e-12 and abs(g0.meta["t"] / f0.meta["t"] - 0.5) < 1e-12


@pytest.mark.parametrize("scale", (2.0 ** -600, 1e-150, 1e150))
def test_volume_tet_scale(sphere, scale):
    """Power-of-two scales are bitwise; otherwise Qhull's choices among the lattice's cospherical points are
    rounding-sensitive (a relative 1e-15 change of the input moves φ by ~3e-6 at unit scale too, a change of
    the frame mantissa by ~1 %), so only agreement to the discretisation is asserted there."""
    V, F, _ = sphere
    kw = dict(domain="tet", resolution=6, options=gsdf.VolumeHeatOptions(theta=0.0))
    f0 = gsdf.signed_heat_volume(mesh=(V, F), **kw)
    f = _quiet(lambda: gsdf.signed_heat_volume(mesh=(V * scale, F), **kw))
    tol = 0.0 if scale == 2.0 ** -600 else 0.05
    _close(f.values / scale, f0.values, tol)
    Q = np.array([[0.0, 0, 0], [0.3, 0.2, -0.1]])
    _close(_quiet(lambda: f(Q * scale)) / scale, f0(Q), max(tol, 1e-7))
    Vi = _quiet(lambda: f.isosurface(0.0))[0]
    assert np.abs(np.linalg.norm(Vi / scale, axis=1) - 1).max() < 0.2


@pytest.mark.parametrize("scale", SCALES)
def test_voxel_surface_scale(scale):
    x = np.indices((12, 12, 12)) - 5.5
    occ = (x ** 2).sum(0) < 4.5 ** 2
    s0 = gsdf.VoxelSurfaceSignedHeatSolver(occ)
    ref = s0.compute_distance([], points=[0])
    s = _quiet(lambda: gsdf.VoxelSurfaceSignedHeatSolver(occ, spacing=scale))
    phi = _quiet(lambda: s.compute_distance([], points=[0]))
    _close(phi / scale, ref)
    _close(s.vertices / scale, s0.vertices, 1e-15)


@pytest.mark.parametrize("bad", [dict(theta=-1.0), dict(theta=True), dict(theta="x")])
def test_volume_tree_options_are_validated(bad):
    from gsdf.heat.volume import VolumeHeatOptions, signed_heat_volume

    P = np.random.default_rng(0).normal(size=(200, 3))
    with pytest.raises(ValueError, match="theta"):
        signed_heat_volume(points=(P, P), resolution=8, options=VolumeHeatOptions(**bad))


def test_volume_options_are_one_dataclass():
    from gsdf.heat.volume import signed_heat_volume

    P = np.random.default_rng(0).normal(size=(200, 3))
    with pytest.raises(ValueError, match="options"):
        signed_heat_volume(points=(P, P), resolution=8, options={"theta": 1.0})
    with pytest.raises(TypeError):
        signed_heat_volume(points=(P, P), resolution=8, level_set_constraint="none")
