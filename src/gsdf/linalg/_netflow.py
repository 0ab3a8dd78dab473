"""Primal network simplex for min-cost circulations with real capacities and costs (numba), and the L1 dual-graph
program solved through it (the restricted solves of :mod:`gsdf.linalg._band_lp`).

The L1 program of :func:`gsdf.linalg._dual_l1.dual_graph_l1` (least weighted L1 jump ``Σ w |d + x_A − x_B|`` over
per-cell shifts x, with bounds on the jumps; the residual of surface winding numbers, thesis §6.1.2) is the LP
dual of a *pure* minimum-cost circulation on the dual graph: the shifts x are the node potentials of the flow
problem. Pure network LPs are solved by the network simplex, whose bases are spanning trees — no factorization,
one tree path per pivot.

The dual, derived (Lagrangian of ``J = d + x_A − x_B`` with multiplier f per dual edge):

    max_f  Σ_k d_k f_k − c_k*(f_k)   s.t.  Σ_{k out of c} f_k − Σ_{k into c} f_k = 0  at every cell c,

where ``c_k(J) = w_k |J| + [lo_k ≤ J ≤ hi_k]`` and its conjugate, with J = s⁺ − s⁻ and the bounds of s± as in
:func:`gsdf.linalg._dual_l1.dual_graph_l1` (``s⁺ ∈ [a, b]``, ``s⁻ ∈ [a', b']``), is

    c*(t) = a (t − w) + (b − a) (t − w)⁺ + a' (−t − w) + (b' − a') (−t − w)⁺ ,

a convex piecewise linear cost with breakpoints ±w (an infinite b or b' forbids t beyond ±w). Each dual edge
A → B therefore becomes up to four parallel arcs of a circulation: A → B with capacity w and cost
``ℓ = −d + a − a'``, A → B of unbounded capacity and cost ``ℓ + (b − a)`` (only if b is finite), and the mirrored
pair B → A with costs ``−ℓ`` and ``−ℓ + (b' − a')``. The minimum cost of that circulation is
``−(optimum of the L1 program) − Σ w (a + a')``; at the optimum the reduced costs ``cost + π_tail − π_head``
vanish on tree arcs, so with ``x = −π`` every arc in the interior of its range has zero jump, saturated arcs have
the jump's sign, and the unbounded arcs enforce the bounds — complementary slackness, i.e. x is an optimal
solution of the L1 program. :func:`dual_graph_l1_network` checks this numerically (bounds and equal objectives)
before returning.

The solver (:func:`network_simplex`) is the textbook primal network simplex (Dantzig; Cunningham's strongly
feasible trees against cycling; block search pricing as in LEMON's): all flows start at 0 (a circulation is
feasible at 0), the initial tree is a star of zero-cost artificial arcs ``u → root`` that carry no flow ever
(any cycle through the root meets one of them backwards, at flow 0). A pivot: the entering arc closes a cycle
with the tree path between its ends (found by depths), the last blocking arc of the cycle leaves (strongly
feasible rule), the subtree cut off is re-hung at the entering arc (parent pointers reversed along the stem,
children in linked lists), and its potentials and depths are updated by one walk over it. Potentials are
recomputed from the tree before optimality is declared. Work runs in chunks of pivots so that a time limit is
checked between them.

Example
-------
>>> import numpy as np
>>> pairs = np.array([[0, 1], [1, 2], [2, 0]])            # a cycle of three cells
>>> res = dual_graph_l1_network(3, pairs, np.array([1.0, 0.0, 0.0]), np.array([2.0, 1.0, 5.0]))
>>> np.round(res.jumps, 6).tolist()                        # the total 1 goes to the cheapest edge
[0.0, 1.0, 0.0]
"""

from __future__ import annotations

import time

import numba as nb
import numpy as np

from gsdf.linalg._l1_terms import DualL1Result

__all__ = ["network_simplex", "dual_graph_l1_network"]

_CHUNK = 20_000         # pivots between two time-limit checks


@nb.njit(cache=True)
def _detach(c, parent, first_child, next_sib, prev_sib):
    p = parent[c]
    if prev_sib[c] != -1:
        next_sib[prev_sib[c]] = next_sib[c]
    else:
        first_child[p] = next_sib[c]
    if next_sib[c] != -1:
        prev_sib[next_sib[c]] = prev_sib[c]
    next_sib[c] = -1
    prev_sib[c] = -1


@nb.njit(cache=True)
def _attach(c, p, first_child, next_sib, prev_sib):
    f = first_child[p]
    next_sib[c] = f
    prev_sib[c] = -1
    if f != -1:
        prev_sib[f] = c
    first_child[p] = c


@nb.njit(cache=True)
def _tree_potentials(root, src, cost, parent, pred, first_child, next_sib, pi, depth, stack):
    """π and depth from the tree alone (π_root = 0; reduced cost 0 on every tree arc)."""
    pi[root] = 0.0
    depth[root] = 0
    top = 0
    stack[0] = root
    while top >= 0:
        u = stack[top]
        top -= 1
        c = first_child[u]
        while c != -1:
            a = pred[c]
            if src[a] == c:                       # arc c -> parent:  cost + π_c − π_p = 0
                pi[c] = pi[u] - cost[a]
            else:                                 # arc parent -> c:  cost + π_p − π_c = 0
                pi[c] = pi[u] + cost[a]
            depth[c] = depth[u] + 1
            top += 1
            stack[top] = c
            c = next_sib[c]


@nb.njit(cache=True)
def _pivots(n_real, root, src, dst, cap, cost, flow, state, parent, pred, depth, pi, first_child, next_sib,
            prev_sib, stack, tol, block, next_arc, max_pivots):
    """Run at most ``max_pivots`` pivots. Returns (status, pivots done, next_arc): status 0 optimal for the
    current potentials, 1 pivot budget used up, 2 unbounded (a negative cycle of unbounded arcs)."""
    m = n_real
    done = 0
    while done < max_pivots:
        # ---- entering arc: block search (the best of a block, the first block holding a violation)
        best = -tol
        e_in = -1
        cnt = 0
        e = next_arc
        for _ in range(m):
            s = state[e]
            if s != 0:
                c = s * (cost[e] + pi[src[e]] - pi[dst[e]])
                if c < best:
                    best = c
                    e_in = e
            e += 1
            if e == m:
                e = 0
            cnt += 1
            if cnt == block:
                if e_in != -1:
                    break
                cnt = 0
        if e_in == -1:
            return 0, done, next_arc
        next_arc = e
        # ---- cycle: in_arc first -> second, up to the join node, down to first
        if state[e_in] == 1:
            first, second = src[e_in], dst[e_in]
        else:
            first, second = dst[e_in], src[e_in]
        u, v = first, second
        while u != v:
            if depth[u] > depth[v]:
                u = parent[u]
            elif depth[v] > depth[u]:
                v = parent[v]
            else:
                u = parent[u]
                v = parent[v]
        join = u
        delta = cap[e_in]
        result = 0
        u_out = -1
        u = first                                  # traversed join -> first: strict < keeps the last one
        while u != join:
            a = pred[u]
            if src[a] == u:                        # arc up (u -> parent), traversed down: flow decreases
                d = flow[a]
            else:
                d = cap[a] - flow[a]
            if d < 0.0:
                d = 0.0
            if d < delta:
                delta = d
                u_out = u
                result = 1
            u = parent[u]
        u = second                                 # traversed second -> join: <= keeps the last one
        while u != join:
            a = pred[u]
            if src[a] == u:                        # arc up, traversed up: flow increases
                d = cap[a] - flow[a]
            else:
                d = flow[a]
            if d < 0.0:
                d = 0.0
            if d <= delta:
                delta = d
                u_out = u
                result = 2
            u = parent[u]
        if delta == np.inf:
            return 2, done, next_arc
        # ---- push delta around the cycle
        if delta > 0.0:
            val = state[e_in] * delta
            flow[e_in] += val
            u = src[e_in]
            while u != join:
                a = pred[u]
                flow[a] -= val if src[a] == u else -val
                u = parent[u]
            u = dst[e_in]
            while u != join:
                a = pred[u]
                flow[a] += val if src[a] == u else -val
                u = parent[u]
        done += 1
        if result == 0:                            # the entering arc went from one bound to the other
            state[e_in] = -state[e_in]
            flow[e_in] = cap[e_in] if state[e_in] == -1 else 0.0
            continue
        if result == 1:
            u_in, v_in = first, second
        else:
            u_in, v_in = second, first
        a_out = pred[u_out]
        if a_out < m:                              # artificial arcs leave for good (state 0, never priced)
            if flow[a_out] > 0.5 * cap[a_out]:
                state[a_out] = -1
                flow[a_out] = cap[a_out]
            else:
                state[a_out] = 1
                flow[a_out] = 0.0
        state[e_in] = 0
        # ---- potentials shift of the subtree moving under v_in (reduced cost of e_in becomes 0)
        if src[e_in] == u_in:
            sigma = pi[v_in] - pi[u_in] - cost[e_in]
        else:
            sigma = cost[e_in] + pi[v_in] - pi[u_in]
        # ---- re-hang: reverse the parent pointers along the stem u_in .. u_out
        prev_node = v_in
        prev_arc = e_in
        node = u_in
        while True:
            old_parent = parent[node]
            old_arc = pred[node]
            _detach(node, parent, first_child, next_sib, prev_sib)
            parent[node] = prev_node
            pred[node] = prev_arc
            _attach(node, prev_node, first_child, next_sib, prev_sib)
            if node == u_out:
                break
            prev_node = node
            prev_arc = old_arc
            node = old_parent
        # ---- depths and potentials over the moved subtree
        top = 0
        stack[0] = u_in
        depth[u_in] = depth[v_in] + 1
        while top >= 0:
            x = stack[top]
            top -= 1
            pi[x] += sigma
            c = first_child[x]
            while c != -1:
                depth[c] = depth[x] + 1
                top += 1
                stack[top] = c
                c = next_sib[c]
    return 1, done, next_arc


@nb.njit(cache=True)
def _link_children(parent, first_child, next_sib, prev_sib):
    for c in range(len(parent) - 1, -1, -1):
        if parent[c] != -1:
            _attach(c, parent[c], first_child, next_sib, prev_sib)


def _initial_tree(n, tail, head, cap):
    """A strongly feasible first basis at flow 0: a breadth-first spanning tree of every connected component over
    the finite-capacity arcs, each tree arc pointing from a node to its parent (flow can be pushed towards the
    root), the component's first node hanging from the root by its artificial arc. (parent, pred) of n + 1
    nodes; pred indexes the arcs, artificial arc of u = m + u."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import breadth_first_order, connected_components

    m = len(tail)
    root = n
    parent = np.full(n + 1, -1, dtype=np.int64)
    pred = np.full(n + 1, -1, dtype=np.int64)
    ok = np.flatnonzero((cap > 0) & np.isfinite(cap))
    Gs = sp.coo_matrix((np.ones(len(ok)), (tail[ok], head[ok])), shape=(n, n)).tocsr()
    nc, lab = connected_components(Gs, directed=False)
    starts = np.full(nc, n, dtype=np.int64)
    np.minimum.at(starts, lab, np.arange(n))
    Gt = Gs.T.tocsr()                                   # p -> c wherever an arc c -> p exists
    key = tail[ok] * n + head[ok]
    srt = np.argsort(key, kind="stable")
    for r in starts:
        order, prd = breadth_first_order(Gt, int(r), directed=True, return_predecessors=True)
        parent[r] = root
        pred[r] = m + r
        ch = order[1:]
        if len(ch):
            par = prd[ch].astype(np.int64)
            pos = np.searchsorted(key[srt], ch * n + par)          # the arc child -> parent
            parent[ch] = par
            pred[ch] = ok[srt[pos]]
    left = np.flatnonzero(parent[:n] == -1)                # not reached along arcs towards a start: artificial
    parent[left] = root
    pred[left] = m + left
    return parent, pred


def network_simplex(n_nodes: int, tail, head, cap, cost, time_limit: float = 300.0, tol: float = 1e-11):
    """Minimum-cost circulation ``min Σ cost·f`` with ``0 ≤ f ≤ cap`` and flow conservation at every node.

    Parameters
    ----------
    n_nodes : int
    tail, head : (m,) int, the arcs ``tail → head`` (no self-loops)
    cap : (m,) float ≥ 0, capacities (``np.inf`` allowed)
    cost : (m,) float, finite
    time_limit : float, seconds; beyond it a ValueError
    tol : float, relative tolerance on reduced costs (times max |cost|)

    Returns
    -------
    flow : (m,) float
    potentials : (n_nodes,) float π with reduced costs ``cost + π_tail − π_head`` ≥ −tol at flow 0, ≤ tol at
        capacity and ≈ 0 in between (π = 0 at one node of every tree hanging from the artificial root)
    pivots : int

    Example
    -------
    >>> f, pi, _ = network_simplex(3, [0, 1, 2, 1], [1, 2, 0, 0], [1.0, 1.0, 1.0, 5.0], [-1.0, 0.0, 0.0, 0.5])
    >>> f.tolist()                                  # one unit around 0 -> 1 -> 2 -> 0 (cost -1, not -0.5)
    [1.0, 1.0, 1.0, 0.0]
    """
    n = int(n_nodes)
    tail = np.ascontiguousarray(tail, dtype=np.int64)
    head = np.ascontiguousarray(head, dtype=np.int64)
    cap = np.ascontiguousarray(cap, dtype=np.float64)
    cost = np.ascontiguousarray(cost, dtype=np.float64)
    m = len(tail)
    if not (head.shape == cap.shape == cost.shape == (m,)):
        raise ValueError("tail/head/cap/cost: expected equal 1-d shapes")
    if m and (min(tail.min(), head.min()) < 0 or max(tail.max(), head.max()) >= n or np.any(tail == head)):
        raise ValueError("tail/head: node index out of range or a self-loop")
    if np.isnan(cap).any() or (cap < 0).any() or not np.isfinite(cost).all():
        raise ValueError("cap/cost: need capacities >= 0 (inf allowed) and finite costs")
    root = n
    # real arcs 0..m-1, artificial arc m+u: u -> root, cost 0, unbounded, flow 0
    src = np.concatenate([tail, np.arange(n, dtype=np.int64)])
    dst = np.concatenate([head, np.full(n, root, dtype=np.int64)])
    cp = np.concatenate([cap, np.full(n, np.inf)])
    cs = np.concatenate([cost, np.zeros(n)])
    flow = np.zeros(m + n)
    state = np.ones(m + n, dtype=np.int8)          # 1: at 0, -1: at capacity, 0: in the tree
    state[m:] = 0
    parent, pred = _initial_tree(n, tail, head, cap)
    depth = np.zeros(n + 1, dtype=np.int64)
    pi = np.zeros(n + 1)
    first_child = np.full(n + 1, -1, dtype=np.int64)
    next_sib = np.full(n + 1, -1, dtype=np.int64)
    prev_sib = np.full(n + 1, -1, dtype=np.int64)
    _link_children(parent, first_child, next_sib, prev_sib)
    state[pred[:n]] = 0
    stack = np.zeros(n + 2, dtype=np.int64)
    _tree_potentials(root, src, cs, parent, pred, first_child, next_sib, pi, depth, stack)
    scale = max(1.0, float(np.abs(cost).max())) if m else 1.0
    tol_abs = tol * scale
    block = max(10, int(np.sqrt(max(m, 1))))
    t0 = time.perf_counter()
    total, next_arc, exact = 0, 0, False
    while m:
        status, done, next_arc = _pivots(m, root, src, dst, cp, cs, flow, state, parent, pred, depth, pi,
                                         first_child, next_sib, prev_sib, stack, tol_abs, block, next_arc,
                                         _CHUNK)
        total += done
        if status == 2:
            raise ValueError("network simplex: unbounded (a negative-cost cycle of unbounded arcs)")
        if done:
            exact = False
        if status == 0:
            if exact:                              # no pivot since the potentials were recomputed: optimal
                break
            # potentials from the tree alone (no drift from the incremental updates), then price once more
            _tree_potentials(root, src, cs, parent, pred, first_child, next_sib, pi, depth, stack)
            exact = True
        if time.perf_counter() - t0 > time_limit:
            raise ValueError(f"network simplex: hit its time limit after {time.perf_counter() - t0:.1f} s "
                             f"(time_limit={time_limit}, {total} pivots)")
    return flow[:m].copy(), pi[:n].copy(), total


def _l1_by_circulation(n, P, d, w, lo, hi, time_limit):
    """The circulation of the module docstring, solved: (shifts x = −π, flow f per dual edge (A → B positive),
    optimum of the L1 program by strong duality). ValueError on infeasible bounds or the time limit."""
    k = len(P)
    a_lo = np.where(lo > 0, lo, 0.0)               # s+ ∈ [a_lo, a_hi], s- ∈ [b_lo, b_hi] (as dual_graph_l1)
    a_hi = np.where(hi < 0, 0.0, hi)
    b_lo = np.where(hi < 0, -hi, 0.0)
    b_hi = np.where(lo > 0, 0.0, -lo)
    lin = -d + a_lo - b_lo
    A, B = P[:, 0], P[:, 1]
    ea = np.flatnonzero(np.isfinite(a_hi))
    eb = np.flatnonzero(np.isfinite(b_hi))
    edge = np.concatenate([np.arange(k), np.arange(k), ea, eb])
    sign = np.concatenate([np.ones(k), -np.ones(k), np.ones(len(ea)), -np.ones(len(eb))])
    tail = np.concatenate([A, B, A[ea], B[eb]])
    head = np.concatenate([B, A, B[ea], A[eb]])
    cap = np.concatenate([w, w, np.full(len(ea) + len(eb), np.inf)])
    cost = np.concatenate([lin, -lin, lin[ea] + (a_hi - a_lo)[ea], -lin[eb] + (b_hi - b_lo)[eb]])
    keep = (cap > 0) & (tail != head)              # zero-weight links carry nothing; A == B has J = d fixed
    try:
        flow, pi, _ = network_simplex(n, tail[keep], head[keep], cap[keep], cost[keep], time_limit=time_limit)
    except ValueError as exc:
        if "unbounded" in str(exc):
            raise ValueError("linear program: infeasible jump bounds (network simplex: unbounded dual)") from exc
        raise ValueError(f"linear program: {exc}") from exc
    f = np.bincount(edge[keep], weights=sign[keep] * flow, minlength=k)
    # strong duality: minus the circulation's cost, plus the fixed jumps of links with A == B (J = d there)
    loop = A == B
    flow_obj = -(float(np.dot(cost[keep], flow)) - float(np.dot(w[~loop], (a_lo + b_lo)[~loop]))) + \
        float(np.dot(w[loop], np.abs(d[loop])))
    return -pi, f, flow_obj


def dual_graph_l1_network(n_cells: int, pairs, offsets, weights, bounds=None, time_limit: float = 300.0,
                          gauge: str = "component") -> DualL1Result:
    """The program of :func:`gsdf.linalg._dual_l1.dual_graph_l1` solved as its dual min-cost circulation (module docstring).

    Same parameters and result as :func:`gsdf.linalg._dual_l1.dual_graph_l1` (``algorithm`` aside); the same optimum
    (equal objective; ties may pick another optimal x). Checked before returning: the jumps respect the bounds
    and the primal objective equals the circulation's (strong duality) to 1e-7 relative — otherwise ValueError.

    Example
    -------
    >>> r = dual_graph_l1_network(2, [[0, 1]], [0.5], [1.0], bounds=[[1.0, 2.0]])
    >>> round(float(r.jumps[0]), 6), round(float(r.objective), 6)
    (1.0, 1.0)
    """
    from gsdf.linalg._l1_terms import _checked_terms

    n, P, d, w, lo, hi, gauge_cells, labels = _checked_terms(n_cells, pairs, offsets, weights, bounds, time_limit,
                                                             gauge)
    k = len(P)
    if k == 0:
        return DualL1Result(np.zeros(n), np.zeros(0), 0.0, 0.0)
    t0 = time.perf_counter()
    x, f, flow_obj = _l1_by_circulation(n, P, d, w, lo, hi, time_limit)
    secs = time.perf_counter() - t0
    if gauge_cells is not None:                    # the gauge: 0 at the first cell of every component
        x = x - x[gauge_cells][labels]
    A, B = P[:, 0], P[:, 1]
    J = d + x[A] - x[B]
    scale = max(1.0, float(np.abs(d).max()))
    if (J < lo - 1e-7 * scale).any() or (J > hi + 1e-7 * scale).any():
        raise ValueError("linear program: network simplex result violates the jump bounds (numerical trouble)")
    J = np.clip(J, lo, hi)
    obj = float(np.dot(w, np.abs(J)))
    if abs(obj - flow_obj) > 1e-7 * max(1.0, abs(obj), float(np.dot(w, np.abs(d)))):
        raise ValueError(f"linear program: network simplex duality gap {obj - flow_obj:.3g} (numerical trouble)")
    return DualL1Result(x, J, obj, secs)
