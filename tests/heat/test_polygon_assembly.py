"""Issue 17 fast paths of the surface signed heat method: the per-polygon assembly of the polygon Laplacian, the
connection Laplacian on L's pattern, the cached sources of repeated solves and nested BLAS regions.

Each fast path is checked against an independent construction: the refined mesh's cotan Laplacian and mass
prolonged by sparse products (Bunge et al. 2020 §4), the numpy transport of the connection Laplacian, fresh
sources, and threadpoolctl's own view of the BLAS threads."""

import numpy as np
import scipy.sparse as sp

from gsdf.contour import region_boundary_curves
from gsdf.heat import PolygonMeshSignedHeatSolver, SurfaceSignedHeatSolver
from gsdf.heat.polygon._domain import PolygonDomain, connection_laplacian, frame_transport
from gsdf.data._shapes import sphere_mesh
from gsdf.mesh._triangle_ops import TriangleOperators


def _nonplanar_mixed(seed=0):
    """A bumpy jittered grid of quads, hexagons and triangles (nonplanar polygons of several degrees)."""
    n = 7
    x = np.linspace(-1, 1, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    rng = np.random.default_rng(seed)
    V = np.stack([X.ravel() + 0.05 * rng.normal(size=X.size), Y.ravel() + 0.05 * rng.normal(size=X.size),
                  0.3 * np.sin(2 * X.ravel()) * np.cos(3 * Y.ravel())], 1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    polys = []
    for i in range(n):
        j = 0
        while j < n:
            a = [idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]]
            if i % 3 == 0 and j + 1 < n:
                polys.append([idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i + 1, j + 2], idx[i, j + 2],
                              idx[i, j + 1]])
                j += 2
                continue
            if i % 3 == 1:
                polys += [[a[0], a[1], a[2]], [a[0], a[2], a[3]]]
            else:
                polys.append(a)
            j += 1
    return V, polys


def test_polygon_assembly_equals_prolonged_refined_operators():
    V, polys = _nonplanar_mixed()
    d = PolygonDomain(V, polys)
    fine = TriangleOperators(d.V_refined, d.F_refined, edges=False)
    P = d.P
    L_ref = (P.T @ fine.cotan_laplacian() @ P).toarray()
    M_ref = P.T @ fine.vertex_mass()
    assert np.abs(d.L.toarray() - L_ref).max() < 1e-12 * np.abs(L_ref).max()
    assert np.abs(d.M - M_ref).max() < 1e-12 * M_ref.max()
    assert (d.L != d.L.T).nnz == 0                                   # exactly symmetric
    assert np.abs(d.L @ np.ones(len(V))).max() < 1e-12               # constants in the kernel
    # normals: area-weighted fine normals at the original vertices
    An = np.zeros((len(d.V_refined), 3))
    for k in range(3):
        np.add.at(An, d.F_refined[:, k], fine.normals * fine.areas[:, None])
    N_ref = An[: len(V)] / np.linalg.norm(An[: len(V)], axis=1, keepdims=True)
    assert np.abs(d.N - N_ref).max() < 1e-12
    # steps II–III data equal the fine operators' (gather projects with the fine normals, divergence)
    Y = np.random.default_rng(1).normal(size=(len(d.F_refined), 3))
    assert np.allclose(d.divergence(Y), P.T @ fine.divergence(Y), atol=1e-13)
    assert np.allclose(d.fine_ops.normals, fine.normals)


def test_connection_laplacian_kernel_matches_numpy_transport():
    V, polys = _nonplanar_mixed(seed=2)
    d = PolygonDomain(V, polys)
    Lc = connection_laplacian(d.L, d.N, d.e1, d.e2)
    # independent: the numpy transport on the upper entries, conjugated below
    C = sp.coo_matrix(d.L)
    up = C.row < C.col
    r = frame_transport(d.N, d.e1, d.e2, C.row[up], C.col[up])
    n = len(V)
    ref = sp.csr_matrix((np.concatenate([C.data[up] * r, C.data[up] * np.conj(r), d.L.diagonal()]),
                         (np.concatenate([C.row[up], C.col[up], np.arange(n)]),
                          np.concatenate([C.col[up], C.row[up], np.arange(n)]))), shape=(n, n))
    assert abs(Lc - ref).max() < 1e-13 * abs(ref).max()
    assert (Lc != Lc.conj().T).nnz == 0                              # exactly Hermitian
    # a pattern that is not symmetric takes the numpy path and still gives a Hermitian matrix
    A = sp.csr_matrix(np.triu(d.L.toarray()))
    H = connection_laplacian(A, d.N, d.e1, d.e2)
    assert abs(H - H.conj().T).max() == 0


def test_planar_quads_take_the_pseudo_inverse_and_keep_exact_answers():
    # a planar quad grid (every quad on the slow, pseudo-inverse path of the weights): linear precision
    x = np.linspace(-1, 1, 7)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    idx = np.arange(49).reshape(7, 7)
    Q = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()], 1)
    d = PolygonDomain(V, Q)
    assert np.allclose(d.P[49:].toarray().sum(1), 1.0)
    assert np.allclose(d.V_refined[49:, :2], V[Q].mean(1)[:, :2])    # squares: virtual vertex = centre
    inner = np.flatnonzero((np.abs(V[:, :2]) < 1 - 1e-9).all(1))
    f = 2.0 * V[:, 0] - V[:, 1]                                        # linear: L f = 0 inside
    assert np.abs((d.L @ f)[inner]).max() < 1e-12


def test_repeated_solves_reuse_sources_and_follow_changed_curves():
    V, F = sphere_mesh(3)
    s = SurfaceSignedHeatSolver(V, F)
    loop = region_boundary_curves(F, V[F].mean(1)[:, 2] < 0.3)      # vertex loops along edges
    a = s.compute_distance(loop)
    S1 = s.core._last_sources[1]
    b = s.compute_distance(loop)
    assert s.core._last_sources[1] is S1                              # no second assembly
    assert np.array_equal(a, b)
    fresh = SurfaceSignedHeatSolver(V, F).compute_distance([c.copy() for c in loop])
    assert np.abs(a - fresh).max() < 1e-12
    # the same array objects with new contents (reversed in place): a new key, new sources, φ negated
    arrs = [np.array(c) for c in loop]
    s.compute_distance(arrs)
    for c in arrs:
        c[:] = c[::-1].copy()
    assert np.abs(s.compute_distance(arrs) + a).max() < 1e-12 * np.abs(a).max()
    # other curves
    other = region_boundary_curves(F, V[F].mean(1)[:, 2] < -0.2)
    arr = [np.asarray(c) for c in other]
    ref = SurfaceSignedHeatSolver(V, F).compute_distance(arr)
    got = s.compute_distance(arr)
    assert np.abs(got - ref).max() < 1e-12
    # polygon meshes too, and a bad repeated call still raises each time
    p = PolygonMeshSignedHeatSolver(V, F)
    x = p.compute_distance(loop)
    assert np.array_equal(x, p.compute_distance(loop))
    for _ in range(2):
        try:
            p.compute_distance([np.array([0, len(V) + 5])])
        except ValueError as exc:
            assert "out of range" in str(exc)
        else:
            raise AssertionError("no ValueError")


def test_nested_blas_regions_restore_the_outer_limit():
    from threadpoolctl import threadpool_info

    from gsdf import threads

    def blas():
        return sorted({d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"})

    before = blas()
    with threads.blas_region(1):
        with threads.blas_region(1):                                  # same limit: nothing set
            assert blas() in ([1], [])
        with threads.blas_region(2):
            assert blas() in ([2], [1], [])                           # a 1-thread BLAS build stays at 1
        assert blas() in ([1], [])
    assert blas() == before


def test_prolongation_csr_equals_the_coo_build_and_connection_fast_path():
    """P is built directly in canonical CSR: bit-identical to scipy's COO conversion of (virtual vertex,
    corner, weight) triplets; the connection Laplacian without the transpose check equals the checked one."""
    from gsdf.heat.polygon._domain import virtual_vertex_weights

    V, polys = _nonplanar_mixed()
    d = PolygonDomain(V, polys)
    n = len(V)
    rows, cols, vals = [np.arange(n)], [np.arange(n)], [np.ones(n)]
    nv = n
    for s in sorted({len(p) for p in polys}):                 # the domain numbers virtual vertices by degree
        if s == 3:
            continue
        Q = np.array([p for p in polys if len(p) == s])
        w = virtual_vertex_weights(V[Q])
        rows.append(np.repeat(nv + np.arange(len(Q)), s))
        cols.append(Q.ravel())
        vals.append(w.ravel())
        nv += len(Q)
    P_ref = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(nv, n))
    assert d.P.shape == P_ref.shape
    for k in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(d.P, k), getattr(P_ref, k))
    assert np.allclose(d.V_refined[n:], P_ref[n:] @ V, rtol=0, atol=1e-14)
    fast = connection_laplacian(d.L, d.N, d.e1, d.e2, symmetric_pattern=True)
    slow = connection_laplacian(d.L, d.N, d.e1, d.e2)
    assert (fast != slow).nnz == 0 and (fast != d.Lconn).nnz == 0
    assert (fast != fast.conj().T).nnz == 0                   # exactly Hermitian


def test_flat_polygon_layout_pattern_and_vector_heat_matrix_equal_the_coo_builds():
    """The polygon Laplacian's CSR pattern from the incidence (polygon_csr_pattern) and its slot-summed values
    are bit-identical to coo_to_csr of the (corner, corner) triplets in polygon order; the vector heat matrix
    built in one pass equals diags(M) + t · Lconn; a repeated vertex names the polygon's input index."""
    import pytest

    from gsdf.heat.polygon._kernels import polygon_csr_pattern
    from gsdf.heat.polygon._domain import _parse_polygons
    from gsdf.linalg._assembly import coo_to_csr

    V, polys = _nonplanar_mixed()
    n = len(V)
    start, corners = _parse_polygons(polys, n)
    sizes = np.diff(start)
    assert np.all(np.diff(sizes) >= 0)                             # ascending degree
    order = np.argsort([len(p) for p in polys], kind="stable")
    assert np.array_equal(corners, np.concatenate([polys[k] for k in order]))
    rows = np.concatenate([np.repeat(corners[a:b], b - a) for a, b in zip(start[:-1], start[1:])])
    cols = np.concatenate([np.tile(corners[a:b], b - a) for a, b in zip(start[:-1], start[1:])])
    vals = np.random.default_rng(2).normal(size=len(rows))
    ref = coo_to_csr(rows, cols, vals, (n, n))
    indptr, indices, slot = polygon_csr_pattern(start, corners, n)
    assert np.array_equal(indptr, ref.indptr) and np.array_equal(indices, ref.indices)
    assert np.array_equal(np.bincount(slot, weights=vals, minlength=len(indices)), ref.data)
    d = PolygonDomain(V, polys)
    A = d.vector_heat_matrix()
    B = (sp.diags(d.Mv.astype(np.complex128)) + d.t * d.Lconn).tocsr()
    B.sort_indices()
    for k in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(A, k), getattr(B, k))
    # steps II–III kernels: the numpy prolongation / projection and bincount divergence, to rounding
    rng = np.random.default_rng(4)
    X = rng.normal(size=n) + 1j * rng.normal(size=n)
    Xf = d.P @ d.to_3d(X)
    Yr = Xf[d.F_refined].sum(axis=1)
    Yr -= d._fine_normals * np.einsum("fj,fj->f", Yr, d._fine_normals)[:, None]
    np.testing.assert_allclose(d.gather(X), Yr, rtol=0, atol=1e-14 * np.abs(Yr).max())
    Y = rng.normal(size=Yr.shape)
    bf = np.bincount(d.F_refined.ravel(), weights=np.einsum("fkj,fj->fk", d._fine_G, Y).ravel(),
                     minlength=d.P.shape[0])
    br = d.P.T @ bf
    np.testing.assert_allclose(d.divergence(Y), br, rtol=0, atol=1e-14 * np.abs(br).max())
    bad = [list(p) for p in polys]
    bad[5] = [bad[5][0]] + list(bad[5])[:-1] if len(bad[5]) > 3 else [bad[5][0], bad[5][0], bad[5][1]]
    with pytest.raises(ValueError, match=r"polygons\[5\]: repeats a vertex"):
        PolygonDomain(V, bad)
