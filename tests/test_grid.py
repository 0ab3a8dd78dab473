"""gsdf.Grid: one rule for resolution (nodes along the longest side, cubic cells) and for padding."""

import numpy as np
import pytest

import gsdf
from gsdf.grid import PAD, Grid, grid_points, padded_box


def test_fit_rule():
    g = Grid.fit(([0, 0, 0], [2.0, 1.05, 0.5]), 21)
    assert g.shape == (21, 12, 6)  # h = 0.1: ceil(10.5) + 1 = 12 nodes, 5 + 1 = 6 nodes
    assert np.allclose(g.spacing, 0.1) and np.array_equal(g.bbox_min, [0, 0, 0])
    assert np.allclose(g.bbox_max, [2.0, 1.1, 0.5])  # the upper corner moves up to the last node
    assert g.size == 21 * 12 * 6 and g.points().shape == (g.size, 3)
    assert np.array_equal(g.points()[-1], g.bbox_max) and np.array_equal(g.points()[0], g.bbox_min)
    # a cube gets resolution nodes on every side; a flat box two nodes on its flat side
    assert Grid.fit(([-1, -1, -1], [1, 1, 1]), 17).shape == (17, 17, 17)
    assert Grid.fit(([0, 0, 0], [1, 1, 0]), 5).shape == (5, 5, 2)


def test_points_order_chunks_and_voxels():
    g = Grid(([0, 0, 0], [1, 2, 3]), (2, 3, 4))
    P = g.points()
    assert np.array_equal(P[1], [0, 0, 1]) and np.array_equal(P[4], [0, 1, 0])  # C order, k fastest
    idx = np.array([5, 0, 23])
    assert np.array_equal(g.points(idx), P[idx])
    assert np.array_equal(grid_points([0, 0, 0], [1, 2, 3], (2, 3, 4)), P)
    lo, hi = g.voxel_box()
    assert np.allclose(lo, [-0.5, -0.5, -0.5]) and np.allclose(hi, [1.5, 2.5, 3.5])
    assert np.allclose((hi - lo) / np.array(g.shape), g.spacing)


def test_around_pads_by_the_diagonal():
    X = np.array([[0, 0, 0], [3, 4, 0.0]])
    lo, hi = padded_box(X, 0.1)
    assert np.allclose(lo, -0.5) and np.allclose(hi, [3.5, 4.5, 0.5])
    g = Grid.around(X, 11)
    assert PAD == 0.1 and np.allclose(g.bbox_min, -0.5) and np.allclose(g.spacing, 0.5)
    assert g == Grid.fit(padded_box(X), 11) and g != Grid.around(X, 11, pad=0.2)
    assert np.allclose(padded_box([[1, 2, 3]], 0.1)[0], [0.9, 1.9, 2.9])  # one point: pad in absolute units


def test_gridfield_grid_round_trip():
    g = Grid.fit(([0, 0, 0], [1, 0.5, 0.25]), 9)
    f = gsdf.GridField(np.zeros(g.shape), *g.box)
    assert f.grid == g and np.array_equal(f.grid_points(), g.points())


def test_bad_grids():
    with pytest.raises(ValueError, match="resolution"):
        Grid.fit(([0, 0, 0], [1, 1, 1]), 1)
    with pytest.raises(ValueError, match="box size"):
        Grid.fit(([0, 0, 0], [0, 0, 0]), 4)
    with pytest.raises(ValueError, match="shape"):
        Grid(([0, 0, 0], [1, 1, 1]), (1, 2, 2))
    with pytest.raises(ValueError, match="shape"):
        Grid(([0, 0, 0], [1, 1, 1]), (2, 2))
    with pytest.raises(ValueError, match="exceed"):
        Grid(([0, 0, 0], [1, 0, 1]), (2, 2, 2))
    with pytest.raises(ValueError, match="box"):
        Grid([0, 0, 0], (2, 2, 2))
    with pytest.raises(ValueError, match="NaN"):
        Grid(([0, 0, np.nan], [1, 1, 1]), (2, 2, 2))
    with pytest.raises(ValueError, match="pad"):
        padded_box(np.eye(3), -0.1)


@pytest.mark.parametrize("idx,why", [([0.5], "fractions"), ([-1], "out of range"), ([24], "out of range"),
                                     ([1j], "complex"), (["a"], "strings"), ([[0, 1]], r"shape \(k,\)")])
def test_points_flat_index_checked(idx, why):
    g = Grid(([0, 0, 0], [1, 2, 3]), (2, 3, 4))
    with pytest.raises(ValueError, match="flat_index: .*" + why):
        g.points(idx)
    np.testing.assert_array_equal(g.points([23.0]), g.points()[[23]])


def test_a_grid_too_large_for_any_address_space_is_refused_at_construction():
    from gsdf.grid import MAX_NODES
    for make in (lambda: Grid.around(np.eye(3), 10 ** 9), lambda: Grid.fit(([0, 0, 0], [1, 1, 1]), 10 ** 6),
                 lambda: Grid(([0, 0, 0], [1, 1, 1]), (2 ** 20, 2 ** 20, 2 ** 15))):
        with pytest.raises(ValueError, match=r"grid has .* nodes, more than a grid can have .*resolution"):
            make()
    assert Grid(([0, 0, 0], [1, 1, 1]), (2 ** 20, 2 ** 20, 2 ** 14)).size == MAX_NODES   # lazy: still fine
    assert Grid.fit(([0, 0, 0], [1, 1e-9, 1e-9]), 10 ** 9).shape[1:] == (2, 2)             # long and thin: fine
