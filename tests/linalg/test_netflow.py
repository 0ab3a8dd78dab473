"""The network simplex (gsdf.linalg._netflow) and the banded LP (gsdf.linalg._band_lp) against HiGHS: min-cost
circulations, the L1 dual-graph program, and the full residual LP of surface winding numbers on small meshes of
genus 1 and 2 and with boundary — equal optimal objectives (the same program, solved through its LP dual)."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import linprog

import gsdf.linalg._netflow as NF
from gsdf.linalg._dual_l1 import dual_graph_l1
from gsdf.linalg._netflow import dual_graph_l1_network, network_simplex
from gsdf.swn._solver import SurfaceWindingNumbers
from tests.shapes import annulus, double_torus, torus


def cases():
    rng = np.random.default_rng(3)
    V, F, idx = torus(24, 12)
    yield "torus", V, F, [idx[5, :9], idx[14, list(range(12)) + [0]], idx[:18, 3]]
    V, F, idx = annulus(6, 32)
    yield "annulus", V, F, [idx[0, 3:20], idx[:, 7], idx[2, list(range(10, 32)) + [0, 1, 2]]]
    V, F = double_torus(24)
    swn = SurfaceWindingNumbers(V, F)
    E = swn.dec.edges
    # random broken edge walks as curves
    curves = []
    for _ in range(4):
        v = int(rng.integers(len(V)))
        walk = [v]
        for _ in range(25):
            nb = np.concatenate([E[E[:, 0] == walk[-1], 1], E[E[:, 1] == walk[-1], 0]])
            nb = nb[~np.isin(nb, walk)]
            if len(nb) == 0:
                break
            walk.append(int(rng.choice(nb)))
        curves.append(walk)
    yield "double torus", V, F, curves



def _residual_lp(V, F, curves, eps):
    """The full residual LP of surface winding numbers (the first decomposition of ``solve``) as dual-graph L1 data:
    (n_faces, pairs, offsets, weights, bounds, band seeds: the faces along the curves and their completions)."""
    swn = SurfaceWindingNumbers(V, F)
    r = swn.solve(curves, method="lp")
    interior, d, w, bounds = swn._full_lp_terms(r.gamma, r.chain, eps)
    topo = swn.topology
    path = (r.chain != 0) | (swn._complete_chain(r.chain, r.endpoints) != 0)
    seeds = np.unique(topo.edge_faces[path & (topo.edge_face_count == 2)])
    return swn.dec.n_faces, topo.edge_faces[interior], d, w, bounds, seeds


def _random_graph(rng, n, m):
    a = rng.integers(0, n, m)
    b = (a + rng.integers(1, n, m)) % n                      # no self-loops
    ring = np.arange(n)                                     # keep it connected
    return np.concatenate([a, ring]), np.concatenate([b, (ring + 1) % n])


@pytest.mark.parametrize("seed", range(4))
def test_network_simplex_matches_highs(seed):
    rng = np.random.default_rng(seed)
    n = 30
    tail, head = _random_graph(rng, n, 90)
    m = len(tail)
    cap = rng.uniform(0.1, 2.0, m)
    cap[rng.random(m) < 0.15] = np.inf
    cost = rng.normal(size=m)
    cost[np.isinf(cap)] = np.abs(cost[np.isinf(cap)]) + 0.1  # no negative cycle of unbounded arcs
    f, pi, _ = network_simplex(n, tail, head, cap, cost)
    M = sp.csr_matrix((np.r_[np.ones(m), -np.ones(m)], (np.r_[tail, head], np.r_[np.arange(m), np.arange(m)])),
                      shape=(n, m))
    ref = linprog(cost, A_eq=M, b_eq=np.zeros(n), bounds=np.column_stack([np.zeros(m), cap]), method="highs")
    assert ref.status == 0
    assert abs(cost @ f - ref.fun) <= 1e-9 * max(1.0, abs(ref.fun))
    assert np.abs(M @ f).max() < 1e-9 and (f >= -1e-12).all() and (f <= cap + 1e-12).all()
    # optimality conditions of the potentials
    rc = cost + pi[tail] - pi[head]
    assert (rc[f < 1e-12] >= -1e-9).all() and (rc[f > cap - 1e-12] <= 1e-9).all()
    mid = (f > 1e-9) & (f < cap - 1e-9)
    assert np.abs(rc[mid]).max(initial=0) < 1e-9


@pytest.mark.parametrize("seed", range(4))
def test_l1_network_matches_highs(seed):
    rng = np.random.default_rng(10 + seed)
    n = 40
    a, b = _random_graph(rng, n, 60)
    P = np.stack([a, b], 1)
    k = len(P)
    d = rng.normal(size=k)
    w = rng.uniform(0.0, 2.0, k)
    w[:3] = 0.0
    lo, hi = np.full(k, -np.inf), np.full(k, np.inf)
    kind = rng.integers(0, 5, k)                            # free, [0, g], [g, 0], [lo > 0, hi], [-inf, hi < 0]
    g = rng.choice([-2.0, -1.0, 1.0, 2.0], k)
    lo[kind == 1], hi[kind == 1] = np.minimum(0, g[kind == 1]), np.maximum(0, g[kind == 1])
    lo[kind == 2], hi[kind == 2] = -1.5, -1.5 + rng.uniform(0, 3, (kind == 2).sum())
    lo[kind == 3], hi[kind == 3] = 0.2, np.inf
    hi[kind == 4] = -0.1
    # feasible by construction: the bounds hold at the jumps of some shifts x0
    x0 = rng.normal(size=n)
    J0 = d + x0[a] - x0[b]
    lo = np.minimum(lo, J0)
    hi = np.maximum(hi, J0)
    B = np.column_stack([lo, hi])
    r1 = dual_graph_l1(n, P, d, w, bounds=B)
    r2 = dual_graph_l1_network(n, P, d, w, bounds=B)
    assert abs(r1.objective - r2.objective) <= 1e-8 * max(1.0, r1.objective)
    assert np.all(r2.jumps >= lo - 1e-9) and np.all(r2.jumps <= hi + 1e-9)
    assert np.allclose(r2.jumps, d + r2.shifts[a] - r2.shifts[b], atol=1e-9)
    assert abs(r2.shifts[0]) < 1e-12                         # the gauge


@pytest.mark.parametrize("name,V,F,curves", list(cases()), ids=lambda x: x if isinstance(x, str) else "")
def test_network_residual_lp_equals_face_form(name, V, F, curves):
    for eps in (1e-2, 0.5):
        n, pairs, d, w, bounds, _ = _residual_lp(V, F, curves, eps)
        rh = dual_graph_l1(n, pairs, d, w, bounds=bounds, algorithm="highs-ds")
        rn = dual_graph_l1_network(n, pairs, d, w, bounds=bounds)
        assert rh.objective > 1e-6
        assert abs(rh.objective - rn.objective) <= 1e-7 * max(1.0, rh.objective), (name, eps)


def test_network_bad_input(monkeypatch):
    with pytest.raises(ValueError, match="self-loop|out of range"):
        network_simplex(2, [0], [0], [1.0], [1.0])
    with pytest.raises(ValueError, match="out of range"):
        network_simplex(2, [0], [2], [1.0], [1.0])
    with pytest.raises(ValueError, match="cap/cost"):
        network_simplex(2, [0], [1], [np.nan], [1.0])
    with pytest.raises(ValueError, match="cap/cost"):
        network_simplex(2, [0], [1], [1.0], [np.inf])
    with pytest.raises(ValueError, match="shapes"):
        network_simplex(2, [0, 1], [1], [1.0], [1.0])
    with pytest.raises(ValueError, match="unbounded"):                 # negative cycle of unbounded arcs
        network_simplex(2, [0, 1], [1, 0], [np.inf, np.inf], [-1.0, 0.5])
    with pytest.raises(ValueError, match="algorithm"):
        dual_graph_l1(2, [[0, 1]], [0.0], [1.0], algorithm="network")
    with pytest.raises(ValueError, match="weights"):
        dual_graph_l1_network(2, [[0, 1]], [0.0], [-1.0])
    with pytest.raises(ValueError, match="infeasible"):                # J = 1 on the three links of a cycle
        dual_graph_l1_network(3, [[0, 1], [1, 2], [2, 0]], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0],
                              bounds=[[1.0, 1.0]] * 3)
    monkeypatch.setattr(NF, "_CHUNK", 1)
    with pytest.raises(ValueError, match="time limit"):
        dual_graph_l1_network(3, [[0, 1], [1, 2], [2, 0]], [1.0, 0.0, 0.0], [2.0, 1.0, 5.0], time_limit=1e-9)


# ------------------------------------------------------------------------------------------------ banded LP
from gsdf.linalg._band_lp import banded_l1, certify  # noqa: E402


@pytest.mark.parametrize("name,V,F,curves", list(cases()), ids=lambda x: x if isinstance(x, str) else "")
def test_band_residual_lp_equals_face_form(name, V, F, curves):
    for eps in (1e-2, 0.5):
        n, pairs, d, w, bounds, seeds = _residual_lp(V, F, curves, eps)
        rh = dual_graph_l1(n, pairs, d, w, bounds=bounds, algorithm="highs-ds")
        rb = banded_l1(n, pairs, d, w, bounds=bounds, seeds=seeds)
        assert rh.objective > 1e-6
        assert abs(rh.objective - rb.objective) <= 1e-7 * max(1.0, rh.objective), (name, eps)


def test_band_is_proven_on_a_small_band():
    # torus with a broken meridian: the band starts thin (rings=1) and is proven before it covers the surface
    V, F, idx = torus(40, 20)
    swn = SurfaceWindingNumbers(V, F)
    curves = [idx[5, :15]]
    g = swn.chain(curves)
    gamma = swn.solve(curves, method="lp").gamma
    interior, d, w, bounds = swn._full_lp_terms(gamma, g, 1e-2)
    pairs = swn.topology.edge_faces[interior]
    seeds = np.unique(pairs[g[interior] != 0])
    info = {}
    rb = banded_l1(swn.dec.n_faces, pairs, d, w, bounds=bounds, seeds=seeds, rings=1, _info=info)
    rh = dual_graph_l1(swn.dec.n_faces, pairs, d, w, bounds=bounds)
    assert info["proven"] and "fallback" not in info
    assert info["band_cells"][-1] < swn.dec.n_faces
    assert abs(rb.objective - rh.objective) <= 1e-7 * max(1.0, rh.objective)
    assert np.all(rb.jumps >= bounds[:, 0] - 1e-7) and np.all(rb.jumps <= bounds[:, 1] + 1e-7)
    assert certify(swn.dec.n_faces, pairs, rh.jumps, w, bounds[:, 0], bounds[:, 1])[0]


def test_certificate_accepts_the_optimum_only():
    # a cycle of three cells, period 1: optimal on the cheapest link (w = 1), not on the others
    P = np.array([[0, 1], [1, 2], [2, 0]])
    w = np.array([2.0, 1.0, 5.0])
    inf = np.full(3, np.inf)
    assert certify(3, P, np.array([0.0, 1.0, 0.0]), w, -inf, inf)[0]
    ok, reach = certify(3, P, np.array([1.0, 0.0, 0.0]), w, -inf, inf)
    assert not ok and reach is not None
    assert not certify(3, P, np.array([0.0, 0.0, 1.0]), w, -inf, inf)[0]
    # with J ≤ 0.5 on the cheap link the optimum splits 0.5 / 0.5 between the two cheapest links
    hi = np.array([np.inf, 0.5, np.inf])
    assert certify(3, P, np.array([0.5, 0.5, 0.0]), w, -inf, hi)[0]
    assert not certify(3, P, np.array([0.0, 0.5, 0.5]), w, -inf, hi)[0]


@pytest.mark.parametrize("seed", range(3))
def test_band_matches_highs_on_random_graphs(seed):
    rng = np.random.default_rng(40 + seed)
    n = 60
    a, b = _random_graph(rng, n, 60)
    P = np.stack([a, b], 1)
    k = len(P)
    d = rng.normal(size=k) * (rng.random(k) < 0.3)
    w = rng.uniform(0.1, 2.0, k)
    info = {}
    r1 = dual_graph_l1(n, P, d, w)
    r2 = banded_l1(n, P, d, w, seeds=[0, 1], rings=1, _info=info)
    assert abs(r1.objective - r2.objective) <= 1e-7 * max(1.0, r1.objective)


def test_band_bad_input():
    P = [[0, 1], [1, 2], [2, 0]]
    with pytest.raises(ValueError, match="rings"):
        banded_l1(3, P, [1.0, 0, 0], [1.0, 1, 1], rings=-1)
    with pytest.raises(ValueError, match="rings"):
        banded_l1(3, P, [1.0, 0, 0], [1.0, 1, 1], rings=True)
    with pytest.raises(ValueError, match="max_rounds"):
        banded_l1(3, P, [1.0, 0, 0], [1.0, 1, 1], max_rounds=0)
    with pytest.raises(ValueError, match="seeds"):
        banded_l1(3, P, [1.0, 0, 0], [1.0, 1, 1], seeds=[5])
    with pytest.raises(ValueError, match="seeds"):
        banded_l1(3, P, [1.0, 0, 0], [1.0, 1, 1], seeds=np.ones(2, bool))
    with pytest.raises(ValueError, match="offsets"):
        banded_l1(3, P, [np.nan, 0, 0], [1.0, 1, 1])
