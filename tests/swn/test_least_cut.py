"""The least cut of the face labels (gsdf.swn._gaps.least_cut_labels): every face rounded up or down so that the
label boundary off the curves is short and near w's level — the exact minimum (one s–t cut), and its effect on
broken region boundaries."""

from __future__ import annotations

import itertools

import numpy as np

from gsdf.data._shapes import grid_mesh
from gsdf.swn._gaps import least_cut_labels
from gsdf.swn._solver import SurfaceWindingNumbers
from tests.swn.test_grown_regions import blob, grown_regions_case, mislabelled


def cut_cost(dec, L, wl, b, eps):
    t = dec.topology
    inter = np.flatnonzero(t.edge_face_count == 2)
    A, B = t.edge_faces[inter, 0], t.edge_faces[inter, 1]
    wm = 0.5 * (wl[A] + wl[B])
    h = 0.5 - np.abs(wm - np.round(wm))
    ell = dec.edge_len[inter]
    w = np.where(b[inter] != 0, ell * np.abs(b[inter]), ell * (h + eps))
    return np.abs(L[..., A] - L[..., B] - b[inter]) @ w          # L (m,) or (k, m): one cost per labelling


def test_least_cut_is_the_minimum_over_all_up_down_choices():
    V, F = grid_mesh(3)                                     # 18 faces: 2^18 choices
    swn = SurfaceWindingNumbers(V, F)
    dec = swn.dec
    rng = np.random.default_rng(0)
    for trial in range(3):
        wl = rng.uniform(-1.2, 2.2, dec.n_faces)
        b = np.zeros(dec.n_edges)
        b[rng.choice(dec.n_edges, 6, replace=False)] = rng.choice([-1.0, 1.0, 2.0], 6)
        L = least_cut_labels(dec, wl, b)
        base = np.floor(wl).astype(np.int64)
        assert np.all((L == base) | (L == base + 1))
        X = np.array(list(itertools.product([0, 1], repeat=dec.n_faces)), np.int64)
        best = cut_cost(dec, base + X, wl, b, 0.1).min()
        assert cut_cost(dec, L, wl, b, 0.1) <= best * (1 + 1e-6) + 1e-12


def test_closed_curves_keep_the_rounded_labels():
    V, F = blob(3)
    swn = SurfaceWindingNumbers(V, F)
    segs, truth, A = grown_regions_case(V, F, 0, deleted=0.0)
    res = swn.solve(segs)
    assert np.all(res.label_shift == 0)                     # no endpoints: no gap shift, no cut
    assert mislabelled(res.face_labels, truth, A) == 0


def test_cut_lowers_the_error_of_broken_region_boundaries():
    """Grown regions with 40 % of their boundaries deleted: the labels after the cut against the rounded labels
    (the global level with the gap shifts) it starts from; faces it moves keep round(mean of corners) = label."""
    V, F = blob(4)
    swn = SurfaceWindingNumbers(V, F)
    before, after = [], []
    for s in range(3):
        segs, truth, A = grown_regions_case(V, F, s)
        res = swn.solve(segs)
        assert np.array_equal(np.round(res.corner_values.mean(1)).astype(np.int64), res.face_labels)
        w = res.corner_values + res.offset + res.label_shift[:, None]
        wf = w.mean(1)
        bends = res.endpoints | swn.dec.chain_endpoints(np.round(res.bounding), tol=0.5)
        W0 = np.round(wf - res.offset - swn.gap_shift(wf, res.bounding, bends, res.offset))
        before.append(mislabelled(W0, truth, A))
        after.append(mislabelled(res.face_labels, truth, A))
    assert np.mean(after) < np.mean(before)
