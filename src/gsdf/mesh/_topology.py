"""Topology of triangle meshes: welding coincident vertices, splitting non-manifold vertices, a report
saying whether a mesh is welded, edge-manifold, vertex-manifold and closed (:func:`manifold_report`), and a
summary with components, Euler characteristic and genus (:func:`mesh_topology`, :func:`is_sphere`).

Every function of gsdf that returns a surface as "closed" or "watertight" checks it with
:func:`manifold_report` and hands the report back (``report=True``), so the claim can be verified.

* *welded*: no two used vertices have the same coordinates;
* *edge-manifold*: every undirected edge has at most two faces, and two faces sharing an edge traverse it
  in opposite directions (consistent orientation);
* *vertex-manifold*: the faces around every vertex form a single fan (one umbrella, open or closed);
* *closed*: edge-manifold with every edge shared by exactly two faces.

Example
-------
>>> import numpy as np
>>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
>>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> r = manifold_report(V, F)
>>> r["closed"], r["edge_manifold"], r["vertex_manifold"], r["welded"]
(True, True, True, True)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from gsdf._checks import as_mesh

__all__ = ["weld", "manifold_report", "split_nonmanifold_vertices", "mesh_topology", "is_sphere"]


def weld(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices with bitwise-identical coordinates, drop faces that become degenerate (a repeated
    vertex) and unused vertices. Returns ``(V', F')``."""
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if len(V) == 0 or len(F) == 0:
        return V[:0].reshape(0, 3), F[:0].reshape(0, 3)
    U, inv = np.unique(V, axis=0, return_inverse=True)
    F = inv.reshape(-1)[F]
    ok = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])
    F = F[ok]
    used, Fc = np.unique(F, return_inverse=True)
    return np.ascontiguousarray(U[used]), np.ascontiguousarray(Fc.reshape(-1, 3), dtype=np.int64)


def _edges(F):
    """Directed half-edges (3m, 2) of F, their face, and undirected keys."""
    E = np.stack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]], axis=1).reshape(-1, 2)
    face = np.repeat(np.arange(len(F)), 3)
    return E, face


def _fan_components(F, pair_ok=None):
    """Connected components of face corners: the corners of two faces that share an edge (exactly two faces
    on it, or a pair chosen by ``pair_ok`` on an edge with more) are joined at both shared endpoints.
    Returns (corner labels (m, 3), number of labels). Vectorized (scipy connected components)."""
    m = len(F)
    flat = F.reshape(-1)
    E, _ = _edges(F)
    ca = np.arange(3 * m)  # half-edge h = (f, k) runs from corner (f, k) to corner (f, (k+1) % 3)
    cb = np.repeat(np.arange(m), 3) * 3 + (np.tile(np.arange(3), m) + 1) % 3
    nv = int(F.max()) + 1
    key = np.minimum(E[:, 0], E[:, 1]) * nv + np.maximum(E[:, 0], E[:, 1])
    order = np.argsort(key, kind="stable")
    ks = key[order]
    starts = np.flatnonzero(np.r_[True, ks[1:] != ks[:-1]])
    sizes = np.diff(np.r_[starts, len(ks)])
    two = starts[sizes == 2]
    h1, h2 = order[two], order[two + 1]
    if pair_ok is not None:
        extra = [pq for s, n in zip(starts[sizes > 2], sizes[sizes > 2]) for pq in pair_ok(order[s:s + n])]
        if extra:
            X = np.asarray(extra, dtype=np.int64).reshape(-1, 2)
            h1, h2 = np.r_[h1, X[:, 0]], np.r_[h2, X[:, 1]]
    same = flat[ca[h1]] == flat[ca[h2]]
    u = np.r_[ca[h1], cb[h1]]
    v = np.r_[np.where(same, ca[h2], cb[h2]), np.where(same, cb[h2], ca[h2])]
    G = sp.coo_matrix((np.ones(len(u)), (u, v)), shape=(3 * m, 3 * m))
    n, lab = connected_components(G, directed=False)
    return lab.reshape(m, 3), int(n)


def split_nonmanifold_vertices(V, F, pair_ok=None):
    """Give every fan of faces around a vertex its own copy of the vertex.

    Faces are connected across an edge when exactly two faces share it, or, for edges with more faces, in the
    pairs chosen by ``pair_ok(half_edge_ids) -> [(h1, h2), ...]`` (e.g. the two faces of the same voxel);
    unpaired faces at such an edge are cut apart there. Returns ``(V', F')`` where every vertex has a single
    fan; an edge left with more than two faces by ``pair_ok=None`` stays non-manifold.
    """
    F = np.asarray(F, dtype=np.int64)
    if len(F) == 0:
        return np.asarray(V), F
    lab, n = _fan_components(F, pair_ok)
    src = np.empty(n, np.int64)
    src[lab.reshape(-1)] = F.reshape(-1)
    return np.ascontiguousarray(np.asarray(V)[src]), np.ascontiguousarray(lab, dtype=np.int64)


def manifold_report(V, F) -> dict:
    """Topology of ``(V, F)``: a dict with booleans ``welded``, ``edge_manifold``, ``vertex_manifold``,
    ``oriented``, ``closed`` and counts ``boundary_edges``, ``nonmanifold_edges``, ``nonmanifold_vertices``,
    ``duplicate_vertices``, ``vertices``, ``faces``."""
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    rep = dict(vertices=int(len(V)), faces=int(len(F)))
    if len(F) == 0:
        rep.update(welded=True, edge_manifold=True, vertex_manifold=True, oriented=True, closed=False,
                   boundary_edges=0, nonmanifold_edges=0, nonmanifold_vertices=0, duplicate_vertices=0)
        return rep
    used = np.unique(F)
    dup = len(used) - len(np.unique(V[used], axis=0))
    E, _ = _edges(F)
    nv = int(F.max()) + 1
    und = np.minimum(E[:, 0], E[:, 1]) * nv + np.maximum(E[:, 0], E[:, 1])
    _, cnt = np.unique(und, return_counts=True)
    directed = E[:, 0] * nv + E[:, 1]
    _, dcnt = np.unique(directed, return_counts=True)
    nonman_e = int((cnt > 2).sum())
    boundary = int((cnt == 1).sum())
    oriented = bool((dcnt == 1).all())
    # vertex-manifold: fans around each vertex (joined across 2-face edges) = one per vertex
    lab, _ = _fan_components(F)
    fans = np.unique(np.column_stack([F.reshape(-1), lab.reshape(-1)]), axis=0)
    per_vertex = np.bincount(fans[:, 0], minlength=nv)
    nonman_v = int((per_vertex > 1).sum())
    rep.update(welded=dup == 0, edge_manifold=nonman_e == 0 and oriented, vertex_manifold=nonman_v == 0,
               oriented=oriented, closed=nonman_e == 0 and boundary == 0 and oriented,
               boundary_edges=boundary, nonmanifold_edges=nonman_e, nonmanifold_vertices=nonman_v,
               duplicate_vertices=int(dup))
    return rep


def mesh_topology(V, F) -> dict:
    """Topological summary of the triangle mesh (V, F).

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions (only their count matters).
    F : (m, 3) int
        Triangles as vertex indices.

    Returns
    -------
    dict
        ``closed`` (every edge in exactly two faces; also False if some edge has one), ``edge_manifold``
        (no edge in more than two faces), ``vertex_manifold`` (the faces around every used vertex form one fan),
        ``oriented`` (every interior edge used once in each direction), ``components`` (face-connected through
        edges), ``euler`` (V − E + F over used vertices), ``genus`` (list, per component, ``(2 − χ_c) / 2``
        when the mesh is closed and manifold, else None), ``degenerate_faces`` (faces repeating a vertex),
        ``n_faces``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> t = gsdf.mesh_topology(V, F)
    >>> t["closed"], t["oriented"], t["genus"]
    (True, True, [0])
    """
    V, F = as_mesh(V, F, allow_empty_faces=True)
    nF = len(F)
    out = {"n_faces": nF, "closed": False, "edge_manifold": False, "vertex_manifold": False, "oriented": False,
           "components": 0, "euler": 0, "genus": [], "degenerate_faces": 0}
    if nF == 0:
        return out
    deg = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 0] == F[:, 2])
    out["degenerate_faces"] = int(deg.sum())
    H, _ = _edges(F)                                            # directed half-edges
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
    if out["edge_manifold"]:
        # the faces around every used vertex form one fan: one corner component per used vertex
        _, nfan = _fan_components(F)
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
