"""Surface winding numbers (issue 12), simply connected cases: label rules for the faces in the gaps, measured.

Replays the cases of bench/bench_swn.py (same meshes, seeds, case ids,
random breaking; the cases with at least one input edge) and relabels the faces from the solver's corner values
``w`` (branch endpoint rule) by several rules; the error is the mislabeled area after the best integer shift, as in
bench_swn.py. Most of the error sits next to the deleted boundary edges (sections swn-reading, swn-floor), so the
rules change the level at which w is rounded *near the gaps* only.

Rules from the input alone:

- ``base``: the library's labels with ``labels="global"`` (``round(mean of the face's corners - s)``, s from
  ``rounding_offset``; the default before the gap labels).
- ``library labels="gaps"``: the library's default now (SurfaceWindingNumbers.gap_shift) — the ``local level,
  |dw| paths`` rule below as one vectorised pass (pairing by connected components, one numba pass of
  point-to-point Dijkstra searches over all gaps); same labels as the bench loop, its time is the library's.
- ``fill``: projective fill at endpoints (thesis §6.1: near an endpoint w is constant along rays from it): the
  corner at an interior endpoint takes the mean of its face's other corners; offset s from the plain means.
- ``fill+median``: as fill, faces off the endpoints labelled by the median of the linear w on the triangle.
- ``local level, length paths`` / ``local level, |dw| paths``: start from the fill labels; the label boundary
  off the input (edges where the labels jump but no input edge lies) is split into connected pieces; a piece
  with exactly two endpoints is re-traced by the shortest edge path between them over edges off the input,
  weighted by edge length (or length / (|jump of the face values across the edge| + 0.1), so the path follows
  the steepest part of w); the faces touching that path are rounded at the mean of w across the path's edges
  (the field's own level across the gap) instead of the global level s + 1/2 (mean of the shifts where several
  paths touch a face).

Oracles (use the truth; lower bounds, no method can do these):

- ``oracle closure``: every gap closed by the shortest path between its own two ends, labels of the closed curve.
- ``oracle per-gap threshold``: for the faces next to each gap, the best rounding threshold in [-1/2, 1/2].
- ``oracle truth-path level``: the local level as above taken on the deleted truth edges themselves.
- ``oracle pairing, |dw| paths``: the |dw| path rule with the truth's pairing of gap ends.

Usage::

    PYTHONPATH=src python3 bench/bench_swn_gaps.py              # the 420 cases (~8 min on a loaded machine)
    PYTHONPATH=src python3 bench/bench_swn_gaps.py --every 4    # every 4th case of each mesh

Writes section "swn-gaps" ("swn-gaps-every<k>") of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, dijkstra

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_swn as B  # noqa: E402
from bench_swn_floor import gap_pieces, shortest_path_closure  # noqa: E402
from common import machine, table, write_section  # noqa: E402

from gsdf.swn._solver import SurfaceWindingNumbers  # noqa: E402


def wrap(x):
    return (x + 0.5) % 1.0 - 0.5


def fill_values(swn, r):
    """Face values with the endpoint corners filled by the mean of the face's other corners (§6.1)."""
    w = r.corner_values
    isE = r.endpoints[swn.dec.F]
    cnt = (~isE).sum(1)
    return np.where(cnt > 0, np.where(isE, 0, w).sum(1) / np.maximum(cnt, 1), w.mean(1))


def tri_median(w):
    """The median of a linear function on a triangle from its corner values (m, 3)."""
    v = np.sort(w, 1)
    v1, v2, v3 = v[:, 0], v[:, 1], v[:, 2]
    F2 = np.where(v2 > v1, (v2 - v1) / np.maximum(v3 - v1, 1e-300), 0.0)
    lo = v1 + np.sqrt(0.5 * (v2 - v1) * (v3 - v1))
    hi = v3 - np.sqrt(0.5 * (v3 - v1) * (v3 - v2))
    return np.where(F2 >= 0.5, lo, hi)


def _offset(swn, wf, gb):
    gg = np.where(swn.topology.boundary_edges, 0.0, gb)
    return swn.rounding_offset(wf, gg, np.zeros(swn.dec.n_edges)), gg


def rule_base(swn, r, gb, g, truth):
    return r.face_labels


def rule_library_gaps(swn, r, gb, g, truth):
    wf = r.corner_values.mean(1) + r.offset           # r: labels="global" (scalar offset)
    s = swn.rounding_offset(wf, r.chain, np.zeros(swn.dec.n_edges))
    return np.round(wf - s - swn.gap_shift(wf, r.bounding, r.endpoints, s)).astype(int)


def rule_fill(swn, r, gb, g, truth):
    s, _ = _offset(swn, r.corner_values.mean(1), gb)
    return np.round(fill_values(swn, r) - s).astype(int)


def rule_fill_median(swn, r, gb, g, truth):
    w = r.corner_values
    s, _ = _offset(swn, w.mean(1), gb)
    isE = r.endpoints[swn.dec.F].any(1)
    wf = np.where(isE, fill_values(swn, r), tri_median(w))
    return np.round(wf - s).astype(int)


def _path_edges(pred, a, b, key, n):
    p = [b]
    while p[-1] != a:
        if pred[p[-1]] < 0:
            return None, None
        p.append(int(pred[p[-1]]))
    p = np.array(p)
    return np.searchsorted(key, np.minimum(p[:-1], p[1:]) * n + np.maximum(p[:-1], p[1:])), p


def local_level(swn, r, gb, g, truth, weight="dw", pairing="auto", eps=0.1):
    d, topo = swn.dec, swn.topology
    n, E = d.n_vertices, d.edges
    key = E[:, 0] * n + E[:, 1]
    wf = fill_values(swn, r)
    ends = r.endpoints
    s, gg = _offset(swn, wf, gb)
    inter = topo.edge_face_count == 2
    eA, eB = topo.edge_faces[:, 0], np.maximum(topo.edge_faces[:, 1], 0)
    mid = np.where(inter, 0.5 * (wf[eA] + wf[eB]), np.nan)
    dw = np.where(inter, np.abs(wf[eA] - wf[eB]), 0.0)
    wt = d.edge_len if weight == "len" else d.edge_len / (dw + eps)
    free = gg == 0
    G = sp.coo_matrix((wt[free], (E[free, 0], E[free, 1])), shape=(n, n)).tocsr()
    if pairing == "oracle":
        pairs = [(a, b) for mem, a, b in gap_pieces(d, g, gb) if a >= 0 and b >= 0]
    else:
        W = np.round(wf - s)
        bd = d.d1.T @ W
        comp_e = np.flatnonzero((np.abs(bd) > 0.5) & free & inter)
        pairs = []
        if len(comp_e):
            inc = sp.coo_matrix((np.ones(2 * len(comp_e)), (np.repeat(np.arange(len(comp_e)), 2),
                                                             E[comp_e].ravel())), shape=(len(comp_e), n)).tocsr()
            nc, lab = connected_components(inc @ inc.T, directed=False)
            for c in range(nc):
                vs = np.unique(E[comp_e[lab == c]].ravel())
                ev = vs[ends[vs]]
                if len(ev) == 2:
                    pairs.append(tuple(ev))
    acc = np.zeros(d.n_faces)
    cnt = np.zeros(d.n_faces)
    for a, b in pairs:
        _, pred = dijkstra(G, directed=False, indices=a, return_predecessors=True)
        pe, p = _path_edges(pred, a, b, key, n)
        if pe is None or not np.isfinite(mid[pe]).any():
            continue
        dl = wrap(np.nanmean(mid[pe]) - (s + 0.5))
        zv = np.zeros(n, bool)
        zv[p] = True
        fz = np.flatnonzero(zv[d.F].any(1))
        acc[fz] += dl
        cnt[fz] += 1
    so = s + np.where(cnt > 0, acc / np.maximum(cnt, 1), 0.0)
    return np.round(wf - so).astype(int)


def oracle_closure(swn, r, gb, g, truth):
    return swn.solve(shortest_path_closure(swn, g, gb)).face_labels


def oracle_gap_threshold(swn, r, gb, g, truth):
    d, topo, A = swn.dec, swn.topology, swn.dec.areas
    wf = fill_values(swn, r)
    s, _ = _offset(swn, wf, gb)
    W = np.round(wf - s)
    k = min(np.unique(truth - W), key=lambda t: A[(W + t) != truth].sum())
    W = W + k
    for mem, a, b in gap_pieces(d, g, gb):
        f = topo.edge_faces[mem].ravel()
        f = np.unique(f[f >= 0])
        best = None
        for t in np.linspace(-0.5, 0.5, 41):
            c = A[f][(np.round(wf[f] - s - t) + k) != truth[f]].sum()
            if best is None or c < best[0] - 1e-15 or (abs(c - best[0]) < 1e-15 and abs(t) < abs(best[1])):
                best = (c, t)
        W[f] = np.round(wf[f] - s - best[1]) + k
    return W.astype(int)


def oracle_truth_path(swn, r, gb, g, truth):
    d, topo = swn.dec, swn.topology
    wf = fill_values(swn, r)
    s, _ = _offset(swn, wf, gb)
    inter = topo.edge_face_count == 2
    eA, eB = topo.edge_faces[:, 0], np.maximum(topo.edge_faces[:, 1], 0)
    mid = np.where(inter, 0.5 * (wf[eA] + wf[eB]), np.nan)
    acc = np.zeros(d.n_faces)
    cnt = np.zeros(d.n_faces)
    for mem, a, b in gap_pieces(d, g, gb):
        if not np.isfinite(mid[mem]).any():
            continue
        dl = wrap(np.nanmean(mid[mem]) - (s + 0.5))
        f = topo.edge_faces[mem].ravel()
        f = np.unique(f[f >= 0])
        acc[f] += dl
        cnt[f] += 1
    so = s + np.where(cnt > 0, acc / np.maximum(cnt, 1), 0)
    return np.round(wf - so).astype(int)


RULES = [
    ("base (library labels=\"global\")", rule_base, False),
    ("library labels=\"gaps\" (default; gap_shift)", rule_library_gaps, False),
    ("fill (projective fill at endpoints, §6.1)", rule_fill, False),
    ("fill + triangle median", rule_fill_median, False),
    ("local level, length paths", lambda *a: local_level(*a, weight="len"), False),
    ("local level, \\|dw\\| paths (eps 0.1)", lambda *a: local_level(*a, weight="dw"), False),
    ("oracle closure (truth pairing, shortest paths)", oracle_closure, True),
    ("oracle per-gap threshold", oracle_gap_threshold, True),
    ("oracle truth-path level", oracle_truth_path, True),
    ("oracle pairing, \\|dw\\| paths", lambda *a: local_level(*a, weight="dw", pairing="oracle"), True),
]


NOTES = """\
Reading (branch swn9). Why the |dw|-path level works: next to an interior endpoint w is a branch point (it takes
every value of a unit interval on a small circle round it), so every level set of w in that interval runs from
one end of a gap to the other — a pencil of closing curves through the two ends (in the plane, for a straight
curve with a gap, the circular arcs through both ends). One global level picks the same member of the pencil in
every gap (the curves' own level: right for a broken circle, SurfaceWindingNumbers.rounding_offset); the path
of steepest w between the two ends is where the pencil's members crowd, and the mean of the face values across
it is the level at which w crosses *this* gap. On 110 of the cases (every 4th per mesh; 2095 gaps, 97 % of them
paired: a piece of label boundary with exactly two endpoints), the path is the deleted edges themselves for 63 %
of the paired gaps (every gap of 1 edge, half of those of 2): there the faces of the deleted edges are then all
right (mislabeled area per case 0.0365 % → 0.0002 %). The misses left are paths that cut a corner of the deleted
staircase (a 2-edge gap closed by the third edge of its triangle, whose level then separates two faces that lie
on the same side): on those gaps 0.162 % with one global level, 0.175 % with the path's; the per-gap threshold
oracle reaches 0.044 % on all paired gaps.

Long gaps: the closing path is a chord, and over a long gap the curve's own bend matters more (a circle with a
quarter missing is closed along the circle by the global level, inscribed-angle theorem; the chord's level cuts
it). Without a limit the rule made the long-gap scheme worse (bench_swn.py --breaking long --topology simply, 420
cases: mean 1.683 % → 1.816 %, < 0.5 % 53.8 → 51.7 %); the library keeps the global level on gaps whose closing
path has more than 8 edges (GAP_MAX_EDGES): 1.685 % / 54.3 % (section swn-long-simply; limits 5 / 6 / 12 edges:
1.682 / 1.684 / 1.687 %), and the random-interval cases (gaps of at most 5 edges) are unchanged by any limit of
5–12 edges (0.267 %; 3 edges: 0.281 %). Capping the shift's size instead (|shift| <= 0.05 … 0.15) lost most of
the gain on the random cases (0.307 … 0.278 %): the gain is in the large shifts.

Also measured and not kept (scratch runs through the library kernel, 110–140 of the cases, every 3rd / 4th per
mesh; mean error of the rule above on those: 0.194 % / 0.262 %): the faces beside the path labelled by its side
(the closed curve's labels) instead of rounded — same error (0.194 %); the level of the curve edges at the gap's
two ends (1–3 edges deep) — 0.30–0.34 %, averaged with the path's 0.23 %; the shift shrunk toward 0 by ¾ / ½ —
0.265 / 0.271 %; the middle of the widest gap of the face values within ±0.05 / 0.1 / 0.2 of the path level —
0.263 / 0.270 / 0.353 %; path weight (ℓ / (|dw| + eps))² / its square root — 0.282 / 0.260 % (fewer cases under
0.5 %: 83.6 / 84.3 vs 85.7 %); eps 1e-3 / 1 — 0.265 / 0.272 %; relabelling only the two faces of each path edge
— 0.202 vs 0.194 %, or the faces within two rings — same; the level from the vertex values along the path —
much worse (1.13 %).
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--every", type=int, default=1, help="every k-th case of each mesh")
    a = ap.parse_args()
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    t0 = time.perf_counter()
    errs = {name: [] for name, _, _ in RULES}
    secs = {name: 0.0 for name, _, _ in RULES}
    for mi, (mname, loadf) in enumerate(B.mesh_list()[:B.N_SIMPLY]):
        V, F = loadf()
        mc = B.MeshCases(mname, V, F, seed=1000 + mi)
        swn = SurfaceWindingNumbers(np.asarray(mc.dec.V), np.asarray(mc.dec.F))
        A = swn.dec.areas
        cases = [c for c in B.generate_cases(mc, 42, "random") if np.any(c[5])]
        for c, cid, kind, truth, g, gb, frac, nb in cases[::a.every]:
            r = swn.solve(gb, labels="global")
            for name, fn, _ in RULES:
                t = time.perf_counter()
                W = fn(swn, r, gb, g, truth)
                secs[name] += time.perf_counter() - t
                errs[name].append(B.mislabeled(W, truth, A))
        print(mname, len(cases[::a.every]), flush=True)
    rows = []
    for name, _, orc in RULES:
        e = np.array(errs[name])
        rows.append([name, "yes" if orc else "no", len(e), f"{100 * e.mean():.3f} %", f"{100 * e.max():.2f} %",
                     f"{100 * (e < 0.005).mean():.1f} %", f"{secs[name] / len(e) * 1e3:.0f} ms"])
    flags = "".join(" " + t for t in sys.argv[1:])
    body = (f"Machine: {machine()}. Load at start: `{load}` (shared with other helpers; times are indicative, "
            f"errors are not affected).\nCommand: `PYTHONPATH=src python3 bench/bench_swn_gaps.py{flags}` "
            f"({time.perf_counter() - t0:.0f} s).\n\n"
            + table(["label rule", "uses truth", "cases", "mean error", "max error", "cases < 0.5 %",
                     "time / case (relabel only)"], rows)
            + "\n\nThesis: mean 0.14 %, max 5 %. The rules are described in the docstring of "
              "bench/bench_swn_gaps.py; the bench's own path rules loop over gaps in Python (scipy dijkstra per "
              "gap), the library row is the vectorised pass (its first case includes numba's load / compile).\n"
            + "\n" + NOTES)
    name = "swn-gaps" + (f"-every{a.every}" if a.every > 1 else "")
    write_section(name, "## Surface winding numbers, simply connected: label rules for the gap faces "
                  "(issue 12)\n\n" + body)
    print(body)


if __name__ == "__main__":
    main()
