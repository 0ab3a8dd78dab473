"""Topology of a triangle mesh: closed, edge-manifold, vertex-manifold, oriented, components, χ, genus.

Used by the reconstruction tests and benchmarks to assert the promise of :mod:`gsdf.recon` ("one closed,
manifold sphere") on every output, independently of how the output was built.

Example
-------
>>> import numpy as np
>>> from gsdf.recon.topology import mesh_topology
>>> V = np.eye(4)[:, :3]; F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> t = mesh_topology(V, F); t["closed"], t["components"], t["euler"], t["genus"]
(True, 1, 2, [0])
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

__all__ = ["mesh_topology", "is_sphere"]


def mesh_topology(V, F) -> dict:
    """Topological summary of the triangle mesh (V, F).

    Returns
    -------
    dict with ``closed`` (every edge in exactly two faces; also False if some edge has one), ``edge_manifold``
    (no edge in more than two faces), ``vertex_manifold`` (the faces around every used vertex form one fan),
    ``oriented`` (every interior edge used once in each direction), ``components`` (face-connected through
    edges), ``euler`` (V − E + F over used vertices), ``genus`` (list, per component, ``(2 − χ_c) / 2`` when the
    mesh is closed and manifold, else None), ``degenerate_faces`` (faces repeating a vertex), ``n_faces``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> t = gsdf.mesh_topology(V, F)
    >>> t["closed"], t["oriented"], t["genus"]
    (True, True, [0])
    """
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    nF = len(F)
    out = {"n_faces": nF, "closed": False, "edge_manifold": False, "vertex_manifold": False, "oriented": False,
           "components": 0, "euler": 0, "genus": [], "degenerate_faces": 0}
    if nF == 0:
        return out
    deg = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 0] == F[:, 2])
    out["degenerate_faces"] = int(deg.sum())
    H = np.stack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]], axis=1).reshape(-1, 2)   # directed halfedges
    key = np.sort(H, axis=1)
    E, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    out["edge_manifold"] = bool(cnt.max() <= 2) and not deg.any()
    out["closed"] = bool(cnt.min() == 2 and cnt.max() == 2)
    dirs = np.bincount(inv, (H[:, 0] < H[:, 1]).astype(float), minlength=len(E))
    out["oriented"] = bool(out["edge_manifold"] and np.all((cnt == 1) | (dirs == 1)))
    used = np.unique(F)
    out["euler"] = int(len(used) - len(E) + nF)
    # face components through shared edges
    hf = np.repeat(np.arange(nF), 3)
    A = sp.csr_matrix((np.ones(len(hf)), (hf, inv)), shape=(nF, len(E)))
    ncomp, comp = connected_components(A @ A.T, directed=False)
    out["components"] = int(ncomp)
    # vertex manifoldness: corners around a vertex joined through the faces' shared edges must form one fan
    if out["edge_manifold"]:
        corner_v = F.ravel()                                       # corner c = 3f + k at vertex F[f, k]
        order = np.argsort(inv, kind="stable")
        pairs = order.reshape(-1, 2) if out["closed"] else None
        if pairs is None:
            two = np.flatnonzero(cnt == 2)
            starts = np.searchsorted(inv[order], two)
            pairs = np.stack([order[starts], order[starts + 1]], axis=1)
        h1, h2 = pairs[:, 0], pairs[:, 1]
        f1, k1, f2, k2 = h1 // 3, h1 % 3, h2 // 3, h2 % 3
        # halfedge (f, k) runs from corner k to corner k+1 of face f; join corners of equal vertex
        rows, cols = [], []
        for a1, a2 in ((k1, k2), ((k1 + 1) % 3, (k2 + 1) % 3), (k1, (k2 + 1) % 3), ((k1 + 1) % 3, k2)):
            c1, c2 = 3 * f1 + a1, 3 * f2 + a2
            same = corner_v[c1] == corner_v[c2]
            rows.append(c1[same]); cols.append(c2[same])
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        G = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(3 * nF, 3 * nF))
        nfan, fan = connected_components(G, directed=False)
        out["vertex_manifold"] = bool(nfan == len(used))
    if out["closed"] and out["edge_manifold"] and out["vertex_manifold"]:
        nfc = np.bincount(comp, minlength=ncomp)
        e_comp = np.zeros(len(E), dtype=np.int64)
        e_comp[inv] = comp[hf]
        nec = np.bincount(e_comp, minlength=ncomp)
        v_comp = np.zeros(int(F.max()) + 1, dtype=np.int64)
        v_comp[F.ravel()] = np.repeat(comp, 3)
        nvc = np.bincount(v_comp[used], minlength=ncomp)
        g = [int((2 - chi) // 2) for chi in (nvc - nec + nfc)]
        out["genus"] = g
    else:
        out["genus"] = None
    return out


def is_sphere(V, F, components: int = 1) -> bool:
    """True when (V, F) is ``components`` closed, oriented, edge- and vertex-manifold spheres (genus 0 each)."""
    t = mesh_topology(V, F)
    return bool(t["closed"] and t["edge_manifold"] and t["vertex_manifold"] and t["oriented"]
                and t["components"] == components and t["genus"] == [0] * components)
