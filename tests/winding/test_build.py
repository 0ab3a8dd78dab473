"""The fast winding tree build (gsdf.spatial._binned, the bottom-up moments of gsdf.winding._fast): tree
structure, moments against direct sums, thread-count independence, and winding numbers against brute force."""

import numba
import numpy as np
import pytest

import gsdf
from gsdf.spatial import _binned as binned
from gsdf.spatial._bvh import build_bvh, build_volume_bvh
from gsdf.spatial._wide import widen
from gsdf.winding import _fast as fast


def _soup(m=3000, seed=0):
    """Random triangles in the unit cube, some tiny, some duplicated and some zero-area: a broken soup."""
    rng = np.random.default_rng(seed)
    c = rng.random((m, 3))
    size = np.where(rng.random(m) < 0.2, 1e-3, 0.08)[:, None, None]
    T = c[:, None, :] + size * rng.normal(size=(m, 3, 3))
    T[:50] = T[50:100]                    # duplicated faces
    T[100:110, 2] = T[100:110, 1]         # zero-area faces
    V = T.reshape(-1, 3)
    return V, np.arange(len(V)).reshape(-1, 3)


def _check_tree(t, lo, hi, leaf_size):
    n = t.n_elements
    assert np.array_equal(np.sort(t.order), np.arange(n))
    leaf = t.right < 0
    assert ((t.end - t.start) <= leaf_size)[leaf].all()
    # preorder: left child i + 1, children split the parent's range, skip = end of the subtree
    inner = np.flatnonzero(~leaf)
    assert np.array_equal(t.start[inner + 1], t.start[inner])
    assert np.array_equal(t.end[inner + 1], t.start[t.right[inner]])
    assert np.array_equal(t.end[t.right[inner]], t.end[inner])
    assert t.skip[0] == t.n_nodes
    # every node's box is exactly its elements' box
    for i in range(0, t.n_nodes, max(1, t.n_nodes // 300)):
        o = t.order[t.start[i]:t.end[i]]
        assert np.array_equal(lo[o].min(axis=0), t.lo[i]) and np.array_equal(hi[o].max(axis=0), t.hi[i])


def test_volume_build_structure_and_rows_in_tree_order():
    V, F = _soup()
    E = fast._triangle_elements(V, F)
    E0 = E.copy()
    t = build_volume_bvh(E, 4)
    _check_tree(t, E0[:, 3:6], E0[:, 6:9], 4)
    np.testing.assert_array_equal(E, E0[t.order])           # rows reordered in place into tree order
    t2 = build_bvh(E0[:, :3], E0[:, 3:6], E0[:, 6:9], 4, split="volume")
    assert np.array_equal(t2.order, t.order) and np.array_equal(t2.right, t.right)


def test_element_rows_come_with_the_root_bounds():
    for m in (500, fast.PARALLEL_BUILD_FACES + 5000):       # one pass, and ranges on the threads
        V, F = _soup(m=m, seed=3)
        E, root = fast._triangle_elements_root(V, F)
        np.testing.assert_array_equal(root, binned._root_bounds(E))
        t = build_volume_bvh(E.copy(), 4, root)
        assert np.array_equal(t.order, build_volume_bvh(E.copy(), 4).order)


def test_volume_build_coincident_centroids_and_tiny_inputs():
    P = np.zeros((200, 3))                                     # every centroid in one point
    t = build_bvh(P, P - 1, P + 1, 4, split="volume")
    _check_tree(t, P - 1, P + 1, 4)
    assert t.n_nodes < 2 * 200 and (t.skip - np.arange(t.n_nodes)).max() == t.n_nodes
    one = build_bvh(P[:1], P[:1], P[:1], 4, split="volume")
    assert one.n_nodes == 1 and one.right[0] == -1


def test_volume_build_is_the_same_tree_on_one_or_more_threads():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one numba thread")
    V, F = _soup(m=binned.PARALLEL_ELEMENTS + 5000, seed=1)  # above the size where subtrees grow in parallel
    E = fast._triangle_elements(V, F)
    trees = [binned.build_volume_rows(E.copy(), 4, threads) for threads in (1, 2)]
    for a, b in zip(*trees):
        np.testing.assert_array_equal(a, b)


def _sweep_reference(E, n):
    """The exhaustive sweep of binned._split_sweep in numpy: stable sorts along the two longest axes of the
    centroid box (all three when the shortest is within binned.TIE of the next), prefix / suffix boxes, n r³ costs, the cheapest
    position (ties: the more balanced one, then the first axis / position)."""
    def cube(lo, hi):
        d2 = 0.25 * ((hi - lo) ** 2).sum(axis=1)
        return d2 * np.sqrt(d2)
    best = (np.inf, 0, n // 2)
    ext = np.ptp(E[:n, 0:3], axis=0)
    lo, mid = np.sort(ext)[:2]
    shortest = -1 if lo >= (1 - binned.TIE) * mid else 2 - int(np.argmin(ext[::-1]))
    for a in [a for a in range(3) if a != shortest]:
        p = np.argsort(E[:n, a], kind="stable")
        lo, hi = E[p, 3:6], E[p, 6:9]
        pre = np.arange(1, n) * cube(np.minimum.accumulate(lo)[:-1], np.maximum.accumulate(hi)[:-1])
        suf = np.arange(n - 1, 0, -1) * cube(np.minimum.accumulate(lo[::-1])[::-1][1:],
                                             np.maximum.accumulate(hi[::-1])[::-1][1:])
        for i in range(1, n):
            c = pre[i - 1] + suf[i - 1]
            if c < best[0] or (c == best[0] and abs(2 * i - n) < abs(2 * best[2] - n)):
                best = (c, a, i)
    return best[1], best[2], np.argsort(E[:n, best[1]], kind="stable")


def test_small_node_sweep_matches_a_reference_sort_and_cost():
    rng = np.random.default_rng(7)
    S = binned.SMALL
    scratch = (np.empty((3, S), np.int64), np.empty(S), np.empty((2, S)), np.empty((S, 9)), np.empty(S, np.int64),
               np.empty(24))
    for trial in range(300):
        n = int(rng.integers(2, S + 1))
        c = rng.random((n, 3))
        if trial % 3 == 0:
            c = np.round(c * 3) / 3            # many equal centroids: the sort must be stable
        if trial % 5 == 0:
            c = np.sort(c, axis=0)             # rows already sorted along every axis
        E = np.hstack([c, c - rng.random((n, 3)) * 0.1, c + rng.random((n, 3)) * 0.1])
        order = np.arange(n)
        E1 = E.copy()
        m = binned._split_sweep(E1, order, 0, n, *scratch)
        axis, pos, p = _sweep_reference(E, n)
        assert m == pos, (trial, axis)
        np.testing.assert_array_equal(order, p)
        np.testing.assert_array_equal(E1, E[p])
        out = scratch[-1]
        np.testing.assert_array_equal(out[0:3], E[p[:pos], 3:6].min(axis=0))
        np.testing.assert_array_equal(out[15:18], E[p[pos:], 6:9].max(axis=0))


def test_moments_are_the_same_on_one_or_more_threads():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one numba thread")
    V, F = _soup(m=fast.PARALLEL_BUILD_FACES + 5000, seed=5)  # above the size where subtrees run on threads
    t = build_volume_bvh(fast._triangle_elements(V, F), 4)
    before = numba.get_num_threads()
    got = []
    try:
        for threads in (1, 2):
            numba.set_num_threads(threads)
            got.append(fast._tree_moments(V, F, t.order, t.start, t.end, t.right, t.lo, t.hi))
    finally:
        numba.set_num_threads(before)
    for a, b in zip(*got):
        np.testing.assert_array_equal(a, b)
    roots, above = fast._split_top(t.start, t.end, t.right, 16)
    covered = np.zeros(t.n_nodes, int)      # the subtrees and the nodes above them cover every node once
    for r in roots:
        covered[r:fast._subtree_end(t.right, r)] += 1
    covered[above] += 1
    assert len(roots) == 16 and (covered == 1).all()


def test_build_volume_bvh_rejects_bad_rows():
    with pytest.raises(ValueError, match="E"):
        build_volume_bvh(np.zeros((5, 6)), 4)
    with pytest.raises(ValueError, match="E"):
        build_volume_bvh(np.zeros((5, 9), np.float32), 4)
    with pytest.raises(ValueError, match="zero elements"):
        build_volume_bvh(np.zeros((0, 9)), 4)
    with pytest.raises(ValueError, match="leaf_size"):
        build_volume_bvh(np.zeros((5, 9)), 0)


def test_bottom_up_moments_equal_direct_sums():
    V, F = _soup(m=2000, seed=2)
    f = gsdf.FastWindingNumber(V, F)
    t = f.tree
    Vn = f._frame.geometry(V)
    T9 = Vn[F[t.order]].reshape(-1, 9)
    np.testing.assert_array_equal(f._T[:, :9], T9)
    X = T9.reshape(-1, 3, 3).mean(axis=1)
    AN = 0.5 * np.cross(T9[:, 3:6] - T9[:, 0:3], T9[:, 6:9] - T9[:, 0:3])
    M = np.zeros((len(F), 6))
    for k in range(3):   # Eq. 29: edge midpoints about the centroid
        q = 0.5 * (T9[:, 3 * k:3 * k + 3] + T9[:, 3 * ((k + 1) % 3):3 * ((k + 1) % 3) + 3]) - X
        M += np.column_stack([q[:, 0] ** 2, q[:, 1] ** 2, q[:, 2] ** 2,
                              q[:, 0] * q[:, 1], q[:, 0] * q[:, 2], q[:, 1] * q[:, 2]]) / 3
    D = fast._node_moments(t.start, t.end, X, AN, M, np.empty((len(X), 0)), fast.NODE_WIDTH)
    far = np.maximum(np.abs(t.lo - D[:, :3]), np.abs(t.hi - D[:, :3]))
    D[:, 3] = (far ** 2).sum(axis=1)
    T, Df = fast._tree_moments(Vn, F, t.order, t.start, t.end, t.right, t.lo, t.hi)  # the build's (not kept)
    np.testing.assert_array_equal(T, f._T)
    np.testing.assert_allclose(Df, D, rtol=1e-11, atol=1e-13 * np.abs(D).max())
    # the lanes hold the compact fold of those moments
    lane = f._W[1:, 4:, :].transpose(0, 2, 1).reshape(-1, fast.COMPACT_WIDTH - 1)
    kids = widen(t, fast.WIDTH).kids.ravel()   # lane rows 1: are the wide view's nodes (row 0 holds the root)
    ok = kids >= 0
    np.testing.assert_allclose(lane[ok], fast._fold_moments(Df)[kids[ok], :23], rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("order", [1, 2])
def test_new_build_winding_numbers_match_brute_force_on_a_soup(order):
    V, F = _soup(m=3000, seed=3)
    rng = np.random.default_rng(4)
    Q = rng.uniform(-0.2, 1.2, (20000, 3))
    exact = gsdf.winding_number(V, F, Q)          # direct sum of solid angles over every triangle
    w = gsdf.FastWindingNumber(V, F, order=order)(Q)
    rms = np.sqrt(np.mean((w - exact) ** 2))
    assert rms < (1e-2 if order == 1 else 2e-3)
    # far from the soup the root's expansion alone answers: relative error ~ (r/d)^(order+1), r ≈ 0.9
    far = np.array([[10.0, 10.0, 10.0], [-9.0, 0.5, 0.5]])
    np.testing.assert_allclose(gsdf.FastWindingNumber(V, F, order=order)(far), gsdf.winding_number(V, F, far),
                               rtol=(0.1 ** (order + 1)), atol=0)


@pytest.mark.parametrize("m", [3000, fast.PARALLEL_BUILD_FACES + 5000])  # serial, and subtrees on the threads
def test_one_pass_moments_and_lanes_equal_the_two_pass_form_bit_for_bit(m):
    from gsdf._checks import as_mesh
    from gsdf.spatial._triangle_tree import triangle_tree

    V, F = as_mesh(*_soup(m=m, seed=4))
    tt = triangle_tree(V, F)
    t = tt.bvh
    for order in (0, 1, 2):
        T, D = fast._tree_moments(tt.Vf, tt.F, t.order, t.start, t.end, t.right, t.lo, t.hi)
        ref = fast._pack_wide(D, t, 4.0, order, fast.WIDTH, tt.wide)
        got = fast._moments_lanes(tt.Vf, tt.F, t, tt.wide, 4.0, order)
        assert np.array_equal(got[0], T)
        for a, b in zip(ref[:4], got[1:5]):
            assert np.array_equal(a, b)
        assert got[5] == ref[4]
