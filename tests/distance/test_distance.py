"""Unsigned/signed distance to triangle soups and point clouds (gsdf.distance)."""

import importlib

import numpy as np
import pytest

from gsdf.distance import (
    TriangleDistance,
    brute_force_distance,
    closest_point_triangle,
    point_cloud_distance,
    signed_distance,
    signed_distance_points,
    unsigned_distance,
)
from gsdf.mesh._pseudonormals import corner_angles, edge_pseudonormals, pseudonormals, vertex_pseudonormals

# ----------------------------------------------------------------------------------------------------
# geometry generated in code
# ----------------------------------------------------------------------------------------------------


def cube(h=0.5):
    """Closed cube [-h, h]^3 with outward-oriented triangles."""
    V = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return V, F


def cube_distance(Q, h=0.5):
    """Analytic unsigned distance to the surface of the cube [-h, h]^3."""
    a = np.abs(Q) - h
    outside = np.linalg.norm(np.maximum(a, 0), axis=1)
    inside = -a.max(axis=1)
    return np.where(a.max(axis=1) > 0, outside, inside)


def icosphere(subdiv=2):
    """Unit icosphere, outward oriented."""
    t = (1 + 5 ** 0.5) / 2
    V = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
         [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
         [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    V = [np.array(v, float) / np.linalg.norm(v) for v in V]
    for _ in range(subdiv):
        cache, F2 = {}, []

        def mid(i, j):
            key = (min(i, j), max(i, j))
            if key not in cache:
                m = V[i] + V[j]
                V.append(m / np.linalg.norm(m))
                cache[key] = len(V) - 1
            return cache[key]

        for a, b, c in F:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            F2 += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        F = F2
    return np.array(V), np.array(F)


def numpy_point_triangle_d2(Q, A, B, C):
    """Independent reference: squared point-triangle distances, broadcasting over leading dimensions.

    Minimizes |a + s e0 + t e1 - q|^2 by solving the 2x2 normal equations; if the minimizer is outside
    the triangle (or the triangle is degenerate), takes the best of the three clamped segments.
    """
    dot = lambda X, Y: (X * Y).sum(-1)  # noqa: E731
    e0, e1, w = B - A, C - A, Q - A
    a00, a01, a11 = dot(e0, e0), dot(e0, e1), dot(e1, e1)
    b0, b1 = dot(e0, w), dot(e1, w)
    det = a00 * a11 - a01 * a01
    ok = det > 1e-14 * np.maximum(a00, a11) ** 2
    safe = np.where(ok, det, 1.0)
    s = (a11 * b0 - a01 * b1) / safe
    t = (a00 * b1 - a01 * b0) / safe
    inside = ok & (s >= 0) & (t >= 0) & (s + t <= 1)
    P = A + s[..., None] * e0 + t[..., None] * e1
    d_face = np.where(inside, dot(Q - P, Q - P), np.inf)

    def seg(P0, P1):
        e = P1 - P0
        ee = dot(e, e)
        u = np.clip(dot(Q - P0, e) / np.where(ee > 0, ee, 1.0), 0, 1)
        u = np.where(ee > 0, u, 0.0)
        r = Q - P0 - u[..., None] * e
        return dot(r, r)

    return np.minimum(d_face, np.minimum(seg(A, B), np.minimum(seg(B, C), seg(C, A))))


def numpy_mesh_distance(V, F, Q):
    T = V[F][None]  # (1, m, 3, 3)
    d2 = numpy_point_triangle_d2(Q[:, None], T[..., 0, :], T[..., 1, :], T[..., 2, :])
    return np.sqrt(d2.min(axis=1))


def exact_winding_number(V, F, Q):
    """Van Oosterom-Strackee solid angle sum / 4 pi (independent of gsdf.winding)."""
    A = V[F[:, 0]][None] - Q[:, None]
    B = V[F[:, 1]][None] - Q[:, None]
    C = V[F[:, 2]][None] - Q[:, None]
    la, lb, lc = (np.linalg.norm(X, axis=-1) for X in (A, B, C))
    det = np.einsum("qtd,qtd->qt", A, np.cross(B, C))
    den = la * lb * lc + (A * B).sum(-1) * lc + (B * C).sum(-1) * la + (C * A).sum(-1) * lb
    return (2 * np.arctan2(det, den)).sum(axis=1) / (4 * np.pi)


def exact_winding_number_points(P, N, Q, areas=None):
    a = np.ones(len(P)) if areas is None else np.asarray(areas, float)
    D = P[None] - Q[:, None]
    r = np.linalg.norm(D, axis=-1)
    return (a * np.einsum("qpd,pd->qp", D, N) / (4 * np.pi * r ** 3)).sum(axis=1)


@pytest.fixture
def winding(monkeypatch):
    """Use gsdf.winding if it exists, otherwise inject the exact references above."""
    try:
        mod = importlib.import_module("gsdf.winding")
    except ImportError:
        import sys
        import types

        mod = types.ModuleType("gsdf.winding")
        monkeypatch.setitem(sys.modules, "gsdf.winding", mod)
    if not hasattr(mod, "fast_winding_number"):
        monkeypatch.setattr(mod, "fast_winding_number",
                            lambda V, F, Q, beta=2.0, order=2: exact_winding_number(V, F, Q), raising=False)
    if not hasattr(mod, "fast_winding_number_points"):
        monkeypatch.setattr(mod, "fast_winding_number_points",
                            lambda P, N, Q, areas=None, beta=2.3: exact_winding_number_points(P, N, Q, areas),
                            raising=False)
    return mod


def tri_distance(P, A, B, C):
    d, _, _ = closest_point_triangle(P, A, B, C)
    return d


# ----------------------------------------------------------------------------------------------------
# unsigned distance
# ----------------------------------------------------------------------------------------------------


def test_cube_matches_analytic_distance():
    V, F = cube()
    rng = np.random.default_rng(0)
    Q = rng.uniform(-2, 2, (20000, 3))
    d, face, C = unsigned_distance(V, F, Q, return_closest=True)
    np.testing.assert_allclose(d, cube_distance(Q), rtol=0, atol=1e-14)
    assert face.dtype == np.int64 and face.min() >= 0 and face.max() < len(F)
    np.testing.assert_allclose(np.linalg.norm(Q - C, axis=1), d, atol=1e-14)
    # the closest point lies on the cube surface and on the reported face
    assert np.abs(np.abs(C).max(axis=1) - 0.5).max() < 1e-14
    np.testing.assert_allclose(tri_distance(C, *(V[F[face, k]] for k in range(3))), 0, atol=1e-14)


@pytest.mark.parametrize("leaf_size", [1, 3, 8, 32])
def test_sphere_against_brute_force(leaf_size):
    V, F = icosphere(3)  # 1280 faces
    rng = np.random.default_rng(leaf_size)
    Q = np.vstack([rng.uniform(-1.6, 1.6, (600, 3)), rng.normal(size=(200, 3)) * 1e-3,  # around centre
                   V[rng.integers(0, len(V), 200)] * (1 + rng.normal(size=(200, 1)) * 1e-3)])
    td = TriangleDistance(V, F, leaf_size=leaf_size)
    d, face, C = td.query(Q)
    d_bf, _ = brute_force_distance(V, F, Q)
    d_np = numpy_mesh_distance(V, F, Q)
    np.testing.assert_allclose(d, d_bf, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d, d_np, rtol=0, atol=1e-13)
    assert face.min() >= 0 and face.max() < len(F)
    np.testing.assert_allclose(np.linalg.norm(Q - C, axis=1), d, atol=1e-14)
    # reported face really is at distance d
    np.testing.assert_allclose(tri_distance(Q, *(V[F[face, k]] for k in range(3))), d, atol=1e-14)
    # chord error of the inscribed polyhedron bounds |d - | |q| - 1 ||
    h = 1 - np.cos(np.max(np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1)))
    assert np.all(np.abs(d - np.abs(np.linalg.norm(Q, axis=1) - 1)) <= h + 1e-12)


def test_chunks_and_repeat_queries_agree():
    V, F = icosphere(2)
    td = TriangleDistance(V, F)
    Q = np.random.default_rng(3).uniform(-2, 2, (1000, 3))
    d, f, c, b = td._query(Q)
    d7, f7, c7, b7 = td._query(Q, chunk=7)
    np.testing.assert_allclose(d7, d, atol=1e-15)
    np.testing.assert_allclose(c7, c, atol=1e-15)
    # a single query, and a 1-D query point
    d1, f1, c1 = td.query(Q[5])
    assert d1.shape == (1,) and abs(d1[0] - d[5]) < 1e-15


def test_closest_point_triangle_regions_and_barycentrics():
    rng = np.random.default_rng(7)
    n = 20000
    A, B, C = (rng.normal(size=(n, 3)) for _ in range(3))
    # include slivers and needles
    C[:2000] = A[:2000] + 0.3 * (B[:2000] - A[:2000]) + 1e-6 * rng.normal(size=(2000, 3))
    B[2000:3000] = A[2000:3000] + 1e-7 * rng.normal(size=(1000, 3))
    P = rng.normal(size=(n, 3)) * 2
    d, X, bary = closest_point_triangle(P, A, B, C)
    ref = np.sqrt(numpy_point_triangle_d2(P, A, B, C))
    np.testing.assert_allclose(d, ref, rtol=0, atol=1e-12)
    assert np.all(bary >= 0) and np.allclose(bary.sum(axis=1), 1)
    np.testing.assert_allclose(X, bary[:, :1] * A + bary[:, 1:2] * B + bary[:, 2:] * C, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(P - X, axis=1), d, atol=1e-12)


def test_degenerate_triangles_are_finite_and_exact():
    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [5, 5, 5]], float)
    F = np.array([
        [0, 0, 3],   # repeated vertex: segment (0,0,0)-(0,1,0)
        [0, 1, 2],   # collinear: segment (0,0,0)-(2,0,0)
        [1, 2, 0],   # collinear, middle vertex last
        [4, 4, 4],   # a single point
    ])
    rng = np.random.default_rng(1)
    Q = np.vstack([rng.uniform(-1, 6, (3000, 3)), V, [[0.5, 0, 0], [1.5, 0.0, 0], [0, 0.5, 0], [3, 0, 0]]])
    for faces in ([F], [F[k:k + 1] for k in range(4)]):
        for Fk in faces:
            d, face, C = unsigned_distance(V, Fk, Q, return_closest=True)
            assert np.all(np.isfinite(d)) and np.all(np.isfinite(C))
            np.testing.assert_allclose(d, numpy_mesh_distance(V, Fk, Q), rtol=0, atol=1e-14)
            np.testing.assert_allclose(np.linalg.norm(Q - C, axis=1), d, atol=1e-14)
    # analytic spot checks on the soup
    d = unsigned_distance(V, F, [[1.0, 1.0, 0.0], [3, 0, 0], [5, 5, 6], [-1, -1, 0]])
    np.testing.assert_allclose(d, [1.0, 1.0, 1.0, np.sqrt(2)], atol=1e-15)
    # bary of a degenerate triangle stay valid
    _, _, bary = closest_point_triangle([[0.5, 3, 0]], [0, 0, 0], [1, 0, 0], [2, 0, 0])
    assert np.all(np.isfinite(bary)) and abs(bary.sum() - 1) < 1e-15


def test_queries_on_vertices_and_edges():
    V, F = icosphere(2)
    E = np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    rng = np.random.default_rng(2)
    t = rng.random((len(E), 1))
    Q = np.vstack([V, (1 - t) * V[E[:, 0]] + t * V[E[:, 1]], V[F].mean(axis=1)])
    d, face, C = TriangleDistance(V, F).query(Q)
    assert d.max() < 1e-15
    np.testing.assert_allclose(C, Q, atol=1e-15)
    # vertices come back exactly
    assert np.array_equal(C[: len(V)], V)


def test_pseudonormals_sphere_and_cube():
    V, F = icosphere(2)
    vn = vertex_pseudonormals(V, F)
    np.testing.assert_allclose(vn, V, atol=2e-2)
    # on a closed manifold the angles around each vertex sum to < 2 pi (convex) and > 0
    ang = np.bincount(F.ravel(), corner_angles(V, F).ravel())
    assert np.all(ang < 2 * np.pi) and np.all(ang > 5)
    Vc, Fc = cube()
    edges, en, fe = edge_pseudonormals(Vc, Fc)
    assert len(edges) == 18 and np.array_equal(np.unique(fe), np.arange(18))
    np.testing.assert_allclose(np.linalg.norm(en, axis=1), 1, atol=1e-15)
    # cube corners: the angle-weighted normal points along (+-1, +-1, +-1)
    np.testing.assert_allclose(vertex_pseudonormals(Vc, Fc), Vc / np.linalg.norm(Vc, axis=1)[:, None], atol=1e-15)
    pn = pseudonormals(Vc, Fc)
    assert pn.face.shape == (12, 3) and pn.edge.shape == (12, 3, 3) and pn.vertex.shape == (8, 3)
    # a diagonal edge between two coplanar faces has the face normal as pseudonormal
    np.testing.assert_allclose(pn.edge[0, 1], [-1, 0, 0], atol=1e-15)  # face [0,1,3], edge (3,0)


# ----------------------------------------------------------------------------------------------------
# signed distance
# ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("shape", ["cube", "sphere"])
def test_signed_both_modes_agree_on_closed_meshes(shape, winding):
    V, F = cube() if shape == "cube" else icosphere(2)
    rng = np.random.default_rng(4)
    Q = rng.uniform(-1.5, 1.5, (4000, 3))
    # add points just off the surface near vertices and edges (pseudonormal edge/vertex features)
    Q = np.vstack([Q, V * 1.01, V * 0.99, V[F].mean(axis=1) * 1.001])
    d = unsigned_distance(V, F, Q)
    sw = signed_distance(V, F, Q, sign="winding")
    sp = signed_distance(V, F, Q, sign="pseudonormal")
    np.testing.assert_allclose(np.abs(sw), d, atol=0)
    np.testing.assert_allclose(np.abs(sp), d, atol=0)
    inside = exact_winding_number(V, F, Q) > 0.5
    assert np.all(sw[inside & (d > 0)] < 0) and np.all(sw[~inside] >= 0)
    assert np.all(sp[inside & (d > 0)] < 0) and np.all(sp[~inside] >= 0)
    np.testing.assert_array_equal(np.sign(sw), np.sign(sp))
    if shape == "cube":
        np.testing.assert_allclose(sp, np.where(np.abs(Q).max(axis=1) < 0.5, -1, 1) * cube_distance(Q), atol=1e-14)


def test_pseudonormal_sign_near_concave_features():
    # an L-shaped closed prism (one concave edge): points near the reflex edge must be signed correctly
    P2 = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    n = len(P2)
    V = np.vstack([np.column_stack([P2, np.zeros(n)]), np.column_stack([P2, np.ones(n)])])
    F = [[0, 2, 1], [0, 3, 2], [0, 5, 3], [3, 5, 4]]  # bottom (z=0), facing down
    F += [[n + a, n + b, n + c] for a, c, b in F]  # top, facing up
    for i in range(n):
        j = (i + 1) % n
        F += [[i, j, n + j], [i, n + j, n + i]]
    F = np.array(F)
    assert abs(exact_winding_number(V, F, np.array([[0.5, 0.5, 0.5]]))[0] - 1) < 1e-12
    rng = np.random.default_rng(5)
    Q = np.vstack([rng.uniform(-0.5, 2.5, (3000, 3)), [1, 1, 0.5] + rng.normal(size=(500, 3)) * 0.05])
    inside = exact_winding_number(V, F, Q) > 0.5
    s = signed_distance(V, F, Q, sign="pseudonormal")
    d = unsigned_distance(V, F, Q)
    ok = d > 1e-12
    np.testing.assert_array_equal(s[ok] < 0, inside[ok])


def test_winding_sign_with_a_hole(winding):
    V, F = icosphere(3)
    cen = V[F].mean(axis=1)
    Fh = F[cen[:, 2] < 0.9]  # remove a cap around the north pole
    assert len(Fh) < len(F)
    rng = np.random.default_rng(6)
    Q = rng.uniform(-1.5, 1.5, (3000, 3))
    r = np.linalg.norm(Q, axis=1)
    far = np.linalg.norm(Q - [0, 0, 1], axis=1) > 0.8  # away from the hole
    inside = r < 0.98
    outside = r > 1.02
    s = signed_distance(V, Fh, Q)
    assert np.all(s[far & inside] < 0) and np.all(s[far & outside] > 0)
    np.testing.assert_allclose(np.abs(s), unsigned_distance(V, Fh, Q), atol=0)


def _fibonacci_sphere(n):
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    return np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])


def test_point_cloud_distance_and_sign(winding):
    P = _fibonacci_sphere(3000)
    rng = np.random.default_rng(8)
    Q = rng.uniform(-1.5, 1.5, (2000, 3))
    d, idx, C = point_cloud_distance(P, Q, return_closest=True)
    D = np.linalg.norm(Q[:, None] - P[None], axis=-1)
    np.testing.assert_allclose(d, D.min(axis=1), atol=1e-14)
    assert idx.dtype == np.int64
    np.testing.assert_array_equal(C, P[idx])
    np.testing.assert_allclose(point_cloud_distance(P, Q), d)
    s = signed_distance_points(P, P, Q, areas=np.full(3000, 4 * np.pi / 3000))
    r = np.linalg.norm(Q, axis=1)
    np.testing.assert_allclose(np.abs(s), d)
    assert np.all(s[r < 0.9] < 0) and np.all(s[r > 1.1] > 0)


def test_point_cloud_sign_with_estimated_areas(winding):
    P = _fibonacci_sphere(3000)
    Q = np.random.default_rng(9).uniform(-1.5, 1.5, (2000, 3))
    r = np.linalg.norm(Q, axis=1)
    s = signed_distance_points(P, P, Q)  # areas estimated by gsdf.winding
    assert np.all(s[r < 0.9] < 0) and np.all(s[r > 1.1] > 0)
    np.testing.assert_allclose(np.abs(s), point_cloud_distance(P, Q))


# ----------------------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------------------


def test_bad_input_raises_value_error():
    V, F = cube()
    Q = np.zeros((3, 3))
    Vn = V.copy()
    Vn[2, 1] = np.nan
    Qn = Q.copy()
    Qn[1, 0] = np.inf
    cases = [
        lambda: unsigned_distance(Vn, F, Q),
        lambda: unsigned_distance(V, F, Qn),
        lambda: unsigned_distance(V, F, np.zeros((3, 2))),
        lambda: unsigned_distance(V[:, :2], F, Q),
        lambda: unsigned_distance(V, F[:, :2], Q),
        lambda: unsigned_distance(V, F + 1, Q),
        lambda: unsigned_distance(V, F - 1, Q),
        lambda: unsigned_distance(V, np.zeros((0, 3), int), Q),
        lambda: TriangleDistance(V, F, leaf_size=0),
        lambda: TriangleDistance(V, F, leaf_size=2.5),
        lambda: signed_distance(V, F, Qn),
        lambda: signed_distance(V, F, Q, beta=-1),
        lambda: point_cloud_distance(Vn, Q),
        lambda: signed_distance_points(V, V[:3], Q),
        lambda: signed_distance_points(V, np.zeros_like(V), Q),
        lambda: signed_distance_points(V, V, Q, areas=-np.ones(8)),
        lambda: closest_point_triangle(np.zeros((3, 3)), np.zeros((2, 3)), np.zeros((1, 3)), np.zeros((1, 3))),
    ]
    for k, case in enumerate(cases):
        with pytest.raises(ValueError):
            case()
            pytest.fail(f"case {k} did not raise")
    # no queries is not an error: empty results (tests/test_query_shapes.py covers every call)
    assert unsigned_distance(V, F, np.zeros((0, 3))).shape == (0,)
    assert TriangleDistance(V, F).query(np.zeros((0, 3)))[2].shape == (0, 3)
    assert point_cloud_distance(V, np.zeros((0, 3))).shape == (0,)


def test_bad_sign_mode_names_the_options():
    V, F = cube()
    with pytest.raises(ValueError, match="pseudonormal") as info:
        signed_distance(V, F, np.zeros((1, 3)), sign="normals")
    assert "winding" in str(info.value)


def test_refit_answers_as_a_fresh_tree():
    """TriangleDistance.refit keeps the tree and recomputes its boxes: the same distances as a tree built on
    the moved mesh (brute force too), also after moves of several edge lengths; a wrong vertex count is
    refused."""
    V, F = icosphere(2)
    rng = np.random.default_rng(4)
    Q = rng.normal(size=(400, 3)) * 0.8
    td = TriangleDistance(V, F)
    for scale in (0.01, 0.05, 0.4):
        W = V + rng.normal(scale=scale, size=V.shape)
        d, face, cl, bary = td.refit(W).query_barycentric(Q)
        d0, _, cl0, _ = TriangleDistance(W, F).query_barycentric(Q)
        np.testing.assert_allclose(d, d0, rtol=0, atol=1e-13)
        np.testing.assert_allclose(cl, cl0, atol=1e-12)
        np.testing.assert_allclose(d, numpy_mesh_distance(W, F, Q), atol=1e-12)
        np.testing.assert_allclose(np.einsum("qk,qkx->qx", bary, W[F[face]]), cl, atol=1e-12)
    with pytest.raises(ValueError, match="V"):
        td.refit(V[:-1])


def test_shell_gives_double_sided_sheets_an_inside():
    """Open single-layer sheets have no inside (winding number 1/2 on one side, -1/2 on the other): a point just
    above a wing is outside. With shell=t the wing is a plate of thickness t; the solid fuselage stays inside
    either way; nothing changes beyond t/2 of the surface."""
    import gsdf
    from tests.conformance.helpers import airplane

    V, F = airplane()
    Q = np.array([[0.0, 0.8, 0.01], [0.0, 0.8, -0.01], [0.0, 0.0, 0.05], [0.0, 0.8, 0.3], [0.9, 0.0, 0.0]])
    s = gsdf.signed_distance(V, F, Q)
    assert s[0] > 0 and s[1] > 0 and s[2] < 0 and s[3] > 0 and s[4] < 0
    t = 0.04
    sh = gsdf.signed_distance(V, F, Q, shell=t)
    np.testing.assert_allclose(sh[:2], 0.01 - t / 2, atol=1e-12)  # inside the plate
    assert sh[2] < 0 and sh[4] < 0 and sh[2] <= s[2]
    assert sh[3] == pytest.approx(s[3] - t / 2)
    G = gsdf.signed_distance_grid(V, F, resolution=24, shell=t)
    G0 = gsdf.signed_distance_grid(V, F, resolution=24)
    np.testing.assert_allclose(G.values, np.minimum(G0.values, np.abs(G0.values) - t / 2))
    with pytest.raises(ValueError, match="shell"):
        gsdf.signed_distance(V, F, Q, shell=-1.0)


def test_signed_distance_return_closest_is_libigls_output():
    """libigl's signed_distance(P, V, F) returns (S, I, C, N): the closest triangle, closest point, normal."""
    import gsdf

    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 1, 3], [0, 2, 1], [0, 3, 2], [1, 2, 3]])
    Q = np.array([[0.5, 0.5, 0.5], [0.1, 0.1, -1.0], [-1.0, -1.0, -1.0]])
    for sign in ("winding", "pseudonormal"):
        S, I, C, N = gsdf.signed_distance(V, F, Q, sign=sign, return_closest=True)
        np.testing.assert_allclose(S, gsdf.signed_distance(V, F, Q, sign=sign))
        d, face, C2 = gsdf.unsigned_distance(V, F, Q, return_closest=True)
        np.testing.assert_array_equal(I, face)
        np.testing.assert_allclose(C, C2)
        np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1)
    assert I[0] == 3 and I[1] == 1
    np.testing.assert_allclose(C[0], [1 / 3] * 3, atol=1e-15)
    np.testing.assert_allclose(N[2], -np.ones(3) / np.sqrt(3), atol=1e-12)  # pseudonormal at the corner vertex


def test_return_closest_is_a_switch():
    """'no' is truthy: a string for return_closest is refused, not taken as True."""
    import gsdf

    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    for fn, args in ((gsdf.unsigned_distance, (V, [[0, 1, 2]])), (gsdf.point_cloud_distance, (V,)),
                     (gsdf.signed_distance, (V, [[0, 1, 2]]))):
        with pytest.raises(ValueError, match="return_closest: expected True or False"):
            fn(*args, [[0.2, 0.2, 1.0]], return_closest="no")
