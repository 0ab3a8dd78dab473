"""Record, once, the peers' own outputs that some conformance tests use as their reference.

Run with an interpreter that has the peers installed (libigl, potpourri3d, gpytoolbox, point_cloud_utils, open3d,
signedheat3d; versions in inventory.md):

    python tests/conformance/record_refs.py            # all peers
    python tests/conformance/record_refs.py pp3d gpy   # some of them

Writes data/refs/<peer>.npz (small; float64 unless noted). Every array is documented next to where it is made;
the tests say which array they read. Inputs are the vendored assets under data/ (or generated geometry), so the
files can be regenerated bit for bit from the same peer versions (recorded in each file as `versions`).
"""

from __future__ import annotations

import gzip
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))          # the repository root: tests.conformance.* importable
from tests.conformance.cases import (PP3D_BROKEN, PP3D_CLOUD_CURVE, PP3D_POINTS, PP3D_POLY_CURVE, PP3D_SP_CURVE,  # noqa: E402
                   consistent_normals, fibonacci_sphere_case, sample_on_mesh, uv_sphere_polygons)
DATA = HERE / "data"
REFS = DATA / "refs"


def unpack(rel: str) -> str:
    """Path of a vendored asset; .gz assets are decompressed into a temporary file with the original name."""
    p = DATA / rel
    if p.exists():
        return str(p)
    gz = DATA / (rel + ".gz")
    out = Path(tempfile.mkdtemp()) / Path(rel).name
    out.write_bytes(gzip.decompress(gz.read_bytes()))
    return str(out)


def save(name: str, **arrays):
    REFS.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(REFS / f"{name}.npz", **arrays)
    print(f"data/refs/{name}.npz:", ", ".join(f"{k}{np.shape(v)}" for k, v in arrays.items()))


# --------------------------------------------------------------------------------------------------------------
# potpourri3d: the signed heat solvers of test/sample.py (mesh, polygon mesh, point cloud)
# --------------------------------------------------------------------------------------------------------------


def record_pp3d():
    import potpourri3d as pp3d

    V, F = pp3d.read_mesh(unpack("potpourri3d/bunny_small.ply"))
    s = pp3d.MeshSignedHeatSolver(V, F)
    curves = [[(i, []) for i in c] for c in PP3D_BROKEN]
    rcurves = [[(i, []) for i in c[::-1]] for c in PP3D_BROKEN]
    points = [(i, []) for i in PP3D_POINTS]
    out = dict(
        # sample.py: unsigned_dist = compute_distance(curves, [False]*3, points)
        unsigned=s.compute_distance(curves, [False, False, False], points),
        # sample.py: signed_dist = compute_distance(curves, [], [], preserve_source_normals=True, "none", -1)
        signed_none=s.compute_distance(curves, [], [], preserve_source_normals=True, level_set_constraint="none",
                                       soft_level_set_weight=-1),
        # the same signed curves with the default options (ZeroSet): the plain sign convention
        signed_zero=s.compute_distance(curves, [], []),
        # sample.py: sp_dist = compute_distance(sp_curves, [], [], False, "ZeroSet", -1)
        sp_zero=s.compute_distance([PP3D_SP_CURVE], [], [], preserve_source_normals=False,
                                   level_set_constraint="ZeroSet", soft_level_set_weight=-1),
        # sample.py: mixed_dist = compute_distance(curves, [True]*3, points, False, "ZeroSet", -1)
        mixed_zero=s.compute_distance(curves, [True, True, True], points, preserve_source_normals=False,
                                      level_set_constraint="ZeroSet", soft_level_set_weight=-1),
        # the same with every curve reversed (issue 32: gsdf's mixed result matches this one)
        mixed_zero_reversed=s.compute_distance(rcurves, [True, True, True], points, preserve_source_normals=False,
                                               level_set_constraint="ZeroSet", soft_level_set_weight=-1),
    )
    # polygon mesh (sample.py "Polygon mesh test")
    Vp, Fp = pp3d.read_polygon_mesh(unpack("potpourri3d/bunny_poly.ply"))
    ps = pp3d.PolygonMeshHeatSolver(Vp, Fp)
    out["poly_unsigned"] = ps.compute_distance([100, 1000])
    out["poly_signed"] = ps.compute_signed_distance([PP3D_POLY_CURVE])
    # point cloud = the polygon mesh's vertices (sample.py "Point cloud test")
    cs = pp3d.PointCloudHeatSolver(Vp)
    out["cloud_dist4"] = cs.compute_distance(4)
    out["cloud_dist_multi"] = cs.compute_distance_multisource([4, 13, 784])
    _, _, basisN = cs.get_tangent_frames()
    out["cloud_normals"] = basisN
    out["cloud_signed"] = cs.compute_signed_distance([PP3D_CLOUD_CURVE], basisN, preserve_source_normals=False,
                                                     level_set_constraint="ZeroSet", soft_level_set_weight=-1)
    # the same curve, the cloud's normals made consistent with the polygon mesh's outward vertex normals
    ok = consistent_normals(Vp, Fp, basisN)
    out["cloud_signed_consistent"] = cs.compute_signed_distance([PP3D_CLOUD_CURVE], ok,
                                                                preserve_source_normals=False,
                                                                level_set_constraint="ZeroSet",
                                                                soft_level_set_weight=-1)
    out["cloud_normals_consistent"] = ok
    # the polygon mesh's closed curve on the cloud (consistent normals): comparable with the polygon-mesh solution
    loop = PP3D_POLY_CURVE + [PP3D_POLY_CURVE[0]]
    out["cloud_signed_polyloop_consistent"] = cs.compute_signed_distance([loop], ok, preserve_source_normals=False,
                                                                         level_set_constraint="ZeroSet",
                                                                         soft_level_set_weight=-1)
    out["poly_signed_polyloop"] = ps.compute_signed_distance([loop])
    # an analytic cloud: Fibonacci unit sphere (outward normals), the curve through the points nearest the
    # equator (counter-clockwise seen from +z); exact signed geodesic distance asin(z) (up to the sign convention),
    # exact distance from point 0: arccos(p . p0)
    P, curve = fibonacci_sphere_case()
    sc = pp3d.PointCloudHeatSolver(P)
    out["sphere_signed"] = sc.compute_signed_distance([curve], P, preserve_source_normals=False,
                                                      level_set_constraint="ZeroSet", soft_level_set_weight=-1)
    out["sphere_dist0"] = sc.compute_distance(0)
    # an analytic polygon mesh: UV sphere of quads with triangle fans at the poles (uv_sphere_polygons); distance
    # from a vertex next to the equator (exact: arccos), signed distance to a row of vertices (exact: polar-angle
    # difference)
    Vs, Ps, src, loop = uv_sphere_polygons()
    pss = pp3d.PolygonMeshHeatSolver(Vs, Ps)
    out["uvsphere_dist"] = pss.compute_distance([src])
    out["uvsphere_signed"] = pss.compute_signed_distance([loop])
    out["versions"] = np.array([f"potpourri3d {pp3d_version()}"])
    save("potpourri3d", **out)


def pp3d_version():
    from importlib.metadata import version

    return version("potpourri3d")


# --------------------------------------------------------------------------------------------------------------
# gpytoolbox: the sample points of its tests (random_points_on_mesh with the tests' seeds) and reference distances
# --------------------------------------------------------------------------------------------------------------


def record_gpy():
    import gpytoolbox as gpy

    out = {}
    for name, n in (("bunny_oded", 1000), ("cube", 1000), ("cube", 10000)):
        V, F = gpy.read_mesh(unpack(f"gpytoolbox/{name}.obj"), reader="Python")
        Q, I, _ = gpy.random_points_on_mesh(V, F, n, return_indices=True, rng=np.random.default_rng(5))
        out[f"{name}_{n}_Q"] = Q
        out[f"{name}_{n}_I"] = I.astype(np.int64)
        N = gpy.per_face_normals(V, F, unit_norm=True)
        eps = 1e-3
        pin, pout = Q - eps * N[I], Q + eps * N[I]
        out[f"{name}_{n}_fwn_in"] = gpy.fast_winding_number(pin, V, F)
        out[f"{name}_{n}_fwn_out"] = gpy.fast_winding_number(pout, V, F)
    # test_meshes_magnitude / test_meshes (squared_distance): bunny_oded normalized, decimated to 10 %,
    # 10 random points in [-4, -2]^3 (the test draws them unseeded; seeded here)
    v, f = gpy.read_mesh(unpack("gpytoolbox/bunny_oded.obj"), reader="Python")
    v = gpy.normalize_points(v)
    v, f, _, _ = gpy.decimate(v, f, face_ratio=0.1)
    P = 2 * np.random.default_rng(0).random((10, 3)) - 4
    sqrD, ind, lmb = gpy.squared_distance(P, v, F=f, use_cpp=True)
    sd, sind, slmb = gpy.signed_distance(P, v, f, use_cpp=True)
    out.update(dec_V=v, dec_F=f.astype(np.int64), dec_P=P, dec_sqrD=sqrD, dec_ind=ind.astype(np.int64), dec_lmb=lmb,
               dec_sd=sd)
    # test_precomputed_structures: normalized bunny_oded / cube, P = 2 * default_rng(0).random((50, 3)) - 1
    for name in ("bunny_oded", "cube"):
        V, F = gpy.read_mesh(unpack(f"gpytoolbox/{name}.obj"), reader="Python")
        V = gpy.normalize_points(V)
        P = 2 * np.random.default_rng(0).random((50, 3)) - 1
        d, i, l = gpy.signed_distance(P, V, F, use_cpp=True)
        out[f"pre_{name}_sd"] = d
    # test_winding_number.py::test_synthetic: the polyline of illustrator.png (gpytoolbox.png2poly), 1.5 x
    # normalized, three copies displaced by 0.1 * randn(1, 2) (unseeded in the test; seeded here), the 100 x 100
    # grid on [-2.01, 2.01]^2 and the ground truth sum of "signed_distance < 0" over the copies
    png = "/work/.mirror/sgsellan+gpytoolbox/repo"
    import subprocess

    blob = subprocess.run(["git", f"--git-dir={png}", "show", "HEAD:test/unit_tests_data/illustrator.png"],
                          check=True, capture_output=True).stdout
    tmp = Path(tempfile.mkdtemp()) / "illustrator.png"
    tmp.write_bytes(blob)
    poly = gpy.png2poly(str(tmp))
    V = 1.5 * gpy.normalize_points(poly[0])
    EC = gpy.edge_indices(V.shape[0], closed=True)
    gx, gy = np.meshgrid(np.linspace(-2.01, 2.01, 100), np.linspace(-2.01, 2.01, 100))
    gv = np.vstack((gx.flatten(), gy.flatten())).T
    rng = np.random.default_rng(0)
    Vbig, ECbig, W_gt = [], [], np.zeros(gv.shape[0])
    for i in range(3):
        newV = V + 0.1 * rng.standard_normal((1, 2))
        Vbig.append(newV)
        ECbig.append(EC + i * V.shape[0])
        W_gt[gpy.signed_distance(gv, newV, EC)[0] < 0] += 1
    out.update(synth_V=np.vstack(Vbig), synth_E=np.vstack(ECbig).astype(np.int64), synth_Q=gv, synth_W=W_gt)
    from importlib.metadata import version

    out["versions"] = np.array([f"gpytoolbox {version('gpytoolbox')}"])
    save("gpytoolbox", **out)


# --------------------------------------------------------------------------------------------------------------
# libigl (python bindings): outputs of test_all.py's calls on the triangulated square / single tet, and the
# C++ tests' MeshBoolean cases run through igl.copyleft.cgal.mesh_boolean
# --------------------------------------------------------------------------------------------------------------


def record_igl():
    import igl
    import igl.copyleft.cgal as cgal

    out = {}
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
    F = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    P = np.array([[0.5, 0.5, 0.0], [0.5, 0.5, 0.5]], dtype=np.float64)
    sqrD, I, C = igl.point_mesh_squared_distance(P, V, F)
    out.update(square_sqrD=sqrD, square_I=I.astype(np.int64), square_C=C,
               square_W=igl.winding_number(V, F, P), square_FWN=igl.fast_winding_number(V, F, P))
    S, I, C, N = igl.signed_distance(P, V, F)      # default sign type (= winding number for this call)
    out.update(square_S=S, square_SI=I.astype(np.int64), square_SC=C, square_SN=N)
    T = igl.SignedDistanceType
    for key, t in (("pseudonormal", T.SIGNED_DISTANCE_TYPE_PSEUDONORMAL), ("winding", T.SIGNED_DISTANCE_TYPE_WINDING_NUMBER),
                   ("unsigned", T.SIGNED_DISTANCE_TYPE_UNSIGNED), ("fwn", T.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER)):
        out[f"square_S_{key}"] = igl.signed_distance(P, V, F, sign_type=t)[0]
    # test_cgal: tetrahedron A, z-flipped tetrahedron B (faces reversed)
    VA = np.array([[0, 0, -1], [2, 0, -1], [0, 2, -1], [1, 1, 1]], dtype=np.float64)
    T = np.array([[0, 1, 2, 3]], dtype=np.int64)
    FA, _, _ = igl.boundary_facets(T)
    VB = np.array([[0, 0, 1], [2, 0, 1], [0, 2, 1], [1, 1, -1]], dtype=np.float64)
    FB = FA[:, ::-1].copy()
    VC, FC, J = cgal.mesh_boolean(VA, FA, VB, FB, "union")
    out.update(cgal_FA=FA.astype(np.int64), cgal_union_V=VC, cgal_union_F=FC.astype(np.int64))
    Pq = np.array([[0.5, 0.5, 0.0], [0.5, 0.5, 0.5]], dtype=np.float64)
    # test_all.py passes (VA, FA, P) to the *point-cloud* overload (P, N, Q): FA's rows are used as normals
    out["cgal_fwn"] = cgal.fast_winding_number(VA, FA.astype(np.float64), Pq)
    # point_areas of 1000 points on the union (test_all.py draws them with igl.random_points_on_mesh; drawn here
    # with numpy so gsdf's test can redraw them) with 20 neighbours from igl.knn
    X, N = sample_on_mesh(VC, FC, 1000, seed=0)
    point_indices, CH, CN, W = igl.octree(X)
    I = igl.knn(X, X, 20, point_indices, CH, CN, W)
    A, _ = cgal.point_areas(X, I, N)
    out.update(cgal_pa_X=X, cgal_pa_N=N, cgal_pa_A=A)
    # point areas of 10,000 random unit-sphere points (default_rng(0) normals, normalized), 20 neighbours from
    # igl.knn, normals = the points: libigl's answer to compare with gsdf's against the exact spherical Voronoi
    Ps = np.random.default_rng(0).normal(size=(10000, 3))
    Ps /= np.linalg.norm(Ps, axis=1, keepdims=True)
    point_indices, CH, CN, W = igl.octree(Ps)
    I = igl.knn(Ps, Ps, 20, point_indices, CH, CN, W)
    out["sphere10k_A"], _ = cgal.point_areas(Ps, I, Ps)
    # the C++ MeshBoolean tests (volumes / Euler characteristic of libigl's own answers)
    # (on the generated stand-ins of the libigl-tests-data files, which are not vendored)
    from tests.conformance.helpers import box_mesh, two_boxes_bad_self_union

    empty = (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    cube = box_mesh([-0.5] * 3, [0.5] * 3)
    for key, A, B, op in (("twocubes", two_boxes_bad_self_union(), empty, "union"),
                          ("minus", box_mesh([0, 0, 0], [1, 1, 1]), box_mesh([0, 0.375, 0.375], [2, 0.625, 0.625]),
                           "minus"),
                          ("selfint", cube, cube, "intersect")):
        Vo, Fo, _ = cgal.mesh_boolean(*A, *B, op)
        out[f"{key}_V"], out[f"{key}_F"] = Vo, Fo.astype(np.int64)
    from importlib.metadata import version

    out["versions"] = np.array([f"libigl {version('libigl')}"])
    save("libigl", **out)


# --------------------------------------------------------------------------------------------------------------
# point-cloud-utils: normals and fast winding numbers of its tests' inputs
# --------------------------------------------------------------------------------------------------------------


def record_pcu():
    import point_cloud_utils as pcu

    v, f, n = pcu.load_mesh_vfn(unpack("pcu/cube_twist.obj"))
    _, nk = pcu.estimate_point_cloud_normals_knn(v, 12)
    vb, fb = pcu.load_mesh_vf(unpack("pcu/bunny.ply"))
    p = np.random.default_rng(0).random((1000, 3))   # the test's np.random.rand(1000, 3), seeded
    w = pcu.triangle_soup_fast_winding_number(vb, fb, p.astype(vb.dtype))
    from importlib.metadata import version

    save("pcu", cube_twist_normals_knn12=nk, bunny_fwn_P=p, bunny_fwn=w,
         versions=np.array([f"point_cloud_utils {version('point_cloud_utils')}"]))


# --------------------------------------------------------------------------------------------------------------
# Open3D: its primitive meshes (create_box, create_sphere(0.8)) and its boolean answers on them
# --------------------------------------------------------------------------------------------------------------


def record_o3d():
    import open3d as o3d

    box = o3d.geometry.TriangleMesh.create_box()
    sph = o3d.geometry.TriangleMesh.create_sphere(0.8)
    out = dict(box_V=np.asarray(box.vertices), box_F=np.asarray(box.triangles).astype(np.int64),
               sphere_V=np.asarray(sph.vertices), sphere_F=np.asarray(sph.triangles).astype(np.int64))
    tb = o3d.t.geometry.TriangleMesh.from_legacy(box)
    ts = o3d.t.geometry.TriangleMesh.from_legacy(sph)
    for op in ("union", "intersection", "difference"):
        r = getattr(tb, f"boolean_{op}")(ts)
        out[f"{op}_V"] = r.vertex.positions.numpy().astype(np.float64)
        out[f"{op}_F"] = r.triangle.indices.numpy().astype(np.int64)
    tsph = o3d.t.geometry.TriangleMesh.create_sphere(0.8)
    out["tsphere_V"] = tsph.vertex.positions.numpy().astype(np.float64)
    out["tsphere_F"] = tsph.triangle.indices.numpy().astype(np.int64)
    out["versions"] = np.array([f"open3d {o3d.__version__}"])
    save("open3d", **out)


# --------------------------------------------------------------------------------------------------------------
# SWN (nzfeng/SWN, MIT): the authors' published output data/torus_w.obj for data/torus.obj + data/torus-phi.txt
# --------------------------------------------------------------------------------------------------------------


def record_swn(mirror="/work/.mirror/nzfeng+SWN/repo"):
    """Per face of the authors' output mesh (their program cuts / subdivides the torus: 3899 vertices, 7798 faces):
    its centroid and the winding number at the centroid from the homogeneous texture coordinates (vt u w: value
    = sum(u) / sum(w) over the corners, their projective interpolation)."""
    import subprocess

    text = subprocess.run(["git", f"--git-dir={mirror}", "show", "HEAD:data/torus_w.obj"], check=True,
                          capture_output=True).stdout.decode()
    V, VT, F, FT = [], [], [], []
    for line in text.splitlines():
        t = line.split()
        if not t:
            continue
        if t[0] == "v":
            V.append([float(x) for x in t[1:4]])
        elif t[0] == "vt":
            VT.append([float(x) for x in t[1:3]])
        elif t[0] == "f":
            F.append([int(c.split("/")[0]) - 1 for c in t[1:]])
            FT.append([int(c.split("/")[1]) - 1 for c in t[1:]])
    V, VT, F, FT = np.array(V), np.array(VT), np.array(F), np.array(FT)
    uw = VT[FT]                                  # (m, 3, 2)
    value = uw[:, :, 0].sum(1) / uw[:, :, 1].sum(1)
    save("swn", torus_w_centroids=V[F].mean(axis=1), torus_w_face_value=value,
         versions=np.array(["nzfeng/SWN 49451ae0 data/torus_w.obj"]))


# --------------------------------------------------------------------------------------------------------------
# signed-heat-python (signedheat3d): its own answers in its test.py's configurations
# --------------------------------------------------------------------------------------------------------------


def record_shp():
    """signedheat3d's tet solver at [8, 8, 8] (ZeroSet) on bunny_small.obj: its 0-isosurface (to compare holes /
    closedness and the test's error), and the residual means of test.py's four distance checks."""
    import potpourri3d as pp3d
    import signedheat3d as shm

    V, F = pp3d.read_polygon_mesh(unpack("signed_heat_python/bunny_small.obj"))
    F = np.asarray(F)
    res = np.array([8, 8, 8])
    out = {}
    solver = shm.SignedHeatTetSolver(verbose=False)
    phi = solver.compute_distance_to_mesh(V=V, F=F.tolist(), options={"resolution": res,
                                                                       "level_set_constraint": "ZeroSet"})
    Vi, Fi = solver.isosurface(phi, 0.0)
    out.update(tet_iso_V=np.asarray(Vi, float), tet_iso_F=np.asarray(Fi, np.int64))
    from importlib.metadata import version

    out["versions"] = np.array([f"signedheat3d {version('signedheat3d')}"])
    save("signed_heat_python", **out)


PEERS = {"pp3d": record_pp3d, "gpy": record_gpy, "igl": record_igl, "pcu": record_pcu, "o3d": record_o3d, "swn": record_swn, "shp": record_shp}

if __name__ == "__main__":
    names = sys.argv[1:] or list(PEERS)
    for n in names:
        PEERS[n]()
