"""Surface winding numbers on the grown-regions cases (``tests/swn/test_grown_regions.py``): the default labels
against label variants measured for the issue "three grown regions, 40 % of their boundaries deleted" (none kept;
see docs/decisions.md, "## Surface winding numbers").

Variants (all after the default solve, on its bounding part and face values):

* ``closed-greedy`` / ``closed-assign`` — complete the curves: pair every endpoint where a curve arrives with one
  where a curve leaves by least-cost paths off the curves, cost ℓ / (max(w_left − w_right, 0) + eps) (a path
  whose left side is higher continues the curve's jump), greedily by cost (as the reduced LP's completion,
  thesis §6.3) or by a min-cost assignment; paths over 8 edges are dropped; then the jump solve with the
  completed chain, rounded at the curves' level (the remaining gaps by the gap rule).
* ``closed-true`` — the same paths, but the pairing the generator used (an oracle: the floor of path closures).
* ``islands`` — label components whose whole boundary is off the curves (touching none of their vertices) take
  the label across their longest boundary when smaller than that neighbour.

    PYTHONPATH=src python3 -m bench.bench_swn_grown --variant closed-assign cow bull camel dino
"""

from __future__ import annotations

import argparse
import os

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, dijkstra

import gsdf
from bench.common import data_dir
from gsdf.swn._solver import SurfaceWindingNumbers
from tests.swn.test_grown_regions import grown_regions_case, mislabelled


def complete(swn, wf, g, ends, eps=0.1, max_edges=8, match="greedy"):
    dec = swn.dec
    topo, E, n = dec.topology, dec.edges, dec.n_vertices
    div = dec.d0.T @ g                                   # arrivals > 0, departures < 0
    pos = np.flatnonzero(ends & (div > 0.5))
    neg = np.flatnonzero(ends & (div < -0.5))
    comp = np.zeros(dec.n_edges)
    if len(pos) == 0 or len(neg) == 0:
        return comp, 0
    free = np.flatnonzero((g == 0) & (topo.edge_face_count == 2))
    dfw = wf[topo.edge_faces[free, 0]] - wf[topo.edge_faces[free, 1]]     # left − right walking E0 → E1
    c01 = dec.edge_len[free] / (np.maximum(dfw, 0) + eps)
    c10 = dec.edge_len[free] / (np.maximum(-dfw, 0) + eps)
    G = sp.coo_matrix((np.concatenate([c01, c10]), (np.concatenate([E[free, 0], E[free, 1]]),
                                                    np.concatenate([E[free, 1], E[free, 0]]))), shape=(n, n)).tocsr()
    D, pred = dijkstra(G, directed=True, indices=pos, return_predecessors=True)
    need_p, need_n = np.rint(div[pos]).astype(int), np.rint(-div[neg]).astype(int)
    dd = D[:, neg]
    if isinstance(match, dict):
        ip = {int(v): i for i, v in enumerate(pos)}
        jn = {int(v): j for j, v in enumerate(neg)}
        order = [ip[a] * len(neg) + jn[b] for a, b in match.items() if a in ip and b in jn]
    elif match == "assign":
        from scipy.optimize import linear_sum_assignment
        big = np.where(np.isfinite(dd), dd, 1e30)
        ri, ci = linear_sum_assignment(big)
        order = [i * len(neg) + j for i, j in zip(ri, ci) if big[i, j] < 1e30]
    else:
        order = np.argsort(dd, axis=None)
    used = 0
    for flat in order:
        i, j = divmod(int(flat), len(neg))
        if not np.isfinite(dd[i, j]) or need_p[i] == 0 or need_n[j] == 0:
            continue
        v, path = int(neg[j]), [int(neg[j])]
        while v != pos[i]:
            v = int(pred[i, v])
            path.append(v)
        if len(path) - 1 > max_edges:
            continue
        k = min(need_p[i], need_n[j])
        need_p[i] -= k
        need_n[j] -= k
        path = np.array(path[::-1])
        a, b = path[:-1], path[1:]
        e = np.searchsorted(swn._edge_key, np.minimum(a, b) * n + np.maximum(a, b))
        np.add.at(comp, e, k * np.where(a < b, 1.0, -1.0))
        used += 1
    return comp, used


def closed_labels(swn, res, **kw):
    dec = swn.dec
    wf = (res.corner_values + res.offset + res.label_shift[:, None]).mean(1)
    bounding = np.round(res.bounding)
    bends = res.endpoints | dec.chain_endpoints(bounding, tol=0.5)
    comp, _ = complete(swn, wf, bounding, bends, **kw)
    g2 = bounding + comp
    ends2 = dec.chain_endpoints(g2, tol=0.5)
    rule = "branch" if swn.simply_connected else "exclude"
    wf2 = swn.label_values(swn._jump_solve(g2, ends2, rule), ends2).mean(1)
    s2 = swn.rounding_offset(wf2, g2, np.zeros_like(g2))
    shift = swn.gap_shift(wf2, g2, ends2, s2) if ends2.any() else np.zeros(dec.n_faces)
    return np.round(wf2 - s2 - shift)


def true_pairs(swn, res, V, F, seed):
    """The generator's own pairing: endpoint where a kept run ends → where the next kept run starts."""
    dec, n, E = swn.dec, len(V), swn.dec.edges
    segs, _, _ = grown_regions_case(V, F, seed)
    full, _, _ = grown_regions_case(V, F, seed, deleted=0.0)

    def chain(sg):
        g = np.zeros(dec.n_edges)
        a, b = sg[:, 0], sg[:, 1]
        np.add.at(g, np.searchsorted(swn._edge_key, np.minimum(a, b) * n + np.maximum(a, b)), np.where(a < b, 1.0, -1.0))
        return g
    gone = chain(full) - chain(segs)
    nxt = {}
    for e in np.flatnonzero(gone):
        t, h = (E[e, 0], E[e, 1]) if gone[e] > 0 else (E[e, 1], E[e, 0])
        nxt.setdefault(int(t), []).append(int(h))
    bounding = np.round(res.bounding)
    bends = res.endpoints | dec.chain_endpoints(bounding, tol=0.5)
    div = dec.d0.T @ bounding
    neg = set(np.flatnonzero(bends & (div < -0.5)).tolist())
    match = {}
    for a in np.flatnonzero(bends & (div > 0.5)):
        v, st = int(a), 0
        while v in nxt and st < 50:
            v, st = nxt[v][0], st + 1
            if v in neg:
                break
        match[int(a)] = v
    return match


def islands(swn, W, g):
    dec = swn.dec
    t, E, m = dec.topology, dec.edges, dec.n_faces
    inter = np.flatnonzero(t.edge_face_count == 2)
    A, B = t.edge_faces[inter, 0], t.edge_faces[inter, 1]
    same = W[A] == W[B]
    nc, lab = connected_components(sp.coo_matrix((np.ones(same.sum()), (A[same], B[same])), shape=(m, m)),
                                   directed=False)
    area = np.bincount(lab, weights=dec.areas, minlength=nc)
    cv = np.zeros(dec.n_vertices, bool)
    cv[E[g != 0].ravel()] = True
    jump = inter[~same]
    sup = cv[E[jump]].any(1)
    la, lb, ln = lab[A[~same]], lab[B[~same]], dec.edge_len[jump]
    supported = np.zeros(nc, bool)
    np.logical_or.at(supported, la, sup)
    np.logical_or.at(supported, lb, sup)
    W = W.copy()
    for c in np.flatnonzero(~supported & (np.bincount(np.concatenate([la, lb]), minlength=nc) > 0)):
        nb = np.concatenate([lb[la == c], la[lb == c]])
        u, inv = np.unique(nb, return_inverse=True)
        best = u[np.argmax(np.bincount(inv, weights=np.concatenate([ln[la == c], ln[lb == c]])))]
        if area[c] < area[best]:
            W[lab == c] = W[lab == best][0]
    return W


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("meshes", nargs="*", default=["cow", "bull", "camel", "dino"])
    ap.add_argument("--variant", default="closed-assign",
                    choices=["closed-greedy", "closed-assign", "closed-true", "islands"])
    ap.add_argument("--eps", type=float, default=0.1)
    ap.add_argument("--cases", type=int, default=4)
    a = ap.parse_args()
    for name in a.meshes:
        V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", f"{name}.off"))
        swn = SurfaceWindingNumbers(V, F)
        e0, e1 = [], []
        for s in range(a.cases):
            segs, truth, A = grown_regions_case(V, F, s)
            res = swn.solve(segs)
            if a.variant == "islands":
                W = islands(swn, res.face_labels, res.chain)
            else:
                match = {"closed-greedy": "greedy", "closed-assign": "assign"}.get(a.variant)
                if match is None:
                    match = true_pairs(swn, res, V, F, s)
                W = closed_labels(swn, res, eps=a.eps, match=match)
            e0.append(mislabelled(res.face_labels, truth, A))
            e1.append(mislabelled(W, truth, A))
        print(f"{name}: default {100 * np.mean(e0):.2f} %, {a.variant} {100 * np.mean(e1):.2f} % (cases "
              f"{', '.join(f'{100 * x:.2f}' for x in e1)})", flush=True)


if __name__ == "__main__":
    main()
