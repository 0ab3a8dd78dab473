"""Gap labels of surface winding numbers (SurfaceWindingNumbers.gap_shift, used with an LP): the faces at each gap of
a broken curve rounded at the level of w across that gap, against one global rounding level."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from gsdf.data._shapes import grid_mesh
from gsdf.swn._gaps import _gap_paths
from gsdf.swn._solver import SurfaceWindingNumbers
from tests.shapes import uv_sphere
from tests.shapes import annulus

N = 24                                       # grid_mesh(24): 25 x 25 vertices, vertex (i, j) = 25 i + j


def vid(i, j):
    return (N + 1) * i + j


@pytest.fixture(scope="module")
def grid():
    V, F = grid_mesh(N)
    return SurfaceWindingNumbers(V, F)


def square(a, b):
    """Counter-clockwise square loop on the grid, corners (a, a) and (b, b), as a vertex list (closed)."""
    return ([vid(i, a) for i in range(a, b)] + [vid(b, j) for j in range(a, b)]
            + [vid(i, b) for i in range(b, a, -1)] + [vid(a, j) for j in range(b, a - 1, -1)])


def gap_faces(swn, full, broken):
    """The faces of the edges deleted from ``full`` in ``broken``."""
    gf, gb = swn.chain(full), swn.chain(broken)
    gone = np.flatnonzero((gf != 0) & (gb == 0))
    f = swn.topology.edge_faces[gone].ravel()
    return f[f >= 0]


def wrong(labels, ref, faces=None):
    """Faces whose label differs from ``ref`` after the best integer shift (on ``faces``, or all)."""
    k = np.bincount(ref - labels + 50).argmax() - 50
    bad = (labels + k) != ref
    return int(bad.sum() if faces is None else bad[faces].sum())


def global_labels(res):
    """The labels of one global rounding level from the same solve (SWNResult.label_shift), up to a shift."""
    return np.round(res.corner_values.mean(1) + res.label_shift).astype(np.int64)


def test_straight_gap_closes_along_the_deleted_edges(grid):
    # an 8 x 8 square with 3 edges deleted on a straight side: the gap is closed along the deleted edges
    # (the |Δw| path between its ends is the deleted edges, and the faces beside it are rounded at the level of
    # w across them); one global level, the level of w on the curves, misses a face there (the corners of the
    # square pull the curves' level away from the gap's)
    sq = square(4, 12)
    broken = [sq[:3], sq[5:]]
    ref = grid.solve([sq]).face_labels
    fs = gap_faces(grid, [sq], broken)
    new = grid.solve(broken)
    assert wrong(new.face_labels, ref) == 0
    assert wrong(global_labels(new), ref, fs) >= 1
    assert np.abs(new.label_shift).max() > 0
    assert np.array_equal(np.round(new.corner_values.mean(1)).astype(np.int64), new.face_labels)


def test_latitude_circle_with_gaps_on_a_sphere():
    V, F = uv_sphere(24, 48)
    swn = SurfaceWindingNumbers(V, F)
    ring = list(1 + 14 * 48 + np.arange(48)) + [1 + 14 * 48]
    pieces = [ring[0:9], ring[11:20], ring[23:33], ring[36:45]]      # four gaps of 2-3 edges
    ref = swn.solve([ring]).face_labels
    res = swn.solve(pieces)
    assert res.endpoints.sum() == 8
    assert wrong(res.face_labels, ref, gap_faces(swn, [ring], pieces)) == 0   # every gap closed along the gap
    assert wrong(res.face_labels, ref) == 0


def test_labels_unchanged_without_gaps(grid):
    # closed curves: no endpoints, no gap, shift 0 everywhere, the same labels as one global level
    sq = square(4, 12)
    a = grid.solve([sq])
    assert np.all(a.label_shift == 0)
    assert np.array_equal(a.face_labels, grid.solve([sq], method="none").face_labels)


def test_faces_away_from_the_gaps_keep_the_global_labels(grid):
    sq, sq2 = square(3, 10), square(14, 21)
    broken = [sq[:3], sq[5:], sq2]              # a gap in one square, the other closed
    new = grid.solve(broken)
    far = new.label_shift == 0
    assert far.sum() > 0.9 * len(far)
    assert wrong(new.face_labels[far], global_labels(new)[far]) == 0
    # the relabelled faces sit round the gap: every one touches a vertex within 2 edges of the deleted ones
    touched = np.unique(grid.dec.F[~far])
    gapv = np.array(sq[2:6])
    P = np.array([[i, j] for i in range(N + 1) for j in range(N + 1)])
    d = np.abs(P[touched][:, None, :] - P[gapv][None, :, :]).max(-1).min(1)
    assert d.max() <= 2


def test_annulus_broken_circle_not_simply_connected():
    # with boundary and b1 = 1 (the LP path, endpoint rule "exclude"): a broken circle round the hole bounds
    # together with the inner boundary; its gaps are closed along the deleted edges
    V, F, idx = annulus(8, 48)
    swn = SurfaceWindingNumbers(V, F)
    assert not swn.simply_connected
    ring = list(idx[3]) + [idx[3, 0]]
    pieces = [ring[0:14], ring[16:30], ring[33:49]]
    ref = swn.solve([ring]).face_labels
    res = swn.solve(pieces)
    assert wrong(res.face_labels, ref, gap_faces(swn, [ring], pieces)) == 0
    assert wrong(res.face_labels, ref) == 0


def test_gap_paths_kernel_matches_scipy_dijkstra():
    rng = np.random.default_rng(3)
    n = 60
    i = rng.integers(0, n, 400)
    j = rng.integers(0, n, 400)
    keep = i != j
    i, j = i[keep], j[keep]
    key = np.unique(np.minimum(i, j) * n + np.maximum(i, j))
    a, b = key // n, key % n
    w = rng.uniform(0.1, 1.0, len(a))
    r = np.concatenate([a, b])
    c = np.concatenate([b, a])
    e = np.concatenate([np.arange(len(a))] * 2)
    o = np.lexsort((c, r))
    r, c, e = r[o], c[o], e[o]
    indptr = np.searchsorted(r, np.arange(n + 1)).astype(np.int64)
    src = rng.integers(0, n, 20).astype(np.int64)
    dst = rng.integers(0, n, 20).astype(np.int64)
    keep = src != dst
    src, dst = src[keep], dst[keep]
    pe, ptr, start = _gap_paths(indptr, c.astype(np.int64), e.astype(np.int64), w[e], src, dst, n)
    D = dijkstra(sp.coo_matrix((w, (a, b)), shape=(n, n)).tocsr(), directed=False, indices=src)
    for k in range(len(src)):
        path = pe[ptr[k]:ptr[k + 1]]
        dk = D[k, dst[k]]
        if not np.isfinite(dk):
            assert len(path) == 0
            continue
        assert np.isclose(w[path].sum(), dk)
        # a walk: each step starts where the previous one ended, from src to dst
        v = src[k]
        for s_, ed in zip(start[ptr[k]:ptr[k + 1]], path):
            assert s_ == v
            v = b[ed] if a[ed] == v else a[ed]
        assert v == dst[k]


def test_bad_input(grid):
    m, nE, n = grid.dec.n_faces, grid.dec.n_edges, grid.dec.n_vertices
    wf, g, ends = np.zeros(m), np.zeros(nE), np.zeros(n, bool)
    assert np.all(grid.gap_shift(wf, g, ends, 0.0) == 0)
    with pytest.raises(ValueError, match="wf"):
        grid.gap_shift(np.zeros(m + 1), g, ends, 0.0)
    with pytest.raises(ValueError, match="wf"):
        grid.gap_shift(np.full(m, np.nan), g, ends, 0.0)
    with pytest.raises(ValueError, match="bounding"):
        grid.gap_shift(wf, np.zeros(nE - 1), ends, 0.0)
    with pytest.raises(ValueError, match="ends"):
        grid.gap_shift(wf, g, np.zeros(n), 0.0)
    with pytest.raises(ValueError, match="s:"):
        grid.gap_shift(wf, g, ends, np.nan)
    with pytest.raises(ValueError, match="eps"):
        grid.gap_shift(wf, g, ends, 0.0, eps=0)


def test_long_gap_keeps_the_global_level():
    # a gap closed by a path longer than max_edges keeps the global level: a circle with a quarter of it missing
    # is closed along the circle by the global level (inscribed-angle theorem, test_swn.py
    # test_flat_circle_one_big_gap_offset_is_the_curve_level); the closing path is the chord
    V, F = grid_mesh(60)
    swn = SurfaceWindingNumbers(V, F)
    C = V[F].mean(1)
    disk = np.flatnonzero(np.linalg.norm(C[:, :2], axis=1) < 0.3)
    ind = np.zeros(len(F))
    ind[disk] = 1.0
    g = np.rint(swn.dec.d1.T @ ind)
    M = V[swn.dec.edges].mean(1)
    g[np.mod(np.arctan2(M[:, 1], M[:, 0]), 2 * np.pi) < 2 * np.pi * 0.25] = 0
    r = swn.solve(g)
    assert r.endpoints.sum() == 2
    assert np.all(r.label_shift == 0)
    wf = r.corner_values.mean(1) + r.offset
    s = swn.rounding_offset(wf, r.chain, np.zeros(swn.dec.n_edges))
    assert np.abs(swn.gap_shift(wf, r.bounding, r.endpoints, s, max_edges=100)).max() > 0.05
    with pytest.raises(ValueError, match="max_edges"):
        swn.gap_shift(wf, r.bounding, r.endpoints, s, max_edges=0)
