"""Scale invariance (gsdf._normalize): winding numbers, distances, areas, normals and PAT at coordinates
around 1e-150, 1 and 1e150 and 1e8 from the origin give the unit-scale answers (distances times the scale)."""

import numpy as np
import pytest

import gsdf
from gsdf._normalize import FAR, Frame
from gsdf.mesh._geometry import face_areas, face_normals
from gsdf.mesh._pseudonormals import vertex_pseudonormals
from gsdf.winding._point_areas import estimate_normals, point_areas

from tests.shapes import fibonacci_sphere, uv_sphere

V, F = uv_sphere(12, 24)
P = fibonacci_sphere(600)
Q = np.array([[0.05, 0.1, 0.02], [0.2, -0.3, 0.4], [2.0, 0.5, 0.0], [0.0, 0.0, -1.7]])
INSIDE = np.array([1.0, 1.0, 0.0, 0.0])
SQ = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]) - 0.5
SE = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
CASES = [(1e-150, 0.0), (1.0, 0.0), (1e150, 0.0), (1.0, 1e8), (1e-150, 1e-142), (1e150, -1e158)]  # offsets 1e8 sizes


def _map(X, s, o):
    return X * s + o


@pytest.mark.parametrize("s,o", CASES)
def test_winding_numbers_are_scale_and_translation_invariant(s, o):
    Vs, Ps, Qs = _map(V, s, o), _map(P, s, o), _map(Q, s, o)
    for method in ("direct", "hierarchical"):
        np.testing.assert_allclose(gsdf.winding_number(Vs, F, Qs, method=method), INSIDE, atol=1e-9)
    ref = gsdf.fast_winding_number(V, F, Q)
    np.testing.assert_allclose(gsdf.fast_winding_number(Vs, F, Qs), ref, atol=1e-6)
    np.testing.assert_allclose(gsdf.winding_number_points(Ps, P, Qs), INSIDE, atol=2e-2)
    refp = gsdf.fast_winding_number_points(P, P, Q)
    np.testing.assert_allclose(gsdf.fast_winding_number_points(Ps, P, Qs), refp, atol=1e-6)
    w2 = gsdf.winding_number_2d(_map(SQ, s, o), SE, _map(np.array([[0.1, 0.2], [3.0, 0.0]]), s, o))
    np.testing.assert_allclose(w2, [1.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("s,o", CASES)
def test_distances_scale_linearly(s, o):
    Vs, Ps, Qs = _map(V, s, o), _map(P, s, o), _map(Q, s, o)
    for sign in ("winding", "pseudonormal"):
        ref = gsdf.signed_distance(V, F, Q, sign=sign)
        assert np.all((ref < 0) == (INSIDE > 0.5))
        np.testing.assert_allclose(gsdf.signed_distance(Vs, F, Qs, sign=sign) / s, ref, rtol=1e-6, atol=1e-6)
    d, face, closest = gsdf.unsigned_distance(Vs, F, Qs, return_closest=True)
    np.testing.assert_allclose(d / s, gsdf.unsigned_distance(V, F, Q), rtol=1e-6)
    np.testing.assert_allclose((closest - o) / s, gsdf.unsigned_distance(V, F, Q, return_closest=True)[2],
                               atol=1e-6)
    refp = gsdf.signed_distance_points(P, P, Q)
    np.testing.assert_allclose(gsdf.signed_distance_points(Ps, P, Qs) / s, refp, rtol=1e-6, atol=1e-6)
    a = gsdf.distance.point_cloud_distance(Ps, Qs)
    np.testing.assert_allclose(a / s, gsdf.distance.point_cloud_distance(P, Q), rtol=1e-6)


@pytest.mark.parametrize("s,o", CASES)
def test_areas_normals_and_pat_at_scale(s, o):
    Vs, Ps = _map(V, s, o), _map(P, s, o)
    a = point_areas(Ps, P)
    np.testing.assert_allclose(a / s / s, point_areas(P, P), rtol=1e-6)
    assert abs(a.sum() / s / s - 4 * np.pi) < 0.05 * 4 * np.pi
    np.testing.assert_allclose(np.abs(np.einsum("ij,ij->i", estimate_normals(Ps), P)), 1.0, atol=2e-2)
    if o == 0.0:  # areas of faces 1e8 from the origin lose digits in the input coordinates themselves
        np.testing.assert_allclose(face_areas(Vs, F) / s / s, face_areas(V, F), rtol=1e-9)
    np.testing.assert_allclose(face_normals(Vs, F), face_normals(V, F), atol=1e-6)
    np.testing.assert_allclose(vertex_pseudonormals(Vs, F), vertex_pseudonormals(V, F), atol=1e-6)
    pat = gsdf.PointsAsTori(Ps, P, k=20)
    ref = gsdf.PointsAsTori(P, P, k=20)
    Qs = _map(Q[1:], s, o)  # Q[0] sits at the centre, where neighbours tie
    np.testing.assert_allclose(pat.signed_distance(Qs) / s, ref.signed_distance(Q[1:]), rtol=1e-4, atol=1e-4)
    np.testing.assert_allclose(pat.gradient(Qs), ref.gradient(Q[1:]), atol=1e-4)
    assert abs(pat.r_eval / s - ref.r_eval) <= 1e-6 * ref.r_eval


def test_unit_scale_input_keeps_the_identity_frame():
    fr = Frame.of(V * 0.75)  # centred, half-extent in [0.5, 1)
    assert fr.identity and fr.geometry(V) is V
    X = np.random.default_rng(0).normal(size=(50, 3)) + 3.0
    for k in (-900, -40, 0, 7, 900):  # power-of-two scalings map to bitwise the same frame coordinates
        Y = Frame.of(np.ldexp(X, k)).geometry(np.ldexp(X, k))
        assert np.array_equal(Y, Frame.of(X).geometry(X))
    fr = Frame.of(V * 1e150)
    assert not fr.identity and np.abs(fr.geometry(V * 1e150)).max() <= 1.0


def test_far_queries_are_clamped_and_unrepresentable_ones_refused():
    # a query 1e200 sphere radii away: winding number 0, distance |q| - 1 to relative precision
    Qf = np.array([[1e200, 0, 0], [0, -3e250, 0]])
    np.testing.assert_allclose(gsdf.fast_winding_number(V, F, Qf), 0.0, atol=1e-30)
    np.testing.assert_allclose(gsdf.winding_number(V, F, Qf), 0.0, atol=1e-30)
    d = gsdf.signed_distance(V, F, Qf)
    np.testing.assert_allclose(d, [1e200, 3e250], rtol=1e-14)
    assert FAR < 1e200
    # a geometry 1e-300 across and a query at 1e300: the query's frame coordinate overflows float64; its
    # winding number is still 0 (clamped like any far query), its distance is refused
    np.testing.assert_allclose(gsdf.winding_number(V * 1e-300, F, [[1e300, 0, 0]]), 0.0, atol=1e-30)
    np.testing.assert_allclose(gsdf.fast_winding_number(V * 1e-300, F, [[1e300, 0, 0]]), 0.0, atol=1e-30)
    with pytest.raises(ValueError, match="Q: row 0 cannot be represented"):
        gsdf.unsigned_distance(V * 1e-300, F, [[1e300, 0, 0]])
    # a vertex the faces do not use, beyond float64 range at the scale of the used ones: ignored
    Vu = np.vstack([V * 1e-308, [[1.0, 0, 0]]])
    np.testing.assert_allclose(gsdf.winding_number(Vu, F, [[0.0, 0, 0]]), gsdf.winding_number(V, F, [[0.0, 0, 0]]),
                               atol=1e-12)
    with pytest.raises(ValueError, match="point areas overflow"):
        point_areas(P * 1e300, P)


def test_pat_kd_eps_never_gives_nan():
    rng = np.random.default_rng(0)
    Qr = rng.uniform(-4, 4, (20000, 3))
    for eps in (0.3, 1.0):
        v = gsdf.PointsAsTori(P, P, k=20, options=gsdf.PointsAsToriOptions(kd_eps=eps)).signed_distance(Qr)
        assert np.isfinite(v).all()
        assert np.abs(v - (np.linalg.norm(Qr, axis=1) - 1)).max() < 0.1


# ---- memory guard (gsdf._memory) ---------------------------------------------------------------------


def test_grid_allocations_are_refused_with_size_and_limit(monkeypatch):
    from gsdf._memory import available_bytes, check_bytes
    from gsdf.contour import extract_isosurface
    from gsdf.ops import voxelize, voxels_to_mesh

    with pytest.raises(ValueError, match=r"100000x100000x100000 voxels: needs about 8\.0 PB, more than the"):
        voxelize(mesh=(V, F), resolution=100000)
    with pytest.raises(ValueError, match="extract_isosurface: resolution=100000.*needs about"):
        extract_isosurface(lambda q: q[:, 0], [0, 0, 0], [1, 1, 1], resolution=100000)
    monkeypatch.setenv("GSDF_MEMORY_LIMIT", "1M")
    assert available_bytes() == 1 << 20
    with pytest.raises(ValueError, match=r"more than the 1\.0 MB allowed"):
        voxelize(mesh=(V, F), resolution=64)
    with pytest.raises(ValueError, match="voxels_to_mesh"):
        voxels_to_mesh(np.ones((64, 64, 64), bool), [0, 0, 0], [1, 1, 1])
    with pytest.raises(ValueError, match="queries x"):
        gsdf.PointsAsTori(fibonacci_sphere(5000), fibonacci_sphere(5000), k=64)
    check_bytes(1000, "small")  # under the limit: no error
    monkeypatch.setenv("GSDF_MEMORY_LIMIT", "lots")
    with pytest.raises(ValueError, match="GSDF_MEMORY_LIMIT"):
        available_bytes()
    monkeypatch.delenv("GSDF_MEMORY_LIMIT")
    occ, lo, hi = voxelize(mesh=(V, F), resolution=16)  # the normal path still works
    assert occ.any()


# ---- options, saved state and degenerate views (issue 14 items 6-7) -------------------------------------


def test_bad_options_are_refused():
    P2 = fibonacci_sphere(200)
    Q1 = np.zeros((1, 3))
    bad = [
        (lambda: estimate_normals(P2, k=2 ** 70), "k: 1180591620717411303424 neighbours asked for"),
        (lambda: gsdf.fast_winding_number(V, F, Q1, beta=1e200), "beta: must be a finite positive number"),
        (lambda: gsdf.fast_winding_number(V, F, Q1, beta=True), "beta: expected a real number"),
        (lambda: gsdf.FastWindingNumber(V, F, leaf_size="x"), "leaf_size"),
        (lambda: gsdf.ExactWindingNumber(V, F, leaf_size=1e300), "leaf_size"),
        (lambda: gsdf.distance.TriangleDistance(V, F, leaf_size=2 ** 64), "leaf_size"),
        (lambda: gsdf.fast_winding_number(V, F, Q1, order=np.array([1, 2])), "order: must be 0, 1 or 2"),
        (lambda: gsdf.PointsAsTori(P2, P2, k=16, options=gsdf.PointsAsToriOptions(ridge=-1)),
         "ridge: must be a finite number >= 0"),
        (lambda: gsdf.PointsAsTori(P2, P2, k=16, options=gsdf.PointsAsToriOptions(normal_weight=-1)),
         "normal_weight"),
        (lambda: gsdf.PointsAsTori(P2, P2, k=16, options=gsdf.PointsAsToriOptions(kd_eps=np.nan)), "kd_eps"),
        (lambda: gsdf.PointsAsTori(P2, P2, k=16, estimator=["jet"]), "estimator"),
        (lambda: gsdf.ops.voxelize(mesh=(V, F), resolution=np.inf), "resolution"),
        (lambda: gsdf.contour.extract_isosurface(lambda q: q[:, 0], [-1] * 3, [1] * 3, 8, level=0.0,
                                                 bisection_steps=10 ** 9), "bisection_steps"),
        (lambda: gsdf.tori.offset(lambda q: q[:, 0], [1, 2]), "r: expected a real number"),
        (lambda: gsdf.ops.mesh_boolean(V, F, V + 0.3, F, "union",
                                       options=gsdf.BooleanOptions(beta=np.inf)), "beta"),
    ]
    for fn, msg in bad:
        with pytest.raises(ValueError, match=msg):
            fn()


def test_pat_load_checks_every_array_against_the_points(tmp_path):
    P2 = fibonacci_sphere(300)
    pat = gsdf.PointsAsTori(P2, P2, k=16)
    good = tmp_path / "pat.npz"
    pat.save(good)
    z = dict(np.load(good))
    again = gsdf.PointsAsTori.load(good)
    assert np.array_equal(again(Q), pat(Q))
    np.testing.assert_allclose(again.tori, pat.tori)
    for name, value, msg in [("tori", z["tori"][:10], r"tori must be a \(300, 13\)"),
                             ("tori_frame", z["tori_frame"][:10], "tori_frame must be"),
                             ("N", z["N"][:10], "N has 10 rows but P has 300"),
                             ("coefficients", np.zeros((300, 9)), "coefficients must be"),
                             ("tori", np.full_like(z["tori"], np.nan), "tori contains NaN"),
                             ("k", np.array([1, 2]), "k must be a scalar"),
                             ("C", np.float64(-1), "C: must be a finite positive"),
                             ("k_eval", np.int64(0), "k_eval"),
                             ("format", np.int64(9), "unknown PointsAsTori file format")]:
        d = dict(z)
        d[name] = value
        p = tmp_path / f"bad-{name}.npz"
        np.savez(p, **d)
        with pytest.raises(ValueError, match=msg):
            gsdf.PointsAsTori.load(p)
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"PK\x03\x04" + bytes(range(256)))
    with pytest.raises(ValueError, match="not a saved PointsAsTori file"):
        gsdf.PointsAsTori.load(junk)


def test_render_png_refuses_degenerate_views_and_blank_images(tmp_path):
    ball = lambda q: np.linalg.norm(q, axis=1) - 0.5  # noqa: E731
    out = str(tmp_path / "r.png")
    box = dict(bbox_min=[-1] * 3, bbox_max=[1] * 3)
    with pytest.raises(ValueError, match="empty, flat"):
        gsdf.render_png(ball, out, 16, 16, bbox_min=[0] * 3, bbox_max=[0] * 3)
    with pytest.raises(ValueError, match="view: the zero vector"):
        gsdf.render_png(ball, out, 16, 16, view=(0, 0, 0), **box)
    with pytest.raises(ValueError, match="parallel to the view"):
        gsdf.render_png(ball, out, 16, 16, view=(0, 2, 0), **box)
    with pytest.raises(ValueError, match="no ray hit"):
        gsdf.render_png(ball, out, 16, 16, level=-3.0, **box)
    with pytest.raises(ValueError, match="width"):
        gsdf.render_png(ball, out, 0, 16, **box)
    with pytest.raises(ValueError, match="sdf: returned NaN"):
        gsdf.render_png(lambda q: np.full(len(q), np.nan), out, 8, 8, **box)
    import os

    assert not os.path.exists(out)
    gsdf.render_png(ball, out, 16, 16, **box)
    assert os.path.getsize(out) > 0


def test_marching_tetrahedra_welds_node_crossings():
    from gsdf.contour._tets import marching_tetrahedra
    from scipy.spatial import Delaunay

    g = np.linspace(-1, 1, 7)
    X = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    X = X + np.random.default_rng(0).normal(scale=0.01, size=X.shape)  # no flat tets
    T = Delaunay(X).simplices
    r = np.linalg.norm(X, axis=1)
    for level in (0.77, float(r[np.argmin(np.abs(r - 0.7))])):  # the second passes exactly through a node
        Vt, Ft, rep = marching_tetrahedra(X, T, r, level, report=True)
        assert rep["welded"] and rep["closed"] and rep["edge_manifold"] and rep["vertex_manifold"], rep
        vol = np.einsum("ij,ij->i", Vt[Ft[:, 0]], np.cross(Vt[Ft[:, 1]], Vt[Ft[:, 2]])).sum() / 6
        assert abs(vol - 4 / 3 * np.pi * level ** 3) < 0.15 * vol  # outward (gradient) orientation


def test_grid_node_positions_are_guarded_by_the_memory_estimate():
    from gsdf.grid import grid_points

    with pytest.raises(ValueError, match="grid of nodes.*needs about"):
        grid_points([0, 0, 0], [1, 1, 1], (5000, 5000, 5000))
    assert grid_points([0, 0, 0], [1, 1, 1], (2, 3, 4)).shape == (24, 3)
