"""Points as Tori (thesis ch. 5) and the convolutional baselines: analytic checks."""

import numpy as np
import pytest

from gsdf.data import _shapes as S
from gsdf.tori._baselines import (
    LogSumExpDistance,
    SignedHopfCole,
    SmoothedSignedPlanarDistance,
    WindingNumberPipeline,
)
from gsdf.tori._pat import PointsAsTori
from gsdf.tori._torus import coefficients_to_tori, local_frames, torus_sdf

RNG = np.random.default_rng(7)


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _height_coefficients(sdf, p, n, delta=1e-3):
    """Taylor coefficients (a00, a10, a01, a20, a11, a02) of the zero set of ``sdf`` as a height field over the
    plane (p, n): h(s, t) solves sdf(p + s S + t T + h n) = 0 (Newton), derivatives by central differences."""
    S_, T_ = local_frames(n[None])
    S_, T_ = S_[0], T_[0]

    def h(s, t):
        x = p + s * S_ + t * T_
        hh = 0.0
        for _ in range(60):
            f = sdf((x + hh * n)[None])[0]
            e = 1e-7
            df = (sdf((x + (hh + e) * n)[None])[0] - sdf((x + (hh - e) * n)[None])[0]) / (2 * e)
            hh -= f / df
        return hh

    d = delta
    h00 = h(0, 0)
    hs, hS = h(d, 0), h(-d, 0)
    ht, hT = h(0, d), h(0, -d)
    hst = (h(d, d) - h(d, -d) - h(-d, d) + h(-d, -d)) / (4 * d * d)
    return np.array([h00, (hs - hS) / (2 * d), (ht - hT) / (2 * d), (hs - 2 * h00 + hS) / (2 * d * d), hst,
                     (ht - 2 * h00 + hT) / (2 * d * d)])


def _torus_true(X, c, u, R, r):
    Y = X - c
    a = np.linalg.norm(np.cross(Y, u), axis=1) - R
    return np.hypot(a, Y @ u) - r


def _check(sdf, p, n, X, tol):
    A = _height_coefficients(sdf, np.asarray(p, float), _unit(n))
    T = coefficients_to_tori(np.asarray(p, float)[None], _unit(n)[None], A[None])
    got = torus_sdf(T, X)
    np.testing.assert_allclose(got, sdf(X), atol=tol)
    return T


def test_torus_reproduces_spheres_with_tilted_normals_and_shift():
    X = RNG.uniform(-2, 2, (200, 3))
    for radius, sign in ((0.7, 1), (1.3, 1), (0.9, -1)):  # sign -1: the inside of a spherical cavity
        c0 = np.array([0.1, -0.2, 0.3])
        sdf = lambda Y: sign * (np.linalg.norm(Y - c0, axis=1) - radius)  # noqa: E731
        dirn = _unit([0.3, 0.5, 0.8])
        p = c0 + (radius + 0.01) * dirn  # slightly off the surface: a00 != 0
        T = _check(sdf, p, sign * _unit(dirn + [0.05, -0.03, 0.0]), X, 2e-5)
        assert T[0, 11] == sign  # which side it osculates (Fig. 5.4)


def test_torus_reproduces_cylinders_exactly_in_the_limit():
    X = RNG.uniform(-2, 2, (200, 3))
    u = _unit([1.0, 2.0, -0.5])
    c0 = np.array([0.2, 0.0, -0.1])
    for radius, sign in ((0.4, 1), (0.8, -1)):
        def sdf(Y):
            Y = Y - c0
            return sign * (np.linalg.norm(Y - np.outer(Y @ u, u), axis=1) - radius)

        radial = _unit(np.cross(u, [0, 0, 1.0]))
        p = c0 + radius * radial + 0.3 * u
        T = _check(sdf, p, sign * _unit(radial + [0.02, 0.01, 0.0]), X, 5e-5)
        assert T[0, 10] < 1e-4 * T[0, 9]  # vanishing second curvature handled by the κ form


def test_torus_reproduces_tori_at_outer_and_inner_equator_saddle():
    R, r = 2.0, 0.5
    c, u = np.zeros(3), np.array([0, 0, 1.0])
    sdf = lambda Y: _torus_true(Y, c, u, R, r)  # noqa: E731
    X = RNG.uniform(-3, 3, (300, 3))
    T = _check(sdf, [R + r, 0, 0], [1.0, 0, 0], X, 5e-5)  # outer equator: same-sign curvatures
    assert T[0, 12] == 1
    T = _check(sdf, [R - r, 0, 0], [-1.0, 0, 0], X, 5e-5)  # inner equator: a saddle
    assert T[0, 12] == -1
    # the complement (normals pointing into the tube) gives the negated distance
    _check(lambda Y: -sdf(Y), [R - r, 0, 0], [1.0, 0, 0], X, 5e-5)


def test_planar_and_near_planar_limits_do_not_overflow():
    p, n = np.array([[0.3, 0.1, -0.2]]), np.array([[0.0, 0.6, 0.8]])
    X = RNG.uniform(-1e3, 1e3, (100, 3))
    plane = (X - p) @ n[0]
    for eps in (0.0, 1e-300, 1e-200, 1e-12):
        T = coefficients_to_tori(p, n, [[0, 0, 0, eps, 0.3 * eps, -eps]], k_floor=1e-9)
        g, G = torus_sdf(T, X, return_gradient=True)
        assert np.isfinite(g).all() and np.isfinite(G).all()
        np.testing.assert_allclose(g, plane, atol=1e-6)
    # cylinder-like with an extremely small second curvature: finite, continuous with the exact cylinder
    T0 = coefficients_to_tori(p, n, [[0, 0, 0, -1.0, 0, 0]])
    T1 = coefficients_to_tori(p, n, [[0, 0, 0, -1.0, 0, 1e-300]])
    T2 = coefficients_to_tori(p, n, [[0, 0, 0, -1.0, 0, 1e-9]])
    Y = RNG.uniform(-3, 3, (100, 3))
    np.testing.assert_allclose(torus_sdf(T1, Y), torus_sdf(T0, Y), atol=1e-12)
    np.testing.assert_allclose(torus_sdf(T2, Y), torus_sdf(T0, Y), atol=1e-7)
    # tilted plane from the slope coefficients: n* = (−a10, −a01, 1)/W in the local frame
    T = coefficients_to_tori([[0, 0, 0.0]], [[0, 0, 1.0]], [[0.1, 0.5, 0.0, 0, 0, 0]])
    want = (X - [0, 0, 0.1]) @ _unit(np.array([-0.5, 0, 1.0]) @ np.vstack([local_frames(np.array([[0, 0, 1.0]]))[0],
                                                                          local_frames(np.array([[0, 0, 1.0]]))[1],
                                                                          [[0, 0, 1.0]]]))
    np.testing.assert_allclose(torus_sdf(T, X), want, atol=1e-9)


def test_torus_gradient_matches_finite_differences():
    A = RNG.normal(size=(50, 6)) * [0.05, 0.3, 0.3, 1, 1, 1]
    Pp = RNG.normal(size=(50, 3))
    Nn = RNG.normal(size=(50, 3))
    T = coefficients_to_tori(Pp, Nn, A)
    X = Pp + RNG.normal(size=(50, 3)) * 0.5
    idx = np.arange(50)
    g, G = torus_sdf(T, X, idx, return_gradient=True)
    h = 1e-6
    for a in range(3):
        e = np.zeros(3)
        e[a] = h
        fd = (torus_sdf(T, X + e, idx) - torus_sdf(T, X - e, idx)) / (2 * h)
        np.testing.assert_allclose(G[:, a], fd, atol=1e-5)


def _sphere_cloud(n=2000, radius=0.5):
    i = np.arange(n) + 0.5
    ph, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    N = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    return radius * N, N


def test_pat_sphere_accuracy_gradient_and_save_load(tmp_path):
    P, N = _sphere_cloud()
    pat = PointsAsTori(P, N)
    X = S.grid(20)
    phi = pat.signed_distance(X)
    assert np.abs(phi - S.sphere_sdf(X, 0.5)).mean() < 1e-3
    # jet fitting recovers the curvature 1/0.5 = 2 (tube radius 0.5)
    np.testing.assert_allclose(np.median(pat.tori[:, 9]), 2.0, rtol=5e-2)  # quartic terms bias a quadratic fit
    G = pat.gradient(X[:300])
    h = 1e-6
    for a in range(3):
        e = np.zeros(3)
        e[a] = h
        fd = (pat(X[:300] + e) - pat(X[:300] - e)) / (2 * h)
        assert np.median(np.abs(G[:, a] - fd)) < 1e-6
    eik = np.linalg.norm(pat.gradient(X), axis=1)
    assert np.abs(eik - 1).mean() < 0.02
    f = tmp_path / "pat.npz"
    pat.save(f)
    again = PointsAsTori.load(f)
    np.testing.assert_array_equal(again.signed_distance(X), phi)
    with pytest.raises(ValueError):
        PointsAsTori.load(tmp_path / "missing.npz")


def test_pat_cylinder_is_reasonable_and_signs_are_right():
    rng = np.random.default_rng(1)
    P, N = S.sample_cylinder(2048, 0.3, rng)
    pat = PointsAsTori(P, N)
    X = S.grid(16)
    tr = S.cylinder_sdf(X, 0.3)
    phi = pat(X)
    near = np.abs(tr) < 0.2
    assert np.abs(phi - tr)[near].mean() < 0.02
    assert (np.sign(phi) == np.sign(tr))[np.abs(tr) > 0.05].all()
    V, F = pat.isosurface(0.0, resolution=24)
    assert len(F) > 100 and np.abs(S.cylinder_sdf(V, 0.3)).max() < 0.05


def test_pat_bad_input():
    P, N = _sphere_cloud(200)
    with pytest.raises(ValueError, match="k=64"):
        PointsAsTori(P[:40], N[:40])
    PointsAsTori(P[:40], N[:40], k=20)  # fine with a smaller k
    with pytest.raises(ValueError, match="normals"):
        PointsAsTori(P, None)
    with pytest.raises(ValueError, match="all normals are zero"):
        PointsAsTori(P, np.zeros_like(N))
    Pn = P.copy()
    Pn[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        PointsAsTori(Pn, N)
    with pytest.raises(ValueError, match="rows"):
        PointsAsTori(P, N[:-1])
    with pytest.raises(ValueError, match="estimator"):
        PointsAsTori(P, N, estimator="transformer")
    pat = PointsAsTori(P, N)
    with pytest.raises(ValueError, match="NaN"):
        pat.signed_distance([[0, 0, np.nan]])
    with pytest.raises(ValueError):
        pat.signed_distance(np.zeros((3, 2)))
    # duplicates are merged and zero normals dropped: same field as the clean cloud
    Nz = N.copy()
    Nz[:5] = 0
    noisy = PointsAsTori(np.vstack([P, P[10:30]]), np.vstack([Nz, N[10:30]]))
    clean = PointsAsTori(P[5:], N[5:])
    X = RNG.uniform(-1, 1, (50, 3))
    np.testing.assert_allclose(np.sort(noisy.P, axis=0), np.sort(clean.P, axis=0))
    np.testing.assert_allclose(noisy(X), clean(X), atol=1e-12)
    # unnormalized normals are normalized
    np.testing.assert_allclose(PointsAsTori(P, 3 * N)(X), pat(X), atol=1e-12)


@pytest.mark.parametrize("field", ["k_eval", "k_fallback"])
def test_pat_neighbour_counts_follow_the_baselines_rule(field):
    from gsdf import PointsAsToriOptions

    P, N = _sphere_cloud(200)
    with pytest.raises(ValueError, match=f"{field}: 1000000000 neighbours asked for, but the cloud has 200"):
        PointsAsTori(P, N, options=PointsAsToriOptions(**{field: 10 ** 9}))
    PointsAsTori(P[:40], N[:40], k=20, options=PointsAsToriOptions(**{field: 32}))   # the clamp up to the default


def test_baselines_on_a_sphere():
    P, N = _sphere_cloud(2000)
    X = S.grid(12)
    tr = S.sphere_sdf(X, 0.5)
    for cls, tol in ((SignedHopfCole, 0.03), (SmoothedSignedPlanarDistance, 0.03)):
        v = cls(P, N)(X)
        assert np.abs(v - tr).mean() < tol, cls.__name__
        assert (np.sign(v) == np.sign(tr))[np.abs(tr) > 0.05].all()
    u = LogSumExpDistance(P)(X)
    assert (u >= -1e-9).all() and np.abs(u - np.abs(tr)).mean() < 0.08
    # LogSumExp tends to the nearest distance as λ grows (Eq. 3.15)
    d = LogSumExpDistance([[0, 0, 0.0], [1, 0, 0.0]], areas=np.ones(2), lam=1e4)([[0.2, 0.3, 0.0]])
    np.testing.assert_allclose(d, np.hypot(0.2, 0.3), atol=1e-3)
    w = WindingNumberPipeline(P, N, resolution=24)(X)
    assert np.abs(w - tr).mean() < 0.01


def test_point_knn_matches_scipy_and_is_approximate_within_eps():
    from scipy.spatial import cKDTree

    from gsdf.tori._blend import PointKNN

    P = RNG.normal(size=(3000, 3))
    Q = RNG.uniform(-4, 4, (500, 3))
    d, i = PointKNN(P).query(Q, 40)
    d2, i2 = cKDTree(P).query(Q, k=40)
    np.testing.assert_allclose(d, d2, atol=1e-12)
    da, _ = PointKNN(P).query(Q, 40, eps=0.5)
    assert (da >= d - 1e-12).all() and (da <= 1.5 * d + 1e-12).all()
    # the k_min nearest plus those within the radius, padded with inf
    dr, ir = PointKNN(P).query(Q, 40, k_min=8, radius=1.0)
    want = np.where((np.arange(40) < 8) | (d2 <= 1.0), d2, np.inf)
    np.testing.assert_allclose(dr, want)
    fin = np.isfinite(dr)
    np.testing.assert_array_equal(ir[fin], i2[fin])
    d, i = PointKNN(P[:5]).query(Q[:3], 10)  # k larger than the cloud: clipped
    assert d.shape == (3, 5)
    # Morton-ordered dense queries: the bound seeded from the previous query of a block leaves results exact
    from gsdf.spatial._morton import morton_order

    Q = np.vstack([P[RNG.choice(3000, 2000)] + RNG.normal(scale=0.05, size=(2000, 3)), RNG.uniform(-4, 4, (500, 3))])
    Q = Q[morton_order(Q)]
    d2, i2 = cKDTree(P).query(Q, k=40)
    d, i = PointKNN(P).query(Q, 40)
    np.testing.assert_allclose(d, d2, atol=1e-12)
    for rad in (0.2, 0.6):
        dr, ir = PointKNN(P).query(Q, 40, k_min=8, radius=rad)
        want = np.where((np.arange(40) < 8) | (d2 <= rad), d2, np.inf)
        np.testing.assert_allclose(dr, want, atol=1e-12)
        fin = np.isfinite(dr)
        np.testing.assert_array_equal(ir[fin], i2[fin])


def test_booleans_and_offsets_of_two_point_clouds():
    from gsdf.tori._ops import contour, difference, intersection, offset, union

    P, N = _sphere_cloud(1500, 0.5)
    a = PointsAsTori(P + [0.3, 0, 0], N)
    b = PointsAsTori(P - [0.3, 0, 0], N)
    ta = lambda Q: np.linalg.norm(Q - [0.3, 0, 0], axis=1) - 0.5  # noqa: E731
    tb = lambda Q: np.linalg.norm(Q + [0.3, 0, 0], axis=1) - 0.5  # noqa: E731
    X = RNG.uniform(-1, 1, (400, 3))
    for got, want in ((union(a, b), np.minimum(ta(X), tb(X))), (intersection(a, b), np.maximum(ta(X), tb(X))),
                      (difference(a, b), np.maximum(ta(X), -tb(X))), (offset(a, 0.1), ta(X) - 0.1)):
        np.testing.assert_allclose(got(X), want, atol=0.01)
    V, F = contour(offset(union(a, b), 0.05), [-1.2] * 3, [1.2] * 3, 24)
    assert np.abs(np.minimum(ta(V), tb(V)) - 0.05).max() < 0.02
    with pytest.raises(ValueError):
        union()
