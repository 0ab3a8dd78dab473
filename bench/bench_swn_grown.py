"""Surface winding numbers on the grown-regions cases (``tests/swn/test_grown_regions.py``): the default labels
against label variants measured for the issue "three grown regions, 40 % of their boundaries deleted" (see
docs/decisions.md, "## Surface winding numbers"), where the error sits, and the same cases on refined meshes.

Variants (all after the default solve, on its bounding part and face values):

* ``closed-greedy`` / ``closed-assign`` — complete the curves: pair every endpoint where a curve arrives with one
  where a curve leaves by least-cost paths off the curves, cost ℓ / (max(w_left − w_right, 0) + eps) (a path
  whose left side is higher continues the curve's jump), greedily by cost (as the reduced LP's completion,
  thesis §6.3) or by a min-cost assignment; paths over 8 edges are dropped; then the jump solve with the
  completed chain, rounded at the curves' level (the remaining gaps by the gap rule).
* ``closed-true`` — the same paths, but the pairing the generator used (an oracle: the floor of path closures).
* ``islands`` — label components whose whole boundary is off the curves (touching none of their vertices) take
  the label across their longest boundary when smaller than that neighbour.
* ``no-cut`` — the labels before the least cut (``gsdf.swn._gaps.least_cut_labels``): rounding at the global
  level with the gap shifts only.
* ``cut`` — the least cut with ``--eps`` as the weight floor, or (``--level global``) h measured from the global
  level, without the gap shifts.
* ``area`` — each face takes the label of the larger part of its area (w linear on the face) instead of the value
  at its centroid.
* ``oracle-paths`` — every deleted stretch closed by the shortest edge path (by length, off the kept curves)
  between its own two ends (the generator's pairing), then the labels of the closed chain: the error of the
  straightest closure given the true pairing.
* ``oracle-levels`` — the faces touching each deleted stretch rounded at the level (of 41 in a unit) that fits
  the truth best there: the floor of any per-gap choice of level.

``--where`` splits the mislabelled area of the default labels (and of ``no-cut``) into faces touching a deleted
edge (a vertex of one), faces within 2 more rings, and elsewhere, and gives the default's error per deleted
stretch by its length (6: 6 or more, stretches that meet). ``--refine k`` splits every triangle into 4, k times, the regions
and the curves carried over exactly (children take the parent's truth; a curve edge becomes 2 collinear edges);
with ``--fresh`` the cases are grown on the refined mesh instead (gaps of 1–5 of its shorter edges).

    PYTHONPATH=src python3 -m bench.bench_swn_grown --variant closed-assign cow bull camel dino
    PYTHONPATH=src python3 -m bench.bench_swn_grown --where cow bull camel dino
    PYTHONPATH=src python3 -m bench.bench_swn_grown --variant oracle-paths --refine 1 [--fresh] cow dino
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


def refine(V, F, segs, full, truth, times):
    """Split every triangle into 4, ``times`` times; truth and curves carried over exactly."""
    for _ in range(times):
        n = len(V)
        E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        ue, inv = np.unique(E, axis=0, return_inverse=True)
        mid = n + inv.ravel().reshape(3, -1).T
        V = np.vstack([V, 0.5 * (V[ue[:, 0]] + V[ue[:, 1]])])
        a, b, c = F.T
        ab, bc, ca = mid.T
        F = np.concatenate([np.c_[a, ab, ca], np.c_[ab, b, bc], np.c_[ca, bc, c], np.c_[ab, bc, ca]])
        truth = np.tile(truth, 4)
        key = ue[:, 0] * n + ue[:, 1]
        segs, full = (np.stack([np.c_[S[:, 0], n + np.searchsorted(key, S.min(1) * n + S.max(1))],
                                np.c_[n + np.searchsorted(key, S.min(1) * n + S.max(1)), S[:, 1]]], 1).reshape(-1, 2)
                      for S in (segs, full))
    A = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return V, F, segs, full, truth, A


def where(F, n, segs, full, wrong, A):
    """Mislabelled area shares (total, touching a deleted edge, within 2 more rings, elsewhere)."""
    kept = set(map(tuple, segs.tolist()))
    gone = np.array([e for e in map(tuple, full.tolist()) if e not in kept]).reshape(-1, 2)
    vm = np.zeros(n, bool)
    vm[gone.ravel()] = True
    fa = vm[F].any(1)
    near = fa.copy()
    for _ in range(2):
        v2 = np.zeros(n, bool)
        v2[F[near].ravel()] = True
        near = v2[F].any(1)
    T = A.sum()
    return [A[wrong].sum() / T, A[wrong & fa].sum() / T, A[wrong & near & ~fa].sum() / T, A[wrong & ~near].sum() / T]


def per_gap(swn, segs, full, wrong, A, out):
    """Mislabelled area on the faces touching each deleted stretch, in units of their mean area, by length."""
    n, E, F = swn.dec.n_vertices, swn.dec.edges, swn.dec.F
    gone = np.flatnonzero(swn.chain(full) - swn.chain(segs))
    _, lab = connected_components(sp.coo_matrix((np.ones(len(gone)), (E[gone, 0], E[gone, 1])), shape=(n, n)),
                                  directed=False)
    gl = lab[E[gone, 0]]
    for c in np.unique(gl):
        vs = np.zeros(n, bool)
        vs[E[gone[gl == c]].ravel()] = True
        f = vs[F].any(1)
        out.setdefault(min(int((gl == c).sum()), 6), []).append(A[f & wrong].sum() / A[f].mean())
    return out


def no_cut(swn, res, values=False):
    """The labels before the least cut: the global level with the gap shifts (or the values they round)."""
    dec = swn.dec
    w = res.corner_values + res.offset + res.label_shift[:, None]
    wf = w.mean(1)
    bends = res.endpoints | dec.chain_endpoints(np.round(res.bounding), tol=0.5)
    shift = swn.gap_shift(wf, res.bounding, bends, res.offset) if bends.any() else 0.0
    return (wf - res.offset - shift) if values else np.round(wf - res.offset - shift)


def cut_labels(swn, res, eps, level):
    """The least cut with another weight floor, or with h measured from the global level (no gap shifts)."""
    from gsdf.swn._gaps import least_cut_labels

    wl = no_cut(swn, res, values=True)
    if level == "global":
        wl = res.corner_values.mean(1) + res.label_shift
    return least_cut_labels(swn.dec, wl, res.bounding, eps)


def area_labels(res):
    """Each face: the label of the larger part of its area (corner values linear on the face)."""
    w = np.sort(res.corner_values, axis=1)
    a, b, c = w.T

    def above(t):                                   # area share where w > t
        r = np.where(t <= a, 1.0, 0.0)
        m1 = (t > a) & (t <= b)
        m2 = (t > b) & (t < c)
        r = np.where(m1, 1 - (t - a) ** 2 / np.maximum((b - a) * (c - a), 1e-300), r)
        return np.where(m2, (c - t) ** 2 / np.maximum((c - a) * (c - b), 1e-300), r)
    near = np.round(w.mean(1))
    L = near.copy()
    L[above(near - 0.5) < 0.5] -= 1
    L[above(near + 0.5) > 0.5] += 1
    return L


def oracle_paths(swn, segs, full):
    dec, n, E = swn.dec, swn.dec.n_vertices, swn.dec.edges
    g = swn.chain(segs)
    gone = swn.chain(full) - g
    nxt = {}
    for e in np.flatnonzero(gone):                  # the deleted stretches, walked tail → head
        t, h = (E[e, 0], E[e, 1]) if gone[e] > 0 else (E[e, 1], E[e, 0])
        nxt.setdefault(int(t), []).append(int(h))
    div = dec.d0.T @ gone
    src, heads = np.flatnonzero(div < -0.5), set(np.flatnonzero(div > 0.5).tolist())
    dst = []
    for a in src:
        v, steps = int(a), 0
        while steps < 100:
            v, steps = nxt[v][0], steps + 1
            if v in heads:
                break
        dst.append(v)
    free = np.flatnonzero(g == 0)
    L = dec.edge_len[free]
    G = sp.coo_matrix((np.concatenate([L, L]), (np.concatenate([E[free, 0], E[free, 1]]),
                                                 np.concatenate([E[free, 1], E[free, 0]]))), shape=(n, n)).tocsr()
    comp = np.zeros(dec.n_edges)
    D, pred = dijkstra(G, indices=src, return_predecessors=True)
    for i, a in enumerate(src):
        v = dst[i]
        if not np.isfinite(D[i, v]):
            continue
        path = [v]
        while v != a:
            v = int(pred[i, v])
            path.append(v)
        path = np.array(path[::-1])
        x, y = path[:-1], path[1:]
        np.add.at(comp, np.searchsorted(swn._edge_key, np.minimum(x, y) * n + np.maximum(x, y)),
                  np.where(x < y, 1.0, -1.0))
    g2 = g + comp
    ends = dec.chain_endpoints(g2, tol=0.5)
    wf = swn._jump_solve(g2, ends, "branch").mean(1)
    return np.round(wf - wf.min())                  # the chain is closed: w is an integer plus one constant


def oracle_levels(swn, res, segs, full, truth, A):
    n, E, F = swn.dec.n_vertices, swn.dec.edges, swn.dec.F
    gone = np.flatnonzero(swn.chain(full) - swn.chain(segs))
    _, lab = connected_components(sp.coo_matrix((np.ones(len(gone)), (E[gone, 0], E[gone, 1])), shape=(n, n)),
                                  directed=False)
    W = res.face_labels.copy()
    k = min(range(-6, 7), key=lambda k: A[(W + k) != truth].sum())
    wf = res.corner_values.mean(1) + res.label_shift          # one global level
    for c in np.unique(lab[E[gone, 0]]):
        vs = np.zeros(n, bool)
        vs[E[gone[lab[E[gone, 0]] == c]].ravel()] = True
        f = vs[F].any(1)
        errs = [(A[f][(np.round(wf[f] - d) + k) != truth[f]].sum(), d) for d in np.linspace(-0.5, 0.5, 41)]
        W[f] = np.round(wf[f] - min(errs)[1])
    return W


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("meshes", nargs="*", default=["cow", "bull", "camel", "dino"])
    ap.add_argument("--variant", default="no-cut",
                    choices=["closed-greedy", "closed-assign", "closed-true", "islands", "no-cut", "cut", "area",
                             "oracle-paths", "oracle-levels"])
    ap.add_argument("--where", action="store_true", help="split the default's error by distance to the gaps")
    ap.add_argument("--refine", type=int, default=0, help="split every triangle into 4, this many times")
    ap.add_argument("--fresh", action="store_true", help="grow the cases on the refined mesh")
    ap.add_argument("--eps", type=float, default=0.1)
    ap.add_argument("--level", default="gaps", choices=["gaps", "global"], help="cut: h from which level")
    ap.add_argument("--cases", type=int, default=4)
    a = ap.parse_args()
    for name in a.meshes:
        V0, F0 = gsdf.read_mesh(os.path.join(data_dir(), "meshes", f"{name}.off"))
        V, F, _, _, _, _ = refine(V0, F0, np.zeros((0, 2), np.int64), np.zeros((0, 2), np.int64),
                                  np.zeros(len(F0), np.int64), a.refine)
        swn = SurfaceWindingNumbers(V, F)
        e0, e1, rows, by_len = [], [], [], {}
        for s in range(a.cases):
            if a.fresh or a.refine == 0:
                segs, truth, A = grown_regions_case(V, F, s)
                full, _, _ = grown_regions_case(V, F, s, deleted=0.0)
            else:
                segs, truth, A = grown_regions_case(V0, F0, s)
                full, _, _ = grown_regions_case(V0, F0, s, deleted=0.0)
                _, _, segs, full, truth, A = refine(V0, F0, segs, full, truth, a.refine)
            res = swn.solve(segs)
            if a.where:
                r = []
                for W in (res.face_labels, no_cut(swn, res)):
                    k = min(range(-6, 7), key=lambda k: A[(W + k) != truth].sum())
                    r.append(where(F, len(V), segs, full, (W + k) != truth, A))
                    if len(r) == 1:
                        by_len = per_gap(swn, segs, full, (W + k) != truth, A, by_len)
                rows.append(r)
                print(f"  {name}:{s} default " + " / ".join(f"{100 * x:.2f}" for x in r[0]) + "; no-cut "
                      + " / ".join(f"{100 * x:.2f}" for x in r[1]), flush=True)
                continue
            if a.variant == "islands":
                W = islands(swn, res.face_labels, res.chain)
            elif a.variant == "no-cut":
                W = no_cut(swn, res)
            elif a.variant == "cut":
                W = cut_labels(swn, res, a.eps, a.level)
            elif a.variant == "area":
                W = area_labels(res)
            elif a.variant == "oracle-paths":
                W = oracle_paths(swn, segs, full)
            elif a.variant == "oracle-levels":
                W = oracle_levels(swn, res, segs, full, truth, A)
            else:
                match = {"closed-greedy": "greedy", "closed-assign": "assign"}.get(a.variant)
                if match is None:
                    match = true_pairs(swn, res, V, F, s)
                W = closed_labels(swn, res, eps=a.eps, match=match)
            e0.append(mislabelled(res.face_labels, truth, A))
            e1.append(mislabelled(W, truth, A))
        tag = f"{name} ({len(F)} faces{f', refined {a.refine}x' if a.refine else ''}{', fresh' if a.fresh else ''})"
        if a.where:
            for j, lab in enumerate(["default", "no-cut"]):
                m = 100 * np.mean([r[j] for r in rows], axis=0)
                print(f"{tag} {lab}: mislabelled {m[0]:.2f} %: touching a deleted edge {m[1]:.2f}, within 2 rings "
                      f"{m[2]:.2f}, elsewhere {m[3]:.2f}", flush=True)
            print(f"{tag} default, mislabelled faces per deleted stretch (in mean faces beside it) by its length: "
                  + ", ".join(f"{n} edges {np.mean(v):.2f} ({len(v)})" for n, v in sorted(by_len.items())), flush=True)
            continue
        print(f"{tag}: default {100 * np.mean(e0):.2f} %, {a.variant} {100 * np.mean(e1):.2f} % (cases "
              f"{', '.join(f'{100 * x:.2f}' for x in e1)})", flush=True)

if __name__ == "__main__":
    main()
