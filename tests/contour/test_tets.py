"""Marching tetrahedra on fields with nodes (and whole tets) exactly at the level."""

import numpy as np
from scipy.spatial import Delaunay

from gsdf.contour._tets import marching_tetrahedra
from tests.shapes import fibonacci_sphere


def _zero_constrained_ball(n_surface=600, n_lattice=7, seed=0):
    """A Delaunay tet mesh of a sample of a sphere of radius ~0.6 (values exactly 0, like the signed heat
    method's "zero" constraint on input points), one point inside and a coarse jittered lattice outside (values
    |x| - 0.6): most tets inside have all four vertices on the sphere, at the level."""
    rng = np.random.default_rng(seed)
    S = fibonacci_sphere(n_surface, 0.6)
    S = S * (1 + 0.02 * rng.uniform(-1, 1, (len(S), 1)))  # not cospherical: a generic Delaunay
    g = np.linspace(-1, 1, n_lattice)
    L = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    L = L + rng.normal(scale=0.02, size=L.shape)
    L = L[np.linalg.norm(L, axis=1) > 0.7]
    X = np.vstack([S, [[0.3, 0.0, 0.0]], L])
    s = np.linalg.norm(X, axis=1) - 0.6
    s[:len(S)] = 0.0
    return X, Delaunay(X).simplices, s, len(S)


def test_tets_at_the_level_give_a_closed_surface_through_the_nodes():
    X, T, s, ns = _zero_constrained_ball()
    assert (np.abs(s[T]).max(axis=1) == 0).sum() > 100  # tets whose four vertices are at the level
    V, F, rep = marching_tetrahedra(X, T, s, 0.0, report=True)
    assert rep["closed"] and rep["edge_manifold"] and rep["vertex_manifold"], rep
    # every vertex is a node at the level (crossings on edges to a node at the level are that node)
    on_sphere = {tuple(x) for x in X[:ns]}
    assert all(tuple(v) in on_sphere for v in V)
    vol = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6
    assert abs(vol - 4 / 3 * np.pi * 0.6 ** 3) < 0.05 * vol  # outward, the whole sphere


def test_a_face_at_the_level_between_two_tets_below_gives_no_fin():
    """Two tets sharing a face whose three nodes are at the level, both apexes below it: nothing is emitted
    there (the level counts as below). Counting the level as above emitted that face from both tets with
    opposite orientations: a fin of zero thickness whose vertices have no normal."""
    X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.3, 0.3, 1], [0.3, 0.3, -1], [-1, -1, 1]], float)
    s = np.array([0, 0, 0, -1, -1, 1], float)
    T = np.array([[0, 1, 2, 3], [0, 2, 1, 4], [0, 1, 3, 5]])
    V, F = marching_tetrahedra(X, T, s, 0.0)
    key = np.sort(F, axis=1)
    assert len(np.unique(key, axis=0)) == len(F)  # no face twice
    assert not any(set(map(tuple, V[f])) == {(0, 0, 0), (1, 0, 0), (0, 1, 0)} for f in F)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    vn = np.zeros_like(V)
    np.add.at(vn, F.ravel(), np.repeat(n, 3, axis=0))
    assert (np.linalg.norm(vn, axis=1) > 0).all()


def test_a_level_no_tet_crosses_is_refused_not_leaked():
    """Values beyond the level only at vertices in no tet, or in another tet: numpy's 'need at least one array to
    concatenate' leaked."""
    import pytest

    X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0], [2, 2, 2]])
    T = np.array([[0, 1, 2, 3]])
    with pytest.raises(ValueError, match=r"outside the field's range \[1, 1\] \(over the tets\): no surface"):
        marching_tetrahedra(X, T, np.array([1.0, 1, 1, 1, -1]), 0.0)
    X2 = np.vstack([X[:4], X[:4] + 5.0])
    T2 = np.array([[0, 1, 2, 3], [4, 5, 6, 7]])
    with pytest.raises(ValueError, match="cuts no tet"):
        marching_tetrahedra(X2, T2, np.r_[np.full(4, -1.0), np.full(4, 1.0)], 0.0)
    V, F = marching_tetrahedra(X2, T2, np.r_[X2[:4, 0] - 0.5, np.full(4, 1.0)], 0.0)
    assert F.shape == (1, 3) and np.allclose(V[:, 0], 0.5)
