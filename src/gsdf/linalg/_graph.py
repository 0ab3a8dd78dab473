"""Graph utilities shared by the DEC operators, the L1 programs and surface winding numbers."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order, connected_components

__all__ = ["forest_potentials"]


def forest_potentials(n_nodes: int, a: np.ndarray, b: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Potentials p on the nodes of the graph with directed links a -> b such that p[b] - p[a] = delta along a
    spanning forest (0 at one node per component). Vectorised: BFS from a virtual root, then pointer doubling
    sums the deltas along each tree path in O(log depth) numpy passes."""
    if n_nodes == 0:
        return np.zeros(0)
    G = sp.coo_matrix((np.ones(len(a)), (a, b)), shape=(n_nodes, n_nodes)).tocsr()
    nc, lab = connected_components(G, directed=False)
    first = np.full(nc, n_nodes, dtype=np.int64)
    np.minimum.at(first, lab, np.arange(n_nodes))
    root = n_nodes
    ra = np.concatenate([a, np.full(nc, root)])
    rb = np.concatenate([b, first])
    Gr = sp.coo_matrix((np.ones(len(ra)), (ra, rb)), shape=(n_nodes + 1, n_nodes + 1)).tocsr()
    _, pred = breadth_first_order(Gr, root, directed=False, return_predecessors=True)
    pred = pred.astype(np.int64)
    pred[root] = root
    # delta of each tree link pred -> node: look the directed link up (both directions are present)
    key_lookup = sp.coo_matrix((np.arange(1, len(a) + 1, dtype=np.float64), (a, b)),
                               shape=(n_nodes, n_nodes)).tocsr()
    nodes = np.arange(n_nodes)
    p = pred[:n_nodes]
    d = np.zeros(n_nodes + 1)
    tree = p != root
    idx = np.asarray(key_lookup[p[tree], nodes[tree]]).ravel().astype(np.int64) - 1
    d[nodes[tree]] = delta[idx]
    anc = pred.copy()
    acc = d.copy()
    while np.any(anc != root):
        acc = acc + acc[anc]
        anc = anc[anc]
    return acc[:n_nodes]
