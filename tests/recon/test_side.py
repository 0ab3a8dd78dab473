"""Tests of the one-sided moving-least-squares fits (thin parts): the quadric of a query fitted to the samples on
its side only (oriented normals) and the rescue of dropped points at the tips of thin parts that uses it; the
reconstruction keeps the topology promise."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

import gsdf
from gsdf.mesh._topology import is_sphere
from gsdf.recon._orient import orient_normals
from gsdf.recon._cloud import dense_points, on_side, on_surface, pca_normals, prefilter
from gsdf.recon._relocate import local_surface
from tests.recon.test_thin import _ellipsoid, _with_outliers


def _slab(gap, h=0.01, half=0.1):
    """Two parallel square grids of spacing h at z = ±gap/2 (a thin slab), with their outward normals."""
    g = np.arange(-half, half + 1e-12, h)
    x, y = np.meshgrid(g, g, indexing="ij")
    top = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, gap / 2)])
    bot = top * [1, 1, -1]
    N = np.concatenate([np.tile([0, 0, 1.0], (len(top), 1)), np.tile([0, 0, -1.0], (len(bot), 1))])
    return np.concatenate([top, bot]), N


def test_one_sided_fit_stays_on_its_side_of_a_thin_slab():
    """Sheets 1.5 spacings apart: the 12 nearest samples of a point on the top sheet span both sheets, and
    their quadric runs between them (the foot is pulled towards the middle); the one-sided fit keeps the
    top sheet's samples only and puts the foot on it."""
    h, gap = 0.01, 0.015
    S, NS = _slab(gap, h)
    rng = np.random.default_rng(0)
    Q = np.column_stack([rng.uniform(-0.05, 0.05, (50, 2)), np.full(50, gap / 2 + 0.2 * h)])
    Nq = np.tile([0, 0, 1.0], (50, 1))
    foot2, _, _ = local_surface(Q, S, h, k=12)
    foot1, n1, hgt1 = local_surface(Q, S, h, k=12, normals=NS, query_normals=Nq)
    assert np.median(np.abs(foot2[:, 2] - gap / 2)) > 0.1 * gap        # two-sided: pulled off the sheet
    assert np.abs(foot1[:, 2] - gap / 2).max() < 1e-9                  # one-sided: on it
    assert np.allclose(np.abs(n1[:, 2]), 1.0) and np.allclose(hgt1, 0.2 * h * np.sign(n1[:, 2]))


def test_one_sided_fit_falls_back_and_validates():
    S, NS = _slab(0.015)
    Q = np.array([[0.0, 0.0, 0.01]])
    # a query whose normal faces no sample within reach (it is tangential here: cosine 0 with every one)
    a = local_surface(Q, S, 0.01, k=8)
    b = local_surface(Q, S, 0.01, k=8, normals=NS, query_normals=np.array([[1.0, 0, 0]]))
    assert all(np.array_equal(x, y) for x, y in zip(a, b))            # fewer than 3 on its side: k nearest
    with pytest.raises(ValueError, match="both or neither"):
        local_surface(Q, S, 0.01, normals=NS)
    with pytest.raises(ValueError, match="shapes"):
        local_surface(Q, S, 0.01, normals=NS[:5], query_normals=np.array([[0, 0, 1.0]]))


def _ball_with_thin_cylinder(r=0.04, n_ball=6000, n_out=300, seed=0):
    """A ball of radius 0.8 with a thin cylinder (radius ``r``) through it, sampled at one density, plus
    ``n_out`` outliers moved along the normal by 0.15–0.4; returns the cloud and the cylinder's sample count."""
    rng = np.random.default_rng(seed)
    S, NS = _ellipsoid(n_ball, (0.8, 0.8, 0.8), seed=2)
    S = S + [0, 0, 1.0]
    n = int(n_ball / (4 * np.pi * 0.64) * 2 * np.pi * r * 2)
    t, a = rng.uniform(-1, 1, n), rng.uniform(0, 2 * np.pi, n)
    C = np.column_stack([t, r * np.cos(a), r * np.sin(a)])
    NC = np.column_stack([np.zeros(n), np.cos(a), np.sin(a)])
    X, Nn = np.concatenate([C, S]), np.concatenate([NC, NS])
    i = rng.integers(0, len(X), n_out)
    O = X[i] + Nn[i] * rng.choice([-1, 1], (n_out, 1)) * rng.uniform(0.15, 0.4, (n_out, 1))
    return np.concatenate([X, O]), n, len(X)


def test_side_rescue_keeps_thin_cylinder_samples_the_first_rescue_leaves_and_no_outlier():
    Y, n, n_true = _ball_with_thin_cylinder()
    keep = prefilter(Y, rescue=False)
    keep = keep | dense_points(Y, keep)
    keep = keep | on_surface(Y, keep)
    N = np.zeros((len(Y), 3))
    N[keep] = orient_normals(Y[keep], pca_normals(Y[keep]))
    left = ~keep[:n]                                                  # cylinder samples both tests leave
    add, Nadd = on_side(Y, keep, N)
    assert left.sum() > 20
    assert not (add & keep).any()
    assert add[:n][left].mean() > 0.4                                 # a good part of them is back
    # and no outlier off the surface: an added one lies within the height (2.5 spacings) of the true surface
    sp = float(np.median(cKDTree(Y[keep]).query(Y[keep], k=2)[0][:, 1]))
    P = Y[n_true:][add[n_true:]]
    d_true = np.minimum(np.abs(np.linalg.norm(P - [0, 0, 1.0], axis=1) - 0.8),
                        np.where(np.abs(P[:, 0]) <= 1, np.abs(np.hypot(P[:, 1], P[:, 2]) - 0.04), np.inf))
    assert add[n_true:].sum() <= 2 and np.all(d_true <= 2.5 * sp)
    assert np.allclose(np.linalg.norm(Nadd[add], axis=1), 1.0)
    # the added points' normals mostly agree in sign with their nearest kept point's (each was signed by the
    # point it was measured from, which may be an earlier added one)
    _, j = cKDTree(Y[keep]).query(Y[add])
    assert np.mean(np.einsum("ij,ij->i", Nadd[add], N[keep][j]) > 0) >= 0.8


def test_thin_flat_ellipsoid_with_outliers_keeps_the_promise():
    X, Nn = _ellipsoid(1500, (1.0, 0.5, 0.12), seed=5)               # a thin, flat ellipsoid
    P = _with_outliers(X, Nn, 200, seed=6)
    V, F, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
    assert is_sphere(V, F)
    assert rep["side_rescued"] >= 0
    from gsdf.distance import unsigned_distance
    assert float(np.median(unsigned_distance(V, F, X))) < 0.01 * float(np.linalg.norm(X.max(0) - X.min(0)))
