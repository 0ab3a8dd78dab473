"""gsdf.mesh._tet_ops.TetOperators: the one tet operator set.

Old vs new: ``TetComplex`` (now a subclass) is bit-identical to the former standalone class; the signed heat
method's P1 operators, formerly from barycentric gradients by a batched matrix inverse, now come from the outward
face area vectors (as ``TetComplex`` always did) and move by < 1e-13 relative. Frozen outputs:
tests/mesh/operator_reference.py. Also: unique_rows (packed-key unique of edge / face rows) equals numpy's
row-wise unique; the incidence of a Delaunay tet complex is consistent."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.spatial import Delaunay

from gsdf.dec._tet import TetComplex
from gsdf.heat.tet._mesh import tet_quality
from gsdf.mesh._tet_ops import TetOperators, unique_rows
from tests.mesh.operator_reference import identical, relative_difference, tet_chain, tet_mesh


@pytest.mark.parametrize("k", [2, 3])
def test_unique_rows_matches_numpy(k):
    R = np.sort(np.random.default_rng(k).integers(0, 50, (3000, k)), axis=1).astype(np.int32)
    u, inv = unique_rows(R, 50)
    u0, inv0 = np.unique(R, axis=0, return_inverse=True)
    assert np.array_equal(u, u0) and np.array_equal(inv, inv0.ravel()) and u.dtype == R.dtype
    assert np.array_equal(u[inv], R)


def test_unique_rows_falls_back_when_the_key_would_overflow():
    n = 2 ** 22                                   # n³ ≥ 2⁶³: the packed key would overflow
    R = np.sort(np.random.default_rng(0).integers(n - 40, n, (500, 3)), axis=1)
    u, inv = unique_rows(R, n)
    u0, inv0 = np.unique(R, axis=0, return_inverse=True)
    assert np.array_equal(u, u0) and np.array_equal(inv, inv0.ravel())


def test_tet_complex_incidence_is_consistent():
    P = np.random.default_rng(1).uniform(size=(300, 3))
    K = TetComplex(P, Delaunay(P).simplices)
    # every tet's edges / faces are its vertex pairs / triples
    for t in range(0, K.n_tets, 37):
        vs = set(K.T[t])
        assert all(set(K.edges[e]) <= vs for e in K.tet_edges[t])
        assert all(set(K.faces[f]) <= vs and len(set(K.faces[f])) == 3 for f in K.tet_faces[t])
    assert len(np.unique(K.edges, axis=0)) == K.n_edges and len(np.unique(K.faces, axis=0)) == K.n_faces


def test_tet_complex_is_bit_identical_to_the_former_class():
    P, T = tet_mesh()
    K = TetComplex(P, T)
    for a in ("T", "volumes", "edges", "faces", "tet_edges", "tet_faces", "tet_face_sign", "face_tets", "d0", "d1",
              "d2", "star0", "star1", "star2"):
        assert identical("tet/" + a, getattr(K, a)), a
    assert identical("tet/fem_tet_weights", K.edge_weights())
    assert identical("tet/laplacian", K.laplacian()) and identical("tet/face_areas", K.face_areas())
    u, info = K.jump_laplace(tet_chain(K))
    assert identical("tet/jump_u", u) and identical("tet/jump_omega", info["omega"])


def test_heat_tet_operators_agree_with_the_former_p1_functions():
    P, T = tet_mesh()
    ops = TetOperators(P, T)
    Y = np.random.default_rng(1).normal(size=(len(T), 3))
    # measured: volumes 3.7e-16, quality 6.1e-16, stiffness 5.1e-14, divergence 8.5e-16 (relative)
    for key, A in (("vol", ops.volumes), ("quality", tet_quality(P, T)), ("p1_laplacian", ops.cotan_laplacian()),
                   ("weak_divergence", ops.divergence(Y))):
        assert relative_difference("heat_tet/" + key, A) < 1e-12, key


def test_stiffness_divergence_and_mass():
    P = np.random.default_rng(2).uniform(size=(200, 3))
    ops = TetOperators(P, Delaunay(P).simplices)
    K = ops.cotan_laplacian()
    assert abs(K @ np.ones(len(P))).max() < 1e-12 and abs(K - K.T).max() == 0
    # K = d0ᵀ diag(Σ_T w) d0
    w = np.bincount(ops.tet_edges.ravel(), ops.edge_weights().ravel(), minlength=ops.n_edges)
    assert abs(K - ops.d0.T @ sp.diags(w) @ ops.d0).max() < 1e-12
    # a linear φ: its gradient g is exact per tet, and the weak divergence of g is K φ (both are Σ |T| ∇λ_i·g)
    g = np.array([0.3, -1.2, 0.7])
    assert np.allclose(ops.divergence(np.tile(g, (ops.n_tets, 1))), K @ (P @ g), atol=1e-12)
    assert np.isclose(ops.vertex_mass().sum(), ops.volumes.sum())
