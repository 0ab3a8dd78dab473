"""The residual L1 program of surface winding numbers in cycle form: no face unknowns, vertex rows (HiGHS).

The full residual LP (thesis §6.1.2 step ④, :func:`gsdf.dec.lp.dual_graph_l1` on the faces of a triangle mesh)
minimises ``Σ_e w_e |J_e|`` over jumps ``J = d + x_A − x_B`` (per-face shifts x, interior edges e with left face A
and right face B), with bounds on J. Read as a primal 1-chain, ``J − d = ∂₂x`` restricted to the interior edges,
so the feasible jumps are exactly the chains J with

* ``(∂J)_v = (∂d)_v`` at every interior vertex v (``d0ᵀ`` rows; ∂d = 0 here because d is constant along each
  edge, so the vertex sums telescope), and
* the same intersection numbers as d with a basis of dual loops of the mesh (2g + b − 1 loops: genus g, b ≥ 1
  boundary components; 2g when closed), from a tree–cotree split: a spanning tree T* of the dual graph, then a
  spanning forest of the remaining edges with all boundary vertices merged into one node (relative homology);
  the edges in neither are the generators, and generator k's loop crosses it and runs back through T*.

The two descriptions have the same feasible J (the first has |V_int| + 2g + b − 1 independent conditions, the
dual graph's cycle rank), hence the same optimum: this is an exact reformulation with no face unknowns and about a
third of the rows (vertices instead of edges). ``tests/test_swn_lp_speed.py`` compares the objectives with the
plain LP on small meshes.

Why: the plain LP has |F| + 2|E| columns and |E| rows; this one 2|E| columns and about |V| rows, with the same
network structure (two nonzeros per column, plus the few loop rows). HiGHS time on the scaling case of
``bench/bench_swn_lp.py --only speed`` is in bench/RESULTS.md "swn-lp-speed".

(Column generation on this form — an edge subset priced by the equality duals — was tried and dropped: the duals
of small subsets are far from the full optimum's, nearly every edge got added, and it was slower than one LP.)

Example
-------
>>> import numpy as np
>>> from gsdf.dec.triangle import TriangleDEC
>>> n = 8; i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
>>> a = (i * n + j).ravel(); b = (((i + 1) % n) * n + j).ravel()
>>> c = (((i + 1) % n) * n + (j + 1) % n).ravel(); dd = (i * n + (j + 1) % n).ravel()
>>> u, v = 2 * np.pi * i.ravel() / n, 2 * np.pi * j.ravel() / n
>>> V = np.stack([(2 + np.cos(v)) * np.cos(u), (2 + np.cos(v)) * np.sin(u), np.sin(v)], 1)
>>> dec = TriangleDEC(V, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, dd], 1)]))
>>> inner = np.flatnonzero(dec.topology.edge_face_count == 2)
>>> prob = CycleL1(dec, inner)
>>> prob.n_generators                                       # a torus: two dual loops
2
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order, connected_components, minimum_spanning_tree

from .lp import DualL1Result, solve_highs
from .triangle import TriangleDEC, forest_potentials

__all__ = ["CycleL1"]


def _forest(n_nodes: int, a: np.ndarray, b: np.ndarray, cost: np.ndarray | None = None) -> np.ndarray:
    """Indices into (a, b) of a minimum spanning forest of the multigraph a–b (``cost`` per link, default 1;
    self-loops never chosen)."""
    keep = np.flatnonzero(a != b)
    if len(keep) == 0:
        return np.zeros(0, dtype=np.int64)
    a, b = a[keep], b[keep]
    cst = np.ones(len(keep)) if cost is None else cost[keep]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    order = np.lexsort((cst, lo * n_nodes + hi))             # per node pair, the cheapest link first
    key = (lo * n_nodes + hi)[order]
    first = order[np.r_[True, key[1:] != key[:-1]]]
    G = sp.coo_matrix((cst[first], (lo[first], hi[first])), shape=(n_nodes, n_nodes)).tocsr()
    T = minimum_spanning_tree(G).tocoo()
    tk = np.minimum(T.row, T.col).astype(np.int64) * n_nodes + np.maximum(T.row, T.col)
    fk = (lo * n_nodes + hi)[first]
    srt = np.argsort(fk)
    return keep[first[srt[np.searchsorted(fk[srt], tk)]]]


class CycleL1:
    """The cycle form of the residual L1 program on a fixed mesh and set of interior edges (built once).

    Parameters
    ----------
    dec : TriangleDEC
    interior : (k,) int, the edges carrying a jump (interior edges: two faces each)

    Attributes
    ----------
    C : (r, k) csr, the constraint rows: interior vertices, then one dual loop per generator
    n_generators : int, 2g + b − 1 (or 2g for a closed surface)
    """

    def __init__(self, dec: TriangleDEC, interior):
        topo = dec.topology
        interior = np.asarray(interior, dtype=np.int64)
        if interior.ndim != 1 or (interior.size and (interior.min() < 0 or interior.max() >= dec.n_edges)):
            raise ValueError(f"interior: expected edge indices in [0, {dec.n_edges}), got shape {interior.shape}")
        if np.any(topo.edge_face_count[interior] != 2):
            raise ValueError("interior: every edge must have two faces")
        self.dec, self.interior = dec, interior
        m, n, k = dec.n_faces, dec.n_vertices, len(interior)
        A, B = topo.edge_faces[interior, 0], topo.edge_faces[interior, 1]
        self._A, self._B = A, B
        t = _forest(m, A, B)
        in_t = np.zeros(k, dtype=bool)
        in_t[t] = True
        self._tree_links = t
        # primal forest over the other edges, boundary vertices merged into node n (relative homology)
        bv = topo.boundary_vertices
        node = np.where(bv, n, np.arange(n))
        E = dec.edges[interior]
        cand = np.flatnonzero(~in_t)
        self._cand_nodes = (node[E[cand, 0]], node[E[cand, 1]])
        self._cand = cand
        self._n_nodes = n + 1
        p = cand[_forest(n + 1, *self._cand_nodes)]
        in_p = np.zeros(k, dtype=bool)
        in_p[p] = True
        self.generators = np.flatnonzero(~in_t & ~in_p)
        self.n_generators = len(self.generators)
        # vertex rows (∂ at interior vertices); one row per closed component is redundant: drop it
        D0 = dec.d0[interior].T.tocsr()
        iv = np.flatnonzero(~bv)
        G = sp.coo_matrix((np.ones(k), (E[:, 0], E[:, 1])), shape=(n, n))
        nc, lab = connected_components(G, directed=False)
        closed = np.ones(nc, dtype=bool)
        closed[lab[bv]] = False
        first = np.full(nc, n, dtype=np.int64)
        np.minimum.at(first, lab, np.arange(n))
        drop = np.zeros(n, dtype=bool)
        drop[first[closed & (first < n)]] = True
        iv = iv[~drop[iv]]
        self.C = sp.vstack([D0[iv], self._loop_rows(t)]).tocsr()
        self._CT = self.C.T.tocsr()

    def _loop_rows(self, t) -> sp.csr_matrix:
        """One row per generator: +1 crossing it from its left face A to B, then ±1 along the T* path B → A."""
        k, m = len(self.interior), self.dec.n_faces
        A, B = self._A, self._B
        if self.n_generators == 0:
            return sp.csr_matrix((0, k))
        G = sp.coo_matrix((np.ones(len(t)), (A[t], B[t])), shape=(m, m)).tocsr()
        G = (G + G.T).tocsr()
        parent = np.full(m, -1, dtype=np.int64)
        depth = np.zeros(m, dtype=np.int64)
        nc, lab = connected_components(G, directed=False)
        for c in range(nc):
            r = int(np.argmax(lab == c))
            order, pred = breadth_first_order(G, r, directed=False, return_predecessors=True)
            parent[order[1:]] = pred[order[1:]]
            for f in order[1:]:                                  # BFS order: parents come first
                depth[f] = depth[pred[f]] + 1
        # the tree link between a face and its parent
        child = np.where(parent[A[t]] == B[t], A[t], B[t])
        up_link = np.full(m, -1, dtype=np.int64)
        up_link[child] = t
        rows, cols, vals = [], [], []
        for gi, e in enumerate(self.generators):
            p, q = int(B[e]), int(A[e])                          # walk p -> ... -> q through T*
            steps_p, steps_q = [], []
            while depth[p] > depth[q]:
                steps_p.append(p)
                p = int(parent[p])
            while depth[q] > depth[p]:
                steps_q.append(q)
                q = int(parent[q])
            while p != q:
                steps_p.append(p)
                steps_q.append(q)
                p, q = int(parent[p]), int(parent[q])
            rows.append(gi)
            cols.append(int(e))
            vals.append(1.0)
            for f in steps_p:                                    # crossing from f up to its parent
                li = up_link[f]
                rows.append(gi)
                cols.append(int(li))
                vals.append(1.0 if A[li] == f else -1.0)
            for f in steps_q:                                    # crossing from the parent down to f
                li = up_link[f]
                rows.append(gi)
                cols.append(int(li))
                vals.append(-1.0 if A[li] == f else 1.0)
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n_generators, k))

    def solve(self, offsets, weights, bounds=None, time_limit: float = 300.0,
              algorithm: str = "highs") -> DualL1Result:
        """Minimise ``Σ w |J|`` over the jumps J with ``J − d`` a boundary (see the module docstring).

        Parameters
        ----------
        offsets : (k,) float, d per interior edge
        weights : (k,) float, ≥ 0
        bounds : (k, 2) float, optional bounds ``[lo, hi]`` on J (±inf allowed)
        time_limit : float, seconds HiGHS may take; beyond it a ValueError
        algorithm : "highs", "highs-ds" or "highs-ipm"

        Returns
        -------
        DualL1Result — ``shifts`` per face (J − d integrated over T*, 0 at one face per component), ``jumps`` J,
        ``objective`` Σ w|J|, ``seconds`` (HiGHS)
        """
        k = len(self.interior)
        d = np.asarray(offsets, dtype=np.float64)
        w = np.asarray(weights, dtype=np.float64)
        if d.shape != (k,) or w.shape != (k,):
            raise ValueError(f"offsets/weights: expected shape ({k},), got {d.shape} / {w.shape}")
        if not (np.isfinite(d).all() and np.isfinite(w).all()) or (w < 0).any():
            raise ValueError("offsets/weights: need finite values and weights >= 0")
        if algorithm not in ("highs", "highs-ds", "highs-ipm"):
            raise ValueError(f"algorithm: expected 'highs', 'highs-ds' or 'highs-ipm', got {algorithm!r}")
        if isinstance(time_limit, bool) or not isinstance(time_limit, (int, float)) or not time_limit > 0:
            raise ValueError(f"time_limit: expected a positive number of seconds, got {time_limit!r}")
        if bounds is None:
            lo, hi = np.full(k, -np.inf), np.full(k, np.inf)
        else:
            Bd = np.asarray(bounds, dtype=np.float64)
            if Bd.shape != (k, 2) or np.isnan(Bd).any() or (Bd[:, 0] > Bd[:, 1]).any():
                raise ValueError(f"bounds: expected ({k}, 2) with lo <= hi and no NaN")
            lo, hi = Bd[:, 0], Bd[:, 1]
        # J = s+ − s−, bounds on J as bounds on s± (as gsdf.dec.lp.dual_graph_l1 does)
        sp_lo, sp_hi = np.where(lo > 0, lo, 0.0), np.where(hi < 0, 0.0, hi)
        sm_lo, sm_hi = np.where(hi < 0, -hi, 0.0), np.where(lo > 0, 0.0, -lo)
        if k == 0:
            return DualL1Result(np.zeros(self.dec.n_faces), np.zeros(0), 0.0, 0.0)
        res, secs = solve_highs(np.concatenate([w, w]), sp.hstack([self.C, -self.C]).tocsc(), self.C @ d,
                                np.column_stack([np.concatenate([sp_lo, sm_lo]), np.concatenate([sp_hi, sm_hi])]),
                                algorithm, time_limit)
        J = res.x[:k] - res.x[k:]
        # shifts: x_A − x_B = J − d along the dual tree T*
        t = self._tree_links
        delta = (J - d)[t]
        x = forest_potentials(self.dec.n_faces, np.concatenate([self._B[t], self._A[t]]),
                              np.concatenate([self._A[t], self._B[t]]), np.concatenate([delta, -delta]))
        return DualL1Result(x, J, float(np.dot(w, np.abs(J))), secs)
