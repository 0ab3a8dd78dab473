"""Fast paths of the surface signed heat method (issue 17) against the general code they shortcut."""

import numpy as np
import scipy.sparse as sp


def _pinv_weights(X):
    """The reference: minimum-norm affine weights by the SVD pseudo-inverse (rcond 1e-10) of [Aᵀ; 1ᵀ]."""
    q, s, _ = X.shape
    A = X - X.mean(axis=1, keepdims=True)
    B = np.roll(A, -1, axis=1)
    D = B - A
    out = np.zeros((q, s))
    for k in range(q):
        Dx = np.zeros((s, 3, 3))
        Dx[:, 0, 1], Dx[:, 0, 2] = -D[k, :, 2], D[k, :, 1]
        Dx[:, 1, 0], Dx[:, 1, 2] = D[k, :, 2], -D[k, :, 0]
        Dx[:, 2, 0], Dx[:, 2, 1] = -D[k, :, 1], D[k, :, 0]
        H = np.einsum("sij,sik->jk", Dx, Dx)
        rhs = -np.einsum("sij,si->j", Dx, np.cross(A[k], B[k]))
        x = np.linalg.lstsq(H, rhs, rcond=None)[0]
        K = np.vstack([A[k].T, np.ones(s)])
        out[k] = np.linalg.pinv(K, rcond=1e-10) @ np.r_[x, 1.0]
    return out


def test_virtual_vertex_weights_fast_path_matches_pseudo_inverse():
    from gsdf.heat.polygon._domain import virtual_vertex_weights

    rng = np.random.default_rng(3)
    nonplanar = rng.normal(size=(40, 5, 3))
    planar = rng.normal(size=(40, 6, 3))
    planar[..., 2] = 0.0
    nearly = planar.copy()
    nearly[..., 2] = 1e-7 * rng.normal(size=(40, 6))
    for X in (nonplanar, planar, nearly):
        w = virtual_vertex_weights(X)
        assert np.allclose(w.sum(1), 1.0, atol=1e-12)
        assert np.abs(w - _pinv_weights(X)).max() < 1e-8


def test_reordered_factorization_solves_the_same_system():
    from gsdf.data._shapes import grid_mesh
    from gsdf.heat.triangle._operators import TriangleMeshOperators
    from gsdf.linalg import Factorization, HermitianFactorization

    V, F = grid_mesh(10)
    ops = TriangleMeshOperators(V, F)
    A = (ops.cotan_laplacian() + sp.diags(ops.vertex_mass())).tocsc()
    b = np.random.default_rng(0).normal(size=(A.shape[0], 2))
    x = Factorization(A, reorder=True).solve(b)
    assert np.abs(A @ x - b).max() < 1e-10 * np.abs(b).max()
    assert np.abs(x - Factorization(A).solve(b)).max() < 1e-10 * np.abs(x).max()
    H = (ops.cr_mass() + ops.h ** 2 * ops.cr_connection_laplacian()).tocsc()
    z = np.random.default_rng(1).normal(size=H.shape[0]) + 1j
    y = HermitianFactorization(H).solve(z)
    assert np.abs(H @ y - z).max() < 1e-10 * np.abs(z).max()


def test_batched_vertex_polylines_equal_the_per_curve_loop():
    from gsdf.contour._surface_curves import region_boundary_curves
    from gsdf.curves import as_curves
    from gsdf.data._shapes import grid_mesh
    from gsdf.heat.triangle._operators import TriangleMeshOperators
    from gsdf.heat.triangle._sources import assemble, parse_curves

    V, F = grid_mesh(16)
    c = V[F].mean(1)
    inside = (np.linalg.norm(c[:, :2] - [0.4, 0.4], axis=1) < 0.3) | (np.linalg.norm(c[:, :2] + 0.4, axis=1) < 0.3)
    loops = region_boundary_curves(F, inside)
    assert len(loops) == 2
    loops.append(np.array([loops[0][0], loops[0][0], loops[0][1]]))     # a repeated vertex is skipped
    ops = TriangleMeshOperators(V, F)
    parts = parse_curves(ops, as_curves(loops))
    fast = assemble(ops, parts)
    loop = assemble(ops, parts, batch=False)                            # the general loop
    assert np.array_equal(fast.X0, loop.X0)
    for name in ("node_rows", "shift_rows"):
        a, b = getattr(fast, name), getattr(loop, name)
        assert (a != b).nnz == 0 and np.array_equal(a.indices, b.indices) and np.array_equal(a.data, b.data)
    for name in ("node_vertex", "node_curve", "shift_weights"):
        assert np.array_equal(getattr(fast, name), getattr(loop, name))
    for a, b in zip(fast.extra["midpoints"], loop.extra["midpoints"]):
        assert np.array_equal(a, b)