"""The signed heat method on polygon meshes (§8.3, Bunge et al. 2020 polygon Laplacian)."""

import numpy as np
import pytest
import scipy.sparse as sp

from gsdf.contour import region_boundary_curves
from gsdf.heat import PolygonMeshSignedHeatSolver, SurfaceSignedHeatSolver
from gsdf.data._shapes import sphere_mesh
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.heat.polygon._solver import virtual_vertex_refinement, virtual_vertex_weights


def _quads(n, bump=0.0, jitter=0.0, seed=0):
    x = np.linspace(-1, 1, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), bump * np.sin(3 * X.ravel()) * np.cos(2 * Y.ravel())], 1)
    if jitter:
        inner = (np.abs(V[:, :2]) < 1 - 1e-9).all(1)
        V[inner, :2] += np.random.default_rng(seed).uniform(-jitter, jitter, (int(inner.sum()), 2)) * (2 / n)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    Q = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()], 1)
    return V, Q


def _mixed_planar(n=8, seed=0):
    """Jittered planar mesh of quads, hexagons (two quads merged) and triangles."""
    V, Q = _quads(n, jitter=0.3, seed=seed)
    polys = []
    cells = Q.reshape(n, n, 4)
    for i in range(n):
        j = 0
        while j < n:
            if i % 3 == 0 and j + 1 < n:                      # hexagon: cells (i, j) and (i, j+1) merged
                a, b = cells[i, j], cells[i, j + 1]
                polys.append([a[0], a[1], b[1], b[2], b[3], a[3]])
                j += 2
            elif i % 3 == 1 and j % 2 == 0:                   # two triangles
                c = cells[i, j]
                polys += [[c[0], c[1], c[2]], [c[0], c[2], c[3]]]
                j += 1
            else:
                polys.append(list(cells[i, j]))
                j += 1
    return V, polys


def _uv_sphere(n_lat=16, n_lon=32):
    """UV sphere: quads, triangle fans at the poles; latitude rings are edge loops."""
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")
    V = np.vstack([[0, 0, 1], np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3),
                   [0, 0, -1]])
    idx = 1 + np.arange((n_lat - 1) * n_lon).reshape(n_lat - 1, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    quads = np.stack([idx[:-1], idx[1:], nxt[1:], nxt[:-1]], -1).reshape(-1, 4)
    top = np.stack([np.zeros(n_lon, int), idx[0], nxt[0]], 1)
    bot = np.stack([np.full(n_lon, len(V) - 1), nxt[-1], idx[-1]], 1)
    return V, [list(q) for q in quads] + [list(t) for t in top] + [list(t) for t in bot], idx


def _square_loop(V, Q):
    inside = (np.abs(V[Q].mean(1)[:, :2]) < 0.5).all(1)
    tri = np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    return region_boundary_curves(tri, np.concatenate([inside, inside]))


def test_quad_mesh_square_loop():
    V, Q = _quads(20)
    solver = PolygonMeshSignedHeatSolver(V, Q)
    phi = solver.compute_distance(_square_loop(V, Q))
    assert phi.shape == (len(V),)
    exact = np.abs(V[:, :2]).max(1) - 0.5
    axis = (np.abs(V[:, 0]) < 1e-9) | (np.abs(V[:, 1]) < 1e-9)
    assert np.abs(phi - exact)[axis].max() < 0.05


def test_nonplanar_mixed_polygons_agree_with_triangulation():
    V, Q = _quads(16, bump=0.1)
    polys = [list(q) for q in Q[:-2]] + [[Q[-2][0], Q[-2][1], Q[-2][2]], [Q[-2][0], Q[-2][2], Q[-2][3]]] + [Q[-1]]
    loop = _square_loop(V, Q)
    phi = PolygonMeshSignedHeatSolver(V, polys).compute_distance(loop)
    tri = np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    ref = SurfaceSignedHeatSolver(V, tri).compute_distance(loop)
    assert np.abs(phi - ref).max() < 0.05


def test_virtual_vertex_of_regular_hexagon_is_centre():
    t = np.linspace(0, 2 * np.pi, 6, endpoint=False)
    V = np.stack([np.cos(t) + 2, np.sin(t), 0 * t], 1)
    Vr, Fr, P = virtual_vertex_refinement(V, [np.arange(6)])
    np.testing.assert_allclose(Vr[6], [2, 0, 0], atol=1e-12)
    np.testing.assert_allclose(P.toarray()[6], np.full(6, 1 / 6), atol=1e-12)
    assert len(Fr) == 6


def test_virtual_vertex_minimizes_squared_fan_areas():
    rng = np.random.default_rng(3)
    X = rng.normal(size=(20, 5, 3))                               # nonplanar pentagons
    w = virtual_vertex_weights(X)
    np.testing.assert_allclose(w.sum(1), 1, atol=1e-10)

    def energy(x):                                                # Σ |(x_i - x) × (x_{i+1} - x)|²
        return (np.cross(X - x[:, None], np.roll(X, -1, 1) - x[:, None]) ** 2).sum((1, 2))

    x = np.einsum("qs,qsj->qj", w, X)
    e0 = energy(x)
    for d in np.eye(3):
        for h in (1e-3, -1e-3):
            assert np.all(energy(x + h * d) >= e0 - 1e-12)
    # minimum-norm weights: orthogonal to the null space of [Xᵀ; 1ᵀ]
    K = np.concatenate([np.transpose(X, (0, 2, 1)), np.ones((20, 1, 5))], 1)
    for q in range(20):
        ns = np.linalg.svd(K[q])[2][4:]
        assert np.abs(ns @ w[q]).max() < 1e-8


def test_triangle_mesh_gives_cotan_laplacian_and_barycentric_mass():
    V, F = sphere_mesh(2)
    s = PolygonMeshSignedHeatSolver(V, F)
    ops = TriangleMeshOperators(V, F)
    assert abs(s.L - ops.cotan_laplacian()).max() < 1e-12
    np.testing.assert_allclose(s.M, ops.vertex_mass(), rtol=1e-12)


def test_polygon_laplacian_symmetric_psd_rows_sum_zero_and_mass():
    V, Q = _quads(6, bump=0.3, jitter=0.25)
    polys = [list(q) for q in Q[:-4]] + [[Q[-4][0], Q[-4][1], Q[-3][1], Q[-3][2], Q[-3][3], Q[-4][3]]] + \
        [list(q) for q in Q[-2:]]                                 # one nonplanar hexagon, the rest quads
    s = PolygonMeshSignedHeatSolver(V, polys)
    L = s.L.toarray()
    assert np.abs(L - L.T).max() < 1e-12
    assert np.abs(L.sum(1)).max() < 1e-10
    assert np.linalg.eigvalsh(L).min() > -1e-10
    A = TriangleMeshOperators(s.V_refined, s.F_refined).areas.sum()
    np.testing.assert_allclose(s.M.sum(), A, rtol=1e-12)          # lumped Pᵀ M P keeps the refined area
    # the connection Laplacian is Hermitian PSD and reduces to L where the frames agree
    C = s.Lconn.toarray()
    assert np.abs(C - C.conj().T).max() < 1e-12
    assert np.linalg.eigvalsh(C).min() > -1e-10
    Vp, _ = _quads(6)
    sp_ = PolygonMeshSignedHeatSolver(Vp, polys)
    assert abs(sp_.Lconn - sp.csr_matrix(sp_.L).astype(complex)).max() < 1e-12


def test_linear_precision_on_planar_polygon_mesh():
    V, polys = _mixed_planar(9)
    s = PolygonMeshSignedHeatSolver(V, polys)
    inner = (np.abs(V[:, :2]) < 1 - 1e-9).all(1)
    for u in (V[:, 0], V[:, 1], 2 * V[:, 0] - 3 * V[:, 1] + 1):
        assert np.abs(s.L @ u)[inner].max() < 1e-12


def test_uv_sphere_latitude_loop_matches_geodesic_distance():
    V, polys, idx = _uv_sphere(16, 32)
    r = 5                                                          # latitude ring θ = 6π/16
    loop = np.concatenate([idx[r], idx[r][:1]])                    # counter-clockwise seen from +z: north negative
    s = PolygonMeshSignedHeatSolver(V, polys)
    theta0 = np.arccos(V[idx[r][0], 2])
    exact = np.arccos(np.clip(V[:, 2], -1, 1)) - theta0
    for mode in ("zero", "none", "multiple"):
        phi = s.compute_distance([loop], level_set_constraint=mode)
        assert np.sqrt(np.mean((phi - exact) ** 2)) < 0.01, mode
        assert np.abs(phi - exact).max() < 0.03, mode
    phi = s.compute_distance([loop[::-1]], level_set_constraint="none")   # reversed orientation: negated
    assert np.sqrt(np.mean((phi + exact) ** 2)) < 0.01
    phi = s.compute_distance([loop], level_set_constraint="zero", soft_weight=1e3)
    assert np.sqrt(np.mean((phi - exact) ** 2)) < 0.01


def test_point_source_and_unsigned_curve_on_quads():
    V, Q = _quads(24)
    s = PolygonMeshSignedHeatSolver(V, Q)
    c = int(np.argmin(np.linalg.norm(V, axis=1)))
    phi = s.compute_distance([], points=[c], level_set_constraint="none")
    d = np.linalg.norm(V[:, :2], axis=1)
    assert phi.min() >= -1e-9 and phi[c] < 1e-9
    assert np.abs(phi - d)[d < 0.8].max() < 0.05
    loop = _square_loop(V, Q)
    phi = s.compute_distance(loop, curve_signs=[False], level_set_constraint="zero")
    exact = np.abs(np.abs(V[:, :2]).max(1) - 0.5)
    axis = (np.abs(V[:, 0]) < 1e-9) | (np.abs(V[:, 1]) < 1e-9)
    assert np.abs(phi - exact)[axis].max() < 0.07


def test_polygon_bad_input():
    V, Q = _quads(4)
    with pytest.raises(ValueError, match="at least 3"):
        PolygonMeshSignedHeatSolver(V, [[0, 1]])
    with pytest.raises(ValueError, match="out of range"):
        PolygonMeshSignedHeatSolver(V, [[0, 1, 99]])
    with pytest.warns(UserWarning, match="1 polygons repeat a vertex"):  # dropped, not refused
        s = PolygonMeshSignedHeatSolver(V, list(Q) + [[0, 1, 6, 1]])
    np.testing.assert_allclose(s.compute_distance([], points=[3]),
                               PolygonMeshSignedHeatSolver(V, Q).compute_distance([], points=[3]))
    with pytest.raises(ValueError, match="empty"):
        PolygonMeshSignedHeatSolver(V, [])
    with pytest.raises(ValueError, match="t_coef"):
        PolygonMeshSignedHeatSolver(V, Q, t_coef=-1)
    solver = PolygonMeshSignedHeatSolver(V, Q)
    with pytest.raises(ValueError, match="out of range"):
        solver.compute_distance([np.array([0, 1, 30])])
    with pytest.raises(ValueError, match="not joined by a polygon edge"):
        solver.compute_distance([np.array([0, 6])])                # a quad diagonal
    with pytest.raises(ValueError, match="no sources"):
        solver.compute_distance([])
    with pytest.raises(ValueError, match="level_set_constraint"):
        solver.compute_distance([np.array([0, 1, 2])], level_set_constraint="all")
    with pytest.raises(ValueError, match="curve_signs"):
        solver.compute_distance([np.array([0, 1, 2])], curve_signs=[True, False])


def test_step3_reuses_step1_ordering_and_matches_its_own():
    """Polygon domains order the Dirichlet system of step III by step I's permutation restricted to the free
    vertices (its factor is not flop-heavy: no AMD pass); the distance equals the one with the system ordered on
    its own."""
    from gsdf.linalg._ldl import HINT_AMD_FLOPS, LDLFactorization, _flops, _pattern
    from gsdf.linalg._ordering import order_csr

    V, Q = _quads(12, bump=0.3)
    idx = np.arange(13 * 13).reshape(13, 13)
    loop = np.concatenate([idx[3, 3:9], idx[3:9, 9], idx[9, 9:3:-1], idx[9:2:-1, 3]])
    s = PolygonMeshSignedHeatSolver(V, Q)
    phi = s.compute_distance([loop])
    st = s.core._state()
    full = st["vec"].ordering
    assert full is not None and sorted(full.tolist()) == list(range(len(V)))
    H = sp.csr_matrix(s.domain.vector_heat_matrix())                        # step I: AMD (heat_ordering)
    assert np.array_equal(full, order_csr(H.indptr.astype(np.int64), H.indices.astype(np.int64), len(V), "amd"))
    fact = next(iter(st["poisson"]._cache.values()))
    assert isinstance(fact, LDLFactorization)
    free = np.setdiff1d(np.arange(len(V)), loop)
    rank = np.full(len(V), -1)
    rank[free] = np.arange(len(free))
    induced = rank[full][rank[full] >= 0]
    A = s.domain.L[free][:, free].tocsr()
    ip, ix = A.indptr.astype(np.int64), A.indices.astype(np.int64)
    assert _flops(_pattern(ip, ix, len(free), induced)[4]) < HINT_AMD_FLOPS * len(ix) * np.log2(len(free))
    assert np.array_equal(fact.perm, induced)
    amd = order_csr(ip, ix, len(free), "amd")
    assert not np.array_equal(amd, induced)
    # the same solve with the Dirichlet system ordered on its own: same distance to rounding
    s2 = PolygonMeshSignedHeatSolver(V, Q)
    s2.domain.heat_on_nodes = False
    phi2 = s2.compute_distance([loop])
    fact2 = next(iter(s2.core._state()["poisson"]._cache.values()))
    assert np.abs(phi - phi2).max() <= 1e-10 * np.abs(phi2).max()
    # the induced order's factor solves the reduced system exactly
    b = np.random.default_rng(1).standard_normal(len(free))
    assert np.allclose(A @ fact.solve(b), b, rtol=0, atol=1e-9 * np.abs(b).max())


@pytest.mark.parametrize("bad", [[np.nan] * 4, [0.0, 1.5, 6.0, 5.0], [np.inf, 1, 6, 5]])
def test_polygon_non_integer_indices_refused_not_dropped(bad):
    """A polygon of NaN or fractional indices is refused (np.unique counts NaNs as one value: it must not be
    taken for a polygon repeating a vertex and dropped)."""
    V, Q = _quads(4)
    with pytest.raises(ValueError, match="polygons: vertex indices must be integers"):
        PolygonMeshSignedHeatSolver(V, [np.array(bad, float)] + [np.asarray(q) for q in Q])
