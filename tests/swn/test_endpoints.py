"""Interior endpoints in the jump Laplace solve (gsdf.dec.TriangleDEC.branch_coordinates, the branch points that
gsdf.SurfaceWindingNumbers.solve uses on simply connected surfaces) against analytic answers.

Analytic answer used: on the unit sphere, stereographic projection from the south pole maps the equator to the
unit circle and the north pole to its centre, and it is conformal, so harmonic functions with jumps map to
harmonic functions with the same jumps. In the plane the winding number of arcs of the unit circle at the centre
is the total angle of the arcs over 2π, and 0 at infinity (the south pole). So for any set of equator arcs the
jump harmonic u has u(north) − u(south) = the fraction of the equator present.
"""

import numpy as np
import pytest

from gsdf.dec._triangle import TriangleDEC
from gsdf.swn._solver import SurfaceWindingNumbers
from tests.shapes import uv_sphere

N_LAT, N_LON = 24, 48


@pytest.fixture(scope="module")
def sphere():
    V, F = uv_sphere(N_LAT, N_LON)
    return V, F, SurfaceWindingNumbers(V, F)


def equator(V):
    ring = 1 + (N_LAT // 2 - 1) * N_LON + np.arange(N_LON)
    assert np.abs(V[ring, 2]).max() < 1e-12
    return ring


def pieces(ring, run, gap, start=0):
    """Runs of ``run`` edges separated by gaps of ``gap`` edges along the equator."""
    n = len(ring)
    return [[int(ring[(s + t) % n]) for t in range(run + 1)] for s in range(start, start + n, run + gap)]


def pole_difference(swn, F, n, curves, rule):
    """u(north) − u(south): through ``solve`` (branch points on the sphere), or with the exclusion rule of the
    surfaces that are not simply connected (``_jump_solve(..., "exclude")``)."""
    if rule == "branch":
        w = swn.solve(curves, method="none").corner_values.mean(1)
    else:
        g = swn.chain(curves)
        w = swn._jump_solve(g, swn.dec.chain_endpoints(g), rule).mean(1)
    return w[np.any(F == 0, 1)].mean() - w[np.any(F == n - 1, 1)].mean()


@pytest.mark.parametrize("run,gap", [(1, 1), (2, 1), (1, 2), (2, 4), (4, 2), (5, 3)])
def test_broken_equator_pole_difference_is_the_fraction_present(sphere, run, gap):
    V, F, swn = sphere
    ring = equator(V)
    assert N_LON % (run + gap) == 0
    cur = pieces(ring, run, gap)
    present = len(cur) * run / N_LON
    d = pole_difference(swn, F, len(V), cur, "branch")
    assert abs(d - present) < 0.01, (d, present)
    # the exclusion rule (endpoints and their halfedges excluded) is off on all of these: 1-edge runs vanish,
    # 1-edge gaps close, longer runs and gaps are shrunk / widened by about a one-ring each
    d_old = pole_difference(swn, F, len(V), cur, "exclude")
    assert abs(d_old - present) > 0.02, (d_old, present)


def test_branch_solve_is_linear_in_the_chain(sphere):
    """The jump Laplace equation is linear in its jumps; with the branch rule the discrete solve is too (the
    exclusion rule is not: its excluded set depends on the curves)."""
    V, F, swn = sphere
    dec = swn.dec
    ring = equator(V)
    lat = 1 + 5 * N_LON + np.arange(N_LON)
    g1 = swn.chain(pieces(ring, 3, 2))
    g2 = swn.chain(pieces(lat, 2, 5, start=1))
    ends = lambda g: dec.chain_endpoints(g)  # noqa: E731
    u = lambda g: swn._jump_solve(g, ends(g), "branch")  # noqa: E731
    r = u(g1 + g2) - u(g1) - u(g2)
    A = np.repeat(dec.areas, 3)
    r = r.ravel() - np.average(r.ravel(), weights=A)
    assert np.abs(r).max() < 1e-6
    r_old = (swn._jump_solve(g1 + g2, ends(g1 + g2), "exclude") - swn._jump_solve(g1, ends(g1), "exclude")
             - swn._jump_solve(g2, ends(g2), "exclude")).ravel()
    assert np.abs(r_old - np.average(r_old, weights=A)).max() > 1e-3


def test_branch_coordinates_ramp_closes_around_an_endpoint():
    """Around an endpoint the offsets jump by the curve's jump once and ramp back by it over the full angle:
    consecutive faces (counter-clockwise) differ by −Σ (θ_f + θ_f') / (2Θ) off the curve."""
    V, F = uv_sphere(8, 12)
    dec = TriangleDEC(V, F)
    a, b = 1 + 3 * 12, 1 + 3 * 12 + 1                          # one equator edge: both ends are endpoints
    g = np.zeros(dec.n_edges)
    g[np.flatnonzero((dec.edges == [a, b]).all(1))] = 1.0
    jc = dec.branch_coordinates(g)
    assert not jc.endpoints.any() and jc.walked[[a, b]].all()
    ang = dec.angles
    for v in (a, b):
        f, k = np.nonzero(F == v)
        c = jc.c[f, k]
        # the offsets span the jump minus one half-step: 1 − (θ_first + θ_last) / (2Θ) across the curve edge
        th = ang[f, k]
        assert np.ptp(c) < 1.0 and np.ptp(c) > 1.0 - th.max() / th.sum() - 1e-9
    # without the ramp (the exclusion rule) the endpoints get no offsets at all
    jx = dec.jump_coordinates(g)
    assert jx.endpoints[[a, b]].all() and not jx.walked[[a, b]].any()


def test_endpoints_bad_input(sphere):
    V, F, swn = sphere
    cur = pieces(equator(V), 2, 2)
    g = swn.chain(cur)
    with pytest.raises(ValueError, match="endpoints: expected shape"):
        swn.dec.branch_coordinates(g, np.zeros(3, bool))
    with pytest.raises(ValueError, match="jump"):
        swn.dec.branch_coordinates(np.full(swn.dec.n_edges, np.nan))
