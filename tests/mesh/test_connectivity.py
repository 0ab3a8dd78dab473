"""gsdf.mesh._connectivity: unique edges, adjacency, Euler characteristic, manifold / orientation checks."""

import numpy as np
import pytest

from gsdf.mesh._connectivity import MeshTopology, unique_edges
from tests.shapes import uv_sphere


def torus_grid(nu=12, nv=8):
    """Closed torus as a periodic nu x nv grid, consistently oriented."""
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = (i * nv + j).ravel()
    b = (((i + 1) % nu) * nv + j).ravel()
    c = (((i + 1) % nu) * nv + (j + 1) % nv).ravel()
    d = (i * nv + (j + 1) % nv).ravel()
    return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


def test_unique_edges_canonical_and_signs():
    F = torus_grid()
    E, FE, S = unique_edges(F)
    assert np.all(E[:, 0] < E[:, 1])
    assert len(E) == 3 * len(F) // 2
    nxt = np.roll(F, -1, axis=1)
    assert np.array_equal(np.where(S > 0, F, nxt), E[FE, 0])
    assert np.array_equal(np.where(S > 0, nxt, F), E[FE, 1])


def test_topology_sphere_torus_disk():
    _, Fs = uv_sphere(8, 12)
    t = MeshTopology(Fs)
    assert (t.euler_characteristic, t.n_components, t.betti_1(), t.n_boundary_loops) == (2, 1, 0, 0)
    assert t.is_manifold and t.is_consistently_oriented and t.is_closed
    t = MeshTopology(torus_grid())
    assert (t.euler_characteristic, t.betti_1()) == (0, 2)
    # left / right faces: the left face's slot runs along the edge
    L, R = t.edge_faces[:, 0], t.edge_faces[:, 1]
    assert np.all(L >= 0) and np.all(R >= 0)
    assert np.all(t.face_edges[L, t.edge_slots[:, 0]] == np.arange(t.n_edges))
    assert np.all(t.face_edge_signs[L, t.edge_slots[:, 0]] == 1)
    assert np.all(t.face_edge_signs[R, t.edge_slots[:, 1]] == -1)
    # open cylinder (annulus): torus grid minus one ring of faces
    F = torus_grid(12, 8)
    ring = np.arange(len(F)).reshape(2, 12, 8)[:, 0, :].ravel()
    Fa = np.delete(F, ring, axis=0)
    t = MeshTopology(Fa)
    assert (t.euler_characteristic, t.n_boundary_loops, t.betti_1()) == (0, 2, 1)
    # two components
    t = MeshTopology(np.vstack([Fs, Fs + Fs.max() + 1]))
    assert t.n_components == 2 and t.betti_1() == 0 and t.euler_characteristic == 4


def test_nonmanifold_and_orientation_checks():
    # three triangles on one edge
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    t = MeshTopology(F)
    assert not t.is_manifold
    with pytest.raises(ValueError, match="non-manifold.*edge"):
        t.require_manifold()
    # bow-tie vertex: two triangles touching at vertex 0 only
    t = MeshTopology(np.array([[0, 1, 2], [0, 3, 4]]))
    assert t.vertex_fan_count()[0] == 2 and not t.is_manifold
    with pytest.raises(ValueError, match="vertex 0"):
        t.require_manifold()
    # one flipped face on a sphere: orientable, not consistent; the flip flags repair it
    _, Fs = uv_sphere(6, 8)
    Fb = Fs.copy()
    Fb[3] = Fb[3, ::-1]
    t = MeshTopology(Fb)
    assert not t.is_consistently_oriented and t.is_orientable
    flip = t.orientation_classes()
    Fr = np.where(flip[:, None], Fb[:, ::-1], Fb)
    assert MeshTopology(Fr).is_consistently_oriented
    with pytest.raises(ValueError, match="orientable; flip"):
        t.require_oriented()


def test_moebius_not_orientable():
    n = 10
    F = []
    for i in range(n):
        a, b = i, (i + 1) % n
        ta, tb = a + n, b + n
        if i == n - 1:               # glue with a half twist
            tb, b = b, tb
        F += [[a, b, tb], [a, tb, ta]]
    t = MeshTopology(np.array(F))
    assert t.is_manifold and not t.is_orientable
    with pytest.raises(ValueError, match="not orientable"):
        t.require_oriented()


def test_bad_input():
    with pytest.raises(ValueError, match="F"):
        MeshTopology(np.array([[0, 1]]))
    with pytest.raises(ValueError, match="bool"):
        MeshTopology(np.array([[True, False, True]]))
    with pytest.raises(ValueError, match="degenerate"):
        unique_edges(np.array([[0, 1, 1]]))
    with pytest.raises(ValueError, match="out of range"):
        MeshTopology(np.array([[0, 1, 5]]), n_vertices=3)
    with pytest.raises(ValueError, match="negative"):
        MeshTopology(np.array([[0, 1, -1]]))
