"""Intrinsic Delaunay option of the surface signed heat method (Feng & Crane 2024, §9.4, Fig. 22)."""

import numpy as np
import pytest

from gsdf.heat import SurfaceSignedHeatSolver
from gsdf.heat.surface.curves import level_set_curves, region_boundary_curves
from gsdf.heat.surface.intrinsic import intrinsic_delaunay, layout
from gsdf.heat.surface.meshes import anisotropic_mesh, grid_mesh, polygon_sdf_2d
from gsdf.heat.surface.operators import TriangleMeshOperators


def _eps(ops, phi, exact):
    A = ops.vertex_mass()
    return np.sqrt((A * (phi - exact) ** 2).sum() / A.sum()) / (exact.max() - exact.min())


def _disk_loop(V, F, c=(0.03, 0.02), r=0.5):
    inside = np.linalg.norm(V[F].mean(1)[:, :2] - c, axis=1) < r
    (loop,) = region_boundary_curves(F, inside)
    return loop


@pytest.fixture(scope="module")
def sliver():
    V, F = anisotropic_mesh(32, stretch=8)
    loop = _disk_loop(V, F)
    return V, F, loop, polygon_sdf_2d(V, V[loop])


def test_flips_reach_delaunay_and_keep_area_and_fixed_edges(sliver):
    V, F, loop, _ = sliver
    fixed = np.stack([loop[:-1], loop[1:]], 1)
    Fi, L, nflips = intrinsic_delaunay(V, F, fixed)
    assert nflips > 0 and Fi.shape == F.shape
    ops0, ops = TriangleMeshOperators(V, F), TriangleMeshOperators(V, Fi, P=layout(L))
    assert abs(ops.areas.sum() - ops0.areas.sum()) < 1e-12 * ops0.areas.sum() * len(F)   # flat: same total
    # every curve edge is still an edge, with its original length
    e = ops.edge_lookup(fixed[:, 0], fixed[:, 1])
    assert (e >= 0).all()
    np.testing.assert_allclose(ops.edge_len[e], np.linalg.norm(V[fixed[:, 0]] - V[fixed[:, 1]], axis=1))
    # Delaunay: cot-weight of every interior non-curve edge is >= 0 (cotan Laplacian off-diagonals <= 0)
    C = ops.cotan_laplacian().tocoo()
    off = C.row != C.col
    w = -C.data[off]
    r, c = C.row[off], C.col[off]
    curve = set(map(tuple, np.sort(fixed, 1).tolist()))
    free = np.array([(min(a, b), max(a, b)) not in curve for a, b in zip(r, c)])
    assert w[free].min() > -1e-9
    assert (-ops0.cotan_laplacian().tocoo().data).min() < -1.0     # the input has strongly negative weights


def test_sliver_mesh_error_drops(sliver):
    V, F, loop, exact = sliver
    e = []
    for idt in (False, True):
        s = SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=idt)
        phi = s.compute_distance([loop])
        assert np.isfinite(phi).all() and phi.shape == (len(V),)
        e.append(_eps(s.input_ops, phi, exact))
    assert e[1] < 0.03 and e[1] < 0.4 * e[0]


def test_delaunay_mesh_unchanged():
    V, F = grid_mesh(20, jitter=0.25, delaunay=True, seed=3)
    loop = _disk_loop(V, F)
    a = SurfaceSignedHeatSolver(V, F).compute_distance([loop])
    s = SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=True)
    b = s.compute_distance([loop])
    assert s.ops.n_flips == 0
    np.testing.assert_allclose(a, b, atol=1e-9)
    np.testing.assert_allclose(                                # closed unsigned curves work as well
        SurfaceSignedHeatSolver(V, F).compute_distance([loop], curve_signs=[False], level_set_constraint="none"),
        s.compute_distance([loop], curve_signs=[False], level_set_constraint="none"), atol=1e-9)
    for mode in ("none", "multiple"):
        np.testing.assert_allclose(SurfaceSignedHeatSolver(V, F).compute_distance([loop], level_set_constraint=mode),
                                   s.compute_distance([loop], level_set_constraint=mode), atol=1e-9)


def test_sources_on_vertices_caching_and_rejections(sliver):
    V, F, loop, _ = sliver
    s = SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=True)
    phi = s.compute_distance([loop])
    ops, fact = s.ops, s.vector_heat_factorization
    phi2 = s.compute_distance([loop])                      # same curve edges: same triangulation, only solves
    assert s.ops is ops and s.vector_heat_factorization is fact
    np.testing.assert_allclose(phi, phi2)
    # the same curve as surface points at vertices
    vf = s.input_ops.vertex_faces()
    pts = []
    for v in loop:
        f, k = vf.indices[vf.indptr[v]], vf.data[vf.indptr[v]] - 1
        b = np.zeros(3)
        b[k] = 1
        pts.append((int(f), b))
    np.testing.assert_allclose(s.compute_distance([pts]), phi, atol=1e-10)
    # point sources at vertices: unsigned distance, zero-ish minimum at the source
    d = s.compute_distance([], points=[int(np.argmin(np.linalg.norm(V, axis=1)))])
    assert np.isfinite(d).all() and d.min() == 0
    # rejected inputs
    curves = level_set_curves(V, F, np.linalg.norm(V[:, :2], axis=1) - 0.5)
    with pytest.raises(ValueError, match="intrinsic_delaunay"):
        s.compute_distance(curves)
    with pytest.raises(ValueError, match="vertices"):
        s.compute_distance([], points=[(0, np.array([0.2, 0.3, 0.5]))])
    with pytest.raises(ValueError, match="open unsigned"):
        s.compute_distance([loop[:10]], curve_signs=[False])
    with pytest.raises(NotImplementedError):
        s.compute_distance_l1([loop])
    with pytest.raises(ValueError, match="not joined"):
        s.compute_distance([np.array([loop[0], loop[5]])])


def test_sharpen_with_intrinsic(sliver):
    V, F, loop, exact = sliver
    s = SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=True)
    phi = s.compute_distance([loop])
    sharp = s.sharpen(phi, [loop], iterations=300)
    assert np.isfinite(sharp).all() and np.abs(sharp[loop]).max() < 1e-12
