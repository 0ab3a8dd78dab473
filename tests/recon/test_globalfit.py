"""Tests of the global least-squares fit of all vertex positions (gsdf.recon._globalfit, reconstruct(fit=True)):
geometry only (faces and the sphere topology unchanged), pleats unfolded, closer to the samples of an analytic
surface, bad input refused by name."""

import numpy as np
import pytest

import gsdf
from gsdf.mesh._topology import is_sphere
from gsdf.recon._globalfit import fit_to_samples


def _icosphere(levels):
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
                  [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    V /= np.linalg.norm(V, axis=1)[:, None]
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    for _ in range(levels):
        E = np.sort(np.concatenate([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]]), axis=1)
        uniq, inv = np.unique(E, axis=0, return_inverse=True)
        m = len(V) + inv.ravel().reshape(3, len(F)).T
        M = 0.5 * (V[uniq[:, 0]] + V[uniq[:, 1]])
        V = np.concatenate([V, M / np.linalg.norm(M, axis=1)[:, None]])
        a, b, c = F.T
        ma, mb, mc = m.T
        F = np.concatenate([np.stack([a, mc, mb], 1), np.stack([mc, b, ma], 1), np.stack([mb, ma, c], 1),
                            np.stack([ma, mb, mc], 1)])
    return V, F


def _fibonacci(n):
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    return np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])


def _inverted(V, F):
    """Faces of a mesh around the origin whose normal points inward."""
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    return int((np.einsum("ij,ij->i", N, V[F].mean(axis=1)) < 0).sum())


def _ellipsoid_error(V, F, abc):
    """Mean first-order distance |g| / |∇g| to the ellipsoid g = Σ x_i² / a_i² − 1 over face centroids and edge
    midpoints."""
    Q = np.concatenate([V[F].mean(axis=1), 0.5 * (V[F[:, 0]] + V[F[:, 1]])])
    a2 = np.asarray(abc, float) ** 2
    g = (Q ** 2 / a2).sum(axis=1) - 1.0
    return float(np.mean(np.abs(g) / np.linalg.norm(2 * Q / a2, axis=1)))


def test_fit_unfolds_a_pleat_and_keeps_the_sphere():
    V, F = _icosphere(3)                                   # 642 vertices, 1280 faces, edge ≈ 0.1
    W = V.copy()
    cap = W[:, 2] > 0.9                                    # a mirrored cap: its faces turned inside out
    W[cap, 0] *= -1
    n_inv = _inverted(W, F)
    assert n_inv >= 40 and is_sphere(W, F)
    # samples of the unit sphere, about one per vertex as in the reconstruction (spacing ≈ 0.12)
    S = _fibonacci(800)
    X, rep = fit_to_samples(W, F, S, 0.12, iterations=10, return_report=True)
    assert is_sphere(X, F)                                 # the faces are the input's, so is the topology
    assert _inverted(X, F) == 0                            # the pleat is unfolded
    assert np.abs(np.linalg.norm(X, axis=1) - 1).max() < 0.02
    assert rep["iterations"] == 10 and len(rep["cg_iterations"]) == 10
    # fewer rounds unfold part of it (each round's sample attachment holds the mesh where it is)
    assert 0 < _inverted(fit_to_samples(W, F, S, 0.12, iterations=4), F) < n_inv
    # a mesh already on the surface and unfolded stays so
    Y = fit_to_samples(V, F, S, 0.12)
    assert np.abs(np.linalg.norm(Y, axis=1) - 1).max() < 0.01 and _inverted(Y, F) == 0


def test_fit_moves_a_mesh_onto_an_ellipsoid():
    abc = (1.0, 0.7, 0.5)
    V, F = _icosphere(3)
    V0 = 0.85 * V * np.array(abc)                          # a shrunk copy: every vertex 7-15 % inside
    S = _fibonacci(5000) * np.array(abc)
    e0 = _ellipsoid_error(V0, F, abc)
    X = fit_to_samples(V0, F, S, 0.04, iterations=6)
    e1 = _ellipsoid_error(X, F, abc)
    assert e0 > 0.05
    assert e1 < 0.004                                      # chords of edges ≈ 0.07 on curvature ≤ 4
    assert is_sphere(X, F)


def test_reconstruct_fit_keeps_the_promise_and_the_faces_count():
    rng = np.random.default_rng(3)
    abc = (1.0, 0.6, 0.4)
    D = rng.normal(size=(2500, 3))
    P = D / np.linalg.norm(D, axis=1)[:, None] * np.array(abc)
    out = rng.uniform(-1.2, 1.2, (60, 3))
    P = np.vstack([P, out])
    V1, F1, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
    V0, F0, rep0 = gsdf.reconstruct_simply_connected(P, options=gsdf.ReconstructionOptions(fit=False),
                                                    return_report=True)
    assert is_sphere(V1, F1) and is_sphere(V0, F0)
    assert rep["fit"]["before_flips"]["iterations"] == 4 and rep["fit"]["subdivided"]["iterations"] == 4
    assert rep["timings"]["fit"] > 0
    # both are close to the analytic ellipsoid; the fit is not worse
    e1, e0 = _ellipsoid_error(V1, F1, abc), _ellipsoid_error(V0, F0, abc)
    assert e1 < 0.01 and e1 <= 1.05 * e0
    assert rep0["fit"] is None


@pytest.mark.parametrize("kw, word", [
    (dict(V=np.full((4, 3), np.nan)), "V"),
    (dict(V=np.zeros((4, 2))), "V"),
    (dict(F=np.array([[0, 1, 99]])), "F"),
    (dict(S=np.zeros((2, 3))), "S"),
    (dict(S=np.array([[0.0, np.inf, 0.0]] * 5)), "S"),
    (dict(spacing=0.0), "spacing"),
    (dict(iterations=-1), "iterations"),
    (dict(iterations=1.5), "iterations"),
    (dict(data=-1.0), "data"),
    (dict(membrane=float("nan")), "membrane"),
    (dict(prox=0.0), "prox"),
    (dict(trim=0.0), "trim"),
    (dict(k=2), "k"),
])
def test_fit_to_samples_validates(kw, word):
    V, F = _icosphere(0)
    args = dict(V=V, F=F, S=_fibonacci(50), spacing=0.2)
    args.update(kw)
    with pytest.raises(ValueError, match=word):
        fit_to_samples(args.pop("V"), args.pop("F"), args.pop("S"), args.pop("spacing"), **args)
    with pytest.raises(TypeError):
        fit_to_samples(V, F, _fibonacci(50), 0.2, unknown_option=1)


@pytest.mark.parametrize("bad", ["yes", 1, None, np.array([True])])
def test_reconstruct_fit_option_validates(bad):
    with pytest.raises(ValueError, match="fit"):
        gsdf.ReconstructionOptions(fit=bad)


def _scipy_normal_equations(X, F, S, face, bary, a, foot, nrm, c, membrane, prox):
    """The normal equations assembled the straightforward way (the first implementation of the fit): B from
    the barycentric rows, Bᵀ diag(a) B, the graph Laplacian from unique edges, ⊗ I₃ by scipy.sparse.kron, the
    point-to-plane blocks c n nᵀ as a block-diagonal matrix."""
    import scipy.sparse as sp
    n, m = len(X), len(S)
    B = sp.csr_matrix((bary.ravel(), (np.repeat(np.arange(m), 3), F[face].ravel())), shape=(m, n))
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    E = np.unique(E, axis=0)
    ne = len(E)
    L = sp.csr_matrix((np.r_[np.ones(2 * ne), -np.ones(2 * ne)],
                       (np.r_[E[:, 0], E[:, 1], E[:, 0], E[:, 1]], np.r_[E[:, 0], E[:, 1], E[:, 1], E[:, 0]])),
                      shape=(n, n))
    blocks = [sp.csr_matrix(ci * np.outer(v, v)) for ci, v in zip(c, nrm)]
    M = sp.kron(B.T @ sp.diags(a) @ B + membrane * L + prox * sp.identity(n), sp.identity(3)) + sp.block_diag(blocks)
    eta = nrm * np.einsum("vx,vx->v", nrm, L @ X)[:, None]
    rhs = B.T @ (a[:, None] * S) + (c * np.einsum("vx,vx->v", nrm, foot))[:, None] * nrm + membrane * eta + prox * X
    return M.toarray(), rhs


def test_operator_form_matches_the_scipy_assembly():
    """The kernels of the fit (CSR values of the scalar part on the edge pattern, the mat-vec with the rank-1
    blocks, the Sherman–Morrison block-Jacobi, the fused CG) against the straightforward scipy assembly, on a
    small mesh with a degenerate face (an edge (v, v)) and an unreferenced vertex."""
    from gsdf.distance._triangles import TriangleDistance
    from gsdf.recon._globalfit import _Pattern, _apply, _block_jacobi, _normal_equations, _pcg

    rng = np.random.default_rng(5)
    V, F = _icosphere(1)
    F = np.vstack([F, [[3, 3, 7]]])                        # degenerate face: corners 0 and 1 the same vertex
    V = np.vstack([V * rng.uniform(0.9, 1.1, (len(V), 1)), [[5.0, 5.0, 5.0]]])      # last vertex unreferenced
    n = len(V)
    S = _fibonacci(300) * 1.02
    _, face, _, bary = TriangleDistance(V, F).query_barycentric(S)
    hit = rng.random(len(S)) < 0.3                         # some samples on the degenerate face, too
    face[np.flatnonzero(hit[:40])] = len(F) - 1
    a = rng.uniform(0, 5, len(S)) * (rng.random(len(S)) < 0.9)
    nrm = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    foot = V + rng.normal(scale=0.05, size=V.shape)
    c = rng.uniform(0, 1, n) * (rng.random(n) < 0.8)
    M, rhs0 = _scipy_normal_equations(V, F, S, face, bary, a, foot, nrm, c, 0.2, 0.01)

    P = _Pattern(F, n)
    vals, kd, rhs = _normal_equations(P, V, F, S, face, bary, a, foot, nrm, c, 0.2, 0.01)
    np.testing.assert_allclose(rhs, rhs0, rtol=1e-12, atol=1e-12)
    x = rng.normal(size=(n, 3))
    y = np.empty_like(x)
    _apply(P.indptr, P.indices, vals, c, nrm, x, y)
    np.testing.assert_allclose(y.ravel(), M @ x.ravel(), rtol=1e-12, atol=1e-12)
    D = np.stack([M[3 * v:3 * v + 3, 3 * v:3 * v + 3] for v in range(n)])
    z = np.empty_like(x)
    _block_jacobi(kd, c, nrm, x, z)
    np.testing.assert_allclose(z, np.einsum("vij,vj->vi", np.linalg.inv(D), x), rtol=1e-10, atol=1e-12)
    X = V.copy()
    its, ok = _pcg(P.indptr, P.indices, vals, c, nrm, kd, rhs, X, 1e-12, 1000)
    assert ok and 0 < its < 1000
    np.testing.assert_allclose(X.ravel(), np.linalg.solve(M, rhs0.ravel()), rtol=1e-9, atol=1e-9)


def test_fit_does_not_depend_on_the_vertex_and_sample_labels():
    """The fit relabels vertices and samples along the Z-order curve inside: a permuted input gives the
    permuted output (to rounding)."""
    V, F = _icosphere(2)
    rng = np.random.default_rng(2)
    W = V * rng.uniform(0.92, 1.08, (len(V), 1))
    S = _fibonacci(700)
    X = fit_to_samples(W, F, S, 0.12)
    p = rng.permutation(len(V))
    r = np.empty_like(p)
    r[p] = np.arange(len(p))
    Y = fit_to_samples(W[p], r[F], S[rng.permutation(len(S))], 0.12)
    np.testing.assert_allclose(Y, X[p], atol=1e-10)
