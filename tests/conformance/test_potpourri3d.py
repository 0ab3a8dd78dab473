"""potpourri3d's own tests (test/potpourri3d_test.py) and the signed-heat cases of its test/sample.py,
re-expressed to call gsdf.

Source (read, not copied): github.com/nmwsharp/potpourri3d @ aa509f0a (MIT). Assets vendored under
data/potpourri3d/ with its LICENSE: bunny_small.ply.gz, bunny_poly.ply.gz. sample.py draws pictures and asserts
nothing: its cases are compared with potpourri3d 1.4.0's own answers, recorded once by ../record_refs.py into
data/refs/potpourri3d.npz, and, where the two disagree, with an analytic answer (spheres) to say which is right.

Sign conventions found (every row measured here):

- ``MeshSignedHeatSolver``: gsdf(C) = potpourri3d(C reversed). Without point sources that is −potpourri3d(C)
  (docs/formats.md's rule); with point sources it is not (issue 32: relative L2 0.88 between gsdf and
  −potpourri3d).
- ``PolygonMeshHeatSolver.compute_signed_distance`` and ``PointCloudHeatSolver.compute_signed_distance``: the same
  sign as gsdf (no negation).
"""

from __future__ import annotations

import numpy as np
import pytest

import gsdf
from tests.conformance.cases import (PP3D_BROKEN, PP3D_CLOUD_CURVE, PP3D_POINTS, PP3D_POLY_CURVE, PP3D_SP_CURVE,
                   fibonacci_sphere_case, uv_sphere_polygons)
from tests.conformance.helpers import ref, rel_l2

P = "potpourri3d"
AGREE = 1e-6        # "the same answer": the triangle-mesh solvers agree to 6e-8 - 9e-8 (relative L2)
CLOSE = 1e-2        # two implementations of the same method on polygon meshes / clouds


def generate_verts(n_pts=999):
    np.random.seed(777)
    return np.random.rand(n_pts, 3)


def generate_faces(n_pts=999):
    np.random.seed(777)
    rand_faces = np.random.randint(0, n_pts, size=(2 * n_pts, 3))
    coverage_faces = np.arange(n_pts).reshape(-1, 3)
    return np.vstack((rand_faces, coverage_faces))


@pytest.fixture(scope="module")
def bunny(unpacked):
    return gsdf.read_mesh(unpacked(P, "bunny_small.ply"))


@pytest.fixture(scope="module")
def solver(bunny):
    return gsdf.SurfaceSignedHeatSolver(*bunny)


# ---------------------------------------------------------------------------------------------------------------
# potpourri3d_test.py
# ---------------------------------------------------------------------------------------------------------------


def test_write_read_mesh(tmp_path):
    """potpourri3d_test.py::test_write_read_mesh — a random soup (999 vertices, 2331 faces, some repeating a
    vertex) written as OBJ and read back: max |V - Vnew| < 1e-6, F equal."""
    V, F = generate_verts(), generate_faces()
    p = str(tmp_path / "test.obj")
    gsdf.write_mesh(p, V, F)
    Vnew, Fnew = gsdf.read_mesh(p)
    assert np.amax(np.abs(V - Vnew)) < 1e-6
    assert (F == Fnew).all()


@pytest.mark.parametrize("ext", ["obj", "ply"])
def test_write_read_point_cloud(tmp_path, ext):
    """potpourri3d_test.py::test_write_read_point_cloud — 999 random points written as OBJ / PLY and read back:
    max |V - Vnew| < 1e-6."""
    V = generate_verts()
    p = str(tmp_path / f"test_cloud.{ext}")
    gsdf.write_points(p, V)
    Vnew, _ = gsdf.read_points(p)
    assert np.amax(np.abs(V - Vnew)) < 1e-6


def test_mesh_heat_distance():
    """potpourri3d_test.py::test_mesh_heat_distance — distance from vertex 7 and from [1, 2, 3] on the random
    soup: one value per vertex (stateful solver and one-off calls). The soup has faces that repeat a vertex:
    dropped with a warning. Regression: the mesh was refused ('F: face 986 repeats a vertex')."""
    V, F = generate_verts(), generate_faces()
    with pytest.warns(UserWarning, match="repeat a vertex"):
        s = gsdf.SurfaceSignedHeatSolver(V, F)
    assert s.compute_distance([], points=[7]).shape[0] == V.shape[0]
    assert s.compute_distance([], points=[1, 2, 3]).shape[0] == V.shape[0]


def test_point_cloud_distance():
    """potpourri3d_test.py::test_point_cloud_distance — distance from point 7 and from [1, 2, 3] on 999 random
    points (no normals): one value per point."""
    Pc = generate_verts()
    s = gsdf.PointCloudSignedHeatSolver(Pc)
    assert s.compute_distance([], points=[7]).shape[0] == Pc.shape[0]
    assert s.compute_distance([], points=[1, 2, 3]).shape[0] == Pc.shape[0]


# ---------------------------------------------------------------------------------------------------------------
# sample.py: MeshSignedHeatSolver on bunny_small.ply
# ---------------------------------------------------------------------------------------------------------------


def test_sample_mesh_unsigned(solver):
    """sample.py — compute_distance(curves, [False]*3, points): three unsigned broken curves and two points."""
    r = ref(P)
    phi = solver.compute_distance([gsdf.Curve(c, signed=False) for c in PP3D_BROKEN], points=PP3D_POINTS)
    assert rel_l2(phi, r["unsigned"]) < 1e-3     # measured 4.2e-4


def test_sample_mesh_signed_zero(solver):
    """The broken signed curves of sample.py with potpourri3d's defaults (ZeroSet): gsdf = −potpourri3d."""
    r = ref(P)
    phi = solver.compute_distance([gsdf.Curve(c) for c in PP3D_BROKEN])
    assert rel_l2(phi, -r["signed_zero"]) < AGREE


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): preserve_source_normals=True has no gsdf counterpart: with it potpourri3d's "
                          "level_set_constraint='none' values differ from gsdf's by 1.1 % (relative L2)", strict=True)
def test_sample_mesh_signed_none_preserve_normals(solver):
    """sample.py — compute_distance(curves, [], [], preserve_source_normals=True, level_set_constraint='none')."""
    r = ref(P)
    phi = solver.compute_distance([gsdf.Curve(c) for c in PP3D_BROKEN], level_set_constraint="none")
    assert rel_l2(phi, -r["signed_none"]) < AGREE


def _surface_point(F, idx, coords):
    """potpourri3d's SurfacePoint (idx, []) vertex / (idx, [a, b(, c)]) face point -> (face, barycentric)."""
    if len(coords) == 0:
        f = int(np.flatnonzero((F == idx).any(axis=1))[0])
        b = np.zeros(3)
        b[list(F[f]).index(idx)] = 1.0
        return f, b
    return idx, np.array([coords[0], coords[1], 1.0 - coords[0] - coords[1]])


def test_sample_mesh_surface_point_curve(bunny, solver):
    """sample.py — sp_dist: one curve through vertices and face points (barycentric), ZeroSet."""
    r = ref(P)
    curve = gsdf.Curve([_surface_point(bunny[1], i, c) for i, c in PP3D_SP_CURVE])
    phi = solver.compute_distance([curve])
    assert rel_l2(phi, -r["sp_zero"]) < AGREE


def test_sample_mesh_mixed_reversed_curves(solver):
    """The sign rule (docs/formats.md): gsdf(C) = potpourri3d(C reversed). sample.py's mixed case (signed curves
    and point sources, ZeroSet) against potpourri3d with every curve reversed: equal (measured 2.7e-8). Against
    the negative of potpourri3d's own mixed result — the rule documented before, which holds for signed curves
    alone (test_sample_mesh_signed_zero) — it is 0.88 off: the point distances do not flip."""
    r = ref(P)
    phi = solver.compute_distance([gsdf.Curve(c) for c in PP3D_BROKEN], points=PP3D_POINTS)
    assert rel_l2(phi, r["mixed_zero_reversed"]) < AGREE
    assert rel_l2(phi, -r["mixed_zero"]) > 0.5


# ---------------------------------------------------------------------------------------------------------------
# sample.py: PolygonMeshHeatSolver on bunny_poly.ply, and an analytic polygon mesh
# ---------------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def poly(unpacked):
    V, polys = gsdf.read_mesh(unpacked(P, "bunny_poly.ply"), triangulate=False)
    return V, polys


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): gsdf and potpourri3d differ by 6.7 % (relative L2) on bunny_poly; on the analytic UV "
                          "sphere (next tests) gsdf is 0.8 % from the exact distance, potpourri3d 7.0 %", strict=True)
def test_sample_polygon_unsigned(poly):
    """sample.py — PolygonMeshHeatSolver(V, F).compute_distance([100, 1000])."""
    r = ref(P)
    phi = gsdf.PolygonMeshSignedHeatSolver(*poly).compute_distance([], points=[100, 1000])
    assert rel_l2(phi, r["poly_unsigned"]) < CLOSE


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): gsdf and potpourri3d differ by 5.4 % (relative L2) on bunny_poly (same sign "
                          "convention); on the analytic UV sphere both are within 0.12 % of the exact signed "
                          "distance", strict=True)
def test_sample_polygon_signed(poly):
    """sample.py — PolygonMeshHeatSolver(V, F).compute_signed_distance([curve]) (ZeroSet)."""
    r = ref(P)
    phi = gsdf.PolygonMeshSignedHeatSolver(*poly).compute_distance([gsdf.Curve(PP3D_POLY_CURVE)])
    assert rel_l2(phi, r["poly_signed"]) < CLOSE


def test_analytic_polygon_sphere_unsigned():
    """UV sphere of quads (64 x 32), distance from a vertex beside the equator; exact arccos(p . p0): gsdf within
    2 % and closer than potpourri3d (recorded: 7.0 %)."""
    r = ref(P)
    V, polys, src, _ = uv_sphere_polygons()
    exact = np.arccos(np.clip(V @ V[src], -1, 1))
    phi = gsdf.PolygonMeshSignedHeatSolver(V, polys).compute_distance([], points=[src])
    assert rel_l2(phi, exact) < 2e-2
    assert rel_l2(phi, exact) <= rel_l2(r["uvsphere_dist"], exact)


def test_analytic_polygon_sphere_signed():
    """The same UV sphere, signed distance to the ring beside the equator (counter-clockwise from +z): exact
    = polar angle - the ring's; gsdf within 1 % (potpourri3d recorded: same sign, 0.11 %)."""
    r = ref(P)
    V, polys, _, loop = uv_sphere_polygons()
    exact = np.arccos(np.clip(V[:, 2], -1, 1)) - np.arccos(V[loop[0], 2])
    phi = gsdf.PolygonMeshSignedHeatSolver(V, polys).compute_distance([gsdf.Curve(loop)])
    assert rel_l2(phi, exact) < 1e-2
    assert rel_l2(r["uvsphere_signed"], exact) < 1e-2      # the peer's sign agrees with gsdf's


# ---------------------------------------------------------------------------------------------------------------
# sample.py: PointCloudHeatSolver on the vertices of bunny_poly.ply, and an analytic cloud
# ---------------------------------------------------------------------------------------------------------------


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): gsdf and potpourri3d differ by 9.8 % / 14 % (relative L2) on the bunny cloud; on the "
                          "analytic Fibonacci sphere gsdf is 3.5 % from the exact distance, potpourri3d 1.6 %",
                   strict=True)
@pytest.mark.parametrize("sources,key", [([4], "cloud_dist4"), ([4, 13, 784], "cloud_dist_multi")])
def test_sample_cloud_unsigned(poly, sources, key):
    """sample.py — PointCloudHeatSolver(P).compute_distance(4) / compute_distance_multisource([4, 13, 784])."""
    r = ref(P)
    phi = gsdf.PointCloudSignedHeatSolver(poly[0], r["cloud_normals"]).compute_distance([], points=sources)
    assert rel_l2(phi, r[key]) < CLOSE


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): gsdf and potpourri3d differ by 0.65 (potpourri3d's PCA normals, inconsistent) / 0.47 "
                          "(normals made consistent) relative L2 on the bunny cloud; not a sign convention (same "
                          "sign). Against the polygon-mesh solution with the polygon curve gsdf's cloud is 9.6 % "
                          "off, potpourri3d's 30 %; on the analytic sphere gsdf 1.3 %, potpourri3d 2.1 %",
                   strict=True)
@pytest.mark.parametrize("normals,key", [("cloud_normals", "cloud_signed"),
                                         ("cloud_normals_consistent", "cloud_signed_consistent")])
def test_sample_cloud_signed(poly, normals, key):
    """sample.py — compute_signed_distance(curves, basisN, ZeroSet) on the bunny cloud (and with the normals made
    consistent with the polygon mesh's outward normals)."""
    r = ref(P)
    phi = gsdf.PointCloudSignedHeatSolver(poly[0], r[normals]).compute_distance([gsdf.Curve(PP3D_CLOUD_CURVE)])
    assert rel_l2(phi, r[key]) < CLOSE


def test_analytic_cloud_sphere_signed():
    """4000-point Fibonacci unit sphere, outward normals, the curve through the points nearest the equator
    (counter-clockwise from +z): exact signed distance −asin(z) (north negative, like a winding number of 1
    inside a counter-clockwise loop); gsdf within 2 % and closer than potpourri3d (recorded: 2.1 %)."""
    r = ref(P)
    Pc, curve = fibonacci_sphere_case()
    exact = -np.arcsin(Pc[:, 2])
    phi = gsdf.PointCloudSignedHeatSolver(Pc, Pc).compute_distance([gsdf.Curve(curve)])
    assert rel_l2(phi, exact) < 2e-2
    assert rel_l2(phi, exact) <= rel_l2(r["sphere_signed"], exact)
    assert rel_l2(r["sphere_signed"], exact) < 5e-2      # potpourri3d's cloud solver: the same sign as gsdf


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): on the analytic cloud gsdf's unsigned point distance is 3.5 % from the exact geodesic "
                          "distance, potpourri3d's 1.6 %", strict=True)
def test_analytic_cloud_sphere_unsigned():
    """The same cloud, distance from point 0: exact arccos(p . p0); gsdf no worse than potpourri3d."""
    r = ref(P)
    Pc, _ = fibonacci_sphere_case()
    exact = np.arccos(np.clip(Pc @ Pc[0], -1, 1))
    phi = gsdf.PointCloudSignedHeatSolver(Pc, Pc).compute_distance([], points=[0])
    assert rel_l2(phi, exact) <= rel_l2(r["sphere_dist0"], exact)
