"""Curves on triangle meshes: level sets of vertex functions (marching triangles), as source input for the
signed heat method (the evaluation of Feng & Crane 2024, §9.2, extracts its curves the same way)."""

from __future__ import annotations

import numpy as np

from gsdf import _checks


def level_set_curves(V, F, f, value: float = 0.0) -> list:
    """Oriented polylines of the level set ``f = value`` of a piecewise-linear vertex function.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles.
    f : (n,) float
        One finite value per vertex, linear over each triangle.
    value : float, default 0.0
        The level traced.

    Returns
    -------
    curves : list of lists of ``(face_index, barycentric (3,))``
        One polyline per connected piece (closed ones repeat their first point at the end), one node per
        crossed edge, so every segment lies in one face. Oriented so that ``{f < value}`` lies to the left
        (counter-clockwise w.r.t. the face normals): ``SurfaceSignedHeatSolver`` then returns values that are
        negative where ``f < value``. Empty when the level is not crossed.

    Raises
    ------
    ValueError
        Bad mesh arrays, or ``f`` not one finite value per vertex.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
    >>> (curve,) = gsdf.level_set_curves(V, F, np.array([-1.0, 1.0, 1.0]))
    >>> [(face, b.round(2).tolist()) for face, b in curve]
    [(0, [0.5, 0.5, 0.0]), (0, [0.5, 0.0, 0.5])]
    """
    V, F = _checks.as_mesh(V, F)
    g = _checks.as_values(f, "f", (len(V),))
    g = g - _checks.finite(value, "value")
    scale = max(float(np.abs(g).max()), 1e-300)
    g = np.where(g == 0, 1e-12 * scale, g)                    # no vertex exactly on the level set
    G = g[F]
    neg = G < 0
    cnt = neg.sum(1)
    faces = np.flatnonzero((cnt == 1) | (cnt == 2))
    if len(faces) == 0:
        return []
    # per crossing face: the two crossed slots a (edge v_a -> v_{a+1})
    Gf = G[faces]
    cross = (Gf < 0) != (np.roll(Gf, -1, axis=1) < 0)
    slots = np.argsort(~cross, axis=1, kind="stable")[:, :2]
    ta = Gf[np.arange(len(faces))[:, None], slots]
    tb = Gf[np.arange(len(faces))[:, None], (slots + 1) % 3]
    s = ta / (ta - tb)                                        # position along the slot
    B = np.zeros((len(faces), 2, 3))
    r = np.arange(len(faces))[:, None]
    B[r, [0, 1], slots] = 1 - s
    B[r, [0, 1], (slots + 1) % 3] = s
    P = np.einsum("kpi,kij->kpj", B, V[F[faces]])
    # orientation: left normal n × (q - p) must point towards decreasing f
    Pf = V[F[faces]]
    n = np.cross(Pf[:, 1] - Pf[:, 0], Pf[:, 2] - Pf[:, 0])
    # gradient of f in the face (times 2·area): sum_i g_i n × (v_{i+2} - v_{i+1})
    grad = sum(Gf[:, i, None] * np.cross(n, Pf[:, (i + 2) % 3] - Pf[:, (i + 1) % 3]) for i in range(3))
    left = np.cross(n, P[:, 1] - P[:, 0])
    flip = (left * grad).sum(1) > 0
    B[flip] = B[flip][:, ::-1]
    slots[flip] = slots[flip][:, ::-1]
    # chain segments through shared edges: key of the crossed edge
    Fe = F[faces]
    va = Fe[r, slots]
    vb = Fe[r, (slots + 1) % 3]
    key = np.minimum(va, vb) * len(V) + np.maximum(va, vb)    # (k, 2): entry edge, exit edge
    start_of = {int(k0): i for i, k0 in enumerate(key[:, 0])}
    nxt = np.array([start_of.get(int(k1), -1) for k1 in key[:, 1]])
    has_prev = np.zeros(len(faces), bool)
    has_prev[nxt[nxt >= 0]] = True
    used = np.zeros(len(faces), bool)
    curves = []
    order = list(np.flatnonzero(~has_prev)) + list(range(len(faces)))   # open chains first
    for s0 in order:
        if used[s0]:
            continue
        chain = []
        i = s0
        while i >= 0 and not used[i]:
            used[i] = True
            chain.append(i)
            i = nxt[i]
        pts = [(int(faces[c]), B[c, 0].copy()) for c in chain]
        last = chain[-1]
        pts.append((int(faces[last]), B[last, 1].copy()))
        curves.append(pts)
    return curves


def region_boundary_curves(F, face_mask) -> list:
    """Boundary loops of a set of faces as vertex-index polylines along edges.

    Each loop runs with the region on its left (the faces' own orientation), so the signed heat method makes
    the region negative. Boundary edges of the mesh that bound the region are included. Where the region
    touches itself at a vertex the loops are split there arbitrarily.

    Parameters
    ----------
    F : (m, 3) int
        Triangles (or quads) of the mesh.
    face_mask : (m,) bool
        The faces of the region.

    Returns
    -------
    list of (k,) int64 arrays
        Closed vertex polylines (the first vertex repeated at the end).

    Raises
    ------
    ValueError
        ``F`` not an array of vertex indices of at least 3 per face, ``face_mask`` not one bool per face.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> F = np.array([[0, 1, 2], [0, 2, 3]])
    >>> [c.tolist() for c in gsdf.region_boundary_curves(F, np.array([True, True]))]
    [[0, 1, 2, 3, 0]]
    """
    F = _checks.as_faces(F, _checks.MAX_INT, "F", corners=None, allow_empty=True)
    if F.shape[1] < 3:
        raise ValueError(f"F: expected faces of at least 3 corners (m, 3) or (m, 4), got shape {F.shape}")
    mask = _checks.as_mask(face_mask, len(F), "face_mask")
    Fr = F[mask]
    he = np.stack([Fr.ravel(), np.roll(Fr, -1, axis=1).ravel()], axis=1)   # halfedges i -> j
    n = int(F.max()) + 1 if len(F) else 0
    fwd = he[:, 0] * n + he[:, 1]
    bwd = he[:, 1] * n + he[:, 0]
    bnd = he[~np.isin(fwd, bwd)]                                # halfedges without an opposite in the region
    nxt = {}
    for a, b in bnd.tolist():
        nxt.setdefault(a, []).append(b)
    loops = []
    while nxt:
        start = next(iter(nxt))
        loop = [start]
        v = start
        while v in nxt:
            w = nxt[v].pop()
            if not nxt[v]:
                del nxt[v]
            loop.append(w)
            v = w
            if v == start:
                break
        loops.append(np.array(loop, dtype=np.int64))
    return loops
