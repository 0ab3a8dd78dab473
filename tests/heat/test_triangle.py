"""Signed heat method on triangle meshes (Feng & Crane 2024): analytic answers and bad input."""

import numpy as np
import pytest

from gsdf.heat import SurfaceSignedHeatSolver
from gsdf.contour._surface_curves import level_set_curves, region_boundary_curves
from gsdf.data._shapes import grid_mesh, sphere_mesh


def _eps(solver, phi, exact):
    """Normalized L2 error of §9.1."""
    A = solver.ops.vertex_mass()
    return np.sqrt((A * (phi - exact) ** 2).sum() / A.sum()) / (exact.max() - exact.min())


@pytest.fixture(scope="module")
def disk():
    V, F = grid_mesh(24, jitter=0.25, delaunay=True)
    c = np.array([0.03, -0.02])
    exact = np.linalg.norm(V[:, :2] - c, axis=1) - 0.5
    return V, F, exact, SurfaceSignedHeatSolver(V, F)


@pytest.mark.parametrize("mode", ["zero", "none", "multiple"])
def test_planar_circle_matches_exact_sdf(disk, mode):
    V, F, exact, solver = disk
    curves = level_set_curves(V, F, exact)
    phi = solver.compute_distance(curves, level_set_constraint=mode)
    assert phi.shape == (len(V),)
    assert np.isfinite(phi).all()
    assert _eps(solver, phi, exact) < 0.01
    assert np.abs(phi - exact).max() < 0.05
    assert phi[np.argmin(exact)] < 0 < phi[np.argmax(exact)]           # negative inside


def test_zero_constraint_is_zero_on_curve(disk):
    V, F, exact, solver = disk
    curves = level_set_curves(V, F, exact)
    phi = solver.compute_distance(curves, level_set_constraint="zero")
    vals = [b @ phi[F[f]] for f, b in curves[0]]
    assert np.abs(vals).max() < 1e-8


def test_vertex_polyline_square_and_caching():
    V, F = grid_mesh(20)
    inside = (np.abs(V[F][:, :, :2]) <= 0.5 + 1e-9).all(axis=(1, 2))
    (loop,) = region_boundary_curves(F, inside)
    solver = SurfaceSignedHeatSolver(V, F)
    phi = solver.compute_distance([loop])
    d = np.abs(V[:, :2]).max(1) - 0.5                     # exact SDF of the square: inside, and along the axes
    axis = (np.abs(V[:, 0]) < 1e-9) | (np.abs(V[:, 1]) < 1e-9)
    assert np.abs(phi[axis] - d[axis]).max() < 0.06
    assert np.abs(phi[loop]).max() < 1e-12
    fact = solver.vector_heat_factorization
    n_cached = len(solver._cache)
    phi2 = solver.compute_distance([loop])                # second call: same factorizations, only solves
    assert solver.vector_heat_factorization is fact and len(solver._cache) == n_cached
    np.testing.assert_allclose(phi, phi2)
    # reversing the curve flips the sign
    phi3 = solver.compute_distance([loop[::-1]])
    np.testing.assert_allclose(phi3, -phi, atol=1e-10)


def test_sphere_latitude_circle_and_convergence():
    errs = []
    for s in (2, 3, 4):
        V, F = sphere_mesh(s)
        z0 = 0.3
        curves = level_set_curves(V, F, V[:, 2] - z0)
        exact = np.arccos(z0) - np.arccos(np.clip(V[:, 2], -1, 1))   # geodesic SDF, negative below
        solver = SurfaceSignedHeatSolver(V, F)
        phi = solver.compute_distance(curves)
        errs.append(np.abs(phi - exact).max())
    assert errs[-1] < 0.012
    assert errs[0] > 1.6 * errs[1] > 1.6 * 1.6 * errs[2] * 0.99       # about first order


def test_barycentric_curve_with_long_segments_is_split():
    V, F = grid_mesh(16)
    solver = SurfaceSignedHeatSolver(V, F)
    th = np.linspace(0, 2 * np.pi, 13)[:-1]                # 12 points: segments cross several faces
    pts = np.stack([0.5 * np.cos(th), 0.5 * np.sin(th)], 1)
    curve = [_locate(V, F, p) for p in pts]
    curve.append(curve[0])
    phi = solver.compute_distance([curve], level_set_constraint="none")
    segs = solver.split_segments(curve)
    assert len(segs) > 12
    exact = np.linalg.norm(V[:, :2], axis=1) - 0.5
    assert np.abs(phi - exact).max() < 0.1


def _locate(V, F, p):
    P = V[F][:, :, :2]
    T = np.stack([P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]], axis=2)
    uv = np.linalg.solve(T, (p - P[:, 0])[..., None])[..., 0]
    b = np.column_stack([1 - uv.sum(1), uv])
    f = int(np.argmax(b.min(1)))
    bb = np.clip(b[f], 0, None)
    return f, bb / bb.sum()


def test_point_source_is_unsigned_distance():
    V, F = grid_mesh(20, jitter=0.2, delaunay=True)
    solver = SurfaceSignedHeatSolver(V, F)
    v = int(np.argmin(np.linalg.norm(V, axis=1)))
    phi = solver.compute_distance([], points=[v])
    exact = np.linalg.norm(V - V[v], axis=1)
    assert phi.min() >= -1e-12 and abs(phi[v]) < 1e-9
    assert np.abs(phi - exact).max() < 0.1


def test_unsigned_curve_and_mixed_signs():
    V, F = grid_mesh(20)
    idx = np.arange(21 * 21).reshape(21, 21)
    seg = idx[5:16, 10]                                    # x from -0.5 to 0.5 at y = 0, along edges
    solver = SurfaceSignedHeatSolver(V, F)
    phi = solver.compute_distance([seg], curve_signs=[False])
    x, y = V[:, 0], V[:, 1]
    exact = np.hypot(np.maximum(np.abs(x) - 0.5, 0), y)
    assert phi.min() > -0.03
    assert np.abs(phi - exact).max() < 0.1
    inside = (np.abs(V[F][:, :, :2] - [0.5, 0.5]) <= 0.3 + 1e-9).all(axis=(1, 2))
    (loop,) = region_boundary_curves(F, inside)
    phi2 = solver.compute_distance([seg, loop], curve_signs=[False, True], level_set_constraint="none")
    assert np.isfinite(phi2).all()
    assert phi2[np.argmin(np.linalg.norm(V[:, :2] - [0.5, 0.5], axis=1))] < 0


def test_multiple_level_sets_are_constant_per_component():
    V, F = grid_mesh(24)
    r = np.linalg.norm(V[:, :2], axis=1)
    curves = level_set_curves(V, F, r - 0.3) + level_set_curves(V, F, r - 0.7)
    solver = SurfaceSignedHeatSolver(V, F)
    phi = solver.compute_distance(curves, level_set_constraint="multiple")
    for c in curves:
        vals = np.array([b @ phi[F[f]] for f, b in c])
        assert np.ptp(vals) < 1e-8
    soft = solver.compute_distance(curves, level_set_constraint="zero", soft_weight=1e3)
    assert np.isfinite(soft).all()


def test_boundary_components_and_nonmanifold():
    V, F = grid_mesh(10)
    V2 = V + [3.0, 0, 0]
    VV, FF = np.concatenate([V, V2]), np.concatenate([F, F + len(V)])
    # a fin: a triangle sharing an interior edge of the first grid (nonmanifold edge)
    e = F[40, :2]
    VV = np.concatenate([VV, [[V[e].mean(0)[0], V[e].mean(0)[1], 0.5]]])
    FF = np.concatenate([FF, [[e[0], e[1], len(VV) - 1]]])
    solver = SurfaceSignedHeatSolver(VV, FF)
    exact = np.linalg.norm(V[:, :2], axis=1) - 0.5
    curves = level_set_curves(V, F, exact)
    for mode in ("zero", "none", "multiple"):
        phi = solver.compute_distance(curves, level_set_constraint=mode)
        assert np.isfinite(phi).all()
        assert np.abs(phi[:len(V)] - exact).max() < 0.1


def test_level_set_and_region_helpers():
    V, F = grid_mesh(8)
    cs = level_set_curves(V, F, V[:, 0] - 0.1)
    assert len(cs) == 1 and len(cs[0]) == 17               # open: 16 crossed faces (8 cells × 2), 17 nodes
    loops = region_boundary_curves(F, np.ones(len(F), bool))
    assert len(loops) == 1 and loops[0][0] == loops[0][-1] and len(loops[0]) == 33


# ------------------------------------------------------------------------------------------ bad input
@pytest.fixture(scope="module")
def small():
    V, F = grid_mesh(4)
    return V, F, SurfaceSignedHeatSolver(V, F)


@pytest.mark.parametrize("curves,match", [
    ([np.array([0, 1, 99])], "vertex index 99 out of range"),
    ([np.array([0, -1])], "out of range"),
    ([], "no sources"),
    ([np.array([3])], "at least 2 points"),
    ([[(0, [0.5, 0.5, 0.5]), (0, [0.2, 0.3, 0.5])]], "do not sum to 1"),
    ([[(0, [1.2, -0.2, 0.0]), (0, [0.2, 0.3, 0.5])]], "negative barycentric"),
    ([[(500, [1, 0, 0]), (0, [0.2, 0.3, 0.5])]], "face index 500 out of range"),
    ([[(0, [1, 0]), (0, [0.2, 0.3, 0.5])]], "3 entries"),
    ([np.array([0, 12])], "not joined by a mesh edge"),
])
def test_bad_curves(small, curves, match):
    _, _, solver = small
    with pytest.raises(ValueError, match=match):
        solver.compute_distance(curves)


def test_bad_options(small):
    _, _, solver = small
    with pytest.raises(ValueError, match="level_set_constraint"):
        solver.compute_distance([np.array([0, 1])], level_set_constraint="zeroset")
    with pytest.raises(ValueError, match="curve_signs"):
        solver.compute_distance([np.array([0, 1])], curve_signs=[True, False])
    with pytest.raises(ValueError, match="soft_weight"):
        solver.compute_distance([np.array([0, 1])], soft_weight=-1)
    with pytest.raises(ValueError, match="points"):
        solver.compute_distance([], points=[1000])


def test_bad_mesh():
    V, F = grid_mesh(4)
    with pytest.raises(ValueError, match="every face repeats a vertex"), pytest.warns(UserWarning):
        SurfaceSignedHeatSolver(V, [[0, 0, 1]])
    V2 = np.concatenate([V, [[2.0, 2.0, 0.0]]])
    with pytest.raises(ValueError, match="zero area"):
        SurfaceSignedHeatSolver(V2, np.concatenate([F, [[0, 4, 2]]]))   # collinear (along y = -1)
    with pytest.raises(ValueError, match="t_coef"):
        SurfaceSignedHeatSolver(V, F, t_coef=0)
    with pytest.raises(ValueError, match="out of range"):
        SurfaceSignedHeatSolver(V, F + 100)


def test_l1_piecewise_integration_of_nonbounding_curve():
    # a cylinder whose top edge dips at θ = π; an open generator at θ = 0 does not bound a region, and the
    # generalized SDF is the signed arc length θ with a jump along the shortest generator (θ = π)
    nu, nv = 96, 12
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    U, W = np.meshgrid(u, np.linspace(0, 1, nv + 1), indexing="ij")
    V = np.stack([np.cos(U), np.sin(U), -1 + W * (1.2 + 0.8 * np.cos(U))], -1).reshape(-1, 3)
    idx = np.arange(nu * (nv + 1)).reshape(nu, nv + 1)
    nxt = np.roll(idx, -1, axis=0)
    a, b, c, d = idx[:, :-1].ravel(), nxt[:, :-1].ravel(), nxt[:, 1:].ravel(), idx[:, 1:].ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    solver = SurfaceSignedHeatSolver(V, F)
    corners = solver.compute_distance_l1([idx[0]])
    assert corners.shape == (len(F), 3)
    cen = V[F].mean(1)
    th = np.arctan2(cen[:, 1], cen[:, 0])
    band = (np.abs(th) < np.radians(150)) & (cen[:, 2] < -0.65)
    assert np.abs(corners.mean(1)[band] - th[band]).max() < 0.08
    l2 = solver.compute_distance([idx[0]], level_set_constraint="none")
    thv = np.arctan2(V[:, 1], V[:, 0])
    bandv = (np.abs(thv) < np.radians(150)) & (V[:, 2] < -0.65)
    assert np.abs(l2 - thv)[bandv].max() > 0.5                  # the continuous L2 fit cannot do this


def test_sharpening_keeps_sign_and_lipschitz(disk):
    V, F, exact, solver = disk
    curves = region_boundary_curves(F, (exact[F] < 0).all(1))
    phi0 = solver.compute_distance(curves)
    phi = solver.sharpen(phi0, curves, iterations=2000)
    # solver.ops are in the solver's frame (frame units): map φ there before taking its gradient
    g = np.linalg.norm((solver.ops.gradient() @ solver.frame.inverse_length(phi)).reshape(-1, 3), axis=1)
    assert g.max() < 1.05
    assert np.abs(phi[np.concatenate(curves)]).max() == 0
    far = np.abs(phi0) > 0.05
    assert np.all(np.sign(phi[far]) == np.sign(phi0[far]))
    assert _eps(solver, phi, exact) < 1.2 * _eps(solver, phi0, exact) + 1e-3
    with pytest.raises(ValueError, match="phi0"):
        solver.sharpen(phi0[:-1], curves)
    with pytest.raises(ValueError, match="phi0: expected real numbers, got strings"):
        solver.sharpen(phi0.astype(str), curves)
    with pytest.raises(ValueError, match="iterations=1,000,000,000 .* would take"):
        solver.sharpen(phi0, curves, iterations=10**9)


def test_faces_repeating_a_vertex_are_dropped_with_a_warning():
    """potpourri3d's random soup has faces like (i, i, j): they have no area; the solver drops them with a
    warning (it refused the mesh), the distance equals that on the mesh without them, and face indices in
    sources still refer to the input faces."""
    from gsdf.data._shapes import grid_mesh

    V, F = grid_mesh(8)
    bad = np.array([[3, 3, 4], [10, 11, 10]])
    Fb = np.vstack([F[:5], bad[:1], F[5:], bad[1:]])  # input face 5 and the last are degenerate
    with pytest.warns(UserWarning, match="2 faces repeat a vertex"):
        sb = SurfaceSignedHeatSolver(V, Fb)
    s = SurfaceSignedHeatSolver(V, F)
    np.testing.assert_allclose(sb.compute_distance([], points=[7]), s.compute_distance([], points=[7]))
    b = np.array([0.2, 0.3, 0.5])
    # input face 6 is face 5 of the mesh without the degenerate ones
    np.testing.assert_allclose(sb.compute_distance([], points=[(6, b)]), s.compute_distance([], points=[(5, b)]))
    curve = [(6, b), (20, b), (41, b)]
    np.testing.assert_allclose(sb.compute_distance([curve]), s.compute_distance([[(5, b), (19, b), (40, b)]]))
    with pytest.raises(ValueError, match="face 5 repeats a vertex"):
        sb.compute_distance([], points=[(5, b)])


def test_the_step_methods_check_what_they_are_given():
    """unit_field(X) of another size leaked an IndexError; diffuse(anything) an AttributeError."""
    import gsdf
    from tests.shapes import uv_sphere

    V, F = uv_sphere(12, 8)
    s = gsdf.SurfaceSignedHeatSolver(V, F)
    X = s.diffuse(s.core.sources([np.array([0, 1, 2])], (), None))
    Y = s.unit_field(X)
    assert Y.shape == (len(F), 3)
    np.testing.assert_array_equal(s.unit_field(X.real), s.unit_field(X.real + 0j))
    for bad, why in ((np.zeros((len(V), 3)), r"shape \(264,\)"), (X[:-1], r"shape \(264,\)"),
                     (np.where(np.arange(len(X)) == 3, np.nan, X), "NaN"), (["a"] * len(X), "strings")):
        with pytest.raises(ValueError, match="X: " + ".*" + why):
            s.unit_field(bad)
    with pytest.raises(ValueError, match="sources: expected the assembled sources"):
        s.diffuse(np.zeros(3))
