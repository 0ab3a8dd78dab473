"""The wide walk of the fast winding numbers (gsdf.spatial._wide, gsdf.winding._fast) and query grouping
(gsdf.spatial._morton.cell_order): structure checks and values against exact winding numbers."""

import numpy as np
import pytest

import gsdf
from gsdf.spatial._bvh import build_point_bvh
from gsdf.spatial._morton import cell_order, gather_rows
from gsdf.spatial._wide import widen
from gsdf.winding import _fast as fast


def _sphere(n=2000, seed=0):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(n, 3))
    return P / np.linalg.norm(P, axis=1, keepdims=True)


@pytest.mark.parametrize("width", [2, 4, 8])
def test_widen_covers_every_leaf_once(width):
    t = build_point_bvh(np.random.default_rng(1).random((500, 3)), leaf_size=3)
    w = widen(t, width)
    kids = w.kids[w.kids >= 0]
    leaves = np.flatnonzero(t.right < 0)
    # every binary leaf is the child of exactly one wide node, and internal kids are wide nodes themselves
    assert np.array_equal(np.sort(kids[t.right[kids] < 0]), leaves)
    internal = w.child[w.child >= 0]
    assert np.array_equal(np.sort(internal), np.arange(1, w.n_nodes))
    assert (w.child[(w.kids >= 0) & (t.right[np.maximum(w.kids, 0)] < 0)] == -1).all()
    assert (w.child[w.kids < 0] == -2).all()
    # kids of one node partition its elements
    for n in range(w.n_nodes):
        k = w.kids[n][w.kids[n] >= 0]
        assert (t.end[k] - t.start[k]).sum() == (t.end[k].max() - t.start[k].min())
    with pytest.raises(ValueError, match="width"):
        widen(t, 1)


def test_cell_order_is_a_permutation_grouping_nearby_points():
    Q = np.random.default_rng(2).random((20000, 3))
    o = cell_order(Q)
    assert np.array_equal(np.sort(o), np.arange(len(Q)))
    step = np.linalg.norm(np.diff(Q[o], axis=0), axis=1).mean()
    assert step < 0.25 * np.linalg.norm(np.diff(Q, axis=0), axis=1).mean()
    np.testing.assert_array_equal(gather_rows(Q, o), Q[o])
    assert cell_order(Q[:1]).tolist() == [0]


def test_compact_fold_matches_reference():
    D = np.random.default_rng(3).normal(size=(40, fast.NODE_WIDTH))
    np.testing.assert_allclose(fast._compact_moments(D), fast._fold_moments(D), rtol=0, atol=1e-13)


@pytest.mark.parametrize("order", [0, 1, 2])
def test_wide_walk_against_exact(order):
    P = _sphere(3000)
    import scipy.spatial

    hull = scipy.spatial.ConvexHull(P)
    V, F = P, hull.simplices
    # orient outward
    c = V[F].mean(axis=1)
    nrm = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    F = np.where((np.einsum("ij,ij->i", nrm, c) < 0)[:, None], F[:, ::-1], F)
    rng = np.random.default_rng(4)
    Q = rng.uniform(-1.5, 1.5, (30000, 3))  # > SERIAL_QUERIES: the parallel walk, grouped by cells
    exact = gsdf.ExactWindingNumber(V, F)(Q)
    w = gsdf.FastWindingNumber(V, F, order=order)(Q)
    rms = np.sqrt(np.mean((w - exact) ** 2))
    assert rms < [1.5e-2, 1.5e-2, 1e-3][order]  # measured 6.2e-3, 7.2e-3, 3.9e-4 (the binary walk: 7.6e-3, 9.0e-3, 5.5e-4)
    if order == 2:  # serial (small) and parallel (large) query sets agree
        np.testing.assert_allclose(gsdf.FastWindingNumber(V, F)(Q[:100]), w[:100], atol=1e-12)
        # higher order is more accurate than lower on the same tree
        w0 = gsdf.FastWindingNumber(V, F, order=0)(Q)
        assert rms < np.sqrt(np.mean((w0 - exact) ** 2))


def test_wide_walk_single_triangle_and_far_closed_mesh():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    f = gsdf.FastWindingNumber(V, F[:1])  # a tree that is one leaf
    q = np.array([[0.2, 0.2, 0.5], [0.2, 0.2, -0.5], [10, 10, 10]])
    np.testing.assert_allclose(f(q), gsdf.winding_number(V, F[:1], q), atol=1e-3)
    # far from a closed mesh the root's own expansion (c0 = 0) is used: exactly zero up to round-off
    assert abs(gsdf.FastWindingNumber(V, F)([[50.0, 50.0, 50.0]])[0]) < 1e-12
