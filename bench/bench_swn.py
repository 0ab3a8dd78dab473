"""Surface winding numbers benchmark (issue 12): a seeded, regenerable generator of broken-curve cases on meshes
of genus 0–3 with and without boundary, scored by mislabeled area; plus timing growth and the author data.

Cases (the thesis' 934 are not published; spec notes §1(e).4): for every mesh, ground-truth regions are
either super-level sets of a low Laplace eigenfunction (L φ = λ M φ, eigenvectors 2–6, level at a random
quantile) or region growing from 1–3 random seed faces (Dijkstra over face centroids up to 15–50 % of the
area). The region's oriented boundary is broken by deleting a fraction f ~ U(0.1, 0.5) of its edges, by one
of two schemes (``--breaking``; both seeded, same case draws):

* ``random`` (default) — "random intervals", as the thesis describes its benchmark (§6.3, Fig. 6.7; §7.1:
  curves deleted "at random intervals"): the chain is cut into edge walks (loops, or paths ending on the mesh
  boundary); in a walk of n edges, round(f·n) edges go in many short gaps of 1..ℓmax edges each, uniform,
  ℓmax = clip(n // 20, 2, 5), so no gap is longer than 5 edges (nor than 5 % of a loop of 40+ edges); the
  kept runs between gaps are a uniformly random composition of the other edges with at least 2 edges each
  (1 if 2 do not fit; a path's two end runs may be empty), and on a loop the pattern starts at a random edge.
  Walks under 8 edges stay whole (:meth:`MeshCases.break_random`).
* ``long`` — the first run's scheme: per connected curve component, f·n edges in k ~ U{1..4} intervals grown
  by BFS along the curve from k random seed edges (few long gaps; :meth:`MeshCases.break_long`). With 40–50 %
  deleted in one or two gaps the truth inside them is not determined by the input (see below).

On closed surfaces of genus > 0, half the cases add 1–2 broken homology generators (tree–cotree loops, 0–30 %
deleted by the same scheme) as nonbounding loops; they leave the truth unchanged. How the loops are drawn
(``MeshCases(..., loops=...)``, ``bench_swn_choice.py --loops``):

* ``"tree-cotree"`` (default; every CSV and section before the option) — loops of one tree–cotree basis per
  mesh, drawn without regard to the region: a loop may run along the region boundary or along the other loop.
  Running the same way an edge of the input then carries 2; running opposite ways the two cancel (0) and that
  stretch of both curves is missing from the input with no trace (section swn-ns-runs: 94 of the 157 broken-loop
  cases of the 504-case run share edges).
* ``"disjoint"`` — loops that share no edge with the case's (unbroken) region boundary nor with each other; they
  may meet it and each other at vertices (crossings). Each loop is a tree–cotree loop of a shortest-path tree of
  the edge graph *without* the forbidden edges (the region boundary, the loops drawn before; infinite weight),
  from a random root, with edges that touch a forbidden vertex weighted (1 + 2·touches)× so a loop crosses the
  boundary rather than hugging it vertex by vertex; forbidden edges are preferred into the cotree, so the
  leftover (generator) edges are free ones. The candidates are the loops of that tree whose homology class
  (pairing with the closed forms dual to the library's tree–cotree basis, gsdf.dec._cycles.TreeCotree) is
  nonzero and independent of the loops already drawn; one is picked at random. When a loop has no candidate,
  the case's loop set is drawn again from new roots (a *resample*, counted per case); after MAX_SETS = 6 failed
  sets the region itself is drawn again (same kind, then broken again) from the case's stream
  (:meth:`MeshCases.disjoint_loops`). A loop set can be impossible: where the faces along a boundary zigzag
  across it (a staircase on a grid), the dual edges of its edges form a nonbounding dual cycle, and any primal
  loop crossing that cycle must use one of its edges — the boundary's wedge on one side holds no edge at those
  vertices, so no loop crosses there at a vertex. Paired with the default: the case's region, its breaking, the
  number of loops and each loop's deletion fraction are the default generator's draws (its loops are still
  drawn, then discarded, so the main random stream is unchanged); the loops and their breaking (and a redrawn
  region) come from a per-case stream seeded by (mesh seed, case index), so every case stays seeded and
  reproducible. A loop's class may differ from the default's loop's. Error = area(W + k ≠ truth)
/ area, minimised over the integer k. Methods: full LP ("lp"), reduced LP ("reduced"), naive rounding of u
("none").

How fair the error is (``--only diagnose``): the truth inside a gap is whatever the eigenfunction level set or
the region growing did there, which the broken input does not determine — with 40–50 % of a boundary deleted
in one or two intervals, half a region's outline is simply missing and no method (nor a human) can recover
it. With the boundaries unbroken every simply connected case is solved exactly (0 % error), so the jump solve
is not the loss. The diagnosis reports, next to the plain error, the error *outside the gap zones* (faces
farther than half a gap's length from it, :func:`gap_zones`), which is what the input does determine, and the
error with the best offset in hindsight (an oracle that looks at the truth, a lower bound for any global
rounding offset). Both are reported beside the plain error; no case is dropped.

Usage::

    PYTHONPATH=src python3 bench/bench_swn.py --quick        # 50 cases, random intervals
    PYTHONPATH=src python3 bench/bench_swn.py                # 924 cases (+ scaling + author data)
    PYTHONPATH=src python3 bench/bench_swn.py --breaking long   # the same 924 draws, few long gaps (cases only)
    PYTHONPATH=src python3 bench/bench_swn.py --topology simply # the 420 simply connected cases only (~1 min)
    PYTHONPATH=src python3 bench/bench_swn.py --topology simply --endpoint-rule exclude   # ... with the old rule
    PYTHONPATH=src python3 bench/bench_swn.py --only scaling|author|cases
    PYTHONPATH=src python3 bench/bench_swn.py --only offsets    # solver offset vs oracle (50 fresh cases)
    PYTHONPATH=src python3 bench/bench_swn.py --only diagnose   # simply connected cases: where the error is
    PYTHONPATH=src python3 bench/bench_swn.py --only compare    # both schemes side by side, from the CSVs

Per-case rows go to bench/swn_cases.csv (random) / bench/swn_cases_long.csv (long), ``_simply`` for --topology
simply, ``_quick`` for --quick, ``_exclude`` for --endpoint-rule exclude,
appended as they finish (a rerun resumes; ``--fresh`` starts over); the summary goes to the sections "swn" /
"swn-long" (+ "-quick", "-simply", "-diagnose", ...) of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, dijkstra, minimum_spanning_tree

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import data_dir, machine, write_section  # noqa: E402

from gsdf.io import read_mesh  # noqa: E402
from gsdf.mesh._connectivity import MeshTopology  # noqa: E402
from gsdf.swn._solver import SurfaceWindingNumbers  # noqa: E402

AUTHOR = "/work/shared/data/swn"
CSV = os.path.join(HERE, "swn_cases.csv")
FIELDS = ["case", "mesh", "faces", "b1", "boundary", "region", "broken", "nonbounding", "endpoints",
          "err_lp", "err_reduced", "err_none", "err_lp_global", "err_reduced_global", "t_jump", "t_lp_total", "t_lp_highs", "t_reduced_total",
          "t_reduced_lp", "t_none", "lp_status"]


# ------------------------------------------------------------------------------------------------- meshes
def torus_grid(nu, nv, R=1.0, r=0.4):
    u = 2 * np.pi * np.arange(nu) / nu
    v = 2 * np.pi * np.arange(nv) / nv
    U, W = np.meshgrid(u, v, indexing="ij")
    V = np.stack([(R + r * np.cos(W)) * np.cos(U), (R + r * np.cos(W)) * np.sin(U), r * np.sin(W)], -1)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = (i * nv + j).ravel()
    b = (((i + 1) % nu) * nv + j).ravel()
    c = (((i + 1) % nu) * nv + (j + 1) % nv).ravel()
    d = (i * nv + (j + 1) % nv).ravel()
    return V.reshape(-1, 3), np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


def uv_sphere(n_lat, n_lon):
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")
    V = np.column_stack([np.sin(T).ravel() * np.cos(P).ravel(), np.sin(T).ravel() * np.sin(P).ravel(),
                         np.cos(T).ravel()])
    V = np.vstack([[0, 0, 1], V, [0, 0, -1]])
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)  # noqa: E731
    F = []
    for j in range(n_lon):
        F.append([0, idx(0, j), idx(0, j + 1)])
        F.append([len(V) - 1, idx(n_lat - 2, j + 1), idx(n_lat - 2, j)])
    for i in range(n_lat - 2):
        for j in range(n_lon):
            a, b, c, d = idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1)
            F += [[a, c, d], [a, d, b]]
    return V, np.array(F)


def annulus(nr, nt, r0=0.4, r1=1.0):
    rr = np.linspace(r0, r1, nr + 1)
    t = 2 * np.pi * np.arange(nt) / nt
    R, T = np.meshgrid(rr, t, indexing="ij")
    V = np.stack([R * np.cos(T), R * np.sin(T), 0 * R], -1).reshape(-1, 3)
    i, k = np.meshgrid(np.arange(nr), np.arange(nt), indexing="ij")
    a = (i * nt + k).ravel()
    b = (i * nt + (k + 1) % nt).ravel()
    c = ((i + 1) * nt + (k + 1) % nt).ravel()
    d = ((i + 1) * nt + k).ravel()
    return V, np.concatenate([np.stack([a, c, b], 1), np.stack([a, d, c], 1)])


def disk(n=40):
    """Flat unit disk, triangulated grid clipped to r < 1 (simply connected with boundary)."""
    x = np.linspace(-1, 1, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), 0 * X.ravel()], 1)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b = a + (n + 1)
    c = b + 1
    d = a + 1
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    F = F[np.linalg.norm(V[F].mean(1), axis=1) < 0.95]
    return compact(V, F)


def compact(V, F):
    used = np.unique(F)
    re = np.full(len(V), -1)
    re[used] = np.arange(len(used))
    return V[used], re[F]


def tori_union(centers, n=56, R=0.8, r=0.3):
    """Genus len(centers) surface: marching cubes of a union of solid tori along x."""
    from skimage.measure import marching_cubes

    xs = np.array([c for c in centers])
    lo, hi = xs.min() - 1.3, xs.max() + 1.3
    h = (hi - lo) / (n - 1)
    x = lo + h * np.arange(n)
    y = -1.3 + h * np.arange(int(2.6 / h) + 2)
    z = -0.5 + h * np.arange(int(1.0 / h) + 2)
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    f = np.full(X.shape, np.inf)
    for cx in xs:
        q = np.sqrt((X - cx) ** 2 + Y ** 2) - R
        f = np.minimum(f, np.sqrt(q ** 2 + Z ** 2) - r)
    V, F, _, _ = marching_cubes(f, 0.0, spacing=(h, h, h))
    V = V + np.array([x[0], y[0], z[0]])
    vol = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum()
    return V, (F if vol > 0 else F[:, ::-1]).astype(np.int64)


def torus_with_hole(nu=64, nv=32):
    V, F = torus_grid(nu, nv)
    i0 = (F // nv).min(1)
    j0 = (F % nv).min(1)
    hole = (i0 >= 10) & (i0 < 16) & (j0 >= 4) & (j0 < 9)
    return compact(V, F[~hole])


def mesh_list(quick=False):
    """(name, loader) pairs: 10 simply connected, 12 not."""
    cg = os.path.join(data_dir(), "meshes")
    A = AUTHOR

    def rd(p):
        return lambda: read_mesh(p)

    L = [
        ("sphere-uv", lambda: uv_sphere(36, 64)),
        ("disk", lambda: disk(56)),
        ("cow", rd(f"{cg}/cow.off")),
        ("dino", rd(f"{cg}/dino.off")),
        ("bull", rd(f"{cg}/bull.off")),
        ("blobby", rd(f"{cg}/blobby.off")),
        ("camel", rd(f"{cg}/camel.off")),
        ("mushroom", rd(f"{cg}/mushroom.off")),
        ("author-S", rd(f"{A}/S.obj")),
        ("author-bunny", rd(f"{A}/bunny.obj")),
        ("torus", lambda: torus_grid(64, 36)),
        ("torus-fine", lambda: torus_grid(120, 48)),
        ("knot1", rd(f"{cg}/knot1.off")),
        ("author-torus", rd(f"{A}/torus.obj")),
        ("double-torus-mc", lambda: tori_union([-0.9, 0.9], n=64)),
        ("author-double-torus", rd(f"{A}/double-torus.obj")),
        ("elephant-g3", rd(f"{cg}/elephant.off")),
        ("triple-torus-mc", lambda: tori_union([-1.8, 0.0, 1.8], n=80)),
        ("annulus", lambda: annulus(20, 96)),
        ("author-annulus", rd(f"{A}/annulus.obj")),
        ("shark-holes", rd(f"{cg}/mech-holes-shark.off")),
        ("torus-with-hole", lambda: torus_with_hole()),
    ]
    return L


NEW_ROWS = 0           # rows computed by this process (the rest of the CSV is read back)
LOOP_MODES = ("tree-cotree", "disjoint")   # how nonbounding loops are drawn (MeshCases loops=; module docstring)
TOUCH_PENALTY = 2.0    # "disjoint" loops: edge weight ×(1 + TOUCH_PENALTY · endpoints on forbidden vertices)
MAX_SETS = 6           # "disjoint" loops: loop sets drawn (new roots) before the case's region is drawn again
MAX_REGIONS = 20       # "disjoint" loops: regions drawn again (per-case stream) before the case is given up
N_SIMPLY = 10          # mesh_list()[:10] are simply connected (b1 = 0)


# ------------------------------------------------------------------------------------------------- cases
class MeshCases:
    """Per-mesh data reused by all its cases: the solver, eigenfunctions, dual graph, generator loops."""

    def __init__(self, name, V, F, seed, loops="tree-cotree"):
        if loops not in LOOP_MODES:
            raise ValueError(f"loops: expected one of {LOOP_MODES}, got {loops!r}")
        self.name = name
        self.seed = seed
        self.loops = loops
        self._cocycles = None
        self.swn = SurfaceWindingNumbers(V, F)
        d = self.swn.dec
        self.dec = d
        self.topo = d.topology
        self.area = d.areas
        self.rng = np.random.default_rng(seed)
        n, m = d.n_vertices, d.n_faces
        # eigenfunctions 2..6 of L φ = λ M φ (shift-invert near 0)
        from scipy.sparse.linalg import eigsh

        L = d.laplacian().tocsc()
        M = sp.diags(np.maximum(d.star0, 1e-12 * d.star0.mean())).tocsc()
        v0 = np.random.default_rng(seed).standard_normal(n)
        _, Phi = eigsh(L, k=7, M=M, sigma=-1e-6 * abs(L.diagonal()).mean(), which="LM", v0=v0)
        self.phi_face = Phi[d.F].mean(1)                       # (m, 7), column 0 ≈ constant
        # dual graph with centroid distances
        cen = d.V[d.F].mean(1)
        self.cen = cen
        inter = np.flatnonzero(self.topo.edge_face_count == 2)
        A, B = self.topo.edge_faces[inter, 0], self.topo.edge_faces[inter, 1]
        w = np.linalg.norm(cen[A] - cen[B], axis=1) + 1e-12
        self.dual = sp.coo_matrix((w, (A, B)), shape=(m, m)).tocsr()
        self.closed = self.topo.is_closed
        self.gens = self._generators() if (self.closed and self.swn.betti_1 > 0) else []

    def _generators(self):
        """Tree–cotree homology generators as primal edge loops (chains)."""
        d, topo = self.dec, self.topo
        n = d.n_vertices
        E = d.edges
        G = sp.coo_matrix((d.edge_len, (E[:, 0], E[:, 1])), shape=(n, n)).tocsr()
        root = int(self.rng.integers(n))
        dist, pred = dijkstra(G, directed=False, indices=root, return_predecessors=True)
        child = np.flatnonzero(pred >= 0)
        tkey = np.minimum(child, pred[child]) * n + np.maximum(child, pred[child])
        ekey = E[:, 0] * n + E[:, 1]
        in_tree = np.isin(ekey, tkey)
        # cotree: spanning tree of the dual graph over the edges not in the tree (prefer long dual links)
        cand = np.flatnonzero(~in_tree)
        Af, Bf = topo.edge_faces[cand, 0], topo.edge_faces[cand, 1]
        m = d.n_faces
        W = sp.coo_matrix((1.0 / (1e-9 + d.edge_len[cand]), (Af, Bf)), shape=(m, m)).tocsr()
        T = minimum_spanning_tree(W).tocoo()
        fk = np.minimum(T.row, T.col) * m + np.maximum(T.row, T.col)
        ck = np.minimum(Af, Bf) * m + np.maximum(Af, Bf)
        in_cotree = np.isin(ck, fk)
        left = cand[~in_cotree]
        loops = []
        for e in left:
            a, b = E[e]
            pa, pb = [int(a)], [int(b)]
            while pa[-1] != root:
                pa.append(int(pred[pa[-1]]))
            while pb[-1] != root:
                pb.append(int(pred[pb[-1]]))
            sa = set(pa)
            lca = next(v for v in pb if v in sa)
            path = pa[:pa.index(lca) + 1] + pb[:pb.index(lca)][::-1]          # a -> lca -> b
            cyc = np.array(path + [int(a)])                                   # close through edge b -> a
            loops.append(self.swn.chain([cyc]))
        return loops

    def homology_class(self, z):
        """Integer homology class (b1,) of a closed edge chain z: its pairings with the closed 1-forms dual to the
        library's tree–cotree basis (gsdf.dec._cycles.TreeCotree.closed_form of the unit periods)."""
        if self._cocycles is None:
            from gsdf.dec._cycles import TreeCotree

            tc = TreeCotree(self.dec)
            self._cocycles = np.array([tc.closed_form(np.eye(tc.n_generators)[i])
                                       for i in range(tc.n_generators)])
        c = self._cocycles @ z
        assert np.allclose(c, np.rint(c), atol=1e-6), c
        return np.rint(c).astype(np.int64)

    def loop_candidates(self, root, forbid_e, forbid_v):
        """Tree–cotree loops (closed chains) of the shortest-path tree from ``root`` over the edges not in
        ``forbid_e`` (edge weights ×(1 + TOUCH_PENALTY · endpoints in ``forbid_v``)); forbidden edges go into the
        cotree first, so the generator edges are free ones where the dual graph allows. Loops whose generator
        edge is forbidden or touches a vertex the tree does not reach are left out. Every loop returned shares no
        edge with ``forbid_e``."""
        d, topo = self.dec, self.topo
        n, m = d.n_vertices, d.n_faces
        E = d.edges
        ok = ~forbid_e
        w = d.edge_len * (1.0 + TOUCH_PENALTY * (forbid_v[E[:, 0]].astype(float) + forbid_v[E[:, 1]]))
        G = sp.coo_matrix((w[ok], (E[ok, 0], E[ok, 1])), shape=(n, n)).tocsr()
        dist, pred = dijkstra(G, directed=False, indices=int(root), return_predecessors=True)
        child = np.flatnonzero(pred >= 0)
        tkey = np.minimum(child, pred[child]) * n + np.maximum(child, pred[child])
        in_tree = np.isin(E[:, 0] * n + E[:, 1], tkey)
        cand = np.flatnonzero(~in_tree)
        Af, Bf = topo.edge_faces[cand, 0], topo.edge_faces[cand, 1]
        wc = 1.0 / (1e-9 + d.edge_len[cand])
        reach = np.isfinite(dist)
        low = ~ok[cand] | ~reach[E[cand, 0]] | ~reach[E[cand, 1]]
        wc[low] = 1e-6 * wc.min()                                    # into the cotree first
        T = minimum_spanning_tree(sp.coo_matrix((wc, (Af, Bf)), shape=(m, m)).tocsr()).tocoo()
        fk = np.minimum(T.row, T.col) * m + np.maximum(T.row, T.col)
        in_cotree = np.isin(np.minimum(Af, Bf) * m + np.maximum(Af, Bf), fk)
        out = []
        for e in cand[~in_cotree & ~low]:
            a, b = E[e]
            pa, pb = [int(a)], [int(b)]
            while pa[-1] != root:
                pa.append(int(pred[pa[-1]]))
            while pb[-1] != root:
                pb.append(int(pred[pb[-1]]))
            sa = set(pa)
            lca = next(v for v in pb if v in sa)
            path = pa[:pa.index(lca) + 1] + pb[:pb.index(lca)][::-1]
            z = self.swn.chain([np.array(path + [int(a)])])
            assert not np.any(forbid_e & (z != 0))
            out.append(z)
        return out

    def disjoint_loops(self, g, count, rng):
        """``count`` nonbounding loops (unbroken closed chains) sharing no edge with the region boundary ``g`` nor
        with each other, of independent nonzero homology classes (``loops="disjoint"``; module docstring).
        Loops are drawn one after the other, each from a new random root (:meth:`loop_candidates`); when a loop
        has no candidate the whole set is drawn again from new roots, up to MAX_SETS times.
        Returns (loops or None when every set failed, sets drawn beyond the first)."""
        E = self.dec.edges
        for attempt in range(MAX_SETS):
            forbid_e = g != 0
            forbid_v = np.zeros(self.dec.n_vertices, bool)
            forbid_v[E[forbid_e].ravel()] = True
            loops, classes = [], []
            for _ in range(count):
                root = int(rng.integers(self.dec.n_vertices))
                valid = []
                for z in self.loop_candidates(root, forbid_e, forbid_v):
                    cl = self.homology_class(z)
                    if np.linalg.matrix_rank(np.array(classes + [cl], float)) == len(classes) + 1:
                        valid.append((z, cl))
                if not valid:
                    break
                z, cl = valid[int(rng.integers(len(valid)))]
                loops.append(z)
                classes.append(cl)
                forbid_e = forbid_e | (z != 0)
                forbid_v[E[z != 0].ravel()] = True
            if len(loops) == count:
                return loops, attempt
        return None, MAX_SETS

    def region(self, kind, rng=None):
        """A ground-truth region (m,) int and its boundary chain, drawn from ``rng`` (default ``self.rng``)."""
        m = len(self.area)
        tot = self.area.sum()
        rng = self.rng if rng is None else rng
        for _ in range(20):
            if kind == "eigen":
                k = int(rng.integers(2, 7)) - 1
                f = self.phi_face[:, k]
                q = np.quantile(f, rng.uniform(0.3, 0.7))
                S = f > q
            else:
                S = np.zeros(m, bool)
                target = rng.uniform(0.15, 0.5) * tot
                ns = int(rng.integers(1, 4))
                seeds = rng.choice(m, ns, replace=False)
                D = dijkstra(self.dual, directed=False, indices=seeds).min(axis=0)
                order = np.argsort(D)
                cum = np.cumsum(self.area[order])
                S[order[: int(np.searchsorted(cum, target)) + 1]] = True
            frac = self.area[S].sum() / tot
            ind = S.astype(float)
            g = np.rint(self.dec.d1.T @ ind)
            g[self.topo.boundary_edges] = 0
            if 0.05 < frac < 0.95 and np.abs(g).sum() >= 8:
                return S.astype(np.int64), g
        return None, None

    def break_chain(self, g, frac, k, breaking="long", rng=None):
        """Delete ~frac of every curve component's edges: ``breaking="long"`` in k long intervals
        (:meth:`break_long`), ``"random"`` in many short random intervals (:meth:`break_random`; k unused).
        ``rng``: the random stream (default: the mesh's, ``self.rng``)."""
        if breaking == "random":
            return self.break_random(g, frac, rng)
        if breaking != "long":
            raise ValueError(f"breaking: expected 'random' or 'long', got {breaking!r}")
        return self.break_long(g, frac, k, rng)

    def walks(self, g):
        """The chain g cut into edge walks: (list of edge-index arrays, list of bools "closed"). Every edge is
        oriented by the sign of g (tail -> head); walks start at vertices with more outgoing than incoming edges
        (paths ending on the mesh boundary), the rest are cycles. Each walk turns, at a vertex with several
        ways on, to the first unused outgoing edge (a figure-eight is one cycle, which is fine here)."""
        on = np.flatnonzero(g != 0)
        E = self.dec.edges[on]
        tail = np.where(g[on] > 0, E[:, 0], E[:, 1])
        head = np.where(g[on] > 0, E[:, 1], E[:, 0])
        out = {}
        for i, t in enumerate(tail):
            out.setdefault(int(t), []).append(i)
        indeg = {}
        for h in head:
            indeg[int(h)] = indeg.get(int(h), 0) + 1
        used = np.zeros(len(on), bool)
        walks, closed = [], []
        starts = [v for v in out if len(out[v]) > indeg.get(v, 0)]
        for v0 in starts + [int(t) for t in tail]:
            while any(not used[i] for i in out.get(v0, [])):
                w, v = [], v0
                while True:
                    nxt = next((i for i in out.get(v, []) if not used[i]), None)
                    if nxt is None:
                        break
                    used[nxt] = True
                    w.append(nxt)
                    v = int(head[nxt])
                    if v == v0 and v0 not in starts:
                        break
                walks.append(on[np.array(w)])
                closed.append(v == v0)
        return walks, closed

    def break_random(self, g, frac, rng=None):
        """The "random intervals" breaking (default; thesis §6.3 Fig. 6.7, §7.1: curves deleted "at random
        intervals"). Per walk of n edges (:meth:`walks`): delete D = round(frac·n) edges in gaps of
        1..ℓmax edges each (uniform), ℓmax = clip(n // 20, 2, 5) — no gap longer than 5 edges (nor 5 % of a
        loop of 40+ edges); the kept runs between gaps are a uniformly random composition of the other n − D
        edges with at least 2 edges each (a run's end vertices become endpoints, excluded from the jump solve,
        so 1-edge runs would vanish; 1 edge each when 2 do not fit), a path's end runs may be empty; on a cycle
        the pattern starts at a random edge. Walks shorter than 8 edges are kept whole."""
        out = g.copy()
        if frac <= 0:
            return out
        walks, closed = self.walks(g)
        rng = self.rng if rng is None else rng
        for w, cyc in zip(walks, closed):
            n = len(w)
            if n < 8:
                continue
            lmax = int(np.clip(n // 20, 2, 5))
            D = int(round(frac * n))
            if D == 0:
                continue
            gaps = []
            while sum(gaps) < D:
                gaps.append(int(rng.integers(1, lmax + 1)))
            gaps[-1] -= sum(gaps) - D
            gaps = [x for x in gaps if x > 0]
            k = len(gaps)
            K = k if cyc else k + 1                            # kept runs (a path keeps both ends' runs)
            for mk in (2, 1):                                  # at least 2 kept edges a run; 1 if they don't fit
                mins = np.full(K, mk)
                if not cyc:
                    mins[0] = mins[-1] = 0
                R = n - D - int(mins.sum())
                if R >= 0:
                    break
            if R < 0:
                continue
            cuts = np.sort(rng.integers(0, R + 1, size=K - 1))
            keeps = mins + np.diff(np.concatenate([[0], cuts, [R]]))
            mask = np.zeros(n, bool)
            pos = 0
            for j in range(k):
                pos += int(keeps[j])
                mask[pos:pos + gaps[j]] = True
                pos += gaps[j]
            if cyc:
                mask = np.roll(mask, int(rng.integers(n)))
            out[w[mask]] = 0
        return out

    def break_long(self, g, frac, k, rng=None):
        """Delete ~frac of every curve component's edges in k intervals (BFS along the curve from random seed
        edges), so no component disappears entirely."""
        on = np.flatnonzero(g != 0)
        if frac <= 0 or len(on) == 0:
            return g
        E = self.dec.edges[on]
        nv = self.dec.n_vertices
        inc = sp.coo_matrix((np.ones(2 * len(on)), (np.repeat(np.arange(len(on)), 2), E.ravel())),
                            shape=(len(on), nv)).tocsr()
        adj = (inc @ inc.T).tocsr()
        adj.setdiag(0)
        adj.eliminate_zeros()
        nc, lab = connected_components(adj, directed=False)
        out = g.copy()
        for c in range(nc):
            mem = np.flatnonzero(lab == c)
            kk = min(k, len(mem))
            half = frac * len(mem) / kk / 2
            if half < 0.5:
                continue
            seeds = (self.rng if rng is None else rng).choice(mem, size=kk, replace=False)
            D = dijkstra(adj, directed=False, indices=seeds, unweighted=True, limit=half).min(axis=0)
            out[on[D <= half]] = 0
        return out


def mislabeled(W, truth, area):
    best = 1.0
    for k in np.unique(truth - W):
        best = min(best, float(area[(W + k) != truth].sum() / area.sum()))
    return best


def generate_cases(mc, n, breaking="random"):
    """Cases 0..n-1 of one mesh, in the generator's fixed order (so a case id can be replayed; both breaking
    schemes draw the same numbers before breaking, so ``breaking="long"`` replays the cases of the first run):
    yields (c, case id, region kind, truth (m,), unbroken boundary chain g, broken input gb, fraction deleted,
    number of nonbounding loops added)."""
    for c, cid, kind, truth, g, gb, frac, nb, _parts in generate_cases_parts(mc, n, breaking):
        yield c, cid, kind, truth, g, gb, frac, nb


def generate_cases_parts(mc, n, breaking="random"):
    """:func:`generate_cases` (same draws), also yielding the input's parts for diagnosis: a dict with the broken
    region boundary "region", the broken generator loops "loops" (list), the unbroken ones "loops_full" and
    "resamples" (``loops="disjoint"``: roots drawn beyond the first, :meth:`MeshCases.disjoint_loops`; else 0)."""
    for c in range(n):
        kind = "eigen" if c % 2 == 0 else "grow"
        truth, g = mc.region(kind)
        if truth is None:
            continue
        frac = mc.rng.uniform(0.1, 0.5)
        k = int(mc.rng.integers(1, 5))
        gb = mc.break_chain(g, frac, k, breaking)
        parts = {"region": gb.copy(), "loops": [], "loops_full": [], "resamples": 0, "regions": 0}
        nb = 0
        if mc.gens and mc.rng.random() < 0.5:
            draws = []
            for gi in mc.rng.choice(len(mc.gens), size=min(len(mc.gens), int(mc.rng.integers(1, 3))),
                                    replace=False):
                lf, lk = mc.rng.uniform(0.0, 0.3), int(mc.rng.integers(1, 3))
                loop = mc.break_chain(mc.gens[gi], lf, lk, breaking)
                draws.append((mc.gens[gi], loop, lf, lk))
            if mc.loops == "disjoint":           # same draws as above (main stream unchanged), other loops
                crng = np.random.default_rng([mc.seed, 104729, c])
                full, parts["resamples"] = mc.disjoint_loops(g, len(draws), crng)
                while full is None:              # no disjoint set for this region: a new region (same kind)
                    parts["regions"] += 1
                    if parts["regions"] > MAX_REGIONS:
                        raise RuntimeError(f"{mc.name}:{c}: no disjoint loops after {MAX_REGIONS} regions")
                    truth, g = mc.region(kind, rng=crng)
                    if truth is None:
                        continue
                    gb = mc.break_chain(g, frac, k, breaking, rng=crng)
                    parts["region"] = gb.copy()
                    full, r = mc.disjoint_loops(g, len(draws), crng)
                    parts["resamples"] += r
                draws = [(z, mc.break_chain(z, lf, lk, breaking, rng=crng), lf, lk)
                         for z, (_, _, lf, lk) in zip(full, draws)]
            for full, loop, _, _ in draws:
                gb = gb + loop
                parts["loops"].append(loop)
                parts["loops_full"].append(full)
                nb += 1
        yield c, f"{mc.name}:{c}", kind, truth, g, gb, frac, nb, parts


def run_cases(n_per_mesh, quick, time_limit, resume=True, breaking="random", topology="all",
              endpoint_rule="auto"):
    global NEW_ROWS
    meshes = list(enumerate(mesh_list()))
    if quick:
        meshes = [meshes[i] for i in (0, 2, 8, 10, 12, 14, 16, 18, 19, 21)]
    if topology == "simply":
        meshes = [mm for mm in meshes if mm[0] < N_SIMPLY]
    done = set()
    if resume and os.path.exists(CSV):
        with open(CSV) as fh:
            done = {r["case"] for r in csv.DictReader(fh)}
    new = not os.path.exists(CSV)
    fh = open(CSV, "a", newline="")
    wr = csv.DictWriter(fh, fieldnames=FIELDS)
    if new:
        wr.writeheader()
    for mi, (name, load) in meshes:
        ids = [f"{name}:{c}" for c in range(n_per_mesh)]
        if all(i in done for i in ids):
            continue
        try:
            V, F = load()
            mc = MeshCases(name, V, F, seed=1000 + mi)
        except Exception as exc:                                # a missing / unusable mesh: skip, say so
            print(f"skip {name}: {exc}", flush=True)
            continue
        print(f"{name}: {mc.dec.n_faces} faces, b1 = {mc.swn.betti_1}, {len(mc.gens)} generators", flush=True)
        for c, cid, kind, truth, g, gb, frac, nb in generate_cases(mc, n_per_mesh, breaking):
            if cid in done or not np.any(gb):
                continue
            row = {"case": cid, "mesh": name, "faces": mc.dec.n_faces, "b1": mc.swn.betti_1,
                   "boundary": int(not mc.closed), "region": kind, "broken": round(frac, 3),
                   "nonbounding": nb}
            r0 = mc.swn.solve(gb, method="none", endpoint_rule=endpoint_rule, labels="global")
            row["endpoints"] = int(r0.endpoints.sum())
            row["err_none"] = mislabeled(r0.face_labels, truth, mc.area)
            row["t_none"] = r0.timings["total"]
            row["t_jump"] = r0.timings["jump_solve"]
            status = "ok"
            for meth in ("lp", "reduced"):
                try:
                    r = mc.swn.solve(gb, method=meth, time_limit=time_limit, endpoint_rule=endpoint_rule)
                    row[f"err_{meth}"] = mislabeled(r.face_labels, truth, mc.area)
                    # the labels of one global rounding level (labels="global", before) from the same solve
                    Wg = np.round(r.corner_values.mean(axis=1) + r.label_shift).astype(np.int64)
                    row[f"err_{meth}_global"] = mislabeled(Wg, truth, mc.area)
                    row[f"t_{meth}_total" if meth == "reduced" else "t_lp_total"] = r.timings["total"]
                    row["t_lp_highs" if meth == "lp" else "t_reduced_lp"] = r.timings.get("lp", 0.0)
                except ValueError as exc:
                    status = f"{meth} failed: {str(exc)[:60]}"
                    row[f"err_{meth}"] = row[f"err_{meth}_global"] = float("nan")
            row["lp_status"] = status
            wr.writerow(row)
            fh.flush()
            NEW_ROWS += 1
        print(f"  done {name}", flush=True)
    fh.close()


# ----------------------------------------------------------------------------------------------- summary
def summarize():
    with open(CSV) as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return "no cases"
    f = lambda r, k: float(r[k]) if r.get(k) not in (None, "", "nan") else np.nan  # noqa: E731
    sc = [r for r in rows if int(r["b1"]) == 0]
    ns = [r for r in rows if int(r["b1"]) > 0]
    out = [f"{len(rows)} cases on {len({r['mesh'] for r in rows})} meshes ({len(sc)} simply connected, "
           f"{len(ns)} not); per-case rows in bench/{os.path.basename(CSV)}"
           + (f" ({NEW_ROWS} computed in this run, the others read back from earlier runs of the same generator; "
              "--fresh recomputes all)" if NEW_ROWS < len(rows) else "") + ".", ""]
    if sc:
        e = np.array([f(r, "err_lp") for r in sc])
        eg = np.array([f(r, "err_lp_global") for r in sc])
        en = np.array([f(r, "err_none") for r in sc])
        t = np.array([f(r, "t_lp_total") for r in sc])
        lt = lambda x: f"{100 * np.nanmean(x < 0.005):.1f} %" if np.isfinite(x).any() else "–"  # noqa: E731
        out += ["**Simply connected** (no LP; one jump solve):", "",
                "| | mean error | max error | cases < 0.5 % | median time | max time |", "|---|---|---|---|---|---|",
                f"| SWN (labels=\"gaps\", default) | {100 * np.nanmean(e):.3f} % | {100 * np.nanmax(e):.2f} % | "
                f"{lt(e)} | {np.nanmedian(t):.3f} s | {np.nanmax(t):.2f} s |"]
        if np.isfinite(eg).any():
            out.append(f"| SWN, labels=\"global\" (one rounding level; before) | {100 * np.nanmean(eg):.3f} % | "
                       f"{100 * np.nanmax(eg):.2f} % | {lt(eg)} | | |")
        out += [f"| naive rounding of u | {100 * np.nanmean(en):.3f} % | {100 * np.nanmax(en):.2f} % | {lt(en)} | | |",
                "", "Thesis: mean 0.14 %, max 5 %, typically < 2 s. Both label rows come from the same solves "
                "(SWNResult.label_shift).", ""]
    if ns:
        el = np.array([f(r, "err_lp") for r in ns])
        er = np.array([f(r, "err_reduced") for r in ns])
        en = np.array([f(r, "err_none") for r in ns])
        tl = np.array([f(r, "t_lp_total") for r in ns])
        tr = np.array([f(r, "t_reduced_total") for r in ns])
        hl = np.array([f(r, "t_lp_highs") for r in ns])
        hr = np.array([f(r, "t_reduced_lp") for r in ns])
        fail = sum(1 for r in ns if r["lp_status"] != "ok")
        out += ["**Not simply connected** (genus 1–3 and/or several boundary components):", "",
                "| method | cases < 0.5 % error | mean error | median error | median time | max time |",
                "|---|---|---|---|---|---|",
                f"| full LP (HiGHS) | {100 * np.nanmean(el < 0.005):.1f} % | {100 * np.nanmean(el):.2f} % | "
                f"{100 * np.nanmedian(el):.3f} % | {np.nanmedian(tl):.2f} s | {np.nanmax(tl):.1f} s |",
                f"| reduced LP | {100 * np.nanmean(er < 0.005):.1f} % | {100 * np.nanmean(er):.2f} % | "
                f"{100 * np.nanmedian(er):.3f} % | {np.nanmedian(tr):.3f} s | {np.nanmax(tr):.2f} s |",
                f"| naive rounding of u | {100 * np.nanmean(en < 0.005):.1f} % | {100 * np.nanmean(en):.2f} % | "
                f"{100 * np.nanmedian(en):.3f} % | | |"]
        for k, lab in (("err_lp_global", "full LP, labels=\"global\" (before; same solves)"),
                       ("err_reduced_global", "reduced LP, labels=\"global\" (before; same solves)")):
            x = np.array([f(r, k) for r in ns])
            if np.isfinite(x).any():
                out.append(f"| {lab} | {100 * np.nanmean(x < 0.005):.1f} % | {100 * np.nanmean(x):.2f} % | "
                           f"{100 * np.nanmedian(x):.3f} % | | |")
        out += ["",
                f"Reduced-LP speed-up: total time median {np.nanmedian(tl / tr):.1f}× (mean {np.nanmean(tl / tr):.1f}×); "
                f"the LP alone median {np.nanmedian(hl / np.maximum(hr, 1e-6)):.0f}×. LP failures: {fail}.",
                "Thesis: full LP < 0.5 % on 80 % of models (up to minutes); reduced LP ~100× faster; goal ≥ 90 %.",
                ""]
        # by subgroup
        out += ["| subgroup | cases | full LP < 0.5 % | reduced < 0.5 % | naive < 0.5 % |", "|---|---|---|---|---|"]
        for lab, sel in (("closed, no nonbounding loops", lambda r: r["boundary"] == "0" and r["nonbounding"] == "0"),
                         ("closed, with broken nonbounding loops", lambda r: r["boundary"] == "0" and r["nonbounding"] != "0"),
                         ("with boundary", lambda r: r["boundary"] == "1"),
                         ("regions: eigenfunction level sets", lambda r: r["region"] == "eigen"),
                         ("regions: region growing", lambda r: r["region"] == "grow")):
            rr = [r for r in ns if sel(r)]
            if rr:
                a = lambda k: 100 * np.nanmean(np.array([f(r, k) for r in rr]) < 0.005)  # noqa: E731
                out.append(f"| {lab} | {len(rr)} | {a('err_lp'):.1f} % | {a('err_reduced'):.1f} % | "
                           f"{a('err_none'):.1f} % |")
        out.append("")
    return "\n".join(out)


def compare_endpoint_rules(n_worst=10):
    """Simply connected cases under both endpoint rules of the jump solve (``--topology simply`` with
    ``--endpoint-rule branch`` / ``exclude``): the same case ids, side by side, and the worst cases of the old
    rule. Empty string unless both CSVs exist."""
    paths = {r: os.path.join(HERE, "swn_cases_simply" + ("" if r == "branch" else "_exclude") + ".csv")
             for r in ("exclude", "branch")}
    if not all(os.path.exists(p) for p in paths.values()):
        return ""
    err = {}
    for r, p in paths.items():
        with open(p) as fh:
            # like with like: the exclude CSV predates labels="gaps", so the global-level labels of both
            err[r] = {row["case"]: float(row.get("err_lp_global") or row["err_lp"]) for row in csv.DictReader(fh)}
    ids = sorted(set(err["exclude"]) & set(err["branch"]))
    a = {r: np.array([err[r][i] for i in ids]) for r in err}
    out = ["| endpoint rule of the jump solve | cases | mean error | max error | cases < 0.5 % |", "|---|---|---|---|---|"]
    names = {"exclude": "exclude (endpoints and their halfedges dropped, projective fill; before)",
             "branch": "branch (discrete branch point, the default on simply connected surfaces now)"}
    out_note = ("Both with labels=\"global\" (one rounding level; the exclude CSV predates labels=\"gaps\"; the "
                "default labels are in the table above).")
    for r in ("exclude", "branch"):
        out.append(f"| {names[r]} | {len(ids)} | {100 * a[r].mean():.3f} % | {100 * a[r].max():.2f} % | "
                   f"{100 * (a[r] < 0.005).mean():.1f} % |")
    out += ["", "Thesis: mean 0.14 %, max 5 %. " + out_note, "", f"Worst {n_worst} cases of the old rule:", "",
            "| case | exclude | branch |", "|---|---|---|"]
    for k in np.argsort(-a["exclude"])[:n_worst]:
        out.append(f"| {ids[k]} | {100 * a['exclude'][k]:.2f} % | {100 * a['branch'][k]:.2f} % |")
    kb = np.argsort(-a["branch"])[:n_worst]
    out += ["", f"Worst {n_worst} cases of the new rule: " + ", ".join(
        f"{ids[k]} {100 * a['branch'][k]:.2f} % (was {100 * a['exclude'][k]:.2f} %)" for k in kb) + "."]
    return "\n".join(out)


def compare_breakings(quick=False):
    """One table of both breaking schemes from their per-case CSVs (those present)."""
    f = lambda r, k: float(r[k]) if r.get(k) not in (None, "", "nan") else np.nan  # noqa: E731
    body = []
    for b in ("random", "long"):
        path = os.path.join(HERE, "swn_cases" + ("" if b == "random" else "_long") + ("_quick" if quick else "")
                            + ".csv")
        if not os.path.exists(path):
            continue
        with open(path) as fh:
            rows = list(csv.DictReader(fh))
        sc = np.array([f(r, "err_lp") for r in rows if int(r["b1"]) == 0])
        ns = [r for r in rows if int(r["b1"]) > 0]
        a = lambda k: 100 * np.nanmean(np.array([f(r, k) for r in ns]) < 0.005) if ns else np.nan  # noqa: E731
        body.append(f"| {b} | {len(rows)} | {100 * np.nanmean(sc):.3f} % / {100 * np.nanmax(sc):.2f} % / "
                    f"{100 * np.nanmean(sc < 0.005):.0f} % | {len(ns)} | {a('err_lp'):.1f} % | "
                    f"{a('err_reduced'):.1f} % | {a('err_none'):.1f} % |")
    if not body:
        return ""
    return "\n".join(["| breaking | cases | simply connected: mean / max error / < 0.5 % | not simply connected: "
                      "cases | full LP < 0.5 % | reduced < 0.5 % | naive < 0.5 % |", "|---|---|---|---|---|---|---|"]
                     + body)


# ----------------------------------------------------------------------------------------------- scaling
def scaling(time_limit, sizes):
    rows = ["| faces | step ① jump solve | full LP (lp_algorithm auto): LP / total | reduced LP: LP / total | "
            "errors lp / reduced |",
            "|---|---|---|---|---|"]
    for nu in sizes:
        nv = max(8, nu // 3)
        V, F = torus_grid(nu, nv)
        swn = SurfaceWindingNumbers(V, F)
        idx = np.arange(nu * nv).reshape(nu, nv)
        mer = idx[nu // 7, : int(0.8 * nv)]                    # a broken meridian (nonbounding)
        # a broken bounding loop: the boundary of a band of faces, 30 % deleted
        i0 = (F // nv).min(1)
        band = (i0 >= nu // 3) & (i0 < nu // 2)
        g = np.rint(swn.dec.d1.T @ band.astype(float))
        E = swn.dec.edges
        gap = (E % nv < int(0.3 * nv)).all(axis=1)              # a 30 % arc of each of the band's two loops
        g[gap] = 0
        g = g + swn.chain([mer])
        truth = band.astype(int)
        line = [f"| {len(F)} |"]
        t0 = time.perf_counter()
        r0 = swn.solve(g, method="none")
        line.append(f" {r0.timings['jump_solve']:.3f} s |")
        res = {}
        for meth in ("lp", "reduced"):
            try:
                r = swn.solve(g, method=meth, time_limit=time_limit)
                res[meth] = r
                line.append(f" {r.timings.get('lp', 0):.3f} s / {r.timings['total']:.2f} s |")
            except ValueError as exc:
                line.append(f" failed ({str(exc)[:40]}) |")
        errs = " / ".join(f"{100 * mislabeled(res[m].face_labels, truth, swn.dec.areas):.2f} %"
                          if m in res else "–" for m in ("lp", "reduced"))
        line.append(f" {errs} |")
        rows.append("".join(line))
        print(rows[-1], f"({time.perf_counter() - t0:.1f} s)", flush=True)
    return "\n".join(rows)


# ----------------------------------------------------------------------------------------------- authors
def author_data():
    from gsdf.io._swn_curves import read_swn_curves
    from gsdf.swn._insert import insert_curves

    rows = ["| mesh / curves | faces after insertion | b1 | endpoints | labels (area share), full LP | "
            "nonbounding share of the input | full LP total | reduced LP: labels agree / total |",
            "|---|---|---|---|---|---|---|---|"]
    sets = [("torus.obj", "torus-phi.txt", "1,0.3,1"), ("double-torus.obj", "double-torus.txt", "0.2,1,0.6"),
            ("annulus.obj", "annulus.txt", "0,1,0"), ("S.obj", "S.txt", "0,0,1"),
            ("bunny.obj", "bunny-heart.txt", "0,0,1")]
    for mesh, cur, view in sets:
        V, F = read_mesh(f"{AUTHOR}/{mesh}")
        c = read_swn_curves(f"{AUTHOR}/{cur}", F)
        V2, F2, segs, _ = insert_curves(V, F, c)
        swn = SurfaceWindingNumbers(V2, F2)
        r = swn.solve(list(segs), method="lp")
        rr = swn.solve(list(segs), method="reduced")
        A = swn.dec.areas
        labs = np.unique(r.face_labels)
        share = ", ".join(f"{int(k)}: {100 * A[r.face_labels == k].sum() / A.sum():.1f} %" for k in labs)
        agree = 100 * (1 - mislabeled(rr.face_labels, r.face_labels, A))
        nb = float(np.abs(r.residual[r.chain != 0]).sum() / max(np.abs(r.chain).sum(), 1))
        rows.append(f"| {mesh} / {cur} | {len(F2)} | {swn.betti_1} | {int(r.endpoints.sum())} | {share} | "
                    f"{nb:.2f} | {r.timings['total']:.2f} s | {agree:.1f} % / {rr.timings['total']:.2f} s |")
        from gsdf.render._raster import render_function_png

        m = len(F2)
        png = os.path.join(HERE, f"swn_author_{os.path.splitext(cur)[0]}.png")
        render_function_png(png, V2[F2].reshape(-1, 3), np.arange(3 * m).reshape(m, 3),
                            r.corner_values.ravel() - 0.5, view=[float(t) for t in view.split(",")], size=500)
        print(rows[-1], flush=True)
    return "\n".join(rows)


def offsets_diagnostic(per_mesh=10, breaking="random"):
    """How much of the error is the rounding offset: error with the offset of the solver vs the best offset in
    hindsight (an oracle over 101 offsets), full LP, on fresh cases of five meshes."""
    from gsdf.swn._solver import circular_mean

    meshes = dict(mesh_list())
    rows = {"solver offset (level on the curves)": [], "area circular mean of w": [], "oracle offset": []}
    for name, seed in [("cow", 1), ("sphere-uv", 3), ("torus", 4), ("author-annulus", 5), ("dino", 7)]:
        V, F = meshes[name]()
        mc = MeshCases(name, V, F, seed=seed)
        for c in range(per_mesh):
            truth, g = mc.region("eigen" if c % 2 == 0 else "grow")
            if truth is None:
                continue
            gb = mc.break_chain(g, mc.rng.uniform(0.1, 0.5), int(mc.rng.integers(1, 5)), breaking)
            r = mc.swn.solve(gb, method="lp")
            w = r.corner_values.mean(1) + r.label_shift + r.offset
            E = lambda s: mislabeled(np.round(w - s).astype(int), truth, mc.area)  # noqa: E731
            rows["solver offset (level on the curves)"].append(E(r.offset))
            rows["area circular mean of w"].append(E(circular_mean(w, mc.area) or 0.0))
            rows["oracle offset"].append(min(E(s) for s in np.linspace(-0.5, 0.5, 101)))
    out = ["| rounding offset | mean error | max error | cases < 0.5 % |", "|---|---|---|---|"]
    for k, v in rows.items():
        v = np.array(v)
        out.append(f"| {k} | {100 * v.mean():.2f} % | {100 * v.max():.1f} % | {100 * (v < 0.005).mean():.0f} % |")
    return f"{len(v)} cases (cow, sphere, torus, author annulus, dino; full LP):\n\n" + "\n".join(out)


def gap_zones(mc, g, gb):
    """Faces whose label the broken input does not determine: for every gap (a connected run of deleted
    boundary edges, total length ℓ) the faces with a vertex within edge-graph distance ℓ/2 of the gap's vertices
    — any closure a human would draw (e.g. the chord) stays inside this zone. (m,) bool."""
    d = mc.dec
    gone = np.flatnonzero((g != 0) & (gb == 0))
    zone_v = np.zeros(d.n_vertices, bool)
    if len(gone) == 0:
        return zone_v[d.F].any(1)
    E = d.edges[gone]
    nv = d.n_vertices
    inc = sp.coo_matrix((np.ones(2 * len(gone)), (np.repeat(np.arange(len(gone)), 2), E.ravel())),
                        shape=(len(gone), nv)).tocsr()
    adj = (inc @ inc.T).tocsr()
    nc, lab = connected_components(adj, directed=False)
    G = sp.coo_matrix((d.edge_len, (d.edges[:, 0], d.edges[:, 1])), shape=(nv, nv)).tocsr()
    for c in range(nc):
        mem = gone[lab == c]
        ell = float(d.edge_len[mem].sum())
        src = np.unique(d.edges[mem].ravel())
        D = dijkstra(G, directed=False, indices=src, limit=ell / 2, min_only=True)
        zone_v |= np.isfinite(D)
    return zone_v[d.F].any(1)


def diagnose(n_worst=12, per_mesh=42, breaking="random"):
    """Where the error of the simply connected cases comes from (replays cases 0..per_mesh-1 of the simply
    connected meshes of the full run, the same ids as bench/swn_cases.csv): the same truth with its unbroken
    boundary (tests the jump solve), the best offset in hindsight (the rounding), and the error outside the gap
    zones (:func:`gap_zones`: the part of the surface whose label the broken input determines)."""
    out = ["| case | deleted | endpoints | error | unbroken boundary | best offset in hindsight | gap zones' area | "
           "error outside the gap zones |", "|---|---|---|---|---|---|---|---|"]
    recs = []
    for mi, (name, load) in enumerate(mesh_list()):
        try:
            V, F = load()
            mc = MeshCases(name, V, F, seed=1000 + mi)
        except Exception as exc:
            print(f"skip {name}: {exc}", flush=True)
            continue
        if mc.swn.betti_1 != 0:
            continue
        for c, cid, kind, truth, g, gb, frac, nb in generate_cases(mc, per_mesh, breaking):
            if not np.any(gb):
                continue
            A = mc.area
            r = mc.swn.solve(gb, method="lp")
            rc = mc.swn.solve(g, method="lp")
            w = r.corner_values.mean(1) + r.label_shift + r.offset
            E = lambda s: mislabeled(np.round(w - s).astype(int), truth, A)  # noqa: E731
            e = E(r.offset)
            oracle = min(E(s) for s in np.linspace(-0.5, 0.5, 101))
            z = gap_zones(mc, g, gb)
            W = r.face_labels
            shift = min(np.unique(truth - W), key=lambda k: A[(W + k) != truth].sum())
            bad = (W + shift) != truth
            e_out = float(A[bad & ~z].sum() / A.sum())
            recs.append((e, mislabeled(rc.face_labels, truth, A), oracle, e_out, frac,
                         f"| {cid} | {100 * frac:.0f} % | {int(r.endpoints.sum())} | {100 * e:.1f} % | "
                         f"{{closed}} | {100 * oracle:.1f} % | {100 * A[z].sum() / A.sum():.0f} % | "
                         f"{100 * e_out:.2f} % |"))
        print(f"  diagnosed {name}", flush=True)
    recs.sort(key=lambda t: -t[0])
    for t in recs[:n_worst]:
        out.append(t[5].replace("{closed}", f"{100 * t[1]:.2f} %"))
    a = np.array([t[:5] for t in recs])
    out += ["", f"All {len(a)} simply connected cases:", "",
            "| deleted | cases | error (mean / < 0.5 %) | unbroken boundary (max) | best offset in hindsight "
            "(mean) | error outside the gap zones (mean / < 0.5 %) |", "|---|---|---|---|---|---|"]
    for lo, hi in ((0.1, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, 0.5), (0.1, 0.5)):
        s = (a[:, 4] >= lo) & (a[:, 4] < hi)
        if s.any():
            out.append(f"| {100 * lo:.0f}–{100 * hi:.0f} % | {int(s.sum())} | {100 * a[s, 0].mean():.2f} % / "
                       f"{100 * (a[s, 0] < 0.005).mean():.0f} % | {100 * a[s, 1].max():.2f} % | "
                       f"{100 * a[s, 2].mean():.2f} % | {100 * a[s, 3].mean():.2f} % / "
                       f"{100 * (a[s, 3] < 0.005).mean():.0f} % |")
    return "\n".join(out)


BREAKING_RULES = {
    "random": ("random intervals (default): per curve walk of n edges, round(f·n) edges deleted in gaps of "
               "1..clip(n//20, 2, 5) edges (uniform), kept runs a uniform random composition of the rest with "
               ">= 2 edges each, random start on loops; f ~ U(0.1, 0.5) per case (MeshCases.break_random)"),
    "long": ("long gaps (the first run's scheme): per curve component, f·n edges deleted in k ~ U{1..4} "
             "intervals grown by BFS from k random seed edges; f ~ U(0.1, 0.5) (MeshCases.break_long)"),
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="50 cases on 10 meshes, small scaling run")
    ap.add_argument("--per-mesh", type=int, default=None)
    ap.add_argument("--only", choices=["cases", "scaling", "author", "summary", "offsets", "diagnose",
                                                  "compare"], default=None)
    ap.add_argument("--breaking", choices=["random", "long"], default="random",
                    help="how boundaries are broken: many short random intervals (default) or few long gaps")
    ap.add_argument("--topology", choices=["all", "simply"], default="all",
                    help="'simply': only the 10 simply connected meshes (fast; no LP)")
    ap.add_argument("--time-limit", type=float, default=120.0)
    ap.add_argument("--endpoint-rule", choices=["auto", "branch", "exclude"], default="auto",
                    help="interior endpoints in the jump solves (SurfaceWindingNumbers.solve endpoint_rule); "
                         "'auto' (default): branch on simply connected meshes, exclude otherwise; 'exclude' is the "
                         "rule before (per-case CSV tagged _exclude / _branch)")
    ap.add_argument("--fresh", action="store_true", help="discard this variant's per-case CSV first")
    a = ap.parse_args()
    if (a.topology == "simply" or a.breaking == "long") and a.only is None:
        a.only = "cases"                # the cases alone: scaling and author data do not depend on the breaking
    global CSV
    tag = ("" if a.breaking == "random" else "_long") + ("_simply" if a.topology == "simply" else "") + \
        ("_quick" if a.quick else "") + ("" if a.endpoint_rule == "auto" else "_" + a.endpoint_rule)
    CSV = os.path.join(HERE, f"swn_cases{tag}.csv")
    if a.fresh and os.path.exists(CSV):
        os.remove(CSV)
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    t0 = time.perf_counter()
    parts = {}
    if a.only in (None, "cases"):
        run_cases(a.per_mesh or (5 if a.quick else 42), a.quick, a.time_limit, breaking=a.breaking,
                  topology=a.topology, endpoint_rule=a.endpoint_rule)
    if a.only in (None, "cases", "summary"):
        parts["cases"] = summarize()
    if a.only in (None, "scaling"):
        sizes = [48, 96] if a.quick else [56, 112, 224, 448, 700]
        parts["scaling"] = scaling(a.time_limit * 3, sizes)
    if a.only in (None, "author"):
        parts["author"] = author_data()
    if a.only == "offsets":
        parts["offsets"] = offsets_diagnostic(breaking=a.breaking)
    if a.only == "diagnose":
        parts["diagnose"] = diagnose(breaking=a.breaking)
    if a.only == "compare":
        text_cmp = compare_breakings(a.quick)
    flags = "".join(" " + t for t in sys.argv[1:])
    text = [f"Machine: {machine()}. Load at start: `{load}` (shared with other helpers; times are indicative).",
            f"Command: `PYTHONPATH=src python3 bench/bench_swn.py{flags}` ({time.perf_counter() - t0:.0f} s).",
            "", f"Breaking: {BREAKING_RULES[a.breaking]}.", ""]
    if "cases" in parts:
        text += ["### Generated cases" + (" (quick)" if a.quick else ""), "", parts["cases"], ""]
        cmp_ = compare_breakings(a.quick) if a.topology != "simply" else ""
        if a.topology == "simply" and a.breaking == "random" and compare_endpoint_rules():
            text += ["### Endpoint rule of the jump solve, old vs new (bench/swn_cases_simply*.csv)", "",
                     compare_endpoint_rules(), ""]
        if cmp_:
            text += ["### Both breaking schemes (from bench/swn_cases*.csv)", "", cmp_, ""]
    if "scaling" in parts:
        text += ["### Time vs faces (torus grid, one broken meridian + a 30 %-broken band boundary)", "",
                 parts["scaling"], ""]
    if "author" in parts:
        text += ["### Author data (/work/shared/data/swn; PNGs bench/swn_author_*.png)", "", parts["author"], ""]
    if "offsets" in parts:
        text += ["### Rounding offset: solver rule vs oracle", "", parts["offsets"], ""]
    if "diagnose" in parts:
        text += ["### Worst simply connected cases: where the error comes from", "", parts["diagnose"], ""]
    if a.only == "compare":
        text += ["### Both breaking schemes (from bench/swn_cases*.csv)", "", text_cmp, ""]
    name = "swn" + ("-long" if a.breaking == "long" else "") + ("-quick" if a.quick else "")
    if a.topology == "simply" and a.only == "cases":
        name += "-simply" + ("" if a.endpoint_rule == "auto" else "-" + a.endpoint_rule)
    elif a.only and not (a.only == "cases" and a.breaking == "long"):
        name += "-" + a.only
    title = "## Surface winding numbers (issue 12)" + (", long gaps" if a.breaking == "long" else "")
    write_section(name, title + (" — " + a.only if a.only else "") + (" — simply connected meshes only"
                  if a.topology == "simply" else "") + "\n\n" + "\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
