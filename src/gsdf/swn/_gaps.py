"""Gap labels of surface winding numbers: the faces at the gaps of broken curves rounded at the field's own level.

The rule: :meth:`gsdf.swn._solver.SurfaceWindingNumbers.gap_shift`. This module holds the
kernel — one numba pass of point-to-point Dijkstra searches over all gaps (each search stops when it settles its
target and resets only the vertices it touched, so the pass costs about the gaps' neighbourhoods, not |gaps| × |V|)
— and the vectorised pairing and level steps around it (no Python loop over gaps); and the least cut that then
rounds each face up or down (:func:`least_cut_labels`).
"""

from __future__ import annotations

import heapq

import numba as nb
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

GAP_MAX_EDGES = 8   # a gap whose closing path has more edges keeps the global level: the path is the chord, and over a
                    # long gap the curve's own bend (the member of the pencil through the curves' level, exact for a
                    # broken circle) matters more than the chord
GAP_EPS = 0.1       # path weight ℓ / (|Δw| + GAP_EPS): the floor on |Δw|


@nb.njit(cache=True)
def _gap_paths(indptr, nbr, eid, wt, src, dst, n):
    """Shortest paths src[k] → dst[k] on a symmetric CSR graph (neighbours ``nbr``, edge ids ``eid``, weights
    ``wt``), one Dijkstra per pair that stops when dst[k] is settled.

    Returns (edges, ptr, start): the edge ids of path k in walk order are ``edges[ptr[k]:ptr[k+1]]``, ``start``
    the vertex each step leaves from. An unreachable target gives an empty path."""
    m = len(src)
    dist = np.full(n, np.inf)
    pred_v = np.full(n, -1, np.int64)
    pred_e = np.full(n, -1, np.int64)
    done = np.zeros(n, np.bool_)
    touched = np.empty(n, np.int64)
    out_e = np.empty(16, np.int64)
    out_s = np.empty(16, np.int64)
    ptr = np.zeros(m + 1, np.int64)
    k_out = 0
    for k in range(m):
        a, b = src[k], dst[k]
        nt = 0
        dist[a] = 0.0
        touched[nt] = a
        nt += 1
        heap = [(0.0, a)]
        found = False
        while len(heap) > 0:
            d, v = heapq.heappop(heap)
            if done[v]:
                continue
            done[v] = True
            if v == b:
                found = True
                break
            for j in range(indptr[v], indptr[v + 1]):
                u = nbr[j]
                if done[u]:
                    continue
                nd = d + wt[j]
                if nd < dist[u]:
                    if dist[u] == np.inf:
                        touched[nt] = u
                        nt += 1
                    dist[u] = nd
                    pred_v[u] = v
                    pred_e[u] = eid[j]
                    heapq.heappush(heap, (nd, u))
        if found:
            cnt = 0
            v = b
            while v != a:
                cnt += 1
                v = pred_v[v]
            while k_out + cnt > len(out_e):
                e2 = np.empty(2 * len(out_e), np.int64)
                s2 = np.empty(2 * len(out_s), np.int64)
                e2[:k_out] = out_e[:k_out]
                s2[:k_out] = out_s[:k_out]
                out_e, out_s = e2, s2
            v = b
            i = k_out + cnt - 1
            while v != a:
                out_e[i] = pred_e[v]
                out_s[i] = pred_v[v]
                v = pred_v[v]
                i -= 1
            k_out += cnt
        ptr[k + 1] = k_out
        for i in range(nt):
            t = touched[i]
            dist[t] = np.inf
            done[t] = False
            pred_v[t] = -1
            pred_e[t] = -1
    return out_e[:k_out], ptr, out_s[:k_out]


def gap_pairs(dec, W, curve, ends):
    """Pairs of endpoints joined by one piece of label boundary off the curves.

    W : (m,) labels; curve : (nE,) bool, the edges of the (bounding) curves; ends : (n,) bool endpoints.
    The interior edges where W jumps but no curve edge lies are split into connected pieces (through shared
    vertices); a piece touching exactly two endpoints gives a pair. Returns (k, 2) int64."""
    topo = dec.topology
    E, n = dec.edges, dec.n_vertices
    inter = topo.edge_face_count == 2
    A, B = topo.edge_faces[:, 0], np.maximum(topo.edge_faces[:, 1], 0)
    off = np.flatnonzero(inter & ~curve & (W[A] != W[B]))
    if len(off) == 0:
        return np.zeros((0, 2), np.int64)
    G = sp.coo_matrix((np.ones(len(off)), (E[off, 0], E[off, 1])), shape=(n, n))
    _, lab = connected_components(G, directed=False)
    touched = np.zeros(n, bool)
    touched[E[off].ravel()] = True
    ev = np.flatnonzero(touched & ends)
    cnt = np.bincount(lab[ev], minlength=n)
    ev = ev[cnt[lab[ev]] == 2]
    ev = ev[np.argsort(lab[ev], kind="stable")]
    return ev.reshape(-1, 2).astype(np.int64)


def gap_shift(dec, wf, curve, ends, s, eps=GAP_EPS, max_edges=GAP_MAX_EDGES):
    """Per-face shift of the rounding level at the gaps: labels ``round(wf - s - shift)``.

    dec : TriangleDEC; wf : (m,) face values; curve : (nE,) bool, the edges of the bounding curves; ends : (n,)
    bool, their endpoints; s : the global offset; max_edges : closing paths longer than this keep the global level.
    Returns (shift (m,), number of pairs, number of paths found).
    """
    topo = dec.topology
    E, n, m = dec.edges, dec.n_vertices, dec.n_faces
    inter = topo.edge_face_count == 2
    curve = curve & inter
    A, B = topo.edge_faces[:, 0], np.maximum(topo.edge_faces[:, 1], 0)
    pairs = gap_pairs(dec, np.round(wf - s), curve, ends)
    shift = np.zeros(m)
    if len(pairs) == 0:
        return shift, 0, 0
    # the graph of the edges off the curves, weighted ℓ / (|Δw| + eps): cheap where w changes fast
    dw = np.where(inter, np.abs(wf[A] - wf[B]), 0.0)
    wt = dec.edge_len / (dw + eps)
    free = np.flatnonzero(~curve)
    r = np.concatenate([E[free, 0], E[free, 1]])
    c = np.concatenate([E[free, 1], E[free, 0]])
    ee = np.concatenate([free, free])
    o = np.lexsort((c, r))
    r, c, ee = r[o], c[o].astype(np.int64), ee[o].astype(np.int64)
    indptr = np.searchsorted(r, np.arange(n + 1)).astype(np.int64)
    pe, ptr, start = _gap_paths(indptr, c, ee, wt[ee], pairs[:, 0].copy(), pairs[:, 1].copy(), n)
    npath = np.diff(ptr)
    k = len(pairs)
    pid = np.repeat(np.arange(k), npath)
    # the level of each path: the mean over its interior edges of the mean of the edge's two faces
    ok = inter[pe]
    sw = np.bincount(pid[ok], minlength=k).astype(float)
    sm = np.bincount(pid[ok], weights=0.5 * (wf[A[pe[ok]]] + wf[B[pe[ok]]]), minlength=k)
    has = sw > 0
    lev = sm / np.maximum(sw, 1.0)
    dl = np.where(has, (lev - s + 1.0) % 1.0 - 0.5, 0.0)       # the level minus (s + ½), wrapped to [-½, ½)
    has = has & (npath <= max_edges)                        # long closing paths: the global level (see GAP_MAX_EDGES)
    dl = np.where(has, dl, 0.0)
    # faces touching a vertex of a path (the targets included): the mean shift of the paths they touch
    pv = np.concatenate([start, pairs[npath > 0, 1]])
    pp = np.concatenate([pid, np.flatnonzero(npath > 0)])
    keep = has[pp]
    P = sp.csr_matrix((np.ones(int(keep.sum())), (pp[keep], pv[keep])), shape=(k, n))
    P.data[:] = 1.0                                           # duplicates summed: back to 0 / 1
    VF = sp.csr_matrix((np.ones(3 * m), (dec.F.ravel(), np.repeat(np.arange(m), 3))), shape=(n, m))
    touch = (P @ VF).tocoo()                                  # one entry per (pair, face) touched
    acc = np.bincount(touch.col, weights=dl[touch.row], minlength=m)
    cnt = np.bincount(touch.col, minlength=m)
    shift = np.where(cnt > 0, acc / np.maximum(cnt, 1), 0.0)
    return shift, k, int((npath > 0).sum())


RELABEL_EPS = 0.1   # cut weight ℓ · (distance of w to the label level + RELABEL_EPS) off the curves


def least_cut_labels(dec, wl, bounding, eps=RELABEL_EPS):
    """Labels L, each face rounded up or down (``L ∈ {⌊wl⌋, ⌊wl⌋ + 1}``), minimising the cut
    ``Σ_off ℓ (h + eps) |L_A − L_B| + Σ_curves ℓ |b| |L_A − L_B − b|``: a label boundary off the curves is cheap
    where w crosses the label level (h, the distance of the mean of the edge's two face values to the nearest
    half-integer, is small there) and short; a curve edge whose jump b the labels do not keep is paid in full.

    dec : TriangleDEC; wl : (m,) face values in label units (the level at the half-integers, so that
    ``round(wl)`` are the labels of rounding); bounding : (nE,) the bounding curves as a rounded edge chain;
    eps > 0. The terms are convex in ``L_A − L_B``, so the choice up / down per face is one minimum s–t cut
    (capacities scaled to integers; ``scipy.sparse.csgraph.maximum_flow``). Returns (m,) int64 labels.

    Not in the thesis (its labels are ``round(w)``, §6.1): inside a gap w's level sets form a pencil through the
    gap's ends, and rounding picks one member per gap; the cut prefers, among the faces' up / down choices, the
    short boundary that stays near the level — it closes a broken loop round a cap whose w sits at the level,
    where rounding labelled the whole cap inside (docs/decisions.md, "Surface winding numbers")."""
    from scipy.sparse.csgraph import breadth_first_order, maximum_flow

    topo, m = dec.topology, dec.n_faces
    base = np.floor(wl).astype(np.int64)
    inter = np.flatnonzero(topo.edge_face_count == 2)
    if len(inter) == 0:
        return np.round(wl).astype(np.int64)
    A, B = topo.edge_faces[inter, 0], topo.edge_faces[inter, 1]
    b = np.round(bounding[inter])
    wm = 0.5 * (wl[A] + wl[B])
    h = 0.5 - np.abs(wm - np.round(wm))
    ell = dec.edge_len[inter]
    w = np.where(b != 0, ell * np.abs(b), ell * (h + eps))
    # E(x_A, x_B) = w |c + x_A − x_B| (x = 1: rounded up) = E00 + t x_A − t x_B + p [x_A ≠ x_B] with
    # t = (E10 − E01) / 2 and p = (E01 + E10) / 2 − E00 ≥ 0 (convexity; E11 = E00): p = w where c = 0 and
    # t = ±w where |c| ≥ 1, so only the faces along jumps of the rounded-down labels carry unary terms
    c = base[A] - base[B] - b
    e00 = w * np.abs(c)
    e10 = w * np.abs(c + 1)
    e01 = w * np.abs(c - 1)
    t = 0.5 * (e10 - e01)
    unary = np.bincount(A, weights=t, minlength=m) - np.bincount(B, weights=t, minlength=m)
    pair = 0.5 * (e01 + e10) - e00
    total = np.abs(unary).sum() + 2 * pair.sum()
    if not total > 0:
        return np.round(wl).astype(np.int64)
    scale = 2.0 ** 30 / total
    cu = np.rint(np.abs(unary) * scale).astype(np.int64)
    cp = np.rint(pair * scale).astype(np.int64)
    src, snk = m, m + 1
    up = (unary > 0) & (cu > 0)                     # cost of rounding up: source → face (cut when x = 1)
    dn = (unary < 0) & (cu > 0)                     # cost of rounding down: face → sink (cut when x = 0)
    keep = cp > 0
    rows = np.concatenate([np.full(int(up.sum()), src), np.flatnonzero(dn), A[keep], B[keep]])
    cols = np.concatenate([np.flatnonzero(up), np.full(int(dn.sum()), snk), B[keep], A[keep]])
    cap = np.concatenate([cu[up], cu[dn], cp[keep], cp[keep]]).astype(np.int32)
    C = sp.csr_matrix((cap, (rows, cols)), shape=(m + 2, m + 2))
    C.sum_duplicates()
    flow = maximum_flow(C, src, snk).flow
    R = (C - flow).tocsr()
    R.data = (R.data > 0).astype(np.int32)
    R.eliminate_zeros()
    x = np.ones(m + 2, np.int64)
    x[breadth_first_order(R, src, directed=True, return_predecessors=False)] = 0   # source side: rounded down
    return base + x[:m]
