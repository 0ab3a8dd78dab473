"""gpytoolbox's own tests, re-expressed to call gsdf.

Source (read, not copied): github.com/sgsellan/gpytoolbox @ 8dbc5f98, test/test_*.py (MIT). Assets vendored from
test/unit_tests_data (MIT repository; data_source_credit.txt next to them: the bunny is the Stanford bunny) under
data/gpytoolbox/: bunny_oded.obj.gz, cube.obj, hemisphere.obj, cone.obj, example_cube-ascii.ply,
sphere_binary.stl.gz, fox_ascii.stl.gz, sphere_binary_solid_header.stl.gz, mesh-indices.ply.gz. The random
sample points of the tests (gpytoolbox.random_points_on_mesh with the tests' seeds), the decimated meshes and the
png2poly polyline are recorded from gpytoolbox 0.3.8 in data/refs/gpytoolbox.npz (../record_refs.py).
Missing from the snapshot / too large: armadillo.obj, armadillo_with_tex_and_normal.obj, happy_vrip.ply (absent),
bunny.obj (2.4 MB), mountain.obj (1.7 MB): the tests run on the meshes that are present.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse
import scipy.sparse.csgraph

import gsdf
from tests.conformance.helpers import face_normals, normalize_points, ref, stanford_ply

P = "gpytoolbox"


def _near_surface(unpacked, mesh, n):
    r = ref(P)
    V, F = gsdf.read_mesh(unpacked(P, mesh + ".obj"))
    Q, I = r[f"{mesh}_{n}_Q"], r[f"{mesh}_{n}_I"]
    N = face_normals(V, F)
    eps = 1e-3
    return V, F, Q - eps * N[I], Q + eps * N[I]


# ---------------------------------------------------------------------------------------------------------------
# test_fast_winding_number.py
# ---------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("mesh,n", [("bunny_oded", 1000), ("cube", 10000)])
def test_fast_winding_number__bunny_cube(unpacked, mesh, n):
    """test_fast_winding_number.py::test_bunny / test_cube — points 1e-3 off random surface points along the
    face normal: w_out ≈ 0, w_in ≈ 1 (atol 1e-2)."""
    V, F, pin, pout = _near_surface(unpacked, mesh, n)
    assert np.isclose(gsdf.fast_winding_number(V, F, pout), 0, atol=1e-2).all()
    assert np.isclose(gsdf.fast_winding_number(V, F, pin), 1, atol=1e-2).all()


def test_fast_winding_number__precomputed_bvh(unpacked):
    """test_fast_winding_number.py::test_precomputed_bvh — a tree built once (gsdf.FastWindingNumber) gives the
    one-shot values (atol 1e-6) and the same values again (array_equal)."""
    V, F, pin, pout = _near_surface(unpacked, "bunny_oded", 1000)
    fwn = gsdf.FastWindingNumber(V, F)
    np.testing.assert_allclose(fwn(pin), gsdf.fast_winding_number(V, F, pin), atol=1e-6, rtol=0)
    np.testing.assert_allclose(fwn(pout), gsdf.fast_winding_number(V, F, pout), atol=1e-6, rtol=0)
    assert np.array_equal(fwn(pin), fwn(pin))


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): gpytoolbox.winding_number in 3-D routes to the fast tree "
                          "(identical values); gsdf.winding_number is the exact sum, which the tree approximates "
                          "to ~1e-4 this close (1e-3) to the surface", strict=True)
def test_fast_winding_number__winding_number_routes_to_tree(unpacked):
    """test_fast_winding_number.py::test_precomputed_bvh — winding_number(points_in) equals the fast winding
    number within 1e-6."""
    V, F, pin, _ = _near_surface(unpacked, "bunny_oded", 1000)
    np.testing.assert_allclose(gsdf.winding_number(V, F, pin), gsdf.fast_winding_number(V, F, pin), atol=1e-6,
                               rtol=0)


# ---------------------------------------------------------------------------------------------------------------
# test_winding_number.py
# ---------------------------------------------------------------------------------------------------------------


def test_winding_number__squares():
    """test_winding_number.py::test_squares — 2-D: a square (1 inside, 0 outside) and two overlapping squares
    (2 where they overlap) on a 100 x 100 grid over [-2.01, 2.01]^2; allclose."""
    V = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    EC = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    gx, gy = np.meshgrid(np.linspace(-2.01, 2.01, 100), np.linspace(-2.01, 2.01, 100))
    gv = np.vstack((gx.flatten(), gy.flatten())).T
    W = gsdf.winding_number_2d(V, EC, gv)
    W_gt = np.zeros(len(gv))
    W_gt[(gv[:, 0] > -1) & (gv[:, 0] < 1) & (gv[:, 1] > -1) & (gv[:, 1] < 1)] = 1
    assert np.allclose(W, W_gt)
    Vbig = np.vstack((V, V + 1.0))
    ECbig = np.vstack((EC, EC + 4))
    W = gsdf.winding_number_2d(Vbig, ECbig, gv)
    W_gt[(gv[:, 0] > 0) & (gv[:, 0] < 2) & (gv[:, 1] > 0) & (gv[:, 1] < 2)] = 1
    W_gt[(gv[:, 0] > 0) & (gv[:, 0] < 1) & (gv[:, 1] > 0) & (gv[:, 1] < 1)] = 2
    assert np.allclose(W, W_gt)


def test_winding_number__synthetic():
    """test_winding_number.py::test_synthetic — three randomly displaced copies of illustrator.png's polyline
    (recorded); the winding number counts the copies containing each grid point (allclose)."""
    r = ref(P)
    W = gsdf.winding_number_2d(r["synth_V"], r["synth_E"], r["synth_Q"])
    assert np.allclose(W, r["synth_W"])


@pytest.mark.parametrize("mesh", ["bunny_oded", "cube"])
def test_winding_number__meshes(unpacked, mesh):
    """test_winding_number.py::test_meshes — exact winding number 1e-3 inside / outside: 1 / 0 (atol 1e-2)."""
    V, F, pin, pout = _near_surface(unpacked, mesh, 1000)
    assert np.isclose(gsdf.winding_number(V, F, pout), 0.0, atol=1e-2).all()
    assert np.isclose(gsdf.winding_number(V, F, pin), 1.0, atol=1e-2).all()


# ---------------------------------------------------------------------------------------------------------------
# test_signed_distance.py / test_squared_distance.py / test_unsigned_distance.py
# ---------------------------------------------------------------------------------------------------------------


def _is_consistent(sqrD1, sqrD2, C1, C2):
    """gpytoolbox's is_consistent: same squared distances (np.isclose defaults) and closest points (atol 1e-5)."""
    assert np.isclose(sqrD1 - sqrD2, 0).all()
    assert np.isclose(C1 - C2, 0, atol=1e-5).all()


def _gpy_closest(r):
    V, F = r["dec_V"], r["dec_F"]
    return (r["dec_lmb"][:, :, None] * V[F[r["dec_ind"]]]).sum(axis=1)


def test_signed_distance__meshes_magnitude():
    """test_signed_distance.py::test_meshes_magnitude — normalized bunny_oded decimated to 10 % (recorded), 10
    points in [-4, -2]^3: signed distance squared and its closest points agree with squared_distance."""
    r = ref(P)
    V, F, Pq = r["dec_V"], r["dec_F"], r["dec_P"]
    d = gsdf.signed_distance(V, F, Pq)
    ud, face, C = gsdf.unsigned_distance(V, F, Pq, return_closest=True)
    _is_consistent(r["dec_sqrD"], d ** 2, _gpy_closest(r), C)
    _is_consistent(ud ** 2, d ** 2, C, C)


def test_signed_distance__precomputed_structures(unpacked):
    """test_signed_distance.py::test_precomputed_structures — normalized bunny_oded and cube, 50 points in
    [-1, 1]^3: distances allclose (1e-6) to the reference call (gpytoolbox's recorded signed distances), and a
    second call is identical."""
    r = ref(P)
    for mesh in ("bunny_oded", "cube"):
        V, F = gsdf.read_mesh(unpacked(P, mesh + ".obj"))
        V = normalize_points(V)
        Pq = 2 * np.random.default_rng(0).random((50, 3)) - 1
        d = gsdf.signed_distance(V, F, Pq)
        assert np.allclose(d, r[f"pre_{mesh}_sd"], atol=1e-6)
        assert np.array_equal(d, gsdf.signed_distance(V, F, Pq))


@pytest.mark.parametrize("mesh", ["bunny_oded", "cube"])
@pytest.mark.parametrize("sign", ["winding", "pseudonormal"])
def test_signed_distance__sign_bunny(unpacked, mesh, sign):
    """test_signed_distance.py::test_sign_bunny — sign of the signed distance 1e-3 outside / inside: +1 / -1
    (gpytoolbox's two back ends, use_cpp True/False, map to gsdf's two sign rules)."""
    V, F, pin, pout = _near_surface(unpacked, mesh, 1000)
    assert np.isclose(np.sign(gsdf.signed_distance(V, F, pout, sign=sign)), 1, atol=1e-2).all()
    assert np.isclose(np.sign(gsdf.signed_distance(V, F, pin, sign=sign)), -1, atol=1e-2).all()


def test_squared_distance__find_closest_point_3d_pointcloud():
    """test_squared_distance.py::test_find_closest_point_3d_pointcloud — clouds of 10, 110, ..., 1910 random
    points; the query P[9] + 1e-5 finds index 9 at distance sqrt(3) 1e-5 (atol 1e-5)."""
    np.random.seed(0)
    for ss in range(10, 2000, 100):
        Pc = np.random.rand(ss, 3)
        ptest = Pc[9, :] + 1e-5
        d, ind, closest = gsdf.point_cloud_distance(Pc, ptest[None], return_closest=True)
        assert int(np.ravel(ind)[0]) == 9
        assert np.isclose(np.ravel(d)[0] - np.sqrt(3) * 1e-5, 0, atol=1e-5)


def test_squared_distance__meshes():
    """test_squared_distance.py::test_meshes — the decimated bunny, 10 points in [-4, -2]^3: point-by-point and
    all-at-once queries, a prebuilt tree and a second call all consistent with the reference (gpytoolbox's
    recorded C++ squared_distance)."""
    r = ref(P)
    V, F, Pq = r["dec_V"], r["dec_F"], r["dec_P"]
    d, face, C = gsdf.unsigned_distance(V, F, Pq, return_closest=True)
    _is_consistent(r["dec_sqrD"], d ** 2, _gpy_closest(r), C)
    for i in range(len(Pq)):
        di = gsdf.unsigned_distance(V, F, Pq[i:i + 1])
        assert np.isclose(di[0] ** 2 - r["dec_sqrD"][i], 0)
    tree = gsdf.TriangleDistance(V, F)
    out = tree.query(Pq)
    dt = out[0] if isinstance(out, tuple) else out
    assert np.isclose(np.asarray(dt) ** 2 - r["dec_sqrD"], 0).all()
    out2 = tree.query(Pq)
    assert np.array_equal(np.asarray(out2[0] if isinstance(out2, tuple) else out2), np.asarray(dt))


def test_unsigned_distance__meshes_magnitude():
    """test_unsigned_distance.py::test_meshes_magnitude — unsigned distance squared and closest points agree with
    squared_distance (recorded), also through a prebuilt tree."""
    r = ref(P)
    V, F, Pq = r["dec_V"], r["dec_F"], r["dec_P"]
    d, face, C = gsdf.unsigned_distance(V, F, Pq, return_closest=True)
    _is_consistent(r["dec_sqrD"], d ** 2, _gpy_closest(r), C)


# ---------------------------------------------------------------------------------------------------------------
# test_marching_cubes.py, test_offset_surface.py, test_mesh_boolean.py
# ---------------------------------------------------------------------------------------------------------------


def _marching_cubes_case(unpacked, stride):
    V, F = gsdf.read_mesh(unpacked(P, "bunny_oded.obj"))
    V = normalize_points(V, center=[0.5, 0.5, 0.5])
    gs = 150
    field = gsdf.signed_distance_grid(V, F, resolution=gsdf.Grid.fit(([0, 0, 0], [1, 1, 1]), gs))
    s1 = field.values.ravel()
    U, G = field.isosurface(0.0)
    GV = field.grid_points().reshape(-1, 3)
    s2 = gsdf.signed_distance(U, G, GV[::stride])
    assert np.isclose(s1[::stride], s2, atol=1e-2).all()
    assert np.isclose(gsdf.unsigned_distance(V, F, U) ** 2, 0.0, atol=1e-2).all()


@pytest.mark.slow
def test_marching_cubes__meshes(unpacked):
    """test_marching_cubes.py::test_meshes — bunny_oded normalized into [0,1]^3 (centre 0.5), signed distance on
    the 150^3 grid, its 0-isosurface U, G: the signed distance of the grid to U, G agrees with the first within
    1e-2, and every vertex of U is within squared distance 1e-2 of the bunny. (armadillo.obj: absent.)
    ~1-2 min on 2 cores: run with -m slow."""
    _marching_cubes_case(unpacked, 1)


def test_marching_cubes__meshes_strided(unpacked):
    """test_marching_cubes.py::test_meshes on the same 150^3 grid, the second signed distance checked at every
    97th grid node (the suite's time budget); the vertex check on all of U."""
    _marching_cubes_case(unpacked, 97)


def test_offset_surface__bunny(unpacked):
    """test_offset_surface.py::test_bunny — offsets at 0.05 and 0.1 of bunny_oded on a 50-grid do not intersect.
    (gpytoolbox checks with do_meshes_intersect; gsdf has no triangle–triangle test, so: every vertex of the
    0.1 offset lies outside the 0.05 offset and every vertex of the 0.05 offset inside the 0.1 offset.)"""
    V, F = gsdf.read_mesh(unpacked(P, "bunny_oded.obj"))
    field = gsdf.signed_distance_grid(V, F, resolution=gsdf.Grid.around(V, 50, pad=0.3))
    u1, g1 = gsdf.offset_surface(field, 0.05)
    u2, g2 = gsdf.offset_surface(field, 0.1)
    assert (gsdf.signed_distance(u1, g1, u2) > 0).all()
    assert (gsdf.signed_distance(u2, g2, u1) < 0).all()


def _face_components(F):
    F = np.asarray(F)
    m = len(F)
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    key = np.sort(E, axis=1)
    u, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    fid = np.tile(np.arange(m), 3)
    order = np.argsort(inv, kind="stable")
    rows, cols = [], []
    s = inv[order]
    f = fid[order]
    same = np.flatnonzero(s[1:] == s[:-1])
    rows, cols = f[same], f[same + 1]
    A = scipy.sparse.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(m, m))
    return scipy.sparse.csgraph.connected_components(A, directed=False)[0]


def test_mesh_boolean__cubes(unpacked):
    """test_mesh_boolean.py::test_cubes — two unit cubes, the second moved by 100 random displacements in
    [-2, 2]^3 (seed 0): the union is one component and the intersection nonempty iff max |d| <= 1, else two
    components and an empty intersection."""
    np.random.seed(0)
    v1, f1 = gsdf.read_mesh(unpacked(P, "cube.obj"))
    v1 = normalize_points(v1, center=[0.5, 0.5, 0.5])
    v2, f2 = v1.copy(), f1.copy()
    for _ in range(100):
        displacement = 4 * np.random.rand(1, 3) - 2
        u, g = gsdf.mesh_boolean(v1, f1, v2 + displacement, f2, "union")
        n = _face_components(g)
        uu, gg = gsdf.mesh_boolean(v1, f1, v2 + displacement, f2, "intersection")
        if np.max(np.abs(displacement)) <= 1:
            assert n == 1 and len(uu) > 0
        else:
            assert len(uu) == 0 and n == 2


# ---------------------------------------------------------------------------------------------------------------
# test_read_mesh.py / test_write_mesh.py
# ---------------------------------------------------------------------------------------------------------------


def _parse_obj(path):
    V, F = [], []
    for line in open(path):
        t = line.split()
        if t and t[0] == "v":
            V.append([float(x) for x in t[1:4]])
        elif t and t[0] == "f":
            F.append([int(x.split("/")[0]) - 1 for x in t[1:]])
    return np.array(V), np.array(F)


def test_read_mesh__meshes(unpacked):
    """test_read_mesh.py::test_meshes — the Python and C++ readers agree (V isclose, F equal); here gsdf's reader
    against a plain parse of the same OBJ. (armadillo*.obj, bunny.obj, mountain.obj: absent / not vendored.)"""
    p = unpacked(P, "bunny_oded.obj")
    V, F = gsdf.read_mesh(p)
    V0, F0 = _parse_obj(p)
    assert np.isclose(V, V0).all() and (F == F0).all()


STL = [("sphere_binary.stl", 4080, 1360), ("fox_ascii.stl", 1866, 622), ("sphere_binary_solid_header.stl", 4080, 1360)]


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): gsdf.read_mesh always welds STL corners (682 / 311 / 682 vertices); there is no option to "
                          "keep the 3 corners per triangle (gpytoolbox merge_stl=False)", strict=True)
@pytest.mark.parametrize("name,nv,nf", STL)
def test_read_mesh__stl_reader_unmerged(unpacked, name, nv, nf):
    """test_read_mesh.py::test_stl_reader (merge_stl=False) — V and F counts; every vertex is a boundary vertex
    (STL stores each triangle's corners)."""
    V, F = gsdf.read_mesh(unpacked(P, name))
    assert V.shape[0] == nv and F.shape[0] == nf


@pytest.mark.parametrize("name,nv,nf", STL)
def test_read_mesh__stl_reader_merged(unpacked, name, nv, nf):
    """test_read_mesh.py::test_stl_reader (merge_stl=True) — F count, and the merged mesh has no boundary
    vertices. sphere_binary_solid_header.stl: a binary STL whose header starts with "solid" must not be read as
    ASCII (issue #151 of gpytoolbox)."""
    V, F = gsdf.read_mesh(unpacked(P, name))
    assert F.shape[0] == nf
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, c = np.unique(E, axis=0, return_counts=True)
    assert (c == 2).all()     # no boundary edge, hence no boundary vertex


def _ply_cases(unpacked, tmp_path):
    yield "example_cube-ascii.ply", unpacked(P, "example_cube-ascii.ply")
    # gpytoolbox reads the Stanford bunny.ply (3 MB, libigl-tests-data's copy: not vendored); the same layout
    # (ASCII, x y z confidence intensity) holding bunny_oded.obj is generated instead
    p = str(tmp_path / "bunny.ply")
    stanford_ply(p, *gsdf.read_mesh(unpacked(P, "bunny_oded.obj")))
    yield "bunny.ply", p


@pytest.mark.parametrize("which", ["example_cube-ascii.ply", "bunny.ply"])
@pytest.mark.parametrize("binary", [True, False])
def test_read_mesh__ply_read_then_write(unpacked, tmp_path, which, binary):
    """test_read_mesh.py / test_write_mesh.py::test_ply_read_then_write — read, write (binary / ASCII) with no
    attributes, with random normals, with random RGBA colours (0..255), with both; read back: V, F, N, C equal.
    (happy_vrip.ply: absent. gpytoolbox's `np.isclose(V_2, V).all` is never called; here V is checked.)"""
    src = dict(_ply_cases(unpacked, tmp_path))[which]
    V, F = gsdf.read_mesh(src)
    rng = np.random.default_rng(0)
    N = rng.random((len(V), 3))
    C = np.round(rng.random((len(V), 4)) * 255)
    p = str(tmp_path / "temp.ply")
    for vd in ({}, {"nx": N[:, 0], "ny": N[:, 1], "nz": N[:, 2]},
               {"red": C[:, 0], "green": C[:, 1], "blue": C[:, 2], "alpha": C[:, 3]}):
        gsdf.write_mesh(p, V, F, vertex_data=vd or None, binary=binary)
        V2, F2 = gsdf.read_mesh(p)
        assert np.isclose(V2, V).all() and (F2 == F).all()
        if vd:
            got = gsdf.read_vertex_data(p)
            for k, v in vd.items():
                assert np.isclose(got[k], v).all()


def test_read_mesh__ply_write_normals_as_one_array(unpacked, tmp_path):
    """test_read_mesh.py::test_ply_read_then_write — write_mesh(..., N=N) with N (n, 3): one per-vertex
    attribute of 3 components, read back as its columns normal_0 .. normal_2. Regression: refused."""
    V, F = gsdf.read_mesh(unpacked(P, "example_cube-ascii.ply"))
    N = np.random.default_rng(1).random((len(V), 3))
    p = str(tmp_path / "temp.ply")
    gsdf.write_mesh(p, V, F, vertex_data={"normal": N})
    got = gsdf.read_vertex_data(p)
    assert np.all(np.column_stack([got[f"normal_{j}"] for j in range(3)]) == N)


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): gsdf writes and reads no per-face attributes (gpytoolbox C with one row per face)",
                   strict=True)
def test_write_mesh__ply_face_colors(unpacked, tmp_path):
    """test_write_mesh.py::test_ply_read_then_write — per_face colours C (m, 4) written and read back."""
    V, F = gsdf.read_mesh(unpacked(P, "example_cube-ascii.ply"))
    C = np.round(np.random.rand(len(F), 4) * 255)
    gsdf.write_mesh(str(tmp_path / "temp.ply"), V, F, face_data={"red": C[:, 0]})


def test_read_mesh__ply_index_vs_indices_faces(unpacked):
    """test_read_mesh.py::test_ply_index_vs_indices_faces — a PLY naming its face list 'vertex_index': 934
    faces."""
    V, F = gsdf.read_mesh(unpacked(P, "mesh-indices.ply"))
    assert F.shape[0] == 934


@pytest.mark.parametrize("mesh", ["bunny_oded.obj", "cone.obj", "hemisphere.obj"])
def test_write_mesh__obj_read_then_write(unpacked, tmp_path, mesh):
    """test_write_mesh.py::test_obj_read_then_write (and the meshes of test_obj_default_Ft_Fn) — write, read
    back: V isclose, F equal (UV / normals: gsdf writes none)."""
    V, F = gsdf.read_mesh(unpacked(P, mesh))
    p = str(tmp_path / "temp.obj")
    gsdf.write_mesh(p, V, F)
    V2, F2 = gsdf.read_mesh(p)
    assert np.isclose(V2, V).all() and (F2 == F).all()


@pytest.mark.parametrize("mesh", ["sphere_binary.stl", "fox_ascii.stl"])
@pytest.mark.parametrize("binary", [True, False])
def test_write_mesh__stl_read_then_write(unpacked, tmp_path, mesh, binary):
    """test_write_mesh.py::test_stl_read_then_write — write binary / ASCII STL, read back: V isclose, F equal."""
    V, F = gsdf.read_mesh(unpacked(P, mesh))
    p = str(tmp_path / "temp.stl")
    gsdf.write_mesh(p, V, F, binary=binary)
    V2, F2 = gsdf.read_mesh(p)
    assert np.isclose(V2, V).all() and (F2 == F).all()
