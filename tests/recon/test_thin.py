"""Tests of the stages that choose the surface before the fitting (missed thin parts, spurious sheets): the
spectral orientation of the normals, the depth-ordered growth and its seed, the on-surface rescue of dropped
points — each on analytic clouds, and the topology promise on every output."""

import numpy as np
import pytest
from scipy.spatial import Delaunay

import gsdf
from gsdf.dec._tet import TetComplex
from gsdf.distance import unsigned_distance
from gsdf.mesh._topology import is_sphere
from gsdf.recon._orient import orient_normals
from gsdf.recon._cloud import dense_points, on_surface, pca_normals, prefilter
from gsdf.recon._pipeline import _seeds


def _ellipsoid(n, axes, seed=0):
    """n roughly area-uniform samples of the ellipsoid with semi-axes ``axes`` and their outward normals."""
    rng = np.random.default_rng(seed)
    a = np.asarray(axes, float)
    U = rng.normal(size=(20 * n, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    X = U * a
    Nn = X / a ** 2
    # accept by the area element (the map from the sphere stretches by |N| * prod(a))
    dens = np.linalg.norm(Nn, axis=1) * np.prod(a)
    keep = rng.random(len(X)) < dens / dens.max()
    X, Nn = X[keep][:n], Nn[keep][:n]
    return X, Nn / np.linalg.norm(Nn, axis=1)[:, None]


def _with_outliers(X, Nn, n_out, seed=1, b=0.25):
    """Table-2 style outliers: samples moved along their normal by U[-b, b] × the bbox diagonal."""
    rng = np.random.default_rng(seed)
    diag = float(np.linalg.norm(X.max(0) - X.min(0)))
    i = rng.integers(0, len(X), n_out)
    O = X[i] + Nn[i] * rng.uniform(-b, b, (n_out, 1)) * diag
    return np.concatenate([X, O])


def _ellipsoid_area(a, b, c, n=400):
    """Surface area of an ellipsoid by quadrature over the parameter sphere."""
    th = (np.arange(n) + 0.5) * np.pi / n
    ph = (np.arange(2 * n) + 0.5) * np.pi / n
    T, Ph = np.meshgrid(th, ph, indexing="ij")
    st, ct, sp_, cp = np.sin(T), np.cos(T), np.sin(Ph), np.cos(Ph)
    # |r_theta x r_phi| for r = (a sin t cos p, b sin t sin p, c cos t)
    nx, ny, nz = b * c * st * st * cp, a * c * st * st * sp_, a * b * st * ct
    return float(np.sqrt(nx ** 2 + ny ** 2 + nz ** 2).sum() * (np.pi / n) ** 2)


def _dumbbell(n_ball=2500, r=0.12, seed=0):
    """Two unit spheres centred at x = ±2 joined by a thin cylinder of radius ``r`` along the x axis (the
    inner caps removed where it enters), sampled at one density; returns samples, outward normals, the
    number of sphere samples (the cylinder's follow) and the median sample spacing."""
    rng = np.random.default_rng(seed)
    U = rng.normal(size=(2 * n_ball, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    c = np.where(np.arange(2 * n_ball) < n_ball, -2.0, 2.0)
    inner = (np.sign(U[:, 0]) == -np.sign(c)) & (np.hypot(U[:, 1], U[:, 2]) < r)
    U, c = U[~inner], c[~inner]
    S = U + c[:, None] * np.array([1.0, 0, 0])
    x0 = 2.0 - np.sqrt(1 - r * r)                              # where the cylinder enters the spheres
    nt = int(round(n_ball / (4 * np.pi) * 2 * np.pi * r * 2 * x0))
    t, a = rng.uniform(-x0, x0, nt), rng.uniform(0, 2 * np.pi, nt)
    C = np.column_stack([t, r * np.cos(a), r * np.sin(a)])
    NC = np.column_stack([np.zeros(nt), np.cos(a), np.sin(a)])
    X = np.concatenate([S, C])
    from scipy.spatial import cKDTree
    spacing = float(np.median(cKDTree(X).query(X, k=2)[0][:, 1]))
    return X, np.concatenate([U, NC]), len(S), spacing


# ---------------------------------------------------------------- orientation
def test_spectral_orientation_across_a_thin_slab_with_the_crossing_term():
    """A flat ellipsoid 4.4 spacings thick: the kNN graph links the two sides near the rim, whose normal lines
    agree but whose outward signs are opposite.  From PCA normals, the crossing term recovers nearly all
    signs."""
    X, Nt = _ellipsoid(6000, (1.0, 0.8, 0.03), seed=3)
    N0 = pca_normals(X)
    ok = lambda N: np.mean(np.einsum("ij,ij->i", N, Nt) > 0)      # noqa: E731
    assert ok(orient_normals(X, N0, crossing=1.0)) > 0.93
    # with the true lines (random signs) it is exact
    flip = np.random.default_rng(4).random(len(X)) < 0.5
    assert ok(orient_normals(X, np.where(flip[:, None], -Nt, Nt), crossing=1.0)) > 0.99


def test_spectral_orientation_of_a_thin_tube():
    """A thin torus-like tube (a bent cylinder, radius 2 spacings) from PCA normals: the sheet term damps the
    edges across the tube (|n_i·n_j| ≈ 1 across, the sign opposite)."""
    rng = np.random.default_rng(5)
    n = 6000
    R, r = 1.0, 0.04
    u, v = rng.uniform(0, 2 * np.pi, n), rng.uniform(0, 2 * np.pi, n)
    X = np.column_stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)])
    Nt = np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])
    N0 = pca_normals(X)
    ok = lambda N: np.mean(np.einsum("ij,ij->i", N, Nt) > 0)      # noqa: E731
    assert ok(orient_normals(X, N0)) > 0.9


def test_spectral_orientation_of_a_sphere():
    rng = np.random.default_rng(0)
    P = rng.normal(size=(800, 3))
    P /= np.linalg.norm(P, axis=1)[:, None]
    N = orient_normals(P, P * rng.choice([-1.0, 1.0], (800, 1)))
    assert np.all(np.einsum("ij,ij->i", N, P) > 0)
    # two separate spheres: each component gets its own outward sign
    Q = np.concatenate([P, P + [5.0, 0, 0]])
    Nq = orient_normals(Q, np.concatenate([P, -P]))
    assert np.all(np.einsum("ij,ij->i", Nq, np.concatenate([P, P])) > 0)


# ---------------------------------------------------------------- seed and growth order
def test_seed_is_in_the_component_touching_the_samples_not_the_largest_bubble():
    rng = np.random.default_rng(0)
    S = rng.normal(size=(300, 3))
    S = 0.3 * S / np.linalg.norm(S, axis=1)[:, None]       # small sphere of samples at the origin
    far = rng.uniform(-1, 1, (40, 3)) * 0.2 + [2.0, 0, 0]   # a few points far away
    V = np.concatenate([S, far, [[x, y, z] for x in (-3, 4) for y in (-3, 3) for z in (-3, 3)]])
    K = TetComplex(V, Delaunay(V).simplices)
    cen = K.V[K.T].mean(axis=1)
    body = np.linalg.norm(cen, axis=1) < 0.3
    bubble = np.linalg.norm(cen - [2.0, 0, 0], axis=1) < 1.2       # large tets: more volume than the body
    w = np.where(body, 1.0, np.where(bubble, 2.0, 0.0))
    assert K.volumes[bubble].sum() > K.volumes[body].sum()
    allowed = np.zeros(K.n_tets, dtype=np.int64)
    s_vol = _seeds(K, w, allowed, 1)
    s_smp = _seeds(K, w, allowed, 1, n_samples=len(S))
    assert bubble[s_vol[0]] and body[s_smp[0]]


def test_dumbbell_with_outliers_reaches_the_thin_handle_and_is_one_sphere():
    X, Nn, n_s, spacing = _dumbbell()
    P = _with_outliers(X, Nn, 300, b=0.1)
    V, F, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
    assert is_sphere(V, F)
    handle = X[n_s:][np.abs(X[n_s:, 0]) < 0.6]
    assert len(handle) > 30
    d = unsigned_distance(V, F, handle)
    assert np.mean(d <= spacing) > 0.9
    # the balls are not joined by a web: the output's points near x = 0 stay within the handle's radius + 2 spacings
    mid = V[np.abs(V[:, 0]) < 0.5]
    assert np.hypot(mid[:, 1], mid[:, 2]).max() < 0.1 + 2 * spacing


def test_ellipsoid_with_outliers_area_close_to_the_analytic_area():
    axes = (1.0, 0.6, 0.4)
    X, Nn = _ellipsoid(4000, axes, seed=5)
    P = _with_outliers(X, Nn, 400, seed=6)
    V, F = gsdf.reconstruct_simply_connected(P)
    assert is_sphere(V, F)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()
    exact = _ellipsoid_area(*axes)
    assert abs(area / exact - 1) < 0.05, area / exact
    # and close to it: the samples are within 1 % of the diagonal of the output
    diag = float(np.linalg.norm(2 * np.array(axes)))
    assert np.mean(unsigned_distance(V, F, X) < 0.01 * diag) > 0.97


# ---------------------------------------------------------------- on-surface rescue
def test_on_surface_rescue_keeps_thin_cylinder_samples_not_outliers():
    """A ball with a thin cylinder (radius ≈ 2.3 spacings, same sampling density) and 300 outliers moved along
    the normal by 9–23 spacings: the planar and dense tests drop cylinder samples (curved neighbourhoods in
    the gaps of the random sampling); the rescue takes a part of them back and no outlier."""
    rng = np.random.default_rng(0)
    S, NS = _ellipsoid(6000, (0.8, 0.8, 0.8), seed=2)
    S = S + [0, 0, 1.0]
    r = 0.04
    n = int(6000 / (4 * np.pi * 0.64) * 2 * np.pi * r * 2)
    t, a = rng.uniform(-1, 1, n), rng.uniform(0, 2 * np.pi, n)
    C = np.column_stack([t, r * np.cos(a), r * np.sin(a)])
    NC = np.column_stack([np.zeros(n), np.cos(a), np.sin(a)])
    X = np.concatenate([C, S])
    Nn = np.concatenate([NC, NS])
    i = rng.integers(0, len(X), 300)
    O = X[i] + Nn[i] * rng.choice([-1, 1], (300, 1)) * rng.uniform(0.15, 0.4, (300, 1))
    Y = np.concatenate([X, O])
    planar = prefilter(Y, rescue=False)
    keep = planar | dense_points(Y, planar)
    res = on_surface(Y, keep)
    assert not (res & keep).any()
    dropped = ~keep[:n]                                            # cylinder samples the two tests drop
    assert dropped.sum() > 20 and (~keep[n:len(X)]).sum() <= 5
    assert res[:n][dropped].mean() > 0.25                          # a part of them is back
    assert res[len(X):].sum() == 0                                 # and no outlier


# ---------------------------------------------------------------- the promise on a Table-2-style grid
def _torus_samples(n, R=1.0, r=0.35, seed=4):
    rng = np.random.default_rng(seed)
    u, v = rng.uniform(0, 2 * np.pi, (2, 4 * n))
    keep = rng.random(4 * n) < (R + r * np.cos(v)) / (R + r)          # area-uniform
    u, v = u[keep][:n], v[keep][:n]
    Nn = np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])
    X = np.column_stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)])
    return X, Nn


@pytest.mark.parametrize("shape, n, n_out", [("ellipsoid", 1000, 200), ("ellipsoid", 1000, 800),
                                             ("ellipsoid", 2000, 400), ("torus", 2000, 200),
                                             ("torus", 1000, 800), ("dumbbell", 1500, 400)])
def test_every_table2_style_case_is_one_sphere(shape, n, n_out):
    """The paper's Table-2 protocol on analytic shapes (no download in CI): n samples plus n_out outliers moved
    along the normal by U[-¼, ¼] × the diagonal, unoriented. Every output is one closed, oriented, edge- and
    vertex-manifold genus-0 mesh — also for a genus-1 truth — and lies near the samples."""
    if shape == "ellipsoid":
        X, Nn = _ellipsoid(n, (1.0, 0.6, 0.4), seed=n + n_out)
    elif shape == "torus":
        X, Nn = _torus_samples(n, seed=n + n_out)
    else:
        X, Nn, _, _ = _dumbbell(n_ball=n // 2, seed=n_out)
    P = _with_outliers(X, Nn, n_out, seed=n_out)
    V, F = gsdf.reconstruct_simply_connected(P)
    assert is_sphere(V, F)
    diag = float(np.linalg.norm(X.max(0) - X.min(0)))
    assert float(np.median(unsigned_distance(V, F, X))) < 0.01 * diag
