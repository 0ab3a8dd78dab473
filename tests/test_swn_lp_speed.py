"""The full residual LP in cycle form (gsdf.dec.cycle_lp.CycleL1, SurfaceWindingNumbers(lp_form="cycles")) is
the same program as the face-shift LP (gsdf.dec.lp.dual_graph_l1): equal optimal objectives on small meshes of
genus 1 and 2 and with boundary, and its jumps are feasible for the face form (J − d = x_A − x_B)."""

import numpy as np
import pytest

from gsdf.dec.cycle_lp import CycleL1
from gsdf.dec.lp import dual_graph_l1
from gsdf.winding.surface import SurfaceWindingNumbers
from tests.topo_shapes import annulus, double_torus, torus


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


@pytest.mark.parametrize("name,V,F,curves", list(cases()), ids=lambda x: x if isinstance(x, str) else "")
def test_cycle_form_equals_face_form(name, V, F, curves):
    faces = SurfaceWindingNumbers(V, F, lp_form="faces")
    cyc = SurfaceWindingNumbers(V, F, lp_form="cycles")
    assert not faces.simply_connected
    for eps in (1e-2, 0.5):
        rf = faces.solve(curves, method="lp", epsilon=eps)
        rc = cyc.solve(curves, method="lp", epsilon=eps)
        assert rf.lp_objective > 1e-6
        assert abs(rf.lp_objective - rc.lp_objective) <= 1e-7 * max(1.0, rf.lp_objective), (name, eps)
    # the same LP data through both solvers directly; the cycle form's jumps come from its face shifts
    g = cyc.chain(curves)
    gamma = cyc.solve(curves, method="lp").gamma
    interior, d, w, bounds = cyc._full_lp_terms(gamma, g, 1e-2)
    pairs = cyc.topology.edge_faces[interior]
    r1 = dual_graph_l1(cyc.dec.n_faces, pairs, d, w, bounds=bounds)
    r2 = CycleL1(cyc.dec, interior).solve(d, w, bounds=bounds)
    assert abs(r1.objective - r2.objective) <= 1e-7 * max(1.0, r1.objective)
    J = d + r2.shifts[pairs[:, 0]] - r2.shifts[pairs[:, 1]]
    assert np.abs(J - r2.jumps).max() < 1e-7
    assert np.all(r2.jumps >= bounds[:, 0] - 1e-9) and np.all(r2.jumps <= bounds[:, 1] + 1e-9)


def test_cycle_form_generator_count():
    V, F, _ = torus(16, 8)
    swn = SurfaceWindingNumbers(V, F)
    inner = np.flatnonzero(swn.topology.edge_face_count == 2)
    assert CycleL1(swn.dec, inner).n_generators == 2
    V, F, _ = annulus(4, 24)                                   # b = 2 boundary circles, g = 0: 2g + b − 1 = 1
    swn = SurfaceWindingNumbers(V, F)
    inner = np.flatnonzero(swn.topology.edge_face_count == 2)
    P = CycleL1(swn.dec, inner)
    assert P.n_generators == 1
    # rows: the cycle rank of the dual graph, |E_int| − |F| + 1
    assert P.C.shape[0] == len(inner) - swn.dec.n_faces + 1


def test_cycle_form_bad_input():
    V, F, _ = torus(16, 8)
    swn = SurfaceWindingNumbers(V, F)
    inner = np.flatnonzero(swn.topology.edge_face_count == 2)
    P = CycleL1(swn.dec, inner)
    k = len(inner)
    with pytest.raises(ValueError, match="offsets/weights"):
        P.solve(np.zeros(k - 1), np.ones(k))
    with pytest.raises(ValueError, match="offsets/weights"):
        P.solve(np.full(k, np.nan), np.ones(k))
    with pytest.raises(ValueError, match="bounds"):
        P.solve(np.zeros(k), np.ones(k), bounds=np.ones((k, 3)))
    with pytest.raises(ValueError, match="algorithm"):
        P.solve(np.zeros(k), np.ones(k), algorithm="simplex")
    with pytest.raises(ValueError, match="time_limit"):
        P.solve(np.zeros(k), np.ones(k), time_limit=True)
    with pytest.raises(ValueError, match="interior"):
        CycleL1(swn.dec, np.array([swn.dec.n_edges]))
    with pytest.raises(ValueError, match="lp_form"):
        SurfaceWindingNumbers(V, F, lp_form="dual")
    # J = 1 on every edge: not a relative cycle (vertex sums ≠ 0), no face shifts give it
    with pytest.raises(ValueError, match="infeasible|HiGHS"):
        P.solve(np.zeros(k), np.ones(k), bounds=np.column_stack([np.ones(k), np.ones(k)]))
