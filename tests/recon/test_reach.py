"""Tests of the thin-part corrections of gsdf.recon: the dense-point rescue of the pre-filter, the growth
resumed towards missed samples (``_reach``: simple-tet moves only), and the 1-to-4 subdivision onto the
samples' local surface (geometry only; the topology of the input mesh is kept)."""

import numpy as np
import pytest
from scipy.spatial import Delaunay

import gsdf
from gsdf.dec._tet import TetComplex
from gsdf.distance import unsigned_distance
from gsdf.mesh._topology import is_sphere
from gsdf.recon._grow import grow_regions, region_boundary
from gsdf.recon._cloud import dense_points
from gsdf.recon._pipeline import _circumradii, _reach
from gsdf.recon._relocate import subdivide_onto_samples
from gsdf.recon._steiner import octree_steiner_points


def _sphere(n, seed=0):
    P = np.random.default_rng(seed).normal(size=(n, 3))
    return P / np.linalg.norm(P, axis=1)[:, None]


def test_circumradii_against_known_tets():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [2, 0, 0], [0, 2, 0]], float)
    r = _circumradii(V, np.array([[0, 1, 2, 3], [0, 1, 4, 5]]))
    assert r[0] == pytest.approx(np.sqrt(3) / 2)       # corner of the unit cube: centre (½, ½, ½)
    assert np.isinf(r[1])                               # flat


def test_dense_keeps_samples_not_sparse_outliers():
    rng = np.random.default_rng(0)
    S = _sphere(3000)
    O = rng.uniform(-1.5, 1.5, (300, 3))
    O = O[np.abs(np.linalg.norm(O, axis=1) - 1) > 0.3]
    X = np.concatenate([S, O])
    keep = np.r_[np.ones(2000, bool), np.zeros(len(X) - 2000, bool)]
    d = dense_points(X, keep)
    # random samples: ~95 % have their 5th neighbour within 3 spacings (the planar test keeps the rest)
    assert d[:3000].mean() > 0.9 and d[3000:].mean() < 0.05


def _sphere_with_tube(seed=0, n=2500):
    """Unit-sphere samples plus a thin tube sticking out along +x (radius 1.5 spacings, to x = 1.6)."""
    rng = np.random.default_rng(seed)
    S = _sphere(n, seed)
    sp = float(np.sqrt(4 * np.pi / n))
    r = 1.5 * sp
    nt = int(0.6 * 2 * np.pi * r / sp ** 2)
    t, a = rng.uniform(0.98, 1.6, nt), rng.uniform(0, 2 * np.pi, nt)
    T = np.column_stack([t, r * np.cos(a), r * np.sin(a)])
    S = S[~((S[:, 0] > 0.9) & (np.hypot(S[:, 1], S[:, 2]) < r))]
    return np.concatenate([S, T]), len(S), sp, r


def test_reach_grows_into_a_missed_tube_and_stays_one_sphere():
    X, ns, sp, r = _sphere_with_tube()
    St = octree_steiner_points(X, sp)
    cage = np.array([[x, y, z] for x in (-2.5, 2.5) for y in (-2.5, 2.5) for z in (-2.5, 2.5)])
    V = np.concatenate([X, St, cage])
    K = TetComplex(V, Delaunay(V).simplices)
    rc = np.linalg.norm(K.V[K.T].mean(axis=1), axis=1)
    w = (rc < 1.0).astype(float)                        # a field that misses the tube
    label, _ = grow_regions(K, w, 0.5, priority=w - 0.05 * rc)
    tip = X[ns:][X[ns:, 0] > 1.1]
    gap = lambda lab: unsigned_distance(K.V, region_boundary(K, lab), tip) / sp
    assert np.mean(gap(label) <= 1) < 0.05
    lab2, added = _reach(K, label, np.zeros(K.n_tets, dtype=np.int64), np.ones(len(X), dtype=bool), sp)
    assert is_sphere(K.V, region_boundary(K, lab2))
    assert added > 20 and ((lab2 >= 0) | (label < 0)).all()       # only growth, net
    assert np.mean(gap(lab2) <= 1) > 0.95
    # what was added hugs the tube: every new tet's centroid within the tube's radius plus one spacing
    cen = K.V[K.T].mean(axis=1)
    new = (lab2 >= 0) & (label < 0)
    outside_ball = new & (rc > 1.05)
    assert outside_ball.sum() > 10
    assert (np.hypot(cen[outside_ball, 1], cen[outside_ball, 2]) < r + sp).all()


def test_reconstruction_keeps_a_thin_tube_and_the_promise():
    X, ns, sp, r = _sphere_with_tube(seed=1)
    V, F, rep = gsdf.reconstruct_simply_connected(X, return_report=True)
    assert is_sphere(V, F)
    tip = X[ns:][X[ns:, 0] > 1.1]
    assert np.mean(unsigned_distance(V, F, tip) <= sp) > 0.9


# ---------------------------------------------------------------- subdivision
def _icosahedron():
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
                  [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    V /= np.linalg.norm(V, axis=1)[:, None]
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    return V, F


def test_subdivision_onto_a_sphere_lowers_the_chord_error_and_keeps_the_topology():
    V, F = _icosahedron()
    S = _sphere(20000, seed=2)

    def err(V, F):                                       # face centroids' distance to the unit sphere
        return np.abs(np.linalg.norm(V[F].mean(axis=1), axis=1) - 1).mean()

    V1, F1, rep = subdivide_onto_samples(V, F, S, 0.2, return_report=True)
    V2, F2 = subdivide_onto_samples(V, F, S, 0.2, levels=2)
    assert (len(V1), len(F1), len(V2), len(F2)) == (42, 80, 162, 320)
    assert rep == {"midpoints": 30, "projected": 30, "kept_flat": 0}
    assert np.array_equal(V1[:12], V) and np.array_equal(F1[:0], F[:0])
    for Vs, Fs in ((V1, F1), (V2, F2)):
        assert is_sphere(Vs, Fs)
        assert np.abs(np.linalg.norm(Vs, axis=1) - 1).max() < 2e-3       # the MLS quadric of 12 samples
    assert err(V2, F2) < 0.3 * err(V1, F1) < 0.3 * err(V, F)
    # orientation kept: outward normals
    n = np.cross(V1[F1[:, 1]] - V1[F1[:, 0]], V1[F1[:, 2]] - V1[F1[:, 0]])
    assert (np.einsum("fx,fx->f", n, V1[F1].mean(axis=1)) > 0).all()


def test_subdivision_does_not_move_where_the_samples_are_not_one_sheet_or_would_flip():
    V, F = _icosahedron()
    # samples of two parallel planes far from the mesh: the fits are fine but the steps are capped, and on
    # two close sheets (a thin part) the quadric residual is large, so nothing moves
    g = np.linspace(-1.5, 1.5, 60)
    A = np.array([[x, y, 0.0] for x in g for y in g])
    S = np.concatenate([A + [0, 0, 0.05], A - [0, 0, 0.05]])
    V1, F1, rep = subdivide_onto_samples(V, F, S, 0.05, return_report=True)
    assert is_sphere(V1, F1)
    assert rep["projected"] < rep["midpoints"]
    n0 = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    n1 = np.cross(V1[F1[:, 1]] - V1[F1[:, 0]], V1[F1[:, 2]] - V1[F1[:, 0]])
    assert (np.einsum("fx,fx->f", n1, np.tile(n0, (4, 1))) > 0).all()     # no child turned against its parent


@pytest.mark.parametrize("kw, match", [
    (dict(levels=-1), "levels"), (dict(levels=True), "levels"), (dict(spacing=0.0), "spacing"),
    (dict(S=np.zeros((2, 3))), "S"), (dict(F=np.array([[0, 1, 99]])), "F"), (dict(fit_tol=-1.0), "fit_tol"),
    (dict(V=np.full((12, 3), np.nan)), "V"), (dict(k=2), "k"),
])
def test_subdivision_bad_input(kw, match):
    V, F = _icosahedron()
    args = dict(V=V, F=F, S=_sphere(500), spacing=0.2)
    args.update(kw)
    V_, F_, S_, sp_ = args.pop("V"), args.pop("F"), args.pop("S"), args.pop("spacing")
    with pytest.raises(ValueError, match=match):
        subdivide_onto_samples(V_, F_, S_, sp_, **args)


def test_reconstruction_subdivide_validates_and_splits_each_face_in_four():
    P = _sphere(300)
    with pytest.raises(ValueError, match="subdivide"):
        gsdf.ReconstructionOptions(subdivide=True)
    with pytest.raises(ValueError, match="subdivide"):
        gsdf.ReconstructionOptions(subdivide=4)
    V0, F0 = gsdf.reconstruct_simply_connected(P, options=gsdf.ReconstructionOptions(subdivide=0))
    V1, F1 = gsdf.reconstruct_simply_connected(P)
    assert len(F1) == 4 * len(F0) and is_sphere(V1, F1)
