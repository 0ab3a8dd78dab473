"""The L1 dual-graph program restricted to a band of cells, with a proof that the restriction lost nothing.

The program of :func:`gsdf.linalg._dual_l1.dual_graph_l1`, ``min Σ w |J|`` with ``J = d + x_A − x_B`` and bounds on J, has
sparse optimal jumps when d is closed (the sum of d around every vertex loop of the dual graph vanishes, as for the
residual of surface winding numbers, thesis §6.1.2): J lives near the input curves and the paths that close their
gaps. Solving it on all cells costs simplex pivots that only route the dual flow through the far field. Here:

1. **band**: the seed cells (e.g. the faces along the curves and along the reduced LP's completion paths, §6.3)
   grown by ``rings`` rings of neighbours; outside it, J = 0 is imposed: every connected piece of the outside is
   integrated once (``x_B − x_A = d`` along a spanning forest) and becomes a single cell. If d is not exact on
   a piece (a non-forest link inside it would get a jump: the piece has a loop with a period), the cells of
   such links (the forest's seam) join the band and step 1 repeats;
2. **restricted solve** of the contracted program (band cells + one cell per outside piece) by the network simplex
   (:mod:`gsdf.linalg._netflow`) — a restriction of the full program (J = 0 outside), so its optimum is ≥ the full
   one, and equal when some full optimum has no jump outside the band;
3. **proof**: the shifts x of step 2 are optimal for the *full* program iff a dual certificate exists — a flow f
   per link, conserved at every cell, with f in the subdifferential of the link's cost at its jump
   (``w·sign J`` where J ≠ 0, ``[−w, w]`` where J = 0, unbounded towards the feasible side where J sits on a
   bound; complementary slackness of the LP pair of :mod:`gsdf.linalg._netflow`). Whether such a circulation exists
   is one maximum-flow problem on all cells (Hoffman's circulation theorem: the few links with a fixed nonzero
   flow become sources and sinks; ``scipy.sparse.csgraph.maximum_flow``, integer capacities: the intervals
   are scaled by S ≈ 10⁹ / (total fixed flow) and rounded inwards; a deficit up to 10⁻⁶ of the fixed flow is
   accepted, and jumps below 10⁻⁶ (relative to max |d|) count as 0, so the flow is a certificate up to these
   resolutions). Found: the result is the full optimum (same objective). Not
   found: the band is grown and steps 1–3 repeat, at most ``max_rounds`` times, then the full program is
   solved (HiGHS interior point, :func:`gsdf.linalg._dual_l1.dual_graph_l1`).

Example
-------
>>> import numpy as np
>>> pairs = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])      # a cycle of four cells, d closed but for its period 1
>>> r = banded_l1(4, pairs, np.array([1.0, 0.0, 0.0, 0.0]), np.array([3.0, 1.0, 2.0, 2.0]), seeds=[1], rings=0)
>>> np.round(r.jumps, 6).tolist(), round(r.objective, 6)  # the period goes to the cheapest link
([0.0, 1.0, 0.0, 0.0], 1.0)
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order, connected_components, maximum_flow

from gsdf.linalg._l1_terms import DualL1Result, _checked_terms
from gsdf.linalg._dual_l1 import dual_graph_l1
from gsdf.linalg._netflow import _l1_by_circulation
from gsdf.linalg._graph import forest_potentials

__all__ = ["banded_l1"]

_INT_MAX = 2**31 - 1


def _grow(band, G, rings):
    for _ in range(int(rings)):
        band = band | (G @ band.astype(np.float64) > 0)
    return band


def _integrate(n, a, b, d):
    """x with x_b − x_a = d along a spanning forest of the links a–b (one link per cell pair)."""
    if len(a) == 0:
        return np.zeros(n)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    _, first = np.unique(lo * n + hi, return_index=True)
    a, b, d = a[first], b[first], d[first]
    return forest_potentials(n, np.concatenate([a, b]), np.concatenate([b, a]), np.concatenate([d, -d]))


def certify(n, P, J, w, lo, hi, tol=1e-9):
    """(True, None) when a circulation f with f ∈ ∂c(J) on every link exists (the shifts behind J are optimal),
    decided by one integer maximum flow (module docstring, step 3); else (False, mask of the cells on the source
    side of a minimum cut)."""
    A, B = P[:, 0], P[:, 1]
    keep = A != B
    A, B, J, w, lo, hi = A[keep], B[keep], J[keep], w[keep], lo[keep], hi[keep]
    zero = np.abs(J) <= tol
    # f ∈ ∂(w|J|) = {w sign J} or [−w, w]; plus [0, inf) at J = hi, (−inf, 0] at J = lo
    l = np.where(zero, -w, w * np.sign(J))
    u = l.copy()
    u[zero] = w[zero]
    u = np.where(np.isfinite(hi) & (J >= hi - tol), np.inf, u)
    l = np.where(np.isfinite(lo) & (J <= lo + tol), -np.inf, l)
    # preload where 0 is outside [l, u]: f = l + g (l > 0) or f = u − g (u < 0)
    pre = np.where(l > 0, l, np.where(u < 0, u, 0.0))
    fwd = np.where(l > 0, u - l, np.where(u < 0, 0.0, u))       # capacity A → B of the rest
    bwd = np.where(l > 0, 0.0, np.where(u < 0, u - l, -l))      # capacity B → A
    # the preloads leave A and enter B: B must pass pre on, A must receive it
    b = np.bincount(B, weights=pre, minlength=n) - np.bincount(A, weights=pre, minlength=n)
    need = float(np.abs(b).sum()) / 2
    if need == 0.0:
        return True, None
    S = min(1e9 / need, 1e9 / max(1e-300, float(np.max(np.where(np.isfinite(fwd), fwd, 0), initial=0)),
                                   float(np.max(np.where(np.isfinite(bwd), bwd, 0), initial=0))))
    big = _INT_MAX // 4

    def icap(c):
        return np.where(np.isfinite(c), np.minimum(np.floor(c * S), big), big).astype(np.int64)

    bi = np.rint(b * S).astype(np.int64)
    src, snk = n, n + 1
    pos, neg = np.flatnonzero(bi > 0), np.flatnonzero(bi < 0)
    rows = np.concatenate([A, B, np.full(len(pos), src), neg])
    cols = np.concatenate([B, A, pos, np.full(len(neg), snk)])
    caps = np.concatenate([icap(fwd), icap(bwd), bi[pos], -bi[neg]])
    ok = caps > 0
    G = sp.csr_matrix((caps[ok].astype(np.int32), (rows[ok], cols[ok])), shape=(n + 2, n + 2))
    G.sum_duplicates()
    res = maximum_flow(G, src, snk)
    # the capacities were rounded down to units of 1/S (≈ 1e-9 of the fixed flow): accept a deficit of 1e-6 of
    # the fixed flow (a conservation error that small: a certificate to that resolution)
    want = min(bi[pos].sum(), -bi[neg].sum())
    if res.flow_value >= want - max(abs(int(bi.sum())), int(1e-6 * want) + 1):
        return True, None
    # no certificate: the cells the source still reaches in the residual graph (a minimum cut) — shifting them
    # lowers the objective, so new jumps belong on the links around them
    R = (G - res.flow).tocsr()
    R.data = (R.data > 0).astype(np.float64)
    R.eliminate_zeros()
    order = breadth_first_order(R, src, directed=True, return_predecessors=False)
    reach = np.zeros(n + 2, dtype=bool)
    reach[order] = True
    return False, reach[:n]


def banded_l1(n_cells: int, pairs, offsets, weights, bounds=None, seeds=None, rings: int = 4, max_rounds: int = 6,
              time_limit: float = 300.0, gauge: str = "component", _info: dict | None = None) -> DualL1Result:
    """The program of :func:`gsdf.linalg._dual_l1.dual_graph_l1`, solved on a band around ``seeds`` and proven optimal
    for all cells (module docstring); the full program (HiGHS interior point) if no band of ``max_rounds`` tries
    can be proven.

    Parameters
    ----------
    n_cells, pairs, offsets, weights, bounds, time_limit, gauge : as :func:`gsdf.linalg._dual_l1.dual_graph_l1`
    seeds : (s,) int or (n_cells,) bool, the cells where jumps are expected (default: the cells of links with a
        bound that excludes 0 or a weight below a tenth of the median — cheap links)
    rings : int ≥ 0, neighbour rings added to the seeds; after a failed proof the band grows by ``rings`` rings
        around the links of the certificate's minimum cut (where the better shifts jump) and one ring everywhere
    max_rounds : int ≥ 1

    Returns
    -------
    DualL1Result (``seconds``: all rounds, proofs and any fallback)

    Example
    -------
    >>> r = banded_l1(3, [[0, 1], [1, 2], [2, 0]], [1.0, 0.0, 0.0], [2.0, 1.0, 5.0], seeds=[0])
    >>> round(r.objective, 6)
    1.0
    """
    t_start = time.perf_counter()
    n, P, d, w, lo, hi, gauge_cells, labels = _checked_terms(n_cells, pairs, offsets, weights, bounds, time_limit,
                                                             gauge)
    if isinstance(rings, bool) or not isinstance(rings, (int, np.integer)) or rings < 0:
        raise ValueError(f"rings: expected an integer >= 0, got {rings!r}")
    if isinstance(max_rounds, bool) or not isinstance(max_rounds, (int, np.integer)) or max_rounds < 1:
        raise ValueError(f"max_rounds: expected an integer >= 1, got {max_rounds!r}")
    k = len(P)
    A, B = P[:, 0], P[:, 1]
    band = np.zeros(n, dtype=bool)
    if seeds is None:
        cheap = (w < 0.1 * np.median(w)) if k else np.zeros(0, bool)
        fixed = (lo > 0) | (hi < 0)
        band[A[cheap | fixed]] = True
        band[B[cheap | fixed]] = True
    else:
        s = np.asarray(seeds)
        if s.dtype == bool:
            if s.shape != (n,):
                raise ValueError(f"seeds: a boolean mask needs shape ({n},), got {s.shape}")
            band |= s
        else:
            if s.size and (not np.issubdtype(s.dtype, np.integer) or s.min() < 0 or s.max() >= n):
                raise ValueError(f"seeds: expected cell indices in [0, {n})")
            band[s.astype(np.int64)] = True
    # links whose bounds exclude J = 0 must be in the band (outside, J = 0 is imposed)
    fixed = (lo > 0) | (hi < 0)
    band[A[fixed]] = True
    band[B[fixed]] = True
    G = sp.coo_matrix((np.ones(k), (A, B)), shape=(n, n)).tocsr()
    G = (G + G.T).tocsr()
    band = _grow(band, G, rings)
    scale = max(1.0, float(np.abs(d).max())) if k else 1.0
    # a link inside an outside piece "has a period" beyond this (d is closed only to rounding: the curl sums of
    # ~1e-13 per vertex add up over the vertices a loop encloses)
    tol = 1e-7 * scale
    info = _info if _info is not None else {}
    info.update(rounds=0, band_cells=[], objectives=[], proven=False, t_restricted=0.0, t_proof=0.0)
    r_cur = int(rings)
    for rnd in range(int(max_rounds)):
        info["rounds"] = rnd + 1
        # ---- 1. integrate the outside pieces; grow over links inside them that would get a jump
        for _ in range(20):
            out = ~band
            oo = np.flatnonzero(out[A] & out[B] & (A != B))
            x = _integrate(n, A[oo], B[oo], d[oo])
            x[band] = 0.0
            bad = oo[np.abs(d[oo] + x[A[oo]] - x[B[oo]]) > tol]
            if len(bad) == 0:
                break
            grow = np.zeros(n, dtype=bool)
            grow[A[bad]] = True
            grow[B[bad]] = True
            band = band | grow                    # the seam of the forest: cells of the links with a period
        else:
            break
        info["band_cells"].append(int(band.sum()))
        # ---- 2. contracted program: band cells and one cell per outside piece
        Go = sp.coo_matrix((np.ones(len(oo)), (A[oo], B[oo])), shape=(n, n))
        _, lab = connected_components(Go, directed=False)
        nb = int(band.sum())
        node = np.empty(n, dtype=np.int64)
        node[band] = np.arange(nb)
        olab = np.unique(lab[~band], return_inverse=True)[1]
        node[~band] = nb + olab
        n_c = nb + (int(olab.max()) + 1 if len(olab) else 0)
        cut = np.flatnonzero(band[A] | band[B] | (A == B))
        left = time_limit - (time.perf_counter() - t_start)
        if not left > 0:
            raise ValueError(f"linear program: band solve hit its time limit (time_limit={time_limit})")
        Pc = np.stack([node[A[cut]], node[B[cut]]], 1)
        t1 = time.perf_counter()
        s_c, _, _ = _l1_by_circulation(n_c, Pc, d[cut] + x[A[cut]] - x[B[cut]], w[cut], lo[cut], hi[cut], left)
        info["t_restricted"] += time.perf_counter() - t1
        xf = x + s_c[node]
        J = d + xf[A] - xf[B]
        J[oo] = 0.0
        if (J < lo - 1e-7 * scale).any() or (J > hi + 1e-7 * scale).any():
            raise ValueError("linear program: band solve violates the jump bounds (numerical trouble)")
        J = np.clip(J, lo, hi)
        info["objectives"].append(float(np.dot(w, np.abs(J))))
        # ---- 3. proof over all cells
        t1 = time.perf_counter()
        ok, reach = certify(n, P, J, w, lo, hi, tol=1e-6 * scale)
        info["t_proof"] += time.perf_counter() - t1
        if ok:
            info["proven"] = True
            if gauge_cells is not None:
                xf = xf - xf[gauge_cells][labels]
            Jr = d + xf[A] - xf[B]
            return DualL1Result(xf, Jr, float(np.dot(w, np.abs(Jr))), time.perf_counter() - t_start)
        # grow the band over the links of the minimum cut (where the next jumps go), and a little everywhere
        across = reach[A] != reach[B]
        grow = np.zeros(n, dtype=bool)
        grow[A[across]] = True
        grow[B[across]] = True
        band = _grow(band, G, 1) | _grow(grow, G, max(1, r_cur))
    left = time_limit - (time.perf_counter() - t_start)
    if not left > 0:
        raise ValueError(f"linear program: band solve hit its time limit (time_limit={time_limit})")
    info["fallback"] = True
    r = dual_graph_l1(n, P, d, w, bounds=np.column_stack([lo, hi]), time_limit=left, gauge=gauge,
                      algorithm="highs-ipm")
    return DualL1Result(r.shifts, r.jumps, r.objective, time.perf_counter() - t_start)
