"""Surface winding numbers: a seeded, regenerable generator of broken-curve cases on meshes of genus 0–3 with
and without boundary, scored by mislabeled area; plus timing growth and the author data.

Cases (the thesis' 934 are not published): for every mesh, ground-truth regions are either super-level sets of a
low Laplace eigenfunction (L φ = λ M φ, eigenvectors 2–6, level at a random quantile) or region growing from 1–3
random seed faces (Dijkstra over face centroids up to 15–50 % of the area). The region's oriented boundary is
broken by deleting a fraction f ~ U(0.1, 0.5) of its edges, by one of two schemes (``--breaking``; both seeded,
same case draws):

* ``random`` (default) — "random intervals", as the thesis describes its benchmark (§6.3, Fig. 6.7; §7.1):
  the chain is cut into edge walks; in a walk of n edges, round(f·n) edges go in many short gaps of 1..ℓmax
  edges each, ℓmax = clip(n // 20, 2, 5); the kept runs between gaps are a uniformly random composition of the
  other edges with at least 2 edges each; walks under 8 edges stay whole (:meth:`MeshCases.break_random`).
* ``long`` — per connected curve component, f·n edges in k ~ U{1..4} intervals grown by BFS along the curve
  from k random seed edges (few long gaps; :meth:`MeshCases.break_long`). With 40–50 % deleted in one or two
  gaps the truth inside them is not determined by the input.

On closed surfaces of genus > 0, half the cases add 1–2 broken homology generators (tree–cotree loops, 0–30 %
deleted by the same scheme) as nonbounding loops; they leave the truth unchanged. Error = area(W + k ≠ truth)
/ area, minimised over the integer k. Methods: full LP ("lp", the default), reduced LP ("reduced"), naive
rounding of u ("none").

Parts (``--only``, default all), each writing its own section of bench/RESULTS.md:

* ``cases`` ("swn-cases", "swn-cases-long-gaps" with ``--breaking long``): 42 cases per mesh (5 on 10 meshes
  with ``--quick``); per-case rows are appended to ``--rows`` (default in the temporary folder: a rerun resumes,
  ``--fresh`` starts over);
* ``scaling`` ("swn-scaling"): time against faces on a torus grid;
* ``author`` ("swn-author"): the authors' meshes and curves (/work/shared/data/swn); pictures with
  ``--output-dir``.

    PYTHONPATH=src python3 bench/bench_swn.py --quick        # 50 cases, small scaling run
    PYTHONPATH=src python3 bench/bench_swn.py                # 924 cases + scaling + author data
    PYTHONPATH=src python3 bench/bench_swn.py --only cases --breaking long
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import tempfile
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, dijkstra, minimum_spanning_tree

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import command, data_dir, heading, output_dir, write_section
from load import uptime  # noqa: E402  # noqa: E402

from gsdf.io import read_mesh  # noqa: E402
from gsdf.swn import SurfaceWindingNumbers, SWNOptions  # noqa: E402

AUTHOR = "/work/shared/data/swn"
CSV = None  # the per-case rows (main: --rows)
FIELDS = ["case", "mesh", "faces", "b1", "boundary", "region", "broken", "nonbounding", "endpoints",
          "err_lp", "err_reduced", "err_none", "t_jump", "t_lp_total", "t_lp_highs", "t_reduced_total",
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
        self.area = d.face_area
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
        G = sp.coo_matrix((d.edge_length, (E[:, 0], E[:, 1])), shape=(n, n)).tocsr()
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
        W = sp.coo_matrix((1.0 / (1e-9 + d.edge_length[cand]), (Af, Bf)), shape=(m, m)).tocsr()
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
        w = d.edge_length * (1.0 + TOUCH_PENALTY * (forbid_v[E[:, 0]].astype(float) + forbid_v[E[:, 1]]))
        G = sp.coo_matrix((w[ok], (E[ok, 0], E[ok, 1])), shape=(n, n)).tocsr()
        dist, pred = dijkstra(G, directed=False, indices=int(root), return_predecessors=True)
        child = np.flatnonzero(pred >= 0)
        tkey = np.minimum(child, pred[child]) * n + np.maximum(child, pred[child])
        in_tree = np.isin(E[:, 0] * n + E[:, 1], tkey)
        cand = np.flatnonzero(~in_tree)
        Af, Bf = topo.edge_faces[cand, 0], topo.edge_faces[cand, 1]
        wc = 1.0 / (1e-9 + d.edge_length[cand])
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


def run_cases(n_per_mesh, quick, time_limit, resume=True, breaking="random"):
    global NEW_ROWS
    meshes = list(enumerate(mesh_list()))
    if quick:
        meshes = [meshes[i] for i in (0, 2, 8, 10, 12, 14, 16, 18, 19, 21)]
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
            r0 = mc.swn.solve(gb, method="none")
            row["endpoints"] = int(r0.endpoints.sum())
            row["err_none"] = mislabeled(r0.face_labels, truth, mc.area)
            row["t_none"] = r0.timings["total"]
            row["t_jump"] = r0.timings["jump_solve"]
            status = "ok"
            for meth in ("lp", "reduced"):
                try:
                    r = mc.swn.solve(gb, method=meth, options=SWNOptions(time_limit=time_limit))
                    row[f"err_{meth}"] = mislabeled(r.face_labels, truth, mc.area)
                    row[f"t_{meth}_total" if meth == "reduced" else "t_lp_total"] = r.timings["total"]
                    row["t_lp_highs" if meth == "lp" else "t_reduced_lp"] = r.timings.get("lp", 0.0)
                except ValueError as exc:
                    status = f"{meth} failed: {str(exc)[:60]}"
                    row[f"err_{meth}"] = float("nan")
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
           f"{len(ns)} not); per-case rows in {CSV}"
           + (f" ({NEW_ROWS} computed in this run, the others read back from earlier runs of the same generator; "
              "--fresh recomputes all)" if NEW_ROWS < len(rows) else "") + ".", ""]
    if sc:
        e = np.array([f(r, "err_lp") for r in sc])
        en = np.array([f(r, "err_none") for r in sc])
        t = np.array([f(r, "t_lp_total") for r in sc])
        lt = lambda x: f"{100 * np.nanmean(x < 0.005):.1f} %" if np.isfinite(x).any() else "–"  # noqa: E731
        out += ["**Simply connected** (no LP; one jump solve):", "",
                "| | mean error | max error | cases < 0.5 % | median time | max time |", "|---|---|---|---|---|---|",
                f"| SWN (default) | {100 * np.nanmean(e):.3f} % | {100 * np.nanmax(e):.2f} % | "
                f"{lt(e)} | {np.nanmedian(t):.3f} s | {np.nanmax(t):.2f} s |"]
        out += [f"| naive rounding of u | {100 * np.nanmean(en):.3f} % | {100 * np.nanmax(en):.2f} % | {lt(en)} | | |",
                "", "Thesis: mean 0.14 %, max 5 %, typically < 2 s.", ""]
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
                r = swn.solve(g, method=meth, options=SWNOptions(time_limit=time_limit))
                res[meth] = r
                line.append(f" {r.timings.get('lp', 0):.3f} s / {r.timings['total']:.2f} s |")
            except ValueError as exc:
                line.append(f" failed ({str(exc)[:40]}) |")
        errs = " / ".join(f"{100 * mislabeled(res[m].face_labels, truth, swn.dec.face_area):.2f} %"
                          if m in res else "–" for m in ("lp", "reduced"))
        line.append(f" {errs} |")
        rows.append("".join(line))
        print(rows[-1], f"({time.perf_counter() - t0:.1f} s)", flush=True)
    return "\n".join(rows)


# ----------------------------------------------------------------------------------------------- authors
def author_data(out_dir=None):
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
        A = swn.dec.face_area
        labs = np.unique(r.face_labels)
        share = ", ".join(f"{int(k)}: {100 * A[r.face_labels == k].sum() / A.sum():.1f} %" for k in labs)
        agree = 100 * (1 - mislabeled(rr.face_labels, r.face_labels, A))
        nb = float(np.abs(r.residual[r.chain != 0]).sum() / max(np.abs(r.chain).sum(), 1))
        rows.append(f"| {mesh} / {cur} | {len(F2)} | {swn.betti_1} | {int(r.endpoints.sum())} | {share} | "
                    f"{nb:.2f} | {r.timings['total']:.2f} s | {agree:.1f} % / {rr.timings['total']:.2f} s |")
        if out_dir:
            from gsdf.render._raster import render_function_png

            m = len(F2)
            png = os.path.join(out_dir, f"swn_author_{os.path.splitext(cur)[0]}.png")
            render_function_png(png, V2[F2].reshape(-1, 3), np.arange(3 * m).reshape(m, 3),
                                r.corner_values.ravel() - 0.5, view=[float(t) for t in view.split(",")], size=500)
        print(rows[-1], flush=True)
    return "\n".join(rows)


BREAKING_RULES = {
    "random": ("random intervals (default): per curve walk of n edges, round(f·n) edges deleted in gaps of "
               "1..clip(n//20, 2, 5) edges (uniform), kept runs a uniform random composition of the rest with "
               ">= 2 edges each, random start on loops; f ~ U(0.1, 0.5) per case (MeshCases.break_random)"),
    "long": ("long gaps: per curve component, f·n edges deleted in k ~ U{1..4} intervals grown by BFS from k "
             "random seed edges; f ~ U(0.1, 0.5) (MeshCases.break_long)"),
}
PARTS = ("cases", "scaling", "author")


def main(argv=None):
    global CSV
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="50 cases on 10 meshes, small scaling run")
    ap.add_argument("--only", default="", help=f"comma list of parts: {','.join(PARTS)} (default all)")
    ap.add_argument("--per-mesh", type=int, default=None, help="cases per mesh (default 42, 5 with --quick)")
    ap.add_argument("--breaking", choices=["random", "long"], default="random",
                    help="how boundaries are broken: many short random intervals (default) or few long gaps")
    ap.add_argument("--time-limit", type=float, default=120.0, help="seconds per LP")
    ap.add_argument("--rows", default=None, help="per-case CSV (default: in the temporary folder)")
    ap.add_argument("--fresh", action="store_true", help="discard the per-case CSV first")
    ap.add_argument("--output-dir", default=None, help="folder for the author data pictures")
    a = ap.parse_args(argv)
    parts = [p for p in a.only.split(",") if p] or list(PARTS)
    for p in parts:
        if p not in PARTS:
            ap.error(f"--only: unknown part {p!r}; known: {', '.join(PARTS)}")
    tag = ("" if a.breaking == "random" else "_long") + ("_quick" if a.quick else "")
    CSV = a.rows or os.path.join(tempfile.gettempdir(), "gsdf-bench", f"swn_cases{tag}.csv")
    os.makedirs(os.path.dirname(os.path.abspath(CSV)), exist_ok=True)
    if a.fresh and os.path.exists(CSV):
        os.remove(CSV)
    output_dir(a.output_dir)
    for part in parts:
        start, t0 = uptime(), time.perf_counter()
        flags = [f"--only {part}"] + (["--quick"] if a.quick else []) + \
            ([f"--breaking {a.breaking}"] if part == "cases" and a.breaking != "random" else []) + \
            ([f"--per-mesh {a.per_mesh}"] if part == "cases" and a.per_mesh else [])
        cmd = command("bench_swn.py", flags)
        if part == "cases":
            run_cases(a.per_mesh or (5 if a.quick else 42), a.quick, a.time_limit, breaking=a.breaking)
            title = "Surface winding numbers: generated broken-curve cases" + (
                ", few long gaps" if a.breaking == "long" else "")
            body = f"Breaking: {BREAKING_RULES[a.breaking]}.\n\n" + summarize()
            name = "swn-cases" + ("-long-gaps" if a.breaking == "long" else "")
        elif part == "scaling":
            sizes = [48, 96] if a.quick else [56, 112, 224, 448, 700]
            title = "Surface winding numbers: time against faces"
            body = ("Torus grid, one broken meridian + a 30 %-broken band boundary.\n\n"
                    + scaling(a.time_limit * 3, sizes))
            name = "swn-scaling"
        else:
            title, body, name = "Surface winding numbers on the authors' data", author_data(a.output_dir), "swn-author"
        text = heading(title, cmd, start) + f"Part took {time.perf_counter() - t0:.0f} s.\n\n" + body.strip() + "\n"
        print(text, flush=True)
        write_section(name, text)


if __name__ == "__main__":
    main()
