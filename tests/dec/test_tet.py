"""Tests of gsdf.dec._tet: incidence, FEM weights, Hodge canary (harmonic dimension = b1), jump Laplace."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import Delaunay

from gsdf.dec._tet import TetComplex, chain_boundary_vertices


def _ball(n=300, seed=0):
    P = np.random.default_rng(seed).uniform(-1, 1, (n, 3))
    return TetComplex(P, Delaunay(P).simplices)


def _solid_torus(n=6, hole=2, nz=2):
    """A solid torus: an n×n×nz block of unit cubes minus a central hole×hole column, each cube cut into the
    6 Kuhn tets along its main diagonal (consistent across cubes, so the complex is a manifold)."""
    g = np.arange(n + 1)
    V = np.stack(np.meshgrid(g, g, np.arange(nz + 1), indexing="ij"), -1).reshape(-1, 3).astype(float)
    vid = lambda x, y, z: (x * (n + 1) + y) * (nz + 1) + z  # noqa: E731
    lo = (n - hole) // 2
    cubes = np.array([(x, y, z) for x in range(n) for y in range(n) for z in range(nz)
                      if not (lo <= x < lo + hole and lo <= y < lo + hole)])
    import itertools
    T = []
    for perm in itertools.permutations(range(3)):
        path = [np.zeros(3, dtype=int)]
        for ax in perm:
            step = path[-1].copy()
            step[ax] += 1
            path.append(step)
        T.append(np.stack([vid(*(cubes + p).T) for p in path], axis=1))
    T = np.concatenate(T)
    used = np.unique(T)
    remap = -np.ones(len(V), dtype=np.int64)
    remap[used] = np.arange(len(used))
    c = (n / 2.0, n / 2.0, nz / 2.0)
    Vw = (V[used] - c) * 0.2 + np.random.default_rng(1).uniform(-0.01, 0.01, (len(used), 3))
    return TetComplex(Vw, remap[T])


def _harmonic_dim(K):
    """dim ker(d0 d0ᵀ + d1ᵀ d1) on edges (unit metric), by dense eigenvalues — an independent b1."""
    d0, d1 = K.d0.toarray(), K.d1.toarray()
    L1 = d0 @ d0.T + d1.T @ d1
    ev = np.linalg.eigvalsh(L1)
    return int(np.sum(ev < 1e-8 * ev.max()))


def _hodge_gamma(K, omega):
    """Harmonic part of omega in the ⋆1 inner product: ω − d0α − ⋆1⁻¹ d1ᵀ β (seed 003 Eq. 5)."""
    s1 = K.star1
    d0, d1 = K.d0, K.d1
    L0 = (d0.T @ sp.diags(s1) @ d0).tocsc()
    a = np.zeros(K.n_vertices)
    a[1:] = spla.spsolve(L0[1:, 1:], (d0.T @ (s1 * omega))[1:])
    L2 = (d1 @ sp.diags(1.0 / s1) @ d1.T).tocsc()
    b = spla.lsqr(L2, d1 @ omega, atol=1e-14, btol=1e-14, iter_lim=20000)[0]
    return omega - d0 @ a - (d1.T @ b) / s1


def test_incidence_complex_and_orientation():
    K = _ball()
    assert abs(K.d1 @ K.d0).max() == 0 and abs(K.d2 @ K.d1).max() == 0
    # Euler characteristic of a ball
    assert K.n_vertices - K.n_edges + K.n_faces - K.n_tets == 1
    assert (K.volumes > 0).all()
    # every interior face has one tet on each side; divergence of a tet's boundary sums to +-1 per face
    interior = (K.face_tets >= 0).all(axis=1)
    col = np.asarray(abs(K.d2).sum(axis=0)).ravel()
    assert np.array_equal(col == 2, interior)


def test_fem_weights_are_the_p1_stiffness():
    K = _ball(200)
    w = K.edge_weights()
    # an independent P1 stiffness from barycentric gradients: K_ij = |T| ∇λ_i·∇λ_j, w_ij = −K_ij
    V, T = K.V, K.T
    M = np.concatenate([np.ones((len(T), 4, 1)), V[T]], axis=2)            # rows [1 x y z]
    Gr = np.linalg.inv(M)[:, 1:, :]                                         # ∇λ_k as columns
    Kst = K.volumes[:, None, None] * np.einsum("tik,tjk->tij", Gr.transpose(0, 2, 1), Gr.transpose(0, 2, 1))
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    ref = np.stack([-Kst[:, i, j] for i, j in pairs], axis=1)
    assert np.allclose(w, ref, rtol=1e-8, atol=1e-12)
    # regular tet: |e| cot(θ) / 6 with θ = arccos(1/3)
    R = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1.0]])
    Kr = TetComplex(R, np.array([[0, 1, 2, 3]]))
    th = np.arccos(1 / 3)
    assert np.allclose(Kr.edge_weights(), np.sqrt(8) / np.tan(th) / 6)
    assert (K.star1 > 0).all() and (K.star0 > 0).all() and (K.star2 > 0).all()


def test_hodge_canary_ball_and_solid_torus():
    K = _ball(120)
    assert _harmonic_dim(K) == 0
    # the Darboux derivative of a jump field on a ball has no harmonic part (notes 2(b).4)
    c = K.V[K.T].mean(axis=1)
    inside = np.linalg.norm(c, axis=1) < 0.6
    ft = K.face_tets
    sel = (ft >= 0).all(axis=1) & (inside[np.maximum(ft[:, 0], 0)] != inside[np.maximum(ft[:, 1], 0)])
    G = np.zeros(K.n_faces)
    G[sel] = np.where(inside[ft[sel, 0]], 1.0, -1.0)
    cc, _ = K.jump_coordinates(G)
    omega = K.darboux_derivative(cc)
    gamma = _hodge_gamma(K, omega)
    assert np.linalg.norm(omega) > 1
    assert np.linalg.norm(gamma) / np.linalg.norm(omega) < 1e-8
    Kt = _solid_torus()
    chi = Kt.n_vertices - Kt.n_edges + Kt.n_faces - Kt.n_tets
    assert chi == 0                                                    # χ(solid torus) = 0
    # b1 by Alexander duality, independently of any solver: b1 = b0 − χ + b2, b2 = #∂-components − b0
    from gsdf.mesh._topology import mesh_topology
    hull = (Kt.face_tets < 0).any(axis=1)
    top = mesh_topology(Kt.V, Kt.faces[hull])
    assert top["closed"] and top["genus"] == [1]
    assert 1 - chi + (top["components"] - 1) == 1


def test_jump_laplace_dense_sphere_recovers_indicator():
    rng = np.random.default_rng(0)
    S = rng.normal(size=(1500, 3))
    S /= np.linalg.norm(S, axis=1)[:, None]
    P = np.vstack([S, rng.uniform(-1.5, 1.5, (2500, 3))])
    K = TetComplex(P, Delaunay(P).simplices)
    inside = np.linalg.norm(K.V[K.T].mean(axis=1), axis=1) < 1
    ft = K.face_tets
    sel = (ft >= 0).all(axis=1) & (inside[np.maximum(ft[:, 0], 0)] != inside[np.maximum(ft[:, 1], 0)])
    G = np.zeros(K.n_faces)
    G[sel] = np.where(inside[ft[sel, 0]], 1.0, -1.0)
    assert not chain_boundary_vertices(K, G).any()
    u, info = K.jump_laplace(G)
    w = u.mean(axis=1)
    assert np.abs(w - inside).max() < 1e-8
    # ∂W = F0: the faces where the rounded labelling changes are exactly the chain
    W = w > 0.5
    ch = (ft >= 0).all(axis=1) & (W[np.maximum(ft[:, 0], 0)] != W[np.maximum(ft[:, 1], 0)])
    assert np.array_equal(ch, G != 0)


def test_jump_coordinates_exclude_chain_boundary():
    K = _ball(200)
    G = np.zeros(K.n_faces)
    G[np.flatnonzero((K.face_tets >= 0).all(axis=1))[0]] = 1.0     # a single face: its 3 vertices are ∂Γ
    ex = chain_boundary_vertices(K, G)
    assert ex.sum() == 3
    c, ex2 = K.jump_coordinates(G)
    assert np.array_equal(ex, ex2)
    assert np.all(c[np.isin(K.T, np.flatnonzero(ex))] == 0)


@pytest.mark.parametrize("T, msg", [
    (np.zeros((2, 3), dtype=int), "shape"),
    (np.array([[0, 1, 2, 99]]), "indices"),
    (np.array([[0, 1, 2, 2]]), "repeats"),
    (np.array([[0.0, 1, 2, 3]]), "integer"),
    (np.array([[True, False, True, False]]), "integer"),
    (np.zeros((0, 4), dtype=int), "empty"),
])
def test_bad_tets(T, msg):
    V = np.eye(4)[:, :3]
    with pytest.raises(ValueError, match=msg):
        TetComplex(V, T)


def test_bad_chain():
    K = _ball(50)
    with pytest.raises(ValueError, match="G"):
        K.jump_coordinates(np.zeros(3))
    with pytest.raises(ValueError, match="G"):
        K.jump_coordinates(np.full(K.n_faces, np.nan))


def _disk_chain(K):
    """The meridian disk {φ = 0, x > 0} of the solid torus as an oriented face chain."""
    c = K.V[K.T].mean(axis=1)
    lab = np.arctan2(c[:, 1] + 1e-3, c[:, 0]) > 0
    ft = K.face_tets
    l0, l1 = lab[np.maximum(ft[:, 0], 0)], lab[np.maximum(ft[:, 1], 0)]
    fc = K.V[K.faces].mean(axis=1)
    sel = (ft >= 0).all(axis=1) & (l0 != l1) & (fc[:, 0] > 0)
    G = np.zeros(K.n_faces)
    G[sel] = np.where(l0[sel], 1.0, -1.0)
    return G


def test_hodge_decomposition_of_gsdf_dec_on_tets():
    K = _ball(150)
    H = K.hodge()
    assert H.harmonic_basis().shape[1] == 0
    omega = np.random.default_rng(3).normal(size=K.n_edges)
    assert np.linalg.norm(H.decompose(omega).harmonic) < 1e-6 * np.linalg.norm(omega)
    Kt = _solid_torus()
    assert Kt.hodge().harmonic_basis().shape[1] == 1
    # the disk's boundary lies on the hull: no star walk is path dependent
    G = _disk_chain(Kt)
    assert not chain_boundary_vertices(Kt, G).any()


def test_correction_chain_removes_the_harmonic_part_on_a_solid_torus():
    from gsdf.dec._tet import correction_chain
    K = _solid_torus()
    H = K.hodge()
    G = _disk_chain(K)
    c, _ = K.jump_coordinates(G)
    omega = K.darboux_derivative(c)
    gamma = H.decompose(omega).harmonic
    r0 = np.linalg.norm(gamma) / np.linalg.norm(omega)
    assert r0 > 0.1                      # the disk's jump winds around the hole
    # the period of γ around the core circle is the jump of the disk, 1
    Lam, info = correction_chain(K, gamma)
    big = np.abs(Lam) > 0.5
    assert 0 < big.sum() < 0.05 * K.n_faces          # concentrated on a cut surface (L0), not spread
    assert np.all(np.abs(np.abs(Lam[big]) - 1) < 0.05)
    c2, _ = K.jump_coordinates(G + Lam)
    om2 = K.darboux_derivative(c2)
    assert np.linalg.norm(H.decompose(om2).harmonic) < 0.2 * r0 * np.linalg.norm(om2)
    with pytest.raises(ValueError, match="gamma"):
        correction_chain(K, np.zeros(3))
