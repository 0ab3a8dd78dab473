"""Tests of the topology-preserving corrections of gsdf.recon: simple-tet removal (carve_regions), resumed
growth, the sculpting step (pockets filled, bulges peeled) and the thin-part rescue of the pre-filter."""

import numpy as np
import pytest
from scipy.spatial import Delaunay

from gsdf.dec._tet import TetComplex
from gsdf.recon._grow import carve_regions, grow_regions, region_boundary
from gsdf.recon._cloud import prefilter
from gsdf.recon._pipeline import _sculpt, _winding_evidence, _with_winding
from gsdf.recon._steiner import octree_steiner_points
from gsdf.mesh._topology import is_sphere


def _sphere(n, seed=0):
    P = np.random.default_rng(seed).normal(size=(n, 3))
    return P / np.linalg.norm(P, axis=1)[:, None]


def _ball_region(seed, n=600):
    rng = np.random.default_rng(seed)
    P = rng.uniform(-1, 1, (n, 3))
    K = TetComplex(P, Delaunay(P).simplices)
    r = np.linalg.norm(K.V[K.T].mean(axis=1), axis=1)
    label, _ = grow_regions(K, 1.0 - r, threshold=0.1)
    return rng, K, r, label


# ---------------------------------------------------------------- simple-tet removal
@pytest.mark.parametrize("seed", range(4))
def test_carve_random_removals_keep_one_sphere(seed):
    rng, K, r, label = _ball_region(seed)
    assert is_sphere(K.V, region_boundary(K, label))
    removable = rng.random(K.n_tets) < 0.7
    lab2, n = carve_regions(K, label, removable, rng.random(K.n_tets))
    # a large share goes, and only removable tets of the region go; the rest is still one sphere
    assert n > 0.15 * (label >= 0).sum()
    gone = (label >= 0) & (lab2 < 0)
    assert gone.sum() == n and removable[gone].all() and not ((label < 0) & (lab2 >= 0)).any()
    assert is_sphere(K.V, region_boundary(K, lab2))
    assert (label >= 0).sum() > 0 and np.array_equal(label >= 0, (lab2 >= 0) | gone)   # input untouched


def test_carve_one_tet_at_a_time_never_breaks_the_sphere():
    # removing single tets in random order: every accepted removal leaves a sphere (the test of removal is
    # not the test of addition mirrored — a tet with one boundary face whose apex is on the boundary pinches)
    rng, K, r, label = _ball_region(7, n=300)
    accepted = 0
    for _ in range(600):
        t = rng.choice(np.flatnonzero(label >= 0))
        m = np.zeros(K.n_tets, dtype=bool)
        m[t] = True
        label2, n = carve_regions(K, label, m, np.ones(K.n_tets))
        if n:
            accepted += 1
            assert is_sphere(K.V, region_boundary(K, label2))
        label = label2
    assert accepted > 50


def test_carve_peels_to_the_removable_set_and_keeps_marked_vertices():
    rng, K, r, label = _ball_region(3, n=1500)
    assert r[label >= 0].max() > 0.8
    lab2, n = carve_regions(K, label, r > 0.5, r)            # peel everything beyond radius 0.5, outermost first
    assert is_sphere(K.V, region_boundary(K, lab2))
    assert np.mean(r[lab2 >= 0] > 0.5) < 0.05                 # the peel reaches (almost) the removable set's end
    # vertices marked to keep stay in the region
    keep = np.zeros(K.n_vertices, dtype=bool)
    used = np.unique(K.T[label >= 0])
    keep[used[np.linalg.norm(K.V[used], axis=1) > 0.8][:5]] = True
    lab3, _ = carve_regions(K, label, r > 0.5, r, keep_vertex=keep)
    assert is_sphere(K.V, region_boundary(K, lab3))
    assert np.isin(np.flatnonzero(keep), K.T[lab3 >= 0]).all()


def test_carve_and_resume_validate():
    _, K, r, label = _ball_region(0, n=80)
    with pytest.raises(ValueError, match="label"):
        carve_regions(K, label[:-1], r > 0.5, r)
    with pytest.raises(ValueError, match="removable"):
        carve_regions(K, label, (r > 0.5)[:3], r)
    with pytest.raises(ValueError, match="priority"):
        carve_regions(K, label, r > 0.5, np.full(K.n_tets, np.nan))
    with pytest.raises(ValueError, match="keep_vertex"):
        carve_regions(K, label, r > 0.5, r, keep_vertex=np.zeros(2, dtype=bool))
    with pytest.raises(ValueError, match="label"):
        grow_regions(K, 1 - r, label=label[:-1])
    with pytest.raises(ValueError, match="eligible"):
        grow_regions(K, 1 - r, eligible=np.ones(3, dtype=bool))
    with pytest.raises(ValueError, match="allowed"):
        grow_regions(K, 1 - r, allowed=np.zeros(3, dtype=np.int64))
    with pytest.raises(ValueError, match="allowed"):
        grow_regions(K, 1 - r, allowed=np.full(K.n_tets, -2))


def test_grow_resumes_from_a_region():
    rng = np.random.default_rng(4)
    P = rng.uniform(-1, 1, (800, 3))
    K = TetComplex(P, Delaunay(P).simplices)
    r = np.linalg.norm(K.V[K.T].mean(axis=1), axis=1)
    small, _ = grow_regions(K, 1.0 - r, threshold=0.6)          # radius ≲ 0.4
    big, _ = grow_regions(K, 1.0 - r, label=small, eligible=r < 0.8, priority=-r)
    assert is_sphere(K.V, region_boundary(K, big))
    assert ((big >= 0) | (small < 0)).all()                    # the resumed region contains the first
    assert (big >= 0).sum() > 2 * (small >= 0).sum()
    assert (r[(big >= 0) & (small < 0)] < 0.8).all()           # only eligible tets joined


# ---------------------------------------------------------------- sculpting
def _sphere_complex():
    X = _sphere(2500, seed=1)
    spacing = float(np.sqrt(4 * np.pi / len(X)))
    S = octree_steiner_points(X, spacing)
    cage = np.array([[x, y, z] for x in (-1.5, 1.5) for y in (-1.5, 1.5) for z in (-1.5, 1.5)])
    V = np.concatenate([X, S, cage])
    K = TetComplex(V, Delaunay(V).simplices)
    c = K.V[K.T].mean(axis=1)
    return X, spacing, K, c, np.linalg.norm(c, axis=1)


def _boundary_radius_error(K, label):
    return np.abs(np.linalg.norm(K.V[np.unique(region_boundary(K, label))], axis=1) - 1).max()


def test_winding_evidence_fills_a_hole_of_the_jump_field():
    X, spacing, K, c, rc = _sphere_complex()
    # a wrong jump field: inside the sphere except a hole around (0.4, 0, 0)
    hole = np.linalg.norm(c - [0.4, 0, 0], axis=1) < 0.35
    w = np.where((rc < 1.0) & ~hole, 1.0, 0.0)
    wn, d = _winding_evidence(K, X, X)                       # the true outward normals of the unit sphere
    assert np.mean(wn[rc < 0.9] > 0.9) > 0.99 and np.mean(wn[rc > 1.1] < 0.1) > 0.99
    w2 = _with_winding(w, wn)
    for field, filled in ((w, False), (w2, True)):
        label, _ = grow_regions(K, field, 0.5, priority=field - 0.05 * rc)
        assert is_sphere(K.V, region_boundary(K, label))
        if filled:
            assert (label[hole] >= 0).mean() > 0.95
        else:
            assert (label[hole] >= 0).mean() < 0.1


def test_sculpt_peels_a_bulge_far_from_the_samples():
    X, spacing, K, c, rc = _sphere_complex()
    lobe = (rc < 1.6) & (c[:, 2] > 0.9 * rc)                   # a wrong lobe (a cone cap) outside the sphere
    w = np.where((rc < 1.0) | lobe, 1.0, 0.0)
    label, _ = grow_regions(K, w, 0.5, priority=w - 0.05 * rc)
    assert is_sphere(K.V, region_boundary(K, label)) and (label[lobe] >= 0).mean() > 0.5
    assert _boundary_radius_error(K, label) > 0.5
    wn, d = _winding_evidence(K, X, X)
    allowed = np.zeros(K.n_tets, dtype=np.int64)
    samples = np.ones(len(X), dtype=bool)
    lab2, added, removed = _sculpt(K, label, allowed, wn, d, len(X), samples, spacing)
    assert is_sphere(K.V, region_boundary(K, lab2))
    assert removed > 0
    far_lobe = lobe & (rc > 1.2)
    assert far_lobe.sum() > 10 and (label[far_lobe] >= 0).mean() > 0.3
    assert (lab2[far_lobe] >= 0).mean() < 0.05                   # the lobe is peeled back to the samples
    assert _boundary_radius_error(K, lab2) < 0.3
    assert np.isin(np.arange(len(X))[np.isin(np.arange(len(X)), K.T[label >= 0])], K.T[lab2 >= 0]).all()


# ---------------------------------------------------------------- thin parts survive the pre-filter
def test_prefilter_rescues_thin_tube_samples_but_not_outliers():
    rng = np.random.default_rng(1)
    S = _sphere(3000)
    sp = np.sqrt(4 * np.pi / 3000)
    r = 0.6 * sp                                               # a tube thinner than the sample spacing
    nt = int(2 * np.pi * r / sp ** 2)
    t, a = rng.uniform(1, 2, nt), rng.uniform(0, 2 * np.pi, nt)
    T = np.column_stack([t, r * np.cos(a), r * np.sin(a)])
    O = rng.uniform(-2, 2.5, (300, 3))
    O = O[np.abs(np.linalg.norm(O, axis=1) - 1) > 0.3]
    P = np.concatenate([S, T, O])
    X = (P - 0.5 * (P.min(0) + P.max(0))) / np.linalg.norm(P.max(0) - P.min(0))
    tube = slice(3000, 3000 + nt)
    without = prefilter(X, rescue=False)
    with_ = prefilter(X)
    assert without[tube].mean() < 0.3 < 0.45 < with_[tube].mean()
    assert with_[:3000].mean() > 0.99 and with_[3000 + nt:].mean() < 0.05
