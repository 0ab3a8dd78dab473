"""Surface winding numbers on genus-0 meshes: three regions grown from random faces, 40 % of their boundary edges
deleted in short gaps — a small, seeded case generator and where the mislabelled area sits.

Printing the figures on the CGAL meshes (when their folder is there)::

    PYTHONPATH=src python3 -m tests.swn.test_grown_regions cow bull camel dino
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

import gsdf


def grown_regions_case(V, F, seed, regions=3, area=(0.1, 0.2), deleted=0.4):
    """(segments (s, 2) oriented vertex pairs, truth (m,) labels, face areas): ``regions`` disjoint regions grown
    by Dijkstra over face centroids from random seed faces (each to a share of the area in ``area``, within its
    seed's Voronoi cell), the oriented boundary of the labelling chained into edge walks, and in every walk of 8+
    edges a share ``deleted`` of the edges removed in gaps of 1–5 edges between kept runs of 2–5 edges.

    The curves are the boundary of the truth: where two regions touch, their boundaries cancel (both are
    labelled 1, nothing separates them). The regions and the walks come from one random stream and the gaps
    from another, so ``deleted=0.0`` gives the unbroken curves of the same case. The gaps of a walk fit in it
    (a pattern longer than the walk has its kept runs shortened, down to 1 edge), so no gap wraps into
    another."""
    ss = np.random.SeedSequence(seed)
    rng, rng_gap = (np.random.default_rng(s) for s in ss.spawn(2))
    A = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    fid = np.tile(np.arange(len(F)), 3)
    _, inv = np.unique(np.sort(E, axis=1), axis=0, return_inverse=True)
    order = np.argsort(inv.ravel(), kind="stable")
    a, b = fid[order][0::2], fid[order][1::2]
    cen = V[F].mean(axis=1)
    G = sp.coo_matrix((np.linalg.norm(cen[a] - cen[b], axis=1) + 1e-12, (a, b)), shape=(len(F),) * 2).tocsr()
    seeds = rng.choice(len(F), regions, replace=False)
    D = dijkstra(G, directed=False, indices=seeds)
    owner = np.argmin(D, axis=0)
    truth = np.zeros(len(F), np.int64)
    for r in range(regions):
        cand = np.flatnonzero(owner == r)
        cand = cand[np.argsort(D[r, cand])]
        k = int(np.searchsorted(np.cumsum(A[cand]), rng.uniform(*area) * A.sum()))
        truth[cand[:k + 1]] += 1
    # the oriented boundary of the labelling (the regions are disjoint: labels 0 / 1): the halfedges of the
    # labelled faces whose twin is not in a labelled face
    H = E[truth[fid] > 0]
    Hs = set(map(tuple, H.tolist()))
    bnd = [tuple(h) for h in H.tolist() if (h[1], h[0]) not in Hs]
    nxt = {}
    for u, v in bnd:
        nxt.setdefault(u, []).append(v)
    used = set()
    segs = []
    for u, v in bnd:
        if (u, v) in used:
            continue
        walk, x = [(u, v)], v
        used.add((u, v))
        while True:
            y = next((y for y in nxt.get(x, []) if (x, y) not in used), None)
            if y is None:
                break
            used.add((x, y))
            walk.append((x, y))
            x = y
        L = len(walk)
        keep = np.ones(L, bool)
        if L >= 8:
            goal, gaps, runs = int(round(deleted * L)), [], []
            while sum(gaps) < goal:
                runs.append(int(rng_gap.integers(2, 6)))
                gaps.append(min(int(rng_gap.integers(1, 6)), goal - sum(gaps)))
            runs = np.array(runs, np.int64)
            while len(runs) and runs.sum() + goal > L - 1 and runs.max() > 1:
                runs[np.argmax(runs)] -= 1
            start, i = int(rng_gap.integers(L)), 0
            for rlen, glen in zip(runs, gaps):
                i += int(rlen)
                keep[(start + i + np.arange(glen)) % L] = False
                i += glen
        segs += [w for w, k in zip(walk, keep) if k]
    return np.array(segs, np.int64).reshape(-1, 2), truth, A


def mislabelled(labels, truth, A):
    """Share of the area where labels + k differ from the truth, minimised over the integer k."""
    return min(A[(labels + k) != truth].sum() for k in range(-6, 7)) / A.sum()


def blob(subdivisions=4):
    """A closed genus-0 lumpy mesh (an icosphere pushed in and out)."""
    from gsdf.data import sphere_mesh

    V, F = sphere_mesh(subdivisions)
    V = V * (1 + 0.25 * np.sin(3 * V[:, [0]]) * np.cos(2 * V[:, [1]]) + 0.15 * np.sin(4 * V[:, [2]]))
    return V, F


def test_unbroken_regions_are_labelled_exactly():
    V, F = blob(3)
    for s in range(2):
        segs, truth, A = grown_regions_case(V, F, s, deleted=0.0)
        res = gsdf.surface_winding_number(V, F, segs)
        assert mislabelled(res.face_labels, truth, A) == 0


def test_broken_regions_error_sits_at_the_gaps():
    """With 40 % of the boundaries deleted, most of the mislabelled area is on faces touching a deleted edge —
    where the input does not say where the region's staircase boundary ran."""
    V, F = blob(4)
    near_all, err_all = 0.0, 0.0
    for s in range(3):
        segs, truth, A = grown_regions_case(V, F, s)
        full, _, _ = grown_regions_case(V, F, s, deleted=0.0)
        kept = set(map(tuple, segs.tolist()))
        gone = np.array([e for e in map(tuple, full.tolist()) if e not in kept])
        at_gap = np.zeros(len(V), bool)
        at_gap[gone.ravel()] = True
        res = gsdf.surface_winding_number(V, F, segs)
        k = min(range(-6, 7), key=lambda k: A[(res.face_labels + k) != truth].sum())
        wrong = (res.face_labels + k) != truth
        err_all += A[wrong].sum() / A.sum()
        near_all += A[wrong & at_gap[F].any(axis=1)].sum() / A.sum()
    assert err_all / 3 < 0.03
    assert near_all >= 0.6 * err_all


def _report(names):
    import os

    from bench.common import data_dir

    for name in names:
        p = os.path.join(data_dir(), "meshes", f"{name}.off")
        V, F = gsdf.read_mesh(p)
        errs, near = [], []
        for s in range(4):
            segs, truth, A = grown_regions_case(V, F, s)
            full, _, _ = grown_regions_case(V, F, s, deleted=0.0)
            kept = set(map(tuple, segs.tolist()))
            gone = np.array([e for e in map(tuple, full.tolist()) if e not in kept])
            at_gap = np.zeros(len(V), bool)
            at_gap[gone.ravel()] = True
            res = gsdf.surface_winding_number(V, F, segs)
            k = min(range(-6, 7), key=lambda k: A[(res.face_labels + k) != truth].sum())
            wrong = (res.face_labels + k) != truth
            errs.append(A[wrong].sum() / A.sum())
            near.append(A[wrong & at_gap[F].any(axis=1)].sum() / A.sum())
        print(f"{name} ({len(F)} faces): mislabelled {100 * np.mean(errs):.2f} % (cases "
              f"{', '.join(f'{100 * e:.2f}' for e in errs)}), on faces touching a deleted edge "
              f"{100 * np.mean(near):.2f} %")


if __name__ == "__main__":
    _report(sys.argv[1:] or ["cow"])
