"""Fixed-radius grid and the neighbour selection of the convolutional formulas (PAT, baselines)."""

import numpy as np
import pytest

from gsdf.spatial._radius_grid import build_radius_grid, gather_within
from gsdf.tori._blend import NeighbourBlend


def _sphere_cloud(n, seed=0):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(n, 3))
    return P / np.linalg.norm(P, axis=1)[:, None]


def test_gather_within_matches_brute_force():
    rng = np.random.default_rng(1)
    P = _sphere_cloud(3000)
    r = 0.2
    g = build_radius_grid(P, r)
    Q = np.vstack([P[:50] + 0.05 * rng.normal(size=(50, 3)), rng.uniform(-1.6, 1.6, size=(200, 3)),
                   [[5.0, 0, 0], [-1.1, -1.1, -1.1]]])
    cd, ci = np.empty(4096), np.empty(4096, np.int64)
    for x in Q:
        n = gather_within(x[0], x[1], x[2], g.origin, g.cell, g.dims, g.keys, g.start, g.row_start, g.points,
                          g.order, r * r, cd, ci)
        d2 = ((P - x) ** 2).sum(1)
        want = np.flatnonzero(d2 <= r * r)
        assert n == len(want)
        assert sorted(ci[:n].tolist()) == want.tolist()
        np.testing.assert_allclose(np.sort(cd[:n]), np.sort(d2[want]))


def test_radius_grid_refuses_bad_radius():
    P = _sphere_cloud(100)
    assert build_radius_grid(P, 0.0) is None
    assert build_radius_grid(P, np.inf) is None
    assert build_radius_grid(P, 1e-9) is None  # too many rows: callers fall back to the tree


@pytest.mark.parametrize("r_eval", [None, 0.05, 10.0])
def test_blend_neighbours_rule(r_eval):
    """The k_eval nearest within R_eval when at least k_fallback lie there, else the k_fallback nearest;
    the first entry is the nearest point."""
    rng = np.random.default_rng(2)
    P = _sphere_cloud(4000)
    b = NeighbourBlend(P, r_eval=r_eval, k_eval=64, k_fallback=32)
    Q = np.vstack([P[:300] + 0.02 * rng.normal(size=(300, 3)), rng.uniform(-2, 2, size=(300, 3))])
    d, i = b.neighbours(Q)
    D = np.linalg.norm(Q[:, None, :] - P[None, :, :], axis=2)
    order = np.argsort(D, axis=1)
    for j in range(len(Q)):
        within = int((D[j] <= b.r_eval).sum())
        fin = np.isfinite(d[j])
        if within >= 32:
            want = order[j, :min(within, 64)]
        else:
            want = order[j, :32]
        assert set(i[j, fin].tolist()) == set(want.tolist())
        assert i[j, 0] == order[j, 0]
        np.testing.assert_allclose(d[j, fin], D[j, i[j, fin]], rtol=1e-12, atol=1e-15)
