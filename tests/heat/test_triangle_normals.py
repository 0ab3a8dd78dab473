"""Explicit curve normals (``curve_normals=``) of the surface signed heat method, e.g. on nonorientable domains."""

import numpy as np
import pytest

from gsdf.heat import SurfaceSignedHeatSolver
from gsdf.contour._surface_curves import level_set_curves, region_boundary_curves
from gsdf.data._shapes import grid_mesh


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
    for bad, match in (("x", "curve_normals: expected a list"), ([object()], r"curve_normals\[0\]"),
                       (["xyz"], r"curve_normals\[0\]"), ([np.array([0, 0, np.nan])], r"curve_normals\[0\]")):
        with pytest.raises(ValueError, match=match):                   # numpy's own errors leaked before
            s.compute_distance(curves, curve_normals=bad)
    with pytest.raises(ValueError, match="curve_normals"):
        SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=True).compute_distance(
            [np.array([0, 1, 10, 0])], curve_normals=[np.array([0, 0, 1.0])])


# ------------------------------------------------------------------------ nonorientable: real 2×2 block transport
def folded_mobius(nu=96, nv=10, w=0.5, d=2.0):
    """An intrinsically flat Möbius strip: the rectangle [0, 3d) × [-w, w] with (x + 3d, y) ~ (x, -y), folded flat
    into the plane z = 0 along three creases at 60°, 120°, 60° (an immersed mesh; the identification flips the
    face orientation across the seam x = 0). Returns V, F, the development coordinates R (n, 2) and 3d."""
    L = 3 * d
    cs = np.array([d / 2, 3 * d / 2, 5 * d / 2])
    k1 = 1 / np.sqrt(3)
    x = np.arange(nu) * L / nu                                 # nu a multiple of 6: creases on columns
    kx = np.interp(x, [0, cs[0], cs[1], cs[2], L], [0, k1, -k1, k1, 0])
    y = np.linspace(-w, w, nv + 1)
    R = np.stack([x[:, None] + y[None] * kx[:, None], np.broadcast_to(y, (nu, nv + 1))], -1).reshape(-1, 2)
    P = R.copy()
    for c, t in list(zip(cs, [np.pi / 3, 2 * np.pi / 3, np.pi / 3]))[::-1]:   # reflections R1 R2 R3 (right first)
        sel = np.repeat(x >= c - 1e-12, nv + 1)
        u = np.array([np.cos(t), np.sin(t)])
        q = P[sel] - [c, 0]
        P[sel] = [c, 0] + 2 * (q @ u)[:, None] * u - q
    idx = np.arange(nu * (nv + 1)).reshape(nu, nv + 1)
    nxt = np.roll(idx, -1, axis=0)
    nxt[-1] = idx[0, ::-1]                                     # the half twist
    a, b, c_, e = idx[:, :-1].ravel(), nxt[:, :-1].ravel(), nxt[:, 1:].ravel(), idx[:, 1:].ravel()
    F = np.concatenate([np.stack([a, b, c_], 1), np.stack([a, c_, e], 1)])
    return np.concatenate([P, np.zeros((len(P), 1))], 1), F, R, L


def _circle_on_strip(V, F, R, L, c, r):
    """Exact SDF of a circle on the flat strip (nearest of the lifts to the universal cover, a convex strip) and
    its level-set curves, oriented counter-clockwise around the circle's centre in the plane z = 0."""
    d = np.full(len(R), np.inf)
    for k in (-1, 0, 1):
        d = np.minimum(d, np.linalg.norm(np.stack([R[:, 0] + k * L, R[:, 1] * (-1) ** k], 1) - c, axis=1))
    exact = d - r
    out = []
    for cu in level_set_curves(V, F, exact):
        P = np.array([b @ V[F[f]] for f, b in cu])
        ccw = np.cross(P[:-1] - P.mean(0), np.diff(P, axis=0))[:, 2].mean() > 0
        out.append(cu if ccw else cu[::-1])
    return exact, out


def _eps(V, F, phi, exact):
    from gsdf.heat.triangle._operators import TriangleMeshOperators

    A = TriangleMeshOperators(V, F).vertex_mass()
    return np.sqrt((A * (phi - exact) ** 2).sum() / A.sum()) / (exact.max() - exact.min())


def _forced(V, F, connection):
    """A solver whose Step I uses the given form of the connection Laplacian instead of the automatic choice
    (complex Eq. 9 where all faces agree in orientation, real 2×2 blocks otherwise): "complex" on a
    nonorientable mesh rotates where it should reflect, "real" on an orientable one must give the same φ."""
    from gsdf.heat._core import SignedHeatCore
    from gsdf.heat.triangle._domain import TriangleDomain

    s = SurfaceSignedHeatSolver(V, F)
    s.domain = TriangleDomain(t=s.domain.t, connection=connection, ops=s.input_ops)
    s.core = SignedHeatCore(s.domain)
    return s


def test_flat_mobius_matches_development():
    V, F, R, L = folded_mobius()
    s = SurfaceSignedHeatSolver(V, F)
    inner = np.abs(np.abs(R[:, 1]) - 0.5) > 1e-9
    th = np.bincount(F.ravel(), weights=s.ops.angles.ravel(), minlength=len(V))
    assert np.abs(th[inner] - 2 * np.pi).max() < 1e-12            # intrinsically flat
    assert not s.ops.consistent and (s.ops.slot_sigma < 0).sum() == 10   # the seam: 10 reflected edges
    up = np.array([0, 0, 1.0])
    # a circle next to the seam (its heat crosses the seam) and one across the seam
    for c, r, worst in (((0.45, 0.15), 0.25, 0.2), ((0.15, 0.1), 0.3, None)):
        exact, curves = _circle_on_strip(V, F, R, L, np.array(c), r)
        for mode in ("zero", "none"):
            phi = s.compute_distance(curves, curve_normals=[up] * len(curves), level_set_constraint=mode)
            assert np.isfinite(phi).all()
            near = exact < 0.8
            # measured: ε 0.019–0.021, max error 0.045–0.072 within 0.8 of the circle
            assert _eps(V, F, phi, exact) < 0.03 and np.abs(phi - exact)[near].max() < 0.09
        if worst is not None:                                      # complex transport (a rotation) is wrong here
            bad = _forced(V, F, "complex").compute_distance(curves, curve_normals=[up] * len(curves))
            assert _eps(V, F, bad, exact) > worst                  # measured 0.44


def test_real_block_equals_complex_on_orientable():
    from gsdf.data._shapes import sphere_mesh
    from gsdf.linalg import HermitianFactorization

    V, F = grid_mesh(12, jitter=0.2, delaunay=True)
    curves = level_set_curves(V, F, np.linalg.norm(V[:, :2] - 0.1, axis=1) - 0.4)
    Vs, Fs = sphere_mesh(2)
    scurves = level_set_curves(Vs, Fs, Vs[:, 2] - 0.3)
    for (V_, F_, c_) in ((V, F, curves), (Vs, Fs, scurves)):
        a = SurfaceSignedHeatSolver(V_, F_)
        b = _forced(V_, F_, "real")
        assert a.ops.consistent and isinstance(a.vector_heat_factorization, HermitianFactorization)
        for kw in ({}, {"points": [3]}, {"level_set_constraint": "none"}):
            np.testing.assert_allclose(a.compute_distance(c_, **kw), b.compute_distance(c_, **kw), atol=1e-10)
        np.testing.assert_allclose(a.compute_distance([], points=[(5, np.array([0.2, 0.3, 0.5]))]),
                                   b.compute_distance([], points=[(5, np.array([0.2, 0.3, 0.5]))]), atol=1e-10)
    Ar = a.ops.cr_connection_laplacian_real()
    assert abs(Ar - Ar.T).max() < 1e-12


def test_flipped_faces_are_reflections():
    """An orientable mesh with some faces listed clockwise: the real block form makes the result independent
    of the face orientations once the curve normals are given (the complex form would rotate across them)."""
    V, F = grid_mesh(16, jitter=0.2, delaunay=True, seed=2)
    inside = np.linalg.norm(V[F].mean(1)[:, :2] - [0.1, 0], axis=1) < 0.45
    (loop,) = region_boundary_curves(F, inside)
    up = np.array([0, 0, 1.0])
    ref = SurfaceSignedHeatSolver(V, F).compute_distance([loop])
    G = F.copy()
    flip = np.random.default_rng(0).random(len(F)) < 0.3
    G[flip] = G[flip][:, ::-1]
    s = SurfaceSignedHeatSolver(V, G)
    assert not s.ops.consistent
    for mode in ("zero", "none"):
        np.testing.assert_allclose(s.compute_distance([loop], curve_normals=up, level_set_constraint=mode),
                                   SurfaceSignedHeatSolver(V, F).compute_distance([loop], level_set_constraint=mode),
                                   atol=1e-9)
    wrong = _forced(V, G, "complex").compute_distance([loop], curve_normals=up)
    assert np.abs(wrong - ref).max() > 0.1
