"""Surface winding numbers on surfaces that are not simply connected: the residual LP, the final solve with the
bounding part as a subset of the input, the second candidate cycle, and the LP solvers behind the default."""

import numpy as np
import pytest

import gsdf.swn._solver as S
from gsdf import SWNOptions
from gsdf.swn._solver import SurfaceWindingNumbers
from tests.swn.test_solver import boundary_chain, mislabeled
from tests.shapes import annulus, torus


# -------------------------------------------------------------------------------- the final jump solve
def _annulus_spoke(gap_frac):
    """A bounding curve on an annulus (10 x 48): the boundary of the inner ring (3 rows) plus a spoke (8 angle
    steps) reaching the outer boundary; the radial side at angle 8 is deleted over ``gap_frac`` of its length.
    The gap runs across the annulus, so the harmonic part of ω is large (the flux of dθ through the gap)."""
    nr, nt = 10, 48
    V, F, _ = annulus(nr, nt, r0=0.4, r1=1.0)
    swn = SurfaceWindingNumbers(V, F)
    ri = (F // nt).min(1)
    k = F % nt
    ki = np.where(k.max(1) - k.min(1) > 1, k.max(1), k.min(1))
    R = (ri < 3) | (ki < 8)
    g = boundary_chain(swn, np.flatnonzero(R))
    E = swn.dec.edges
    er, ek = E // nt, E % nt
    gap = (ek == 8).all(1) & (er >= 3).all(1) & (er <= 3 + gap_frac * (nr - 3)).all(1)
    g[gap] = 0
    return swn, g, R.astype(int)


def test_final_solve_jumps_only_across_the_input():
    """Thesis §6.1.2 step ⑤: w solves the jump equation with jumps "Γ ∖ Jv" — the bounding part of the input, a
    subset of Γ. The completion of the nonbounding part across the gaps (Jv off the input) is no jump of w: it
    used to be imposed too (g − Jv on every edge), which cut the outside of this bounding curve along a phantom
    path and mislabeled 1.7 % of the area (0.8 % now; naive rounding: 0 %)."""
    swn, g, truth = _annulus_spoke(0.8)
    r = swn.solve(g, method="lp")
    off = (g == 0) & (np.abs(r.residual) > 0.1)
    assert off.any()                                           # the LP did close a gap off the input ...
    w = r.corner_values
    J = swn.dec.corner_jumps(w)
    ends = r.endpoints | swn.dec.chain_endpoints(r.bounding, tol=1e-6)   # incl. where the bounding part ends
    inner = ~swn.topology.boundary_edges & ~ends[swn.dec.edges].any(1)
    assert np.abs(J[off & inner]).max() < 1e-8                 # ... but w does not jump there
    assert mislabeled(r, truth, swn.dec.areas) < 0.01


def test_band_solver_agrees_with_highs(monkeypatch):
    """From ``BAND_FACES`` faces on the full LP is solved on a proven band of faces (gsdf.linalg._band_lp); forced
    on a small torus it gives HiGHS' optimum and the same labels."""
    V, F, idx = torus(24, 12)
    swn = SurfaceWindingNumbers(V, F)
    curves = [idx[3, :9]]
    r = swn.solve(curves)
    monkeypatch.setattr(S, "BAND_FACES", 0)
    rb = swn.solve(curves)
    assert r.lp_objective > 1e-6 and np.isclose(rb.lp_objective, r.lp_objective, rtol=1e-6)
    assert np.array_equal(rb.face_labels, r.face_labels)


# ------------------------------------------------------------------ the bounding part as a subset of Γ
def _patch_and_broken_meridian(keep):
    """Torus 48 x 24: the unbroken boundary of a square patch (bounding) plus a meridian at row 5 kept only on
    the vertex runs ``keep`` (nonbounding, broken)."""
    V, F, idx = torus(48, 24)
    swn = SurfaceWindingNumbers(V, F)
    fj = F % 24
    R = ((F // 24).min(1) >= 20) & ((F // 24).max(1) <= 30) & (fj.min(1) >= 4) & (fj.max(1) <= 14)
    g = boundary_chain(swn, np.flatnonzero(R))
    mer = swn.chain([idx[5, list(k)] for k in keep])
    return swn, g + mer, mer != 0, R


def test_bounding_part_is_a_subset_of_the_input():
    """Thesis §6.1.2 step ⑤: the bounding part is "the complement of the nonbounding components, taken as a
    subset of Γ". The LP explains only 0.55 of this broken meridian's jump (Fig. 6.6: coefficients below 1 on
    broken loops); the former reading g − Jv left a 0.45 jump of w across the kept meridian pieces (a phantom
    step round the torus), the subset reading removes the meridian: w is constant outside the patch."""
    swn, g, mer, R = _patch_and_broken_meridian([range(0, 6), range(9, 15), range(18, 22)])
    truth = R.astype(int)
    r = swn.solve(g, method="lp")
    assert 0.5 < np.abs(r.residual[mer]).min() < 0.7             # partly explained by the residual ...
    assert not np.any(r.bounding[mer])                           # ... and still read as nonbounding
    assert np.array_equal(r.bounding[~mer], r.chain[~mer])      # the patch boundary stays whole
    assert np.ptp(r.corner_values[~R]) < 1e-6 and np.ptp(r.corner_values[R]) < 1e-6
    assert mislabeled(r, truth, swn.dec.areas) == 0.0


def test_subset_reading_stops_when_nothing_is_left_to_remove():
    """An unbroken meridian is removed in the first decomposition; the patch boundary left over is closed and
    bounding (ω of its jump solve has no harmonic part), so the second pass needs no LP."""
    swn, g, mer, R = _patch_and_broken_meridian([range(0, 24)])
    g = g + swn.chain([[5 * 24 + 23, 5 * 24]])                  # the closing edge: a whole meridian
    r = swn.solve(g, method="lp")
    assert r.passes == 2 and np.allclose(r.residual[mer], r.chain[mer], atol=1e-6)
    assert not np.any(r.bounding[mer]) and mislabeled(r, R.astype(int), swn.dec.areas) == 0.0


def test_time_limit_bounds_the_lps_of_all_passes(monkeypatch):
    """time_limit is one budget for the residual LPs of every pass: when the first pass's LP used it all, the
    second pass is refused with the fallback named (before, each pass got the whole limit again)."""
    swn, g, mer, R = _patch_and_broken_meridian([range(0, 6), range(9, 15), range(18, 22)])
    calls = []
    real = swn._residual_full

    def slow(gamma, g_, eps, time_limit, ends, forbid=None):
        calls.append(time_limit)
        Jv, obj, _ = real(gamma, g_, eps, time_limit, ends, forbid)
        return Jv, obj, 0.75 * time_limit if len(calls) == 1 else 0.0   # the first LP takes 3/4 of the budget
    monkeypatch.setattr(swn, "_residual_full", slow)
    r = swn.solve(g, method="lp", options=SWNOptions(time_limit=8.0))
    assert r.passes >= 2 and calls[0] == 8.0 and calls[1:] and all(c == 2.0 for c in calls[1:])   # what is left
    # the first LP takes the whole budget: the second pass is refused, naming the fallback
    monkeypatch.setattr(swn, "_residual_full",
                        lambda gm, g_, e, tl, ends, forbid=None: real(gm, g_, e, tl, ends, forbid)[:2] + (tl,))
    with pytest.raises(ValueError, match=r"whole time_limit.*method='reduced'"):
        swn.solve(g, method="lp", options=SWNOptions(time_limit=8.0))


def _band_and_long_loop():
    """Torus (R = 1, r = 0.4): a band round the inner side (region: 10 ≤ j ≤ 14 round the tube, both sides are
    longitudes of length 2π·0.65, homologous to each other) and a nonbounding loop along the outer equator
    (j = 0, length 2π·1.4, homologous to the band's sides), every curve broken in gaps of a few edges. The loop
    misses a quarter of its edges, the band's side j = 10 a third: that side has less gap length, the loop a
    larger share of its length on the input."""
    V, F, idx = torus(48, 24)
    swn = SurfaceWindingNumbers(V, F)
    fj = F % 24
    R = (fj.min(1) >= 10) & (fj.max(1) <= 14)
    g = boundary_chain(swn, np.flatnonzero(R))
    E = swn.dec.edges
    ej, ei = E % 24, E // 24
    along = (ej[:, 0] == ej[:, 1])                                # longitude edges (i varies)
    lo_i = np.where(np.abs(ei[:, 0] - ei[:, 1]) == 1, ei.min(1), ei.max(1))     # the edge's first i (mod 48)

    def cut(j, gaps):                                           # delete the longitude edges i ∈ gaps at j
        return along & (ej[:, 0] == j) & np.isin(lo_i, gaps)
    g[cut(10, [0, 1, 2, 3, 12, 13, 14, 15, 24, 25, 26, 27, 36, 37, 38, 39])] = 0       # a third of side j = 10
    g[cut(14, [6, 7, 18, 19, 30, 31, 42, 43])] = 0                                      # a sixth of side j = 14
    e0 = np.flatnonzero(along & (ej[:, 0] == 10) & (g != 0) & (np.abs(ei[:, 0] - ei[:, 1]) == 1))[0]
    s = int(np.sign(g[e0]))                                     # +1: side j = 10 runs towards increasing i
    loop = swn.chain([idx[list(range(48)) + [0], 0][::s]])      # the loop runs like it (the same class)
    loop[cut(0, [5, 6, 7, 17, 18, 19, 29, 30, 31, 41, 42, 43])] = 0                    # a quarter of the loop
    return swn, g + loop, loop != 0, R.astype(int)


def test_second_cycle_keeps_the_whole_loop_not_the_band_side(monkeypatch):
    """The LP's optimum (least ε-weighted length, thesis §6.1.2) carries the class on the band's side j = 10 — its
    gaps are shorter than the loop's — which would cut the band open. The solver solves the LP again without that
    side's edges, finds the loop, and keeps it: 3/4 of its jump mass lies on the input against 2/3 on the side."""
    swn, g, loop, truth = _band_and_long_loop()
    A = swn.dec.areas
    r = swn.solve(g, method="lp")
    first, _, _ = swn._residual_full(r.gamma, r.chain, 1e-2, 300.0, r.endpoints)
    assert np.abs(first[loop]).max() < 0.1                       # the LP's own cycle avoids the loop
    assert np.abs(r.residual[loop]).min() > 0.5                  # the loop carries the class
    assert not np.any(r.bounding[loop])
    assert mislabeled(r, truth, A) < 0.01
    monkeypatch.setattr(S, "BAND_FACES", 0)                      # the banded LP chooses alike
    assert np.array_equal(swn.solve(g, method="lp").face_labels, r.face_labels)


# ------------------------------------------------------------- a broken meridian plus a broken region boundary
def _meridian_and_patch(i0, i1, j0, j1):
    """48 x 24 torus: the meridian i = 5 with three 2-edge gaps (18 of its 24 edges kept) and the boundary of the
    face patch i0 ≤ i < i1, j0 ≤ j < j1 with a quarter of its edges deleted (seeded). Returns the solver, the input
    chain, the meridian's input edges and the truth (1 on the patch)."""
    V, F, idx = torus(48, 24)
    swn = SurfaceWindingNumbers(V, F)
    fi, fj = F // 24, F % 24
    ci = np.where(fi.max(1) - fi.min(1) > 1, fi.max(1), fi.min(1))
    cj = np.where(fj.max(1) - fj.min(1) > 1, fj.max(1), fj.min(1))
    R = (ci >= i0) & (ci < i1) & (cj >= j0) & (cj < j1)
    g = boundary_chain(swn, np.flatnonzero(R))
    on = np.flatnonzero(g)
    g[np.random.default_rng(0).choice(on, len(on) // 4, replace=False)] = 0
    mer = list(idx[5, :]) + [idx[5, 0]]
    cuts = (3, 11, 19)
    loop = swn.chain([mer[a + 1:b] for a, b in zip((-1,) + cuts, cuts + (25,))])
    return swn, g + loop, loop != 0, R.astype(int)


def test_broken_meridian_is_the_nonbounding_part_beside_a_broken_region():
    """Analytic case: the nonbounding part is the meridian (every one of its input edges leaves the bounding part),
    the broken patch boundary stays bounding, and the labels are the patch."""
    for box in ((20, 28, 4, 12), (2, 9, 4, 12)):                  # apart from the meridian; crossed by it
        swn, g, mer, truth = _meridian_and_patch(*box)
        r = swn.solve(g, method="lp")
        assert not np.any(np.round(r.bounding[mer]))
        assert np.array_equal(np.round(r.bounding[~mer]), g[~mer])
        assert mislabeled(r, truth, swn.dec.areas) < 0.002
        assert np.allclose(np.round(r.bounding) + np.where(g != 0, np.round(r.residual), 0), g)   # g = bnd + N


@pytest.mark.xfail(strict=True, reason="known limit of the LP decomposition: where "
                   "the meridian runs through the patch, parallel to two of its sides, the residual's cycle leaves "
                   "the meridian at the crossings and follows a patch side")
def test_broken_meridian_through_a_broken_patch_known_limit():
    swn, g, mer, truth = _meridian_and_patch(3, 8, 2, 20)
    r = swn.solve(g, method="lp")
    assert not np.any(np.round(r.bounding[mer]))                # today 12 of the 18 meridian edges stay bounding
