"""Print the figures of the failures the conformance suite found (issue 32): the tet isosurface, booleans, the
SWN demo's twirl and torus, the sign rule, the point-cloud comparison, point areas, the inputs the peers take.

    PYTHONPATH=src python3 tests/conformance/figures.py             # all sections, a few minutes
    PYTHONPATH=src python3 tests/conformance/figures.py tet bool    # some of them

Sections: tet, bool, twirl, sign, cloud, areas, inputs, torus. Public gsdf API only; the peers' answers come
from data/refs/ (record_refs.py); the libigl-tests-data files are the generated stand-ins of helpers.py.
"""

from __future__ import annotations

import gzip
import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))          # the repository root: tests.conformance.* importable

import gsdf  # noqa: E402
from tests.conformance.cases import (PP3D_BROKEN, PP3D_CLOUD_CURVE, PP3D_POINTS, PP3D_POLY_CURVE,  # noqa: E402
                                     fibonacci_sphere_case, uv_sphere_polygons)
from tests.conformance.helpers import (box_mesh, grid_quads, msh22_text, tet_boundary, tet_cube,  # noqa: E402
                                       two_boxes_bad_self_union, wrapped_off_text)

DATA = HERE / "data"
TMP = Path(tempfile.mkdtemp())


def asset(peer, name):
    p = DATA / peer / name
    if p.exists():
        return str(p)
    out = TMP / name
    if not out.exists():
        out.write_bytes(gzip.decompress((DATA / peer / (name + ".gz")).read_bytes()))
    return str(out)


def refs(name):
    return dict(np.load(DATA / "refs" / f"{name}.npz"))


def rel(a, b):
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def boundary_edges(F):
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, c = np.unique(E, axis=0, return_counts=True)
    return int((c == 1).sum()), int((c > 2).sum())


def euler(F):
    E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    return len(np.unique(F)) - len(E) + len(F)


def volume(V, F):
    t = V[F]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6)


def try_(label, f):
    try:
        out = f()
        print(f"  {label}: ok {out if out is not None else ''}")
    except Exception as e:  # noqa: BLE001 - the point is to print what gsdf says
        print(f"  {label}: {type(e).__name__}: {str(e)[:220]}")


# ---------------------------------------------------------------------------------------------------------------


def tet():
    print("tet-domain isosurface (signed-heat-python test_isosurface, bunny_small.obj, level_set_constraint='zero')")
    V, F = gsdf.read_mesh(asset("signed_heat_python", "bunny_small.obj"))

    def normals(X, T):
        fn = np.cross(X[T[:, 1]] - X[T[:, 0]], X[T[:, 2]] - X[T[:, 0]])
        vn = np.zeros_like(X)
        np.add.at(vn, T.ravel(), np.repeat(fn, 3, axis=0))
        with np.errstate(invalid="ignore", divide="ignore"):
            return vn / np.linalg.norm(vn, axis=1, keepdims=True)

    def approx(Q, Pp, N):
        from scipy.spatial import cKDTree

        d, i = cKDTree(Pp).query(Q)
        return np.sign(np.sum(N[i] * (Q - Pp[i]), axis=1)) * d

    for res in (8, 16, 32):
        f = gsdf.signed_heat_volume(mesh=(V, F), domain="tet", resolution=np.array([res] * 3),
                                    options=gsdf.VolumeHeatOptions(level_set_constraint="zero"))
        Vi, Fi = f.isosurface(0.0)
        N1, N2 = normals(V, F), normals(Vi, Fi)
        a, b = approx(V, Vi, N2) ** 2, approx(Vi, V, N1) ** 2
        msd = (a.sum() + b.sum()) / (len(V) + len(Vi))
        msd_ok = (np.nansum(a) + np.nansum(b)) / (len(V) + len(Vi))
        z = f.values[f.tets] == 0
        print(f"  gsdf [{res}]^3: {len(f.tets)} tets ({int(z.all(1).sum())} with 4 zero vertices), isosurface "
              f"{len(Vi)} V / {len(Fi)} F, boundary edges {boundary_edges(Fi)[0]}, vertices with a zero normal "
              f"{int(np.isnan(N2).any(1).sum())}, peer's msd {msd:.3g} (NaN terms dropped: {msd_ok:.3g})")
    r = refs("signed_heat_python")
    Vi, Fi = r["tet_iso_V"], r["tet_iso_F"]
    N2 = normals(Vi, Fi)
    a, b = approx(V, Vi, N2) ** 2, approx(Vi, V, normals(V, F)) ** 2
    print(f"  signedheat3d's own [8]^3 isosurface: {len(Vi)} V / {len(Fi)} F, boundary edges "
          f"{boundary_edges(Fi)[0]}, peer's msd {(a.sum() + b.sum()) / (len(V) + len(Vi)):.3g}")


def bool_():
    print("booleans (libigl MeshBoolean tests; volumes are signed volumes of the result)")
    A = box_mesh([0, 0, 0], [1, 1, 1])
    B = box_mesh([0, 0.375, 0.375], [2, 0.625, 0.625])
    Vo, Fo = gsdf.mesh_boolean(*A, *B, "difference")
    print(f"  MinusTest cube - bar: Euler {euler(Fo)} (want 0), volume {volume(Vo, Fo):.6f} (want 0.9375), "
          f"boundary edges {boundary_edges(Fo)[0]}")
    C = box_mesh([-0.5] * 3, [0.5] * 3)
    Vo, Fo = gsdf.mesh_boolean(*C, *C, "intersection")
    print(f"  IntersectWithSelf cube ∩ cube: {len(Fo)} faces (want a closed genus-0 cube)")
    T = two_boxes_bad_self_union()
    try_("TwoCubes A ∪ ∅ (Euler, boundary edges)", lambda: (lambda R: (euler(R[1]), boundary_edges(R[1])[0]))(
        gsdf.mesh_boolean(*T, np.zeros((0, 3)), np.zeros((0, 3), np.int64), "union")))
    Vo, Fo = gsdf.mesh_boolean(*T, *T, "union")
    print(f"  TwoCubes A ∪ A: boundary edges {boundary_edges(Fo)[0]}, Euler {euler(Fo)} (want 0 boundary, 2)")
    r = refs("libigl")
    VA = np.array([[0, 0, -1], [2, 0, -1], [0, 2, -1], [1, 1, 1]], float)
    VB = np.array([[0, 0, 1], [2, 0, 1], [0, 2, 1], [1, 1, -1]], float)
    Vo, Fo = gsdf.mesh_boolean(VA, r["cgal_FA"], VB, r["cgal_FA"][:, ::-1], "union")
    print(f"  test_all.py tet ∪ flipped tet: volume {volume(Vo, Fo):.6f}, libigl {volume(r['cgal_union_V'], r['cgal_union_F']):.6f}")
    o = refs("open3d")
    for op in ("union", "intersection", "difference"):
        Vo, Fo = gsdf.mesh_boolean(o["box_V"], o["box_F"], o["sphere_V"], o["sphere_F"], op)
        print(f"  Open3D box {op} sphere: {len(Vo)} V / {len(Fo)} F (Open3D {len(o[op + '_V'])} / "
              f"{len(o[op + '_F'])}), volume rel. diff {volume(Vo, Fo) / volume(o[op + '_V'], o[op + '_F']) - 1:.1e}, "
              f"boundary edges {boundary_edges(Fo)[0]}")


def twirl():
    print("surface winding numbers, SWN demo 'twirl'")
    mesh, curves = asset("swn", "twirl.obj"), asset("swn", "twirl.txt")
    from click.testing import CliRunner

    from gsdf.cli.swn import swn

    r = CliRunner().invoke(swn, [mesh, curves, "-o", str(TMP / "tw.ply"), "--quiet"])
    print(f"  gsdf swn twirl.obj twirl.txt: exit code {r.exit_code} {r.output.strip()[-200:]}")
    V, F = gsdf.read_mesh(mesh)
    try_("read_curves(twirl.txt): segments", lambda: sum(len(c) - 1 for c in gsdf.read_curves(curves, F).curves))
    from tests.conformance.test_swn import parse_swn_curves

    res = gsdf.surface_winding_number(V, F, parse_swn_curves(curves))
    labels, counts = np.unique(res.face_labels, return_counts=True)
    print(f"  the same segments passed directly: labels {dict(zip(labels.tolist(), counts.tolist()))}")


def sign():
    print("sign rule vs potpourri3d MeshSignedHeatSolver (bunny_small.ply, sample.py's curves)")
    r = refs("potpourri3d")
    V, F = gsdf.read_mesh(asset("potpourri3d", "bunny_small.ply"))
    s = gsdf.SurfaceSignedHeatSolver(V, F)
    c = [gsdf.Curve(x) for x in PP3D_BROKEN]
    sz = s.compute_distance(c)
    mx = s.compute_distance(c, points=PP3D_POINTS)
    print(f"  signed curves only: rel L2 to -pp3d {rel(sz, -r['signed_zero']):.2g}")
    print(f"  signed curves + points: to -pp3d {rel(mx, -r['mixed_zero']):.2f}, to +pp3d "
          f"{rel(mx, r['mixed_zero']):.2f}, to pp3d with curves reversed {rel(mx, r['mixed_zero_reversed']):.2g}")
    Vp, Pp = gsdf.read_mesh(asset("potpourri3d", "bunny_poly.ply"), triangulate=False)
    ph = gsdf.PolygonMeshSignedHeatSolver(Vp, Pp).compute_distance([gsdf.Curve(PP3D_POLY_CURVE)])
    print(f"  polygon mesh signed: to +pp3d {rel(ph, r['poly_signed']):.3f}, to -pp3d {rel(ph, -r['poly_signed']):.2f}")


def cloud():
    print("point-cloud signed heat vs potpourri3d (bunny_poly.ply's vertices) and vs exact answers")
    r = refs("potpourri3d")
    Vp, Pp = gsdf.read_mesh(asset("potpourri3d", "bunny_poly.ply"), triangulate=False)
    for key, nk in (("cloud_signed", "cloud_normals"), ("cloud_signed_consistent", "cloud_normals_consistent")):
        g = gsdf.PointCloudSignedHeatSolver(Vp, r[nk]).compute_distance([gsdf.Curve(PP3D_CLOUD_CURVE)])
        print(f"  {nk}: gsdf vs pp3d {rel(g, r[key]):.2f} (vs -pp3d {rel(g, -r[key]):.2f})")
    loop = PP3D_POLY_CURVE + [PP3D_POLY_CURVE[0]]
    mesh = gsdf.PolygonMeshSignedHeatSolver(Vp, Pp).compute_distance([gsdf.Curve(loop)])
    g = gsdf.PointCloudSignedHeatSolver(Vp, r["cloud_normals_consistent"]).compute_distance([gsdf.Curve(loop)])
    print(f"  polygon loop, consistent normals, against the polygon-mesh solution: gsdf cloud {rel(g, mesh):.3f}, "
          f"pp3d cloud {rel(r['cloud_signed_polyloop_consistent'], mesh):.3f} (pp3d's polygon mesh "
          f"{rel(r['poly_signed_polyloop'], mesh):.3f})")
    Pc, curve = fibonacci_sphere_case()
    exact = -np.arcsin(Pc[:, 2])
    g = gsdf.PointCloudSignedHeatSolver(Pc, Pc).compute_distance([gsdf.Curve(curve)])
    print(f"  Fibonacci sphere (4000), equator curve, exact -asin(z): gsdf {rel(g, exact):.4f}, pp3d "
          f"{rel(r['sphere_signed'], exact):.4f}")
    d0 = np.arccos(np.clip(Pc @ Pc[0], -1, 1))
    g = gsdf.PointCloudSignedHeatSolver(Pc, Pc).compute_distance([], points=[0])
    print(f"  same cloud, unsigned from point 0: gsdf {rel(g, d0):.4f}, pp3d {rel(r['sphere_dist0'], d0):.4f}")
    Vs, Ps, src, loop = uv_sphere_polygons()
    g = gsdf.PolygonMeshSignedHeatSolver(Vs, Ps).compute_distance([], points=[src])
    d0 = np.arccos(np.clip(Vs @ Vs[src], -1, 1))
    print(f"  UV-sphere polygon mesh, unsigned from a vertex: gsdf {rel(g, d0):.4f}, pp3d {rel(r['uvsphere_dist'], d0):.4f}")


def areas():
    print("point_areas, 10,000 random unit-sphere points (default_rng(0)), exact spherical Voronoi areas")
    from scipy.spatial import SphericalVoronoi

    Pp = np.random.default_rng(0).normal(size=(10000, 3))
    Pp /= np.linalg.norm(Pp, axis=1, keepdims=True)
    exact = SphericalVoronoi(Pp).calculate_areas()
    for kw in ({"k": 20}, {"k": 40}, {"k": 20, "boundary": "square"}):
        e = gsdf.point_areas(Pp, Pp, **kw) / exact - 1
        print(f"  {kw}: > 10 % off {int((np.abs(e) > 0.1).sum())} (too small {int((e < -0.1).sum())}), max "
              f"{np.abs(e).max():.3f}, median {np.median(np.abs(e)):.1e}")
    e = np.abs(refs("libigl")["sphere10k_A"] / exact - 1)
    print(f"  libigl (cgal point_areas, knn 20): median {np.median(e):.3g}, > 10 % off {int((e > 0.1).sum())}")


def inputs():
    print("inputs the peers take")
    p = TMP / "w.off"
    p.write_text(wrapped_off_text(*grid_quads(12, 9)))
    try_("OFF with wrapped faces", lambda: len(gsdf.read_mesh(str(p), triangulate=False)[1]))
    Vt, Tt = tet_cube(3)
    p = TMP / "m.msh"
    p.write_text(msh22_text(Vt, Tt, tet_boundary(Tt)))
    try_(".msh (tri + tet + element data)", lambda: gsdf.read_mesh(str(p))[1].shape)
    p = TMP / "t.mesh"
    p.write_text("MeshVersionFormatted 1\nDimension 3\nVertices\n4\n0 0 0 0\n0 0 1 0\n0 1 0 0\n1 0 0 0\nTetrahedra\n1\n1 2 3 4 0\n")
    try_(".mesh with only a tet", lambda: gsdf.read_mesh(str(p))[1].shape)
    try_("faceless PLY to read_mesh", lambda: gsdf.read_mesh(asset("pcu", "duplicated_pcloud.ply")))
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    F = np.array([[0, 1, 3], [0, 2, 1], [0, 3, 2], [1, 2, 3]])
    try_("signed_distance, Q (2, 5, 3)", lambda: gsdf.signed_distance(V, F, np.zeros((2, 5, 3))).shape)
    try_("signed_distance, Q (0, 3)", lambda: gsdf.signed_distance(V, F, np.zeros((0, 3))).shape)
    try_("winding_number, Q (0, 3)", lambda: gsdf.winding_number(V, F, np.zeros((0, 3))).shape)
    try_("signed_distance(return_closest=True)", lambda: len(gsdf.signed_distance(V, F, V, return_closest=True)))
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        try_("SurfaceSignedHeatSolver, a face repeating a vertex",
             lambda: gsdf.SurfaceSignedHeatSolver(V, np.vstack([F, [[0, 0, 1]]])).F.shape)
    print(f"    warning: {[str(x.message) for x in w]}")
    try_("write_mesh(vertex_data={'n': (n, 3)})",
         lambda: gsdf.write_mesh(str(TMP / "a.ply"), V, F, vertex_data={"n": np.zeros((4, 3))}))
    Vb, Fb = gsdf.read_mesh(asset("signed_heat_python", "bunny_small.obj"))
    try_("signed_heat_volume(bbox ±1) on bunny_small (x up to 1.0014)",
         lambda: gsdf.signed_heat_volume(mesh=(Vb, Fb), bbox_min=[-1] * 3, bbox_max=[1] * 3, resolution=8))


def torus():
    print("surface winding numbers vs the SWN authors' torus_w.obj (torus.obj + torus-phi.txt)")
    from tests.conformance.test_swn import parse_swn_curves

    V, F = gsdf.read_mesh(asset("swn", "torus.obj"))
    res = gsdf.surface_winding_number(V, F, parse_swn_curves(asset("swn", "torus-phi.txt")))
    r = refs("swn")
    _, face, _ = gsdf.unsigned_distance(V, F, r["torus_w_centroids"], return_closest=True)
    diff = res.face_labels[face] - np.round(r["torus_w_face_value"]).astype(int)
    vals, cnt = np.unique(diff, return_counts=True)
    print(f"  label(gsdf) - round(w authors) over the authors' {len(face)} faces: {dict(zip(vals.tolist(), cnt.tolist()))}")


SECTIONS = {"tet": tet, "bool": bool_, "twirl": twirl, "sign": sign, "cloud": cloud, "areas": areas,
            "inputs": inputs, "torus": torus}

if __name__ == "__main__":
    os.environ.setdefault("PYTHONWARNINGS", "ignore")
    for name in sys.argv[1:] or list(SECTIONS):
        SECTIONS[name]()
