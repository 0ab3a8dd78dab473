"""gsdf.dec._tet._unique_rows (packed-key unique of edge / face rows) equals numpy's row-wise unique."""

import numpy as np
import pytest
from scipy.spatial import Delaunay

from gsdf.dec._tet import TetComplex, _unique_rows


@pytest.mark.parametrize("k", [2, 3])
def test_unique_rows_matches_numpy(k):
    R = np.sort(np.random.default_rng(k).integers(0, 50, (3000, k)), axis=1).astype(np.int32)
    u, inv = _unique_rows(R, 50)
    u0, inv0 = np.unique(R, axis=0, return_inverse=True)
    assert np.array_equal(u, u0) and np.array_equal(inv, inv0.ravel()) and u.dtype == R.dtype
    assert np.array_equal(u[inv], R)


def test_unique_rows_falls_back_when_the_key_would_overflow():
    n = 2 ** 22                                   # n³ ≥ 2⁶³: the packed key would overflow
    R = np.sort(np.random.default_rng(0).integers(n - 40, n, (500, 3)), axis=1)
    u, inv = _unique_rows(R, n)
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
