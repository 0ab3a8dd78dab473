"""The selection kernels of the k-nearest-neighbour search and of point_areas' plane fit, and the hull pre-test
of the Voronoi cells: each against a brute-force reference (numpy sort / lexsort, scipy's convex hull)."""

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from gsdf.spatial._knn import NBUCKET, SelfKNN, _kth_smallest
from gsdf.winding._point_areas import _NBUCKET, _cell_inside_hull, _smallest_sorted


def brute_knn(P, k):
    """The k nearest of every point by (squared distance, index), the distance summed as the kernel does."""
    out = np.empty((len(P), k), np.int64)
    for i in range(len(P)):
        u, v, w = P[:, 0] - P[i, 0], P[:, 1] - P[i, 1], P[:, 2] - P[i, 2]
        d = u * u + v * v + w * w
        out[i] = np.lexsort((np.arange(len(P)), d))[:k]
    return out


def clouds():
    rng = np.random.default_rng(11)
    sheet = np.column_stack([rng.random((900, 2)), 0.01 * rng.random(900)])
    dense = 0.05 * rng.normal(size=(300, 3))                          # a dense knot: many rows fall back
    yield "sheet+knot", np.vstack([sheet, dense + 0.5])
    g = np.arange(6) * 0.25
    lattice = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    yield "lattice", lattice                                          # ties at every distance
    base = rng.random((200, 3))
    yield "duplicates", np.vstack([base, base, base[:50]])            # exact duplicates: ties at distance 0
    r = rng.random(800) ** 3                                          # density falling off with the radius
    th, ph = rng.random(800) * 2 * np.pi, np.arccos(2 * rng.random(800) - 1)
    yield "graded", np.column_stack([r * np.cos(th) * np.sin(ph), r * np.sin(th) * np.sin(ph), r * np.cos(ph)])
    yield "line", np.column_stack([np.sort(rng.random(400)), np.zeros(400), np.zeros(400)])


@pytest.mark.parametrize("name,P", list(clouds()))
def test_self_knn_rows_equal_brute_force(name, P):
    """Every row (all rows at once, a row range, ordered rows) is the brute-force set: the k smallest (d², index)."""
    for k in (1, 5, 21, 41, 161):
        if k > len(P):
            continue
        ref = brute_knn(P, k)
        got = SelfKNN(P, k).rows()
        assert np.array_equal(np.sort(got, axis=1), np.sort(ref, axis=1)), (name, k)
        assert np.array_equal(SelfKNN(P, k, ordered=True).rows(), ref), (name, k)
        assert np.array_equal(np.sort(SelfKNN(P, k).rows(7, 60), axis=1), np.sort(ref[7:60], axis=1)), (name, k)


def test_kth_smallest_equals_sort():
    rng = np.random.default_rng(3)
    tmp = np.empty(400)
    hist = np.empty(NBUCKET + 1, np.int64)
    cases = [rng.random(50), rng.random(257) ** 4, np.round(rng.random(120), 1), np.zeros(30),
             np.r_[np.zeros(10), np.ones(10)], np.full(9, 5e-320), rng.random(60) * 1e-300]
    for a in cases:
        a = np.ascontiguousarray(a)
        ref = np.sort(a)
        m = len(a)
        for top in (np.inf, 0.0, float(a.max()), 0.5 * float(a.max()) if a.max() > 0 else 1.0, 4.0 * float(a.max()) + 1):
            for r in sorted({0, 1, m // 3, m // 2, m - 2, m - 1}):
                if 0 <= r < m:
                    before = a.copy()
                    assert _kth_smallest(a, m, r, top, tmp, hist) == ref[r]
                    assert np.array_equal(a, before)   # the input is left as it was


def test_smallest_sorted_equals_lexsort():
    rng = np.random.default_rng(4)
    d2, j2 = np.empty(200), np.empty(200, np.int64)
    bucket, count = np.empty(200, np.int64), np.empty(_NBUCKET + 2, np.int64)
    cases = [rng.random(40), np.round(rng.random(40), 1), np.zeros(25), rng.random(7),
             np.r_[-1e-17, -0.0, rng.random(30)], rng.random(150) ** 6, np.full(12, 1e-310)]
    for d in cases:
        c = len(d)
        j = rng.permutation(10 * c)[:c].astype(np.int64)
        order = np.lexsort((j, d))
        for kk in sorted({0, 1, c // 2, min(20, c), c}):
            n = _smallest_sorted(d.copy(), j.copy(), c, kk, d2, j2, bucket, count)
            assert n == kk
            assert np.array_equal(j2[:kk], j[order[:kk]]) and np.array_equal(d2[:kk], d[order[:kk]])


def voronoi_cell(Q):
    """The Voronoi cell of the origin among the sites Q (half-plane clipping of a big square), CCW vertices."""
    R = 10.0
    poly = np.array([[-R, -R], [R, -R], [R, R], [-R, R]], float)
    for q in Q:
        b = 0.5 * q @ q
        val = poly @ q - b
        out = []
        for s in range(len(poly)):
            p, e = poly[s], poly[(s + 1) % len(poly)]
            dp, dq = val[s], val[(s + 1) % len(poly)]
            if dp <= 0:
                out.append(p)
            if (dp <= 0) != (dq <= 0):
                out.append(p + dp / (dp - dq) * (e - p))
        poly = np.array(out)
    return np.ascontiguousarray(poly)


def test_cell_inside_hull_is_sufficient():
    """When the pre-test says the cell is inside the sites' hull, it is (every vertex strictly inside scipy's hull
    of the sites and the origin); interior cells of a lattice pass, border and corner cells fail."""
    rng = np.random.default_rng(8)
    F, G = np.empty((8, 3)), np.empty((8, 3))
    passed = 0
    for trial in range(400):
        m = int(rng.integers(3, 25))
        if trial % 2:
            Q = rng.normal(size=(m, 2))
        else:   # a neighbourhood with a gap on one side (border-like) or stretched (scan-like)
            Q = rng.normal(size=(m, 2)) * [1.0, 0.2 + rng.random()]
            Q = Q[Q[:, 0] > -0.3 * rng.random()] if trial % 4 == 0 else Q
        Q = np.ascontiguousarray(Q)
        if len(Q) < 3:
            continue
        A = voronoi_cell(Q)
        inside = _cell_inside_hull(Q.copy(), len(Q), A, len(A), F, G)
        if inside:
            passed += 1
            hull = ConvexHull(np.vstack([Q, [0.0, 0.0]]))
            assert (A @ hull.equations[:, :2].T + hull.equations[:, 2] < 0).all()
    assert passed > 50
    g = (np.arange(7) - 3) * 0.1
    X, Y = np.meshgrid(g, g, indexing="ij")
    L = np.column_stack([X.ravel(), Y.ravel()])
    L = np.ascontiguousarray(L[np.abs(L).sum(axis=1) > 0])        # the sites around the lattice's centre
    A = voronoi_cell(L)
    assert _cell_inside_hull(L, len(L), A, len(A), F, G)
    half = np.ascontiguousarray(L[L[:, 0] >= 0])                   # a border point: its cell leaves the hull
    Ah = voronoi_cell(half)
    assert not _cell_inside_hull(half, len(half), Ah, len(Ah), F, G)
    assert not _cell_inside_hull(L[:2].copy(), 2, A, len(A), F, G)  # too few sites to enclose anything


def test_rows_on_threads_equal_one_call(monkeypatch):
    """From PARALLEL_POINTS points the cells are split into ranges run on two threads: the same rows as one call
    on one thread, the ranges covering every cell once; point areas likewise equal their one-thread values."""
    import numba

    from gsdf.spatial import _knn as knn
    from gsdf.winding import _point_areas as pa

    rng = np.random.default_rng(3)
    P = np.vstack([np.column_stack([rng.random((3000, 2)), 0.01 * rng.random(3000)]),
                   0.05 * rng.normal(size=(600, 3)) + 0.5])
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    grid = SelfKNN(P, 41)
    old = numba.get_num_threads()
    try:
        numba.set_num_threads(2)
        ranges = knn._cell_ranges(grid._grid[2], len(P))
        assert len(ranges) > 2 and ranges[0][0] == 0 and ranges[-1][1] == len(grid._grid[2]) - 1
        assert all(a[1] == b[0] for a, b in zip(ranges[:-1], ranges[1:]))
        threaded, a2 = grid.rows(), pa.point_areas(P, N, candidates=2)
        numba.set_num_threads(1)
        assert knn._cell_ranges(grid._grid[2], len(P)) == [(0, len(grid._grid[2]) - 1)]
        single, a1 = grid.rows(), pa.point_areas(P, N, candidates=2)
    finally:
        numba.set_num_threads(old)
    assert np.array_equal(threaded, single)
    assert np.array_equal(np.sort(single, axis=1), np.sort(brute_knn(P, 41), axis=1))
    assert np.array_equal(a1, a2)
    monkeypatch.setattr(knn, "PARALLEL_POINTS", 10 ** 9)
    assert knn._cell_ranges(grid._grid[2], len(P)) == [(0, len(grid._grid[2]) - 1)]
