"""The guarantee layer: grow a tet region that stays a topological ball, and output its boundary sphere.

Seed 003 promises a simply connected, manifold output but its rounding of a tet labelling cannot deliver it
(the boundary of a 3-chain can be a torus, several pieces, or pinched; notes 2(b).4).  Here the inside region
R is grown tet by tet from a seed, in decreasing order of the winding field, accepting a tet T only when it
is *simple* for R (notes 2(b).6): the faces S of T shared with R number 1–3 and ∂T ∩ R = ∪S, i.e.

* |S| = 1: the vertex opposite the shared face is not in R;
* |S| = 2: the edge opposite the shared edge is not in R;
* |S| = 3: always.

Then R ∪ T is R glued to a ball along a disc of both boundaries, again a PL 3-ball, so ∂R is always a
closed, edge- and vertex-manifold triangulated 2-sphere (one component, χ = 2).  Several regions (one per
cluster) are grown at once and never share a vertex, so their boundaries are disjoint spheres.

Example
-------
>>> import numpy as np
>>> from scipy.spatial import Delaunay
>>> from gsdf.dec._tet import TetComplex
>>> from gsdf.recon._grow import grow_regions, region_boundary
>>> P = np.random.default_rng(0).uniform(-1, 1, (400, 3))
>>> K = TetComplex(P, Delaunay(P).simplices)
>>> w = 1.0 - np.linalg.norm(P[K.T].mean(1), axis=1)      # high near the centre
>>> label, _ = grow_regions(K, w, threshold=0.3)
>>> F = region_boundary(K, label)
>>> len(F) - 3 * len(F) // 2 + len(np.unique(F))           # Euler characteristic of the boundary
2
"""

from __future__ import annotations

import numba as nb
import numpy as np

from gsdf.mesh._tet_ops import EDGE_PAIRS

__all__ = ["grow_regions", "carve_regions", "region_boundary"]

# local edge index of each pair of local tet vertices (gsdf.mesh._tet_ops.EDGE_PAIRS)
_PAIR_TO_EDGE = np.full((4, 4), -1, dtype=np.int64)
for _k, (_a, _b) in enumerate(EDGE_PAIRS.tolist()):
    _PAIR_TO_EDGE[_a, _b] = _PAIR_TO_EDGE[_b, _a] = _k


@nb.njit(cache=True)
def _heap_push(keys, vals, size, key, val):
    i = size
    keys[i] = key
    vals[i] = val
    while i > 0:
        p = (i - 1) // 2
        if keys[p] >= keys[i]:
            break
        keys[p], keys[i] = keys[i], keys[p]
        vals[p], vals[i] = vals[i], vals[p]
        i = p
    return size + 1


@nb.njit(cache=True)
def _heap_pop(keys, vals, size):
    val = vals[0]
    size -= 1
    keys[0] = keys[size]
    vals[0] = vals[size]
    i = 0
    while True:
        l = 2 * i + 1
        r = l + 1
        m = i
        if l < size and keys[l] > keys[m]:
            m = l
        if r < size and keys[r] > keys[m]:
            m = r
        if m == i:
            break
        keys[m], keys[i] = keys[i], keys[m]
        vals[m], vals[i] = vals[i], vals[m]
        i = m
    return val, size


@nb.njit(cache=True)
def _neighbour(tet_faces, tet_face_sign, face_tets, t, k):
    f = tet_faces[t, k]
    return face_tets[f, 1] if tet_face_sign[t, k] > 0 else face_tets[f, 0]


@nb.njit(cache=True)
def _accept(t, r, T, tet_edges, tet_faces, tet_face_sign, face_tets, prio, allowed, eligible,
            label, vcount, vowner, ecount, keys, vals, size):
    """Add tet ``t`` to region ``r``: count its vertices and edges, queue its unlabelled eligible neighbours;
    returns the new heap size."""
    label[t] = r
    for k in range(4):
        vcount[T[t, k]] += 1
        vowner[T[t, k]] = r
    for k in range(6):
        ecount[tet_edges[t, k]] += 1
    for k in range(4):
        t2 = _neighbour(tet_faces, tet_face_sign, face_tets, t, k)
        if t2 >= 0 and label[t2] < 0 and eligible[t2] and allowed[t2] == r:
            size = _heap_push(keys, vals, size, prio[t2], t2)
    return size


@nb.njit(cache=True)
def _faces_towards(tet_faces, tet_face_sign, face_tets, label, t, r, inside):
    """How many faces of tet ``t`` face region ``r`` (``inside``) or its complement (hull faces count as the
    complement), and the local indices of the first two of them (-1 if absent)."""
    n = 0
    k0 = -1
    k1 = -1
    for k in range(4):
        t2 = _neighbour(tet_faces, tet_face_sign, face_tets, t, k)
        if (t2 >= 0 and label[t2] == r) == inside:
            if n == 0:
                k0 = k
            elif n == 1:
                k1 = k
            n += 1
    return n, k0, k1


@nb.njit(cache=True)
def _counts(T, tet_edges, label, n_vertices, n_edges):
    """Per-vertex / per-edge tet counts of the labelled tets, and the region owning each vertex."""
    vcount = np.zeros(n_vertices, dtype=np.int64)
    vowner = -np.ones(n_vertices, dtype=np.int64)
    ecount = np.zeros(n_edges, dtype=np.int64)
    for t in range(T.shape[0]):
        if label[t] >= 0:
            for k in range(4):
                vcount[T[t, k]] += 1
                vowner[T[t, k]] = label[t]
            for k in range(6):
                ecount[tet_edges[t, k]] += 1
    return vcount, vowner, ecount


@nb.njit(cache=True)
def _grow(T, tet_edges, tet_faces, tet_face_sign, face_tets, pair_to_edge, eligible, prio, allowed, seeds, label,
          n_vertices, n_edges):
    m = T.shape[0]
    vcount, vowner, ecount = _counts(T, tet_edges, label, n_vertices, n_edges)
    cap = 4 * m + seeds.shape[0] + 1
    keys = np.empty(cap)
    vals = np.empty(cap, dtype=np.int64)
    size = np.int64(0)                  # not a literal 0: the heap kernels would compile once more for it
    rejected = 0
    # resume: queue the eligible unlabelled neighbours of the regions given
    for t in range(m):
        if label[t] >= 0:
            for k in range(4):
                t2 = _neighbour(tet_faces, tet_face_sign, face_tets, t, k)
                if t2 >= 0 and label[t2] < 0 and eligible[t2] and allowed[t2] == label[t]:
                    size = _heap_push(keys, vals, size, prio[t2], t2)
    for r in range(seeds.shape[0]):
        t = seeds[r]
        ok = label[t] < 0
        for k in range(4):
            if vowner[T[t, k]] >= 0:
                ok = False
        if not ok:
            continue
        size = _accept(t, r, T, tet_edges, tet_faces, tet_face_sign, face_tets, prio, allowed, eligible,
                       label, vcount, vowner, ecount, keys, vals, size)
    while size > 0:
        t, size = _heap_pop(keys, vals, size)
        if label[t] >= 0:
            continue
        r = allowed[t]
        # vertices of another region block T (regions must stay vertex-disjoint)
        ok = True
        for k in range(4):
            o = vowner[T[t, k]]
            if o >= 0 and o != r:
                ok = False
        if not ok:
            rejected += 1
            continue
        ns, s0, s1 = _faces_towards(tet_faces, tet_face_sign, face_tets, label, t, r, np.bool_(True))
        if ns == 0 or ns == 4:
            rejected += 1
            continue
        if ns == 1:
            # the shared face is opposite local vertex s0: that vertex must be new
            if vcount[T[t, s0]] > 0:
                rejected += 1
                continue
        elif ns == 2:
            # the two shared faces are opposite s0 and s1; the edge s0–s1 must be new
            if ecount[tet_edges[t, pair_to_edge[s0, s1]]] > 0:
                rejected += 1
                continue
        size = _accept(t, r, T, tet_edges, tet_faces, tet_face_sign, face_tets, prio, allowed, eligible,
                       label, vcount, vowner, ecount, keys, vals, size)
    return label, rejected


@nb.njit(cache=True)
def _carve(T, tet_edges, tet_faces, tet_face_sign, face_tets, pair_to_edge, removable, prio, label, keep_vertex,
           n_vertices, n_edges):
    """Remove removable boundary tets of the regions, largest ``prio`` first, while each removal is simple.

    In the 3-sphere (space closed by a point at infinity) the complement C of a PL ball R is a ball, so
    removing T from R is *adding* T to C, and that keeps C — hence R — a ball exactly when T is simple for
    C: the faces of T shared with C (hull faces count) number 1–3 and ∂T ∩ C is their union, i.e.

    * 1 face shared with C: the vertex opposite it is not in C (every tet around it is in R, not on the hull);
    * 2 faces: the edge opposite their common edge is not in C;
    * 3 faces: always.

    A vertex or edge is in C when one of its tets is outside R or it lies on the hull.  A removal that drops a
    vertex with ``keep_vertex`` from R is refused, and a region is never emptied.
    """
    m = T.shape[0]
    vcount, vowner, ecount = _counts(T, tet_edges, label, n_vertices, n_edges)
    vdeg, _, edeg = _counts(T, tet_edges, np.zeros(m, dtype=np.int64), n_vertices, n_edges)
    vhull = np.zeros(n_vertices, dtype=np.bool_)
    ehull = np.zeros(n_edges, dtype=np.bool_)
    for t in range(m):
        for k in range(4):
            if _neighbour(tet_faces, tet_face_sign, face_tets, t, k) < 0:
                # the hull face opposite local vertex k: its vertices and edges touch the outside
                for j in range(4):
                    if j != k:
                        vhull[T[t, j]] = True
                        for i in range(j + 1, 4):
                            if i != k:
                                ehull[tet_edges[t, pair_to_edge[j, i]]] = True
    cap = 8 * m + 1
    keys = np.empty(cap)
    vals = np.empty(cap, dtype=np.int64)
    size = np.int64(0)
    for t in range(m):
        if label[t] >= 0 and removable[t]:
            for k in range(4):
                t2 = _neighbour(tet_faces, tet_face_sign, face_tets, t, k)
                if t2 < 0 or label[t2] != label[t]:
                    size = _heap_push(keys, vals, size, prio[t], t)
                    break
    removed = 0
    while size > 0:
        t, size = _heap_pop(keys, vals, size)
        r = label[t]
        if r < 0:
            continue
        nc, c0, c1 = _faces_towards(tet_faces, tet_face_sign, face_tets, label, t, r, np.bool_(False))
        if nc == 0 or nc == 4:
            continue
        if nc == 1:
            v = T[t, c0]
            if vhull[v] or vcount[v] < vdeg[v]:
                continue
        elif nc == 2:
            e = tet_edges[t, pair_to_edge[c0, c1]]
            if ehull[e] or ecount[e] < edeg[e]:
                continue
        drop = False
        for k in range(4):
            if vcount[T[t, k]] == 1 and keep_vertex[T[t, k]]:
                drop = True
        if drop:
            continue
        label[t] = -1
        removed += 1
        for k in range(4):
            vcount[T[t, k]] -= 1
            if vcount[T[t, k]] == 0:
                vowner[T[t, k]] = -1
        for k in range(6):
            ecount[tet_edges[t, k]] -= 1
        # newly exposed removable tets of R (and neighbours whose test may have changed)
        for k in range(4):
            t2 = _neighbour(tet_faces, tet_face_sign, face_tets, t, k)
            if t2 >= 0 and label[t2] == r and removable[t2] and size < cap:
                size = _heap_push(keys, vals, size, prio[t2], t2)
    return label, removed


def grow_regions(K, w, threshold: float = 0.5, seeds=None, allowed=None, priority=None, label=None,
                 eligible=None) -> tuple[np.ndarray, int]:
    """Grow vertex-disjoint PL-ball regions of tets with ``w > threshold``, by decreasing ``priority``.

    Parameters
    ----------
    K : gsdf.dec._tet.TetComplex
    w : (m,) float — the winding field per tet (the priority; tets with ``w <= threshold`` never join).
    threshold : float
    seeds : (r,) int tet ids, one per region; default: the tet of maximum ``w``.  A seed is always accepted
        (a single tet is a ball), even below the threshold, so every region is non-empty.
    allowed : (m,) int — the region each tet may join (-1: none); default: every tet may join region 0.
    label : (m,) int or None — resume from these regions (each a PL ball, e.g. an earlier result); default none.
        Seeds of regions already present are skipped.
    eligible : (m,) bool or None — the tets that may join; default ``w > threshold``.
    priority : (m,) float — the order of growth (largest first); default ``w``.  Where w is flat (the jump
        Laplace field is ≈ 1 throughout the inside) ties should be broken geometrically, or the fronts grow
        fractally, meet, and leave one-tet-thick slits that no simple tet can fill.

    Returns
    -------
    label : (m,) int64 region per tet (-1 outside); rejected : int — pops refused by the simple-tet test.
    """
    w = np.ascontiguousarray(w, dtype=np.float64)
    if w.shape != (K.n_tets,) or not np.isfinite(w).all():
        raise ValueError(f"w: expected a finite array of shape ({K.n_tets},), got {w.shape}")
    if label is None:
        label = -np.ones(K.n_tets, dtype=np.int64)
        seeds = np.array([int(np.argmax(w))] if seeds is None else seeds, dtype=np.int64).ravel()
    else:
        label = np.array(label, dtype=np.int64)
        if label.shape != (K.n_tets,):
            raise ValueError(f"label: expected shape ({K.n_tets},), got {label.shape}")
        seeds = np.zeros(0, dtype=np.int64) if seeds is None else np.array(seeds, dtype=np.int64).ravel()
        seeds = seeds[np.isin(np.arange(len(seeds)), np.unique(label[label >= 0]), invert=True)]
    if eligible is None:
        eligible = w > threshold
    eligible = np.ascontiguousarray(eligible, dtype=np.bool_)
    if eligible.shape != (K.n_tets,):
        raise ValueError(f"eligible: expected shape ({K.n_tets},), got {eligible.shape}")
    if allowed is None:
        allowed = np.zeros(K.n_tets, dtype=np.int64)
    allowed = np.ascontiguousarray(allowed, dtype=np.int64)
    if allowed.shape != (K.n_tets,) or allowed.min(initial=-1) < -1:
        raise ValueError(f"allowed: expected region ids >= -1 of shape ({K.n_tets},), got {allowed.shape}")
    prio = w if priority is None else np.ascontiguousarray(priority, dtype=np.float64)
    if prio.shape != (K.n_tets,) or not np.isfinite(prio).all():
        raise ValueError(f"priority: expected a finite array of shape ({K.n_tets},), got {prio.shape}")
    return _grow(K.T, K.tet_edges, K.tet_faces, K.tet_face_sign, K.face_tets, _PAIR_TO_EDGE, eligible, prio, allowed,
                 seeds, label, K.n_vertices, K.n_edges)


def carve_regions(K, label, removable, priority, keep_vertex=None) -> tuple[np.ndarray, int]:
    """Remove ``removable`` tets from the boundary of grown regions by simple-tet removals only.

    The inverse of :func:`grow_regions`: a boundary tet T leaves its region R only when R \\ T is again a
    PL ball (T is simple for R \\ T), so every region stays a ball and its boundary one manifold sphere.
    Removals run by decreasing ``priority``; exposed removable tets join the queue, so a wrong bulge or a
    bridge is peeled layer by layer.

    Parameters
    ----------
    K : TetComplex; label : (m,) int — regions (-1 outside), each a PL ball; removable : (m,) bool;
    priority : (m,) float; keep_vertex : (n_vertices,) bool or None — vertices that must stay in their
    region (inlier samples: the surface must not cut them off); default none.

    Returns
    -------
    label : (m,) int64 (a new array); removed : int.

    Example
    -------
    >>> import numpy as np
    >>> from scipy.spatial import Delaunay
    >>> from gsdf.dec._tet import TetComplex
    >>> from gsdf.mesh._topology import is_sphere
    >>> P = np.random.default_rng(0).uniform(-1, 1, (400, 3)); K = TetComplex(P, Delaunay(P).simplices)
    >>> r = np.linalg.norm(P[K.T].mean(1), axis=1)
    >>> lab, _ = grow_regions(K, 1.0 - r, threshold=0.2)
    >>> lab2, n = carve_regions(K, lab, r > 0.5, r)                 # peel everything beyond radius 0.5
    >>> bool(n > 0), is_sphere(K.V, region_boundary(K, lab2))
    (True, True)
    """
    label = np.array(label, dtype=np.int64)
    if label.shape != (K.n_tets,):
        raise ValueError(f"label: expected shape ({K.n_tets},), got {label.shape}")
    removable = np.ascontiguousarray(removable, dtype=np.bool_)
    prio = np.ascontiguousarray(priority, dtype=np.float64)
    if removable.shape != (K.n_tets,) or prio.shape != (K.n_tets,) or not np.isfinite(prio).all():
        raise ValueError(f"removable, priority: expected shape ({K.n_tets},) (priority finite)")
    if keep_vertex is None:
        keep_vertex = np.zeros(K.n_vertices, dtype=np.bool_)
    keep_vertex = np.ascontiguousarray(keep_vertex, dtype=np.bool_)
    if keep_vertex.shape != (K.n_vertices,):
        raise ValueError(f"keep_vertex: expected shape ({K.n_vertices},), got {keep_vertex.shape}")
    # never empty a region: its last tet is not removable
    return _carve(K.T, K.tet_edges, K.tet_faces, K.tet_face_sign, K.face_tets, _PAIR_TO_EDGE, removable, prio,
                  label, keep_vertex, K.n_vertices, K.n_edges)


def region_boundary(K, label: np.ndarray) -> np.ndarray:
    """(k, 3) outward-oriented boundary faces (vertex ids of ``K.V``) of the tets with ``label >= 0``.

    A face is on the boundary when its two sides carry different labels (the hull counts as -1).
    """
    ft = K.face_tets
    l0 = np.where(ft[:, 0] >= 0, label[np.maximum(ft[:, 0], 0)], -1)
    l1 = np.where(ft[:, 1] >= 0, label[np.maximum(ft[:, 1], 0)], -1)
    out0 = (l0 >= 0) & (l0 != l1)   # face points out of its region tet: canonical orientation
    out1 = (l1 >= 0) & (l1 != l0)   # region tet on the positive side: reversed
    F = np.concatenate([K.faces[out0], K.faces[out1][:, ::-1]])
    return np.ascontiguousarray(F)
