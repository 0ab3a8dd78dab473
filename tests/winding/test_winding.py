import numpy as np
import pytest

import gsdf
from gsdf.winding._fast import NODE_WIDTH, _compact_moments, _far_field_c, _node_moments

from tests.shapes import cube, fibonacci_sphere, uv_sphere


def test_exact_closed_mesh_is_indicator():
    V, F = uv_sphere(24, 48)
    Q = np.array([[0, 0, 0], [0.3, -0.2, 0.1], [2, 0, 0], [0, -3, 1]])
    w = gsdf.winding_number(V, F, Q)
    np.testing.assert_allclose(w, [1, 1, 0, 0], atol=1e-12)
    # flipping orientation negates, duplicating doubles (a soup property)
    np.testing.assert_allclose(gsdf.winding_number(V, F[:, ::-1], Q), -w, atol=1e-12)
    np.testing.assert_allclose(gsdf.winding_number(V, np.vstack([F, F]), Q), 2 * w, atol=1e-12)


def test_exact_open_hemisphere_analytic():
    # Upper hemisphere of the unit sphere (outward normals): at the centre it subtends exactly half the
    # sphere, w = 1/2; on the axis at height z the solid angle of a spherical cap is known in closed form.
    V, F = uv_sphere(64, 128)
    keep = V[F].mean(axis=1)[:, 2] > 0
    w = gsdf.winding_number(V, F[keep], [[0, 0, 0]])
    assert abs(w[0] - 0.5) < 1e-12  # symmetric triangulation: exact


def test_exact_2d_polyline():
    t = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    V = np.column_stack([np.cos(t), np.sin(t)])
    E = np.column_stack([np.arange(200), (np.arange(200) + 1) % 200])
    w = gsdf.winding_number_2d(V, E, [[0, 0], [0.5, 0.3], [3, 0]])
    np.testing.assert_allclose(w, [1, 1, 0], atol=1e-12)
    # half circle open curve: at the centre it subtends π -> 1/2
    w = gsdf.winding_number_2d(V, E[:100], [[0, 0]])
    assert abs(w[0] - 0.5) < 1e-12


def _centre(P, A):
    return (A[:, None] * P).sum(axis=0) / A.sum()  # p̃: the area-weighted centre of the node


@pytest.mark.parametrize("order", [0, 1, 2])
def test_far_field_converges_at_the_taylor_order(order):
    # error of a single cluster expansion must decay like d^-(3 + order)
    rng = np.random.default_rng(1)
    P = rng.normal(size=(50, 3)) * 0.1
    N = rng.normal(size=(50, 3))
    A = rng.uniform(0.5, 1, 50)
    NA = N / np.linalg.norm(N, axis=1)[:, None] * A[:, None]
    C = _compact_moments(_node_moments(np.array([0]), np.array([50]), P, NA, np.zeros((50, 6)), P, NODE_WIDTH))
    errs = []
    for dist in (4.0, 8.0):
        q = np.array([0.7, 0.5, 0.3]) * dist
        exact = gsdf.winding_number_points(P, N, q[None], areas=A)[0]
        r = _centre(P, A) - q
        errs.append(abs(_far_field_c(C, 0, r[0], r[1], r[2], r @ r, order) - exact))
    rate = np.log2(errs[0] / errs[1])
    assert rate > 3 + order - 0.3


def test_fast_triangles_accuracy_and_orders():
    V, F = uv_sphere(40, 80)
    rng = np.random.default_rng(0)
    Q = rng.uniform(-1.5, 1.5, (4000, 3))
    exact = gsdf.winding_number(V, F, Q)
    rms = {}
    for order in (0, 1, 2):
        w = gsdf.fast_winding_number(V, F, Q, beta=2.0, order=order)
        rms[order] = np.sqrt(np.mean((w - exact) ** 2))
    assert rms[2] < 2e-3
    assert rms[2] < rms[0]
    # larger beta is more accurate
    w = gsdf.fast_winding_number(V, F, Q, beta=4.0, order=2)
    assert np.sqrt(np.mean((w - exact) ** 2)) < rms[2] / 5
    # thresholding at 1/2 agrees with the exact answer
    w = gsdf.fast_winding_number(V, F, Q)
    assert np.array_equal(w > 0.5, exact > 0.5)


def test_fast_triangle_soup_with_holes_matches_exact():
    V, F = uv_sphere(30, 60)
    rng = np.random.default_rng(3)
    F = F[rng.random(len(F)) > 0.15]  # 15 % of faces deleted
    Q = rng.uniform(-1.2, 1.2, (3000, 3))
    exact = gsdf.winding_number(V, F, Q)
    fwn = gsdf.FastWindingNumber(V, F)
    w = fwn(Q)
    assert np.sqrt(np.mean((w - exact) ** 2)) < 2e-3
    # reusable: a second call gives the same numbers
    np.testing.assert_array_equal(fwn(Q), w)


def test_fast_points_against_direct_sum():
    P = fibonacci_sphere(3000)
    A = np.full(len(P), 4 * np.pi / len(P))
    rng = np.random.default_rng(2)
    Q = rng.uniform(-1.5, 1.5, (3000, 3))
    exact = gsdf.winding_number_points(P, P, Q, areas=A)
    w = gsdf.fast_winding_number_points(P, P, Q, areas=A)
    assert np.sqrt(np.mean((w - exact) ** 2)) < 1e-2
    r = np.linalg.norm(Q, axis=1)
    assert np.all(np.abs(w[r < 0.8] - 1) < 0.05) and np.all(np.abs(w[r > 1.2]) < 0.05)


def test_fast_points_with_estimated_areas():
    P = fibonacci_sphere(4000) * 2.0
    w = gsdf.fast_winding_number_points(P, P, [[0, 0, 0], [0.5, 0.5, 0], [5, 0, 0]])
    np.testing.assert_allclose(w, [1, 1, 0], atol=0.02)


def test_degenerate_faces_contribute_zero():
    V, F = cube()
    Vd = np.vstack([V, [[0.1, 0.1, 0.1], [0.2, 0.2, 0.2]]])
    n = len(V)
    Fd = np.vstack([F, [[n, n, n + 1], [n, n + 1, n + 1], [0, 0, 0]]])  # zero-area faces
    Q = np.array([[0.0, 0.0, 0.0], [0.15, 0.15, 0.15], [2, 2, 2]])
    np.testing.assert_allclose(gsdf.winding_number(Vd, Fd, Q), gsdf.winding_number(V, F, Q), atol=1e-12)
    w = gsdf.fast_winding_number(Vd, Fd, Q)
    assert np.isfinite(w).all()
    np.testing.assert_allclose(w, [1, 1, 0], atol=1e-6)


def test_query_on_a_point_is_finite():
    P = fibonacci_sphere(500)
    w = gsdf.fast_winding_number_points(P, P, P[:10], areas=np.full(500, 4 * np.pi / 500))
    assert np.isfinite(w).all()


def test_chunked_queries_match(monkeypatch):
    from gsdf.winding import _query

    V, F = uv_sphere(10, 20)
    Q = np.random.default_rng(5).uniform(-1, 1, (1000, 3))
    full = gsdf.fast_winding_number(V, F, Q)
    monkeypatch.setattr(_query, "CHUNK", 77)
    fwn = gsdf.FastWindingNumber(V, F)
    out = _query.map_queries(fwn._kernel, Q, chunk=77, coherent=True, frame=fwn._frame)
    np.testing.assert_allclose(out, full, atol=1e-14)
    # float32 queries accepted
    np.testing.assert_allclose(fwn(Q.astype(np.float32)), fwn(Q.astype(np.float32).astype(np.float64)))


@pytest.mark.parametrize(
    "call",
    [
        lambda V, F, Q: gsdf.winding_number(V, F, Q),
        lambda V, F, Q: gsdf.fast_winding_number(V, F, Q),
    ],
)
def test_bad_input_raises(call):
    V, F = cube()
    Q = np.zeros((2, 3))
    with pytest.raises(ValueError, match="NaN"):
        call(np.where(np.arange(V.size).reshape(V.shape) == 4, np.nan, V), F, Q)
    with pytest.raises(ValueError, match="out of range"):
        call(V, F + 100, Q)
    with pytest.raises(ValueError, match="negative"):
        call(V, F - 100, Q)
    with pytest.raises(ValueError, match="shape"):
        call(V[:, :2], F, Q)
    with pytest.raises(ValueError, match="empty"):
        call(V, F[:0], Q)
    with pytest.raises(ValueError, match="Q"):
        call(V, F, np.array([[np.inf, 0, 0]]))
    with pytest.raises(ValueError, match="Q"):
        call(V, F, np.zeros((3, 4)))
    with pytest.raises(ValueError, match="integer"):
        call(V, F + 0.5, Q)


def test_bad_parameters_and_point_input():
    V, F = cube()
    with pytest.raises(ValueError, match="beta"):
        gsdf.fast_winding_number(V, F, np.zeros((1, 3)), beta=-1)
    with pytest.raises(ValueError, match="order"):
        gsdf.fast_winding_number(V, F, np.zeros((1, 3)), order=3)
    P = fibonacci_sphere(100)
    with pytest.raises(ValueError, match="all normals are zero"):
        gsdf.fast_winding_number_points(P, np.zeros_like(P), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="rows"):
        gsdf.fast_winding_number_points(P, P[:50], np.zeros((1, 3)))
    with pytest.raises(ValueError, match="areas"):
        gsdf.fast_winding_number_points(P, P, np.zeros((1, 3)), areas=-np.ones(100))
    with pytest.raises(ValueError, match="areas"):
        gsdf.fast_winding_number_points(P, P, np.zeros((1, 3)), areas=np.ones(10))


def test_empty_query_returns_empty():
    V, F = cube()
    assert gsdf.fast_winding_number(V, F, np.zeros((0, 3))).shape == (0,)


def test_hierarchical_exact_matches_direct_on_a_broken_soup():
    V, F = uv_sphere(20, 40)
    rng = np.random.default_rng(7)
    F = F[rng.random(len(F)) > 0.3]  # holes
    F = np.vstack([F, F[:15], F[20:40, ::-1], [[0, 0, 1]]])  # duplicates, flipped copies, a degenerate face
    Q = np.vstack([rng.uniform(-1.3, 1.3, (1500, 3)), V[:50]])  # include queries on vertices
    direct = gsdf.winding_number(V, F, Q, method="direct")
    hier = gsdf.winding_number(V, F, Q, method="hierarchical")
    np.testing.assert_allclose(hier, direct, atol=1e-11)
    ex = gsdf.ExactWindingNumber(V, F, leaf_size=2)
    np.testing.assert_allclose(ex(Q), direct, atol=1e-11)
    with pytest.raises(ValueError, match="method"):
        gsdf.winding_number(V, F, Q, method="fast")


@pytest.mark.parametrize("make", [lambda V, F: gsdf.ExactWindingNumber(V, F),
                                  lambda V, F: gsdf.FastWindingNumber(V, F)])
def test_a_progress_that_is_not_callable_is_refused_before_any_query(make):
    V, F = cube()
    ewn = make(V, F)
    for bad in (3, object()):
        with pytest.raises(ValueError, match="progress: expected a callable"):
            ewn(np.zeros((5, 3)), progress=bad)
    seen = []
    ewn(np.zeros((5, 3)), progress=lambda s, f: seen.append(f))
    assert seen == [1.0]
