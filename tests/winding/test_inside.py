"""Inside / outside (gsdf.inside, FastWindingNumber.inside; gsdf.winding._inside): the same answer as the fast
winding number rounded and as the exact winding number rounded, on closed meshes (grid cells and crossing
counts), nested / doubled / inverted components, queries on the surface and on grid planes, and meshes with
a boundary (the walk)."""

import os

import numpy as np
import pytest

import gsdf
from gsdf.winding import _inside

DATA = "/work/cgal/data/meshes"


def _icosphere(levels=3):
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
                  [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    for _ in range(levels):
        V, F = _subdivide(V, F)
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


def _subdivide(V, F):
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    U, inv = np.unique(E, axis=0, return_inverse=True)
    M = V.shape[0] + inv.reshape(3, -1).T
    V2 = np.vstack([V, 0.5 * (V[U[:, 0]] + V[U[:, 1]])])
    a, b, c = F.T
    ab, bc, ca = M.T
    return V2, np.vstack([np.column_stack(x) for x in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))])


def _queries(V, F, n=30000, seed=0):
    lo, hi = V.min(0), V.max(0)
    pad = 0.1 * np.linalg.norm(hi - lo)
    X = np.random.default_rng(seed).uniform(lo - pad, hi + pad, (n, 3))
    # queries on the surface: vertices, edge midpoints, centroids (undecided by counting: the walk)
    return np.vstack([X, V[:500], 0.5 * (V[F[:500, 0]] + V[F[:500, 1]]), V[F[:500]].mean(1)])


def _check(V, F, X, exact=20000, wrong=0):
    got = gsdf.inside(V, F, X)
    assert got.dtype == bool and got.shape == (X.shape[0],)
    assert np.array_equal(got, gsdf.FastWindingNumber(V, F)(X) > 0.5)
    assert np.array_equal(got, gsdf.FastWindingNumber(V, F).inside(X))
    if exact:  # off the surface (the first, random rows): the exact winding number rounded (closed meshes:
        # exactly; with a boundary the walk's far-field error may flip a query where w is within ~1e-3 of 1/2)
        k = exact
        assert (got[:k] != (gsdf.ExactWindingNumber(V, F)(X[:k]) > 0.5)).sum() <= wrong * k
    return got


def test_sphere_matches_the_winding_number():
    V, F = _icosphere(3)
    X = _queries(V, F)
    got = _check(V, F, X, 20000)
    r = np.linalg.norm(X[:30000], axis=1)
    assert np.array_equal(got[:30000][np.abs(r - 1) > 0.02], (r < 1)[np.abs(r - 1) > 0.02])


def test_nested_doubled_and_inverted_components():
    V, F = _icosphere(2)
    n = V.shape[0]
    # a shell (outer sphere, inner sphere inverted: w = 1 between them, 0 in the hole), a doubled sphere far
    # away (w = 2 inside: inside), an inverted sphere (w = -1: outside)
    Vs = np.vstack([V, 0.5 * V, V + [5, 0, 0], V + [5, 0, 0], V + [0, 5, 0]])
    Fs = np.vstack([F, F[:, ::-1] + n, F + 2 * n, F + 3 * n, F[:, ::-1] + 4 * n])
    assert _inside.is_closed(Fs, Vs.shape[0])
    X = _queries(Vs, Fs, 40000)
    got = _check(Vs, Fs, X, 20000)
    for c, want in (([0, 0, 0], False), ([0.75, 0, 0], True), ([5, 0, 0], True), ([0, 5, 0], False)):
        P = np.asarray(c) + 0.1 * np.random.default_rng(1).uniform(-1, 1, (3000, 3))
        assert (gsdf.inside(Vs, Fs, P) == want).all()
    assert got.any() and not got.all()


def test_grid_aligned_and_axis_parallel_queries():
    # a cube: faces parallel to the crossing direction x, queries on lines through its edges and on its faces
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [2, 3, 7], [2, 7, 6],
                  [1, 2, 6], [1, 6, 5], [0, 4, 7], [0, 7, 3]])
    g = np.linspace(-0.25, 1.25, 31)
    X = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    got = gsdf.inside(V, F, X)
    assert np.array_equal(got, gsdf.FastWindingNumber(V, F)(X) > 0.5)
    strict = ((X > 0) & (X < 1)).all(1)
    off = ((X < 0) | (X > 1)).any(1)
    assert got[strict].all() and not got[off].any()


def test_open_meshes_and_soups_walk():
    V, F = _icosphere(2)
    Fh = F[5:]  # holes
    assert not _inside.is_closed(Fh, V.shape[0])
    _check(V, Fh, _queries(V, Fh, 10000), 10000, 1e-3)
    rng = np.random.default_rng(0)
    Fs = np.vstack([F[rng.random(len(F)) > 0.1], F[:30]])  # deleted and duplicated faces
    Fs[::7] = Fs[::7, ::-1]
    _check(V, Fs, _queries(V, Fs, 10000), 10000, 1e-3)


def test_is_closed():
    V, F = _icosphere(1)
    assert _inside.is_closed(F, V.shape[0])
    assert not _inside.is_closed(F[1:], V.shape[0])
    assert not _inside.is_closed(np.vstack([F, F[:1]]), V.shape[0])  # a duplicated face
    assert _inside.is_closed(np.vstack([F, F[:1], F[:1, ::-1]]), V.shape[0])  # a face and its reverse cancel
    assert _inside.is_closed(np.vstack([F, [[0, 0, 1]]]), V.shape[0])  # (0, 1) and (1, 0): cancel


def test_scale_and_small_inputs():
    V, F = _icosphere(2)
    X = _queries(V, F, 5000)[:5000]  # off the surface: the same answers at any scale
    base = gsdf.inside(V, F, X)
    assert np.array_equal(gsdf.inside(V * 1e-6 + 3e-6, F, X * 1e-6 + 3e-6), base)
    assert np.array_equal(gsdf.inside(V * 1e6, F, X * 1e6), base)
    assert np.array_equal(gsdf.inside(V, F, X[:10]), base[:10])  # below the grid's size: the walk
    assert gsdf.inside(V, F, np.zeros((0, 3))).shape == (0,)
    assert gsdf.inside(V, F, [0.0, 0.0, 0.0]).tolist() == [True]


def test_bad_input():
    V, F = _icosphere(1)
    with pytest.raises(ValueError, match="Q"):
        gsdf.inside(V, F, [[0, 0, np.nan]])
    with pytest.raises(ValueError, match="F"):
        gsdf.inside(V, F + 1000, [[0, 0, 0]])
    with pytest.raises(ValueError, match="beta"):
        gsdf.inside(V, F, [[0, 0, 0]], beta=0)


@pytest.mark.skipif(not os.path.isdir(DATA), reason="CGAL meshes not available")
@pytest.mark.parametrize("name", ["fandisk.off", "elephant.off", "double-torus-example.off", "elephant-with-holes.off"])
def test_cgal_meshes(name):
    V, F = gsdf.read_mesh(os.path.join(DATA, name))
    _check(V, F, _queries(V, F, 30000), 20000 if len(F) < 6000 else 0, 1e-3 if "holes" in name else 0)
