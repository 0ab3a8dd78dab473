"""signed_distance_grid against per-point signed_distance on the grid's nodes: closed surfaces (the winding
number evaluated once per region the surface does not separate), open meshes and soups (at every node)."""

from __future__ import annotations

import numpy as np
import pytest

import gsdf
from gsdf.data import path, sphere_mesh
from gsdf.grid import Grid
from gsdf.ops._distance_grid import _is_cycle, _region_inside


def _two_spheres():
    """Two closed components: a sphere and a smaller one nested inside it (winding number 2 there)."""
    V1, F1 = sphere_mesh(3, 1.0)
    V2, F2 = sphere_mesh(2, 0.35)
    return np.vstack([V1, V2 + [0.2, 0.1, 0.0]]), np.vstack([F1, F2 + len(V1)])


def _torus(n=40, m=20, R=1.0, r=0.3):
    u, v = np.meshgrid(np.arange(n) * 2 * np.pi / n, np.arange(m) * 2 * np.pi / m, indexing="ij")
    V = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    F = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return V, F


def _soup():
    V, F = sphere_mesh(3, 1.0)
    rng = np.random.default_rng(1)
    F = F[rng.random(len(F)) >= 0.1]  # holes
    F = np.vstack([F, F[rng.random(len(F)) < 0.05]])  # duplicates
    flip = rng.random(len(F)) < 0.1
    F[flip] = F[flip][:, ::-1]  # flipped
    return V, np.ascontiguousarray(F)


def _open():
    V, F = _torus()
    return V, F[np.linalg.norm(V[F].mean(axis=1) - [1.3, 0, 0], axis=1) > 0.3]  # a hole in the outer wall


def _broken():
    return gsdf.read_mesh(path("broken_soup.obj"))


CASES = {"sphere": lambda: sphere_mesh(3, 1.0), "torus": _torus, "nested": _two_spheres, "soup": _soup,
         "open": _open, "broken_soup.obj": _broken}


@pytest.mark.parametrize("name", sorted(CASES))
@pytest.mark.parametrize("resolution", [17, 40])
def test_grid_equals_signed_distance_on_its_nodes(name, resolution):
    V, F = CASES[name]()
    S = gsdf.signed_distance_grid(V, F, resolution=resolution)
    Q = Grid.around(V, resolution).points()
    ref = gsdf.signed_distance(V, F, Q)
    s = S.values.ravel()
    np.testing.assert_allclose(np.abs(s), np.abs(ref), rtol=1e-12, atol=0)
    w = gsdf.FastWindingNumber(V, F)(Q)
    differ = (s < 0) != (ref < 0)
    assert np.all(np.abs(w[differ] - 0.5) < 1e-6), (name, int(differ.sum()))


def test_cycles():
    V, F = sphere_mesh(2, 1.0)
    Vt, Ft = _torus()
    assert _is_cycle(F, len(V)) and _is_cycle(Ft, len(Vt))
    assert _is_cycle(np.vstack([F, F[:3], F[:3, ::-1]]), len(V))  # a duplicate with its reverse cancels
    assert not _is_cycle(F[1:], len(V))  # a hole
    G = F.copy()
    G[0] = G[0, ::-1]
    assert not _is_cycle(G, len(V))  # one flipped face
    assert not _is_cycle(np.vstack([F, F[:1]]), len(V))  # a duplicate
    assert not _is_cycle(np.zeros((0, 3), np.int64), 0)


def test_region_whose_two_nodes_disagree_is_evaluated_everywhere():
    """A winding number that is not constant on a region (as the fast one could be, were its error above 1/2
    somewhere): the region's two evaluated nodes disagree and every node keeps its own value."""
    grid = Grid(([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), (6, 5, 4))
    Q = grid.points()
    d = 10.0 + Q[:, 0]  # one region, farthest node at x = 1
    inside = _region_inside(lambda X: (X[:, 0] > 0.5).astype(float), Q, d, grid, None)
    np.testing.assert_array_equal(inside, Q[:, 0] > 0.5)
    # consistent values: the region's value everywhere
    inside = _region_inside(lambda X: np.ones(len(X)), Q, d, grid, None)
    assert inside.all()


def test_regions_on_a_grid_with_unequal_spacings():
    V, F = sphere_mesh(2, 1.0)
    grid = Grid(([-1.5, -1.2, -0.05], [1.5, 1.2, 0.05]), (31, 9, 2))
    S = gsdf.signed_distance_grid(V, F, resolution=grid)
    ref = gsdf.signed_distance(V, F, grid.points())
    np.testing.assert_allclose(S.values.ravel(), ref, rtol=1e-12, atol=0)
