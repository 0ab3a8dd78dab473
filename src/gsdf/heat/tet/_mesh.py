"""The tet meshes of the tetrahedral signed-heat domain (Feng & Crane 2024, §8.1 and App. B): graded Delaunay or
TetGen meshes of the box around the input, and the quality that decides which tets the operators use. The
operators (P1 stiffness, weak divergence, lumped masses) are :class:`gsdf.mesh._tet_ops.TetOperators`; the steps
run in :mod:`gsdf.heat._core` over :class:`gsdf.heat.tet._domain.TetDomain`, the front-end is
:func:`gsdf.heat.volume._solve.solve_tet`.

Mesh (``mesher="delaunay"``, default, no extra dependency). The vertex set is

* the *input points* Z: the mesh vertices (or cloud points) and, on input triangles or edges longer than
  h/2, Steiner points sampled on them (spacing ≤ h/2), so that the "zero" constraint of §8.1 can be imposed
  exactly at vertices of the tet mesh and holds along the whole input, not only at its corners;
* an adaptive background lattice, graded like an octree: body-centred cubic (BCC) points of spacing h within
  2h of Z, 2h up to 4h, 4h up to 8h, … (the distance to Z by a k-d tree), the coarsest of ``levels`` levels
  filling the box (the front-end uses 2: spacing ≤ 2h); lattice points closer than 0.35 h to Z are dropped.
  h is the grid spacing the resolution gives;
* the box corners;

tetrahedralized by Delaunay (scipy/Qhull). Delaunay of a dense surface sample creates flat tets whose four
vertices lie (almost) on the input, and Qhull leaves zero-volume tets on the box faces; tets of low quality
(:func:`tet_quality`, 1 for the regular tet) are left out of the operators (with the "zero" constraint such tets
only touch fixed vertices anyway). ``mesher="tetgen"`` uses the optional ``tetgen`` package (AGPL, not a
dependency: ``pip install tetgen``) for a conforming constrained Delaunay mesh of the input inside the box.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import Delaunay, cKDTree

from gsdf.mesh._tet_ops import EDGE_PAIRS, signed_volumes

BYTES_PER_TET_VERTEX = 3000  # ~6.5 tets per vertex, sparse P1 matrix and its Cholesky factor


# ----------------------------------------------------------------------------------------------- vertices
def surface_samples(V, F, spacing: float):
    """Steiner points on the edges and inside the triangles of (V, F) so that no gap exceeds ``spacing``.

    Returns ``(S, face)``: points (k, 3) and, for each, the index of a triangle it lies on (for components).
    Triangles and edges shorter than ``spacing`` contribute nothing; edges are sampled once (shared).
    """
    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    out, owner = [np.zeros((0, 3))], [np.zeros(0, np.int64)]
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    Ef = np.tile(np.arange(len(F)), 3)
    E = np.sort(E, axis=1)
    E, first = np.unique(E, axis=0, return_index=True)
    Ef = Ef[first]
    L = np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1)
    if not np.isfinite(spacing):
        return np.zeros((0, 3)), np.zeros(0, np.int64)
    k = np.ceil(L / spacing).astype(np.int64) - 1  # interior points per edge
    sel = np.flatnonzero(k > 0)
    if len(sel):
        reps = k[sel]
        idx = np.repeat(sel, reps)
        j = np.arange(reps.sum()) - np.repeat(np.cumsum(reps) - reps, reps) + 1
        t = j / (k[idx] + 1.0)
        out.append(V[E[idx, 0]] + t[:, None] * (V[E[idx, 1]] - V[E[idx, 0]]))
        owner.append(Ef[idx])
    T = V[F]
    Lmax = np.linalg.norm(T - T[:, [1, 2, 0]], axis=2).max(axis=1)
    n = np.ceil(Lmax / spacing).astype(np.int64)
    for nn in np.unique(n[n >= 3]):
        fs = np.flatnonzero(n == nn)
        ij = np.array([(i, j) for i in range(1, nn) for j in range(1, nn - i)], float)
        if len(ij) == 0:
            continue
        b = np.column_stack([ij, nn - ij.sum(axis=1)]) / nn  # interior barycentric points
        P = np.einsum("kc,fcd->fkd", b, T[fs]).reshape(-1, 3)
        out.append(P)
        owner.append(np.repeat(fs, len(b)))
    return np.concatenate(out), np.concatenate(owner)


def _axis(a, b, hk):
    """Nodes a, a + hk, … covering [a, b]; the last gap is stretched or shrunk to end exactly at b."""
    x = a + hk * np.arange(int(np.floor((b - a) / hk + 1e-9)) + 1)
    if b - x[-1] > 0.25 * hk or len(x) == 1:
        x = np.append(x, b)
    else:
        x[-1] = b
    return x


def graded_lattice(Z, lo, hi, h, levels: int = 8, exclude: float = 0.35, grading: float = 2.0, seed: int = 0):
    """Body-centred cubic (BCC) lattice points graded toward the points ``Z`` (octree-like).

    Level k has spacing 2^k h and covers the distances [2^k h, 2^{k+1} h) from Z (level 0: [0, 2h)); the last
    level fills the rest of the box. BCC points (cube corners and centres) have a non-degenerate Delaunay
    tetrahedralization of well-shaped tets. Points within ``exclude`` · h of Z are dropped (they would make
    slivers with the input points), and the box corners are added.
    """
    kd = cKDTree(Z)
    rng = np.random.default_rng(seed)
    pts = []
    ext = hi - lo
    for k in range(levels):
        hk = h * 2 ** k
        axes = [_axis(lo[a], hi[a], hk) for a in range(3)]
        mids = [0.5 * (x[1:] + x[:-1]) for x in axes]
        G = np.concatenate([np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3),
                            np.stack(np.meshgrid(*mids, indexing="ij"), -1).reshape(-1, 3)])
        d = kd.query(G, workers=-1)[0]
        last = k == levels - 1 or hk * 2 >= ext.max()
        keep = d >= (grading * hk / 2 if k > 0 else exclude * h)
        if not last:
            keep &= d < grading * hk
        G = G[keep] + rng.uniform(-1e-6, 1e-6, size=(int(keep.sum()), 3)) * hk  # break exact cospherical ties
        pts.append(np.clip(G, lo, hi))
        if last:
            break
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    pts.append(corners)
    P = np.concatenate(pts)
    far = kd.query(P, workers=-1)[0] > 1e-9 * float(ext.max())  # corners may coincide with input points
    return P[far]


def input_points(kind: str, X, F, h: float, surface_spacing: float = 0.5):
    """The constrained vertex set Z (deduplicated) and its component labels.

    Mesh: the vertices referenced by faces plus Steiner points on long edges / large triangles; components
    are the connected components of the face graph. Cloud: the points; components of the graph joining
    each point to its 8 nearest neighbours closer than 3 × the median nearest-neighbour distance.
    """
    from scipy.sparse.csgraph import connected_components

    if kind == "mesh":
        used = np.unique(F)
        remap = np.full(len(X), -1)
        remap[used] = np.arange(len(used))
        V, Fu = X[used], remap[F]
        S, owner = surface_samples(V, Fu, surface_spacing * h)
        E = np.concatenate([Fu[:, [0, 1]], Fu[:, [1, 2]]])
        G = sp.coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(len(V), len(V)))
        ncomp, lab = connected_components(G, directed=False)
        Z = np.concatenate([V, S])
        comp = np.concatenate([lab, lab[Fu[owner, 0]]])
    else:
        from gsdf.heat.volume._sources import cloud_components

        Z = np.asarray(X, float)
        comp = cloud_components(Z)
        ncomp = int(comp.max()) + 1
    # merge coincident points (duplicated vertices of soups, repeated cloud points)
    key = np.round(Z / max(1e-12 * float(np.abs(Z).max()), 1e-300))
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inv = inv.ravel()
    # coincident points of different components join them
    if len(first) < len(Z):
        G = sp.coo_matrix((np.ones(len(Z)), (comp, comp[first[inv]])), shape=(ncomp, ncomp))
        _, cc = connected_components(G, directed=False)
        comp = cc[comp]
    Zu = Z[first]
    cu = comp[first]
    _, cu = np.unique(cu, return_inverse=True)
    return Zu, cu.ravel()


# ----------------------------------------------------------------------------------------------- quality
def tet_quality(P, T) -> np.ndarray:
    """Quality ``6√2 |T| / l_rms³`` of every tet (1 for the regular tet, 0 for flat ones), shape (m,); tets whose
    volume is below 1e-14 l_rms³ get 0."""
    vol = np.abs(signed_volumes(P, T)) / 6.0
    e = P[T[:, EDGE_PAIRS[:, 1]]] - P[T[:, EDGE_PAIRS[:, 0]]]              # (m, 6, 3)
    lrms = np.maximum(np.sqrt((e ** 2).sum(axis=2).mean(axis=1)), 1e-300)
    q = 6.0 * np.sqrt(2.0) * vol / lrms ** 3
    return np.where(vol > 1e-14 * lrms ** 3, q, 0.0)


# ----------------------------------------------------------------------------------------------- meshing
def delaunay_mesh(Z, lo, hi, h, levels: int = 8, grading: float = 2.0):
    """Vertices (Z first), tets and the scipy Delaunay locator of Z + the graded lattice."""
    L = graded_lattice(Z, lo, hi, h, levels=levels, grading=grading)
    P = np.concatenate([Z, L])
    D = Delaunay(P)  # points Qhull leaves out (numerically coincident) stay unused vertices, see solve_tet
    return P, D.simplices.astype(np.int64), D


def tetgen_mesh(Z, F_in, lo, hi, h, quality: float = 1.5):
    """Conforming constrained Delaunay mesh by TetGen (optional ``tetgen`` package, AGPL)."""
    try:
        import tetgen  # noqa: F401
    except ImportError as exc:
        raise ImportError('mesher="tetgen" needs the optional package tetgen (AGPL): pip install tetgen; '
                          'the default mesher="delaunay" has no extra dependency') from exc
    import tetgen

    # the box surface, triangulated at the coarse spacing, plus the lattice-free input
    n = np.maximum(np.ceil((hi - lo) / (4 * h)).astype(int), 1)
    pts, tris = [], []
    base = 0
    for a in range(3):
        b, c = [x for x in range(3) if x != a]
        for side in (lo[a], hi[a]):
            u = np.linspace(lo[b], hi[b], n[b] + 1)
            v = np.linspace(lo[c], hi[c], n[c] + 1)
            U, W = np.meshgrid(u, v, indexing="ij")
            Q = np.zeros((U.size, 3))
            Q[:, a], Q[:, b], Q[:, c] = side, U.ravel(), W.ravel()
            idx = np.arange(U.size).reshape(U.shape) + base
            q0, q1, q2, q3 = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
            tris += [np.column_stack([q0, q1, q2]), np.column_stack([q0, q2, q3])]
            pts.append(Q)
            base += U.size
    B = np.concatenate(pts)
    _, inv = np.unique(np.round((B - lo) / (1e-9 * h)), axis=0, return_inverse=True)
    _, first = np.unique(inv.ravel(), return_index=True)
    B = B[first]
    TB = inv.ravel()[np.concatenate(tris)] + len(Z)
    P = np.concatenate([Z, B])
    Fall = np.concatenate([np.asarray(F_in, np.int64), TB]) if F_in is not None else TB
    tg = tetgen.TetGen(P, Fall)
    vmax = float(h ** 3 / (6 * np.sqrt(2)))  # the regular tet of edge h
    try:
        res = tg.tetrahedralize(order=1, minratio=quality, maxvolume=vmax, fixedvolume=True, nobisect=True,
                                quiet=True)
    except Exception as exc:  # noqa: BLE001 - TetGen reports self-intersections etc. as RuntimeError
        raise ValueError(f"tetgen failed on this input ({exc}); self-intersecting or overlapping input "
                         'triangles cannot be preserved — use mesher="delaunay"') from exc
    nodes, elem = np.asarray(res[0], float), res[1]
    if len(nodes) < len(Z) or np.abs(nodes[: len(Z)] - Z).max() > 1e-9 * h:
        raise ValueError("tetgen did not preserve the input points (self-intersecting input?); "
                         'use mesher="delaunay"')
    return nodes, np.asarray(elem, np.int64)[:, :4], None
