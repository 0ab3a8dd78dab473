"""Tree–cotree homology basis of a triangle mesh: periods of closed 1-forms, closed forms with given periods.

A spanning forest T of the edge graph and a spanning forest C of the dual graph over the edges not in T (faces
as nodes, plus one virtual node that every boundary edge links to, so boundaries are "capped" together) leave
exactly b1 edges in neither: the *generators*. Each generator e closes a loop ``e + (tree path back)``; these loops
form a basis of the first homology H1(M; Z) (every other loop is, modulo face boundaries, an integer combination
of them: a cotree edge's loop is the boundary of the faces it cuts off, minus generator and tree loops). So a
closed 1-form (d1 ω = 0) is known up to an exact form by its b1 periods along the generator loops, and

- :meth:`TreeCotree.periods` integrates ω along the tree (a potential φ) and reads ``ω_e + φ_tail − φ_head`` at
  every generator e;
- :meth:`TreeCotree.closed_form` builds the closed form that is 0 on tree edges, the given periods on the
  generators, and on cotree edges whatever keeps every face closed (a tree-shaped, square sparse system).

The periods give the integer homology class of a closed edge loop (pair it with the closed forms of unit periods),
e.g. to tell nonbounding loops on a surface of genus > 0 (thesis §2.3, §6.1) apart from bounding ones.

Example
-------
>>> from gsdf.data._shapes import grid_mesh
>>> from gsdf.dec._triangle import TriangleDEC
>>> V, F = grid_mesh(4)
>>> TreeCotree(TriangleDEC(V, F)).n_generators           # a disk: no generators
0
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, minimum_spanning_tree

from gsdf.linalg import Factorization
from gsdf.dec._triangle import TriangleDEC
from gsdf.linalg._graph import forest_potentials

__all__ = ["TreeCotree"]


def _spanning_forest_edges(n_nodes: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Indices (into a, b) of the links of a spanning forest of the undirected multigraph a–b (BFS from the
    smallest node of each component; parallel links: one is chosen)."""
    if len(a) == 0:
        return np.zeros(0, dtype=np.int64)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * n_nodes + hi
    ukey, first = np.unique(key, return_index=True)
    G = sp.coo_matrix((np.ones(len(first)), (lo[first], hi[first])), shape=(n_nodes, n_nodes)).tocsr()
    T = minimum_spanning_tree(G).tocoo()              # unit weights: any spanning forest
    tk = np.minimum(T.row, T.col).astype(np.int64) * n_nodes + np.maximum(T.row, T.col)
    return first[np.searchsorted(ukey, tk)]


class TreeCotree:
    """Tree–cotree decomposition of a manifold triangle mesh (built once).

    Parameters
    ----------
    dec : TriangleDEC

    Attributes
    ----------
    tree : (nE,) bool, edges of the primal spanning forest
    cotree : (nE,) bool, edges of the dual spanning forest (boundary edges link to one virtual node)
    generators : (b1,) int, the remaining edges; loop i = generator i + the tree path from its head to its tail
    n_generators : int, equals the first Betti number

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.dec._triangle import TriangleDEC
    >>> n = 12; i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    >>> a = (i * n + j).ravel(); b = (((i + 1) % n) * n + j).ravel()
    >>> c = (((i + 1) % n) * n + (j + 1) % n).ravel(); d = (i * n + (j + 1) % n).ravel()
    >>> u, v = 2 * np.pi * i.ravel() / n, 2 * np.pi * j.ravel() / n
    >>> V = np.stack([(2 + np.cos(v)) * np.cos(u), (2 + np.cos(v)) * np.sin(u), np.sin(v)], 1)
    >>> F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    >>> tc = TreeCotree(TriangleDEC(V, F))
    >>> tc.n_generators                                     # a torus: two loops
    2
    >>> w = tc.closed_form(np.array([1.0, -2.0]))
    >>> bool(abs(TriangleDEC(V, F).d1 @ w).max() < 1e-9), tc.periods(w).round(9).tolist()
    (True, [1.0, -2.0])
    """

    def __init__(self, dec: TriangleDEC):
        self.dec = dec
        topo = dec.topology
        n, m, nE = dec.n_vertices, dec.n_faces, dec.n_edges
        E = dec.edges
        t = _spanning_forest_edges(n, E[:, 0], E[:, 1])
        self.tree = np.zeros(nE, dtype=bool)
        self.tree[t] = True
        # dual graph over the non-tree edges: faces 0..m-1 and the virtual boundary node m
        cand = np.flatnonzero(~self.tree)
        A = topo.edge_faces[cand, 0]
        B = topo.edge_faces[cand, 1]
        A = np.where(A < 0, m, A)
        B = np.where(B < 0, m, B)
        c = _spanning_forest_edges(m + 1, A, B)
        self.cotree = np.zeros(nE, dtype=bool)
        self.cotree[cand[c]] = True
        self.generators = np.flatnonzero(~self.tree & ~self.cotree)
        self.n_generators = len(self.generators)
        # potentials along the tree: p[b] - p[a] = ω_e for tree edge a -> b
        self._ta, self._tb = E[self.tree, 0], E[self.tree, 1]
        # cotree system: d1 restricted to cotree columns; one face per closed dual component is redundant
        self._ct = np.flatnonzero(self.cotree)
        D = dec.d1[:, self._ct].tocsr()
        link_a = np.concatenate([A[c], B[c]])
        link_b = np.concatenate([B[c], A[c]])
        G = sp.coo_matrix((np.ones(len(link_a)), (link_a, link_b)), shape=(m + 1, m + 1))
        _, lab = connected_components(G, directed=False)
        has_virtual = lab[:m] == lab[m]
        # components not containing the virtual node: drop their first face (its row is minus the others' sum)
        first = np.full(lab.max() + 1, m + 1, dtype=np.int64)
        np.minimum.at(first, lab[:m], np.arange(m))
        drop = np.zeros(m, dtype=bool)
        comp_closed = np.unique(lab[:m][~has_virtual])
        drop[first[comp_closed]] = True
        self._rows = np.flatnonzero(~drop)
        self._D = D[self._rows]
        self._fact = None
        if self._D.shape[0] != self._D.shape[1]:      # pragma: no cover - a manifold mesh always gives a square system
            raise ValueError("TreeCotree: the cotree system is not square (non-manifold mesh?)")

    def periods(self, form: np.ndarray) -> np.ndarray:
        """Periods (b1,) of a closed 1-form (nE,) along the generator loops (exact forms have none)."""
        w = self.dec.check_chain(form, "form")
        if self.n_generators == 0:
            return np.zeros(0)
        n = self.dec.n_vertices
        wt = w[self.tree]
        phi = forest_potentials(n, np.concatenate([self._ta, self._tb]), np.concatenate([self._tb, self._ta]),
                                np.concatenate([wt, -wt]))
        lo, hi = self.dec.edges[self.generators, 0], self.dec.edges[self.generators, 1]
        return w[self.generators] + phi[lo] - phi[hi]

    def closed_form(self, periods) -> np.ndarray:
        """The closed 1-form (nE,) with the given periods (b1,) along the generator loops: 0 on tree edges."""
        p = np.asarray(periods, dtype=np.float64).ravel()
        if p.shape != (self.n_generators,) or not np.isfinite(p).all():
            raise ValueError(f"periods: expected {self.n_generators} finite numbers, got shape {p.shape}")
        w = np.zeros(self.dec.n_edges)
        if self.n_generators == 0:
            return w
        w[self.generators] = p
        rhs = -(self.dec.d1[self._rows] @ w)
        if len(self._ct):
            if self._fact is None:
                self._fact = Factorization(self._D.tocsc().astype(np.float64), symmetric=False)
            w[self._ct] = self._fact.solve(rhs)
        return w
