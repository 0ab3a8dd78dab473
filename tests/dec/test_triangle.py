"""gsdf.dec: coboundaries, Hodge stars, Hodge decomposition (harmonic dimension = b1), jump coordinates,
Darboux derivative, dual-graph L1 LP (against brute force)."""

import itertools

import numpy as np
import pytest
import scipy.sparse as sp

from gsdf.dec._hodge import HodgeDecomposition
from gsdf.linalg._dual_l1 import dual_graph_l1
from gsdf.dec._triangle import TriangleDEC
from gsdf.mesh._connectivity import MeshTopology
from tests.shapes import uv_sphere
from tests.shapes import annulus, double_torus, polyline_chain, torus


@pytest.fixture(scope="module")
def meshes():
    Vs, Fs = uv_sphere(12, 20)
    Vt, Ft, it = torus(24, 12)
    Vd, Fd = double_torus(40)
    Va, Fa, ia = annulus()
    return {"sphere": (Vs, Fs, 0, None), "torus": (Vt, Ft, 2, it), "double": (Vd, Fd, 4, None),
            "annulus": (Va, Fa, 1, ia)}


def test_coboundaries_and_stars(meshes):
    for name, (V, F, _, _) in meshes.items():
        dec = TriangleDEC(V, F)
        assert abs(dec.d1 @ dec.d0).max() == 0, name
        assert np.all(dec.star1 > 0) and np.all(dec.star0 >= 0) and np.all(dec.star2 > 0)
        assert np.isclose(dec.star0.sum(), dec.areas.sum())
        # the cotan Laplacian is d0ᵀ ⋆1 d0
        L = dec.laplacian()
        assert abs(L - dec.d0.T @ sp.diags(dec.star1) @ dec.d0).max() < 1e-12
    # d1 of a face is its oriented boundary: Σ over the face of sign · (u_hi - u_lo) telescopes
    V, F, _, _ = meshes["torus"]
    dec = TriangleDEC(V, F)
    u = np.random.default_rng(0).standard_normal(len(V))
    assert np.abs(dec.d1 @ (dec.d0 @ u)).max() < 1e-12


def test_cotan_clamp_on_needles():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1e-9, 0], [0.5, -1, 0]])
    dec = TriangleDEC(V, np.array([[0, 1, 2], [0, 3, 1]]))
    assert dec.cot_clamped.min() >= 1e-3 and dec.cot_clamped.max() <= 1e3


def test_euler_characteristic_of_test_shapes(meshes):
    chis = {k: MeshTopology(F).euler_characteristic for k, (V, F, _, _) in meshes.items()}
    assert chis == {"sphere": 2, "torus": 0, "double": -2, "annulus": 0}


def test_harmonic_dimension_is_betti_number(meshes):
    for name, (V, F, b1, _) in meshes.items():
        dec = TriangleDEC(V, F)
        H = HodgeDecomposition(dec.d0, dec.d1, dec.star1, dec.star0, dec.star2)
        B = H.harmonic_basis()
        assert B.shape[1] == b1 == MeshTopology(F).betti_1(), name
        if b1:
            assert np.abs(dec.d1 @ B).max() < 1e-8
            assert np.abs(dec.d0.T @ (dec.star1[:, None] * B)).max() < 1e-8
            G = B.T @ (dec.star1[:, None] * B)
            assert np.allclose(G, np.eye(b1), atol=1e-6)
            # in the kernel of the Hodge 1-Laplacian
            assert np.abs(H.hodge_laplacian1() @ B).max() < 1e-6


def test_decomposition_is_orthogonal_and_complete(meshes):
    V, F, _, _ = meshes["double"]
    dec = TriangleDEC(V, F)
    H = HodgeDecomposition(dec.d0, dec.d1, dec.star1)
    w = np.random.default_rng(1).standard_normal(dec.n_edges)
    p = H.decompose(w)
    assert np.allclose(p.exact + p.coexact + p.harmonic, w)
    ip = lambda a, b: float(a @ (dec.star1 * b))  # noqa: E731
    nrm = ip(w, w)
    assert abs(ip(p.exact, p.coexact)) < 1e-8 * nrm
    assert abs(ip(p.exact, p.harmonic)) < 1e-8 * nrm
    assert abs(ip(p.coexact, p.harmonic)) < 1e-8 * nrm
    assert ip(p.harmonic, p.harmonic) > 1e-6 * nrm          # genus 2: a random form has a (small) harmonic part
    # an exact form has no coexact or harmonic part
    q = H.decompose(dec.d0 @ np.random.default_rng(2).standard_normal(dec.n_vertices))
    assert np.abs(q.coexact).max() < 1e-8 and np.abs(q.harmonic).max() < 1e-8


def test_jump_coordinates_and_darboux_closed_curve(meshes):
    # sphere latitude loop: the jump solve gives a piecewise constant u (0 / 1) and ω ≡ 0
    V, F, _, _ = meshes["sphere"]
    dec = TriangleDEC(V, F)
    loop = 1 + 5 * 20 + np.arange(20)                   # a latitude ring of uv_sphere(12, 20)
    g = polyline_chain(dec, loop)
    jc = dec.jump_coordinates(g)
    assert not jc.endpoints.any()
    assert np.allclose(dec.corner_jumps(jc.c), g)
    u0, u = dec.solve_jump(jc)
    om = dec.darboux(u)
    assert np.abs(om).max() < 1e-6
    assert np.allclose(dec.corner_jumps(u), g)
    assert np.ptp(u.mean(1)) == pytest.approx(1.0, abs=1e-6)
    # torus meridian: ω is closed and coclosed but not zero (a harmonic form)
    V, F, _, idx = meshes["torus"]
    dec = TriangleDEC(V, F)
    g = polyline_chain(dec, idx[3])
    jc = dec.jump_coordinates(g)
    _, u = dec.solve_jump(jc)
    om = dec.darboux(u)
    assert np.abs(dec.d1 @ om).max() < 1e-9
    assert np.abs(dec.d0.T @ (dec.star1 * om)).max() < 1e-6
    assert np.abs(om).max() > 1e-2


def test_open_curve_endpoints_excluded(meshes):
    V, F, _, idx = meshes["torus"]
    dec = TriangleDEC(V, F)
    path = idx[3, :7]
    g = polyline_chain(dec, path, closed=False)
    jc = dec.jump_coordinates(g)
    assert set(np.flatnonzero(jc.endpoints)) == {path[0], path[-1]}
    _, u = dec.solve_jump(jc)
    assert np.isfinite(u).all()
    om = dec.darboux(u, jc.endpoints)
    touching = jc.endpoints[dec.edges].any(1)
    assert np.all(om[touching] == 0)
    with pytest.raises(ValueError, match="shape"):
        dec.jump_coordinates(np.zeros(3))
    with pytest.raises(ValueError, match="NaN"):
        dec.jump_coordinates(np.full(dec.n_edges, np.nan))
    with pytest.raises(ValueError, match="dtype bool"):
        dec.jump_coordinates(np.zeros(dec.n_edges, bool))


def test_annulus_loop_and_arc(meshes):
    V, F, _, idx = meshes["annulus"]
    dec = TriangleDEC(V, F)
    H = HodgeDecomposition(dec.d0, dec.d1, dec.star1)
    # a circle around the hole bounds (with the inner boundary): ω = 0
    om = dec.darboux(dec.solve_jump(dec.jump_coordinates(polyline_chain(dec, idx[3])))[1])
    assert np.abs(om).max() < 1e-6
    # a radial arc joining the boundary circles does not: its Darboux derivative is harmonic
    jc = dec.jump_coordinates(polyline_chain(dec, idx[:, 0], closed=False))
    assert not jc.endpoints.any()                       # endpoints on the boundary count as closed
    om = dec.darboux(dec.solve_jump(jc)[1])
    h = H.decompose(om).harmonic
    assert np.abs(h - om).max() < 1e-6 and np.abs(om).max() > 1e-2


def test_rejects_nonmanifold_and_misoriented():
    with pytest.raises(ValueError, match="non-manifold"):
        TriangleDEC(np.eye(3).tolist() + [[1, 1, 1], [2, 2, 2]], np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))
    V, F = uv_sphere(6, 8)
    F = F.copy()
    F[0] = F[0, ::-1]
    with pytest.raises(ValueError, match="consistently oriented"):
        TriangleDEC(V, F)


def _brute_l1(n, P, d, w, bounds):
    """Minimum of Σ w|d + x_A - x_B| over vertex solutions: a spanning tree of jumps fixed at 0, lo or hi."""
    best = np.inf
    k = len(P)
    for tree in itertools.combinations(range(k), n - 1):
        for vals in itertools.product(*[sorted({0.0, *[b for b in bounds[t] if np.isfinite(b)]}) for t in tree]):
            # solve x_A - x_B = val - d on the tree edges with x_0 = 0
            A = np.zeros((n, n))
            r = np.zeros(n)
            for row, (t, val) in enumerate(zip(tree, vals)):
                A[row, P[t, 0]] += 1
                A[row, P[t, 1]] -= 1
                r[row] = val - d[t]
            A[n - 1, 0] = 1
            try:
                x = np.linalg.solve(A, r)
            except np.linalg.LinAlgError:
                continue
            J = d + x[P[:, 0]] - x[P[:, 1]]
            if np.all(J >= bounds[:, 0] - 1e-9) and np.all(J <= bounds[:, 1] + 1e-9):
                best = min(best, float(w @ np.abs(J)))
    return best


def test_lp_against_brute_force():
    rng = np.random.default_rng(3)
    n = 5
    P = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 0], [0, 2], [1, 3]])
    for trial in range(6):
        d = rng.integers(-2, 3, len(P)).astype(float) + rng.uniform(-0.3, 0.3, len(P))
        w = rng.uniform(0.1, 2.0, len(P))
        bounds = np.tile([-np.inf, np.inf], (len(P), 1))
        if trial % 2:
            bounds[:2] = [[0.0, 1.0], [-1.0, 0.0]]
        res = dual_graph_l1(n, P, d, w, bounds=bounds)
        assert res.shifts[0] == 0
        assert res.objective == pytest.approx(_brute_l1(n, P, d, w, bounds), abs=1e-7)
        assert np.all(res.jumps >= bounds[:, 0] - 1e-9) and np.all(res.jumps <= bounds[:, 1] + 1e-9)


def test_lp_bad_input_and_limits():
    P = np.array([[0, 1]])
    with pytest.raises(ValueError, match="pairs"):
        dual_graph_l1(2, np.array([[0, 2]]), [0.0], [1.0])
    with pytest.raises(ValueError, match="weights"):
        dual_graph_l1(2, P, [0.0], [-1.0])
    with pytest.raises(ValueError, match="offsets"):
        dual_graph_l1(2, P, [np.nan], [1.0])
    with pytest.raises(ValueError, match="n_cells"):
        dual_graph_l1(True, P, [0.0], [1.0])
    with pytest.raises(ValueError, match="algorithm"):
        dual_graph_l1(2, P, [0.0], [1.0], algorithm="gurobi")
    assert dual_graph_l1(2, P, [0.5], [1.0], algorithm="highs-ipm").objective == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError, match="pairs"):
        dual_graph_l1(2, np.array([[True, False]]), [0.0], [1.0])
    with pytest.raises(ValueError, match="infeasible"):
        # a cycle whose offsets sum to 1 cannot have all jumps in [0, 0.1]
        dual_graph_l1(3, [[0, 1], [1, 2], [2, 0]], [1.0, 0.0, 0.0], [1, 1, 1], bounds=[[0, 0.1]] * 3)
    # HiGHS's time limit: a clear error, not a hang
    rng = np.random.default_rng(0)
    n = 20000
    P = np.stack([rng.integers(0, n, 4 * n), rng.integers(0, n, 4 * n)], 1)
    with pytest.raises(ValueError, match="limit"):
        dual_graph_l1(n, P, rng.standard_normal(4 * n), np.ones(4 * n), time_limit=1e-3)
