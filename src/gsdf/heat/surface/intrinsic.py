"""Intrinsic Delaunay triangulations by edge flipping (Feng & Crane 2024, §9.4, Fig. 22; Sharp et al. 2019).

The vertices stay those of the input mesh; only the connectivity and the edge *lengths* change. An interior
edge ij with opposite corners k (in face ijk) and l (in face jil) is Delaunay when cot α_k + cot α_l ≥ 0
(its opposite angles sum to at most π). Lawson's algorithm flips non-Delaunay edges until none is left; the
new edge kl gets its length from a planar layout of the two triangles (no 3D positions are needed).

Edges that are never flipped: boundary and nonmanifold edges, edges whose two faces are inconsistently
oriented (nonorientable meshes), edges marked ``fixed`` (edges that carry source curves, so that the curves
remain polylines along edges), and flips that would create a second edge between the same two vertices (the
operators identify edges by their vertex pair); in these rare cases the result is "Delaunay up to skipped
flips".

Faces are laid out in 2D (``layout``): slot 0 along +x, the third vertex above it, z = 0, so the operators of
:class:`~gsdf.heat.surface.operators.TriangleMeshOperators` (which only need per-face corner positions) work
unchanged in these per-face frames.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .operators import NEXT


@njit(cache=True)
def _cot_opp(a, b, c):
    """cot of the angle opposite side c in a triangle with sides a, b, c."""
    s = 0.5 * (a + b + c)
    ar2 = s * (s - a) * (s - b) * (s - c)
    if ar2 <= 0.0:
        ar2 = 1e-300
    return (a * a + b * b - c * c) / (4.0 * np.sqrt(ar2))


@njit(cache=True)
def _flip_loop(Fv, FL, FE, EF, ES, fixed, pairs_keys, n, max_flips):
    """Lawson flips in place. Fv (m,3) vertices, FL (m,3) slot lengths, FE (m,3) slot edge ids,
    EF/ES (nE,2) the two (face, slot) of every edge (-1 if not flippable), ``pairs_keys``: typed dict whose keys
    are the existing vertex-pair keys. Returns the number of flips."""
    nE = EF.shape[0]
    stack = np.empty(nE + 4 * max_flips + 4, np.int64)
    inq = np.zeros(nE, np.bool_)
    top = 0
    for e in range(nE):
        if EF[e, 1] >= 0 and not fixed[e]:
            stack[top] = e
            top += 1
            inq[e] = True
    flips = 0
    while top > 0 and flips < max_flips:
        top -= 1
        e = stack[top]
        inq[e] = False
        if EF[e, 1] < 0 or fixed[e]:
            continue
        f0, a0 = EF[e, 0], ES[e, 0]
        f1, a1 = EF[e, 1], ES[e, 1]
        b0, c0 = (a0 + 1) % 3, (a0 + 2) % 3
        b1, c1 = (a1 + 1) % 3, (a1 + 2) % 3
        lij = FL[f0, a0]
        ljk, lki = FL[f0, b0], FL[f0, c0]
        lil, llj = FL[f1, b1], FL[f1, c1]
        cs = _cot_opp(ljk, lki, lij) + _cot_opp(lil, llj, lij)
        if cs >= -1e-12:
            continue
        i, j, k = Fv[f0, a0], Fv[f0, b0], Fv[f0, c0]
        l = Fv[f1, c1]
        if k == l:
            continue
        key = min(k, l) * n + max(k, l)
        if key in pairs_keys:
            continue
        # planar layout of the quad: i = (0, 0), j = (lij, 0), k above, l below
        xk = (lij * lij + lki * lki - ljk * ljk) / (2.0 * lij)
        yk = np.sqrt(max(lki * lki - xk * xk, 0.0))
        xl = (lij * lij + lil * lil - llj * llj) / (2.0 * lij)
        yl = -np.sqrt(max(lil * lil - xl * xl, 0.0))
        lkl = np.sqrt((xk - xl) ** 2 + (yk - yl) ** 2)
        # both new triangles (l, j, k) and (k, i, l) must be nondegenerate (always true for a non-Delaunay edge
        # up to round-off)
        if lkl >= llj + ljk or lkl >= lki + lil or lkl <= 0.0:
            continue
        e_jk, e_ki = FE[f0, b0], FE[f0, c0]
        e_il, e_lj = FE[f1, b1], FE[f1, c1]
        oldkey = min(i, j) * n + max(i, j)
        if oldkey in pairs_keys:
            pairs_keys.pop(oldkey)
        pairs_keys[key] = 1
        # new f0 = (l, j, k): slots (l,j) (j,k) (k,l); new f1 = (k, i, l): slots (k,i) (i,l) (l,k)
        Fv[f0, 0], Fv[f0, 1], Fv[f0, 2] = l, j, k
        FL[f0, 0], FL[f0, 1], FL[f0, 2] = llj, ljk, lkl
        FE[f0, 0], FE[f0, 1], FE[f0, 2] = e_lj, e_jk, e
        Fv[f1, 0], Fv[f1, 1], Fv[f1, 2] = k, i, l
        FL[f1, 0], FL[f1, 1], FL[f1, 2] = lki, lil, lkl
        FE[f1, 0], FE[f1, 1], FE[f1, 2] = e_ki, e_il, e
        EF[e, 0], ES[e, 0], EF[e, 1], ES[e, 1] = f0, 2, f1, 2
        # re-point the four outer edges: (old face, old slot) -> (new face, new slot)
        for q in range(4):
            if q == 0:
                ee, of, os_, nf, ns = e_lj, f1, c1, f0, 0
            elif q == 1:
                ee, of, os_, nf, ns = e_jk, f0, b0, f0, 1
            elif q == 2:
                ee, of, os_, nf, ns = e_ki, f0, c0, f1, 0
            else:
                ee, of, os_, nf, ns = e_il, f1, b1, f1, 1
            for r in range(2):
                if EF[ee, r] == of and ES[ee, r] == os_:
                    EF[ee, r] = nf
                    ES[ee, r] = ns
                    break
            if not inq[ee] and EF[ee, 1] >= 0 and not fixed[ee]:
                stack[top] = ee
                top += 1
                inq[ee] = True
        flips += 1
    return flips


def intrinsic_delaunay(V: np.ndarray, F: np.ndarray, fixed_pairs=None, max_flips: int | None = None):
    """Flip the triangle mesh (V, F) to an intrinsic Delaunay triangulation.

    Parameters
    ----------
    V, F : the input mesh (validated, no degenerate faces).
    fixed_pairs : (k, 2) int array of vertex pairs (edges of F) that must not be flipped.
    max_flips : safety bound (default 50·|F| + 1000).

    Returns
    -------
    F_int : (m, 3) int64 faces of the intrinsic triangulation (same vertices, same face count).
    lengths : (m, 3) intrinsic length of slot a = (v_a, v_{a+1}) of every face.
    flips : number of flips done.

    Example
    -------
    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0.5, 0.1, 0], [0.5, -0.1, 0]])
    >>> F = np.array([[0, 1, 2], [1, 0, 3]])                # the long edge 0-1 is not Delaunay
    >>> Fi, L, nf = intrinsic_delaunay(V, F)
    >>> nf, sorted(map(int, Fi[0]))
    (1, [1, 2, 3])
    """
    from numba import types
    from numba.typed import Dict

    n, m = len(V), len(F)
    Fv = np.array(F, dtype=np.int64, copy=True)
    FL = np.linalg.norm(V[F[:, NEXT]] - V[F], axis=2)
    a, b = Fv, Fv[:, NEXT]
    key = (np.minimum(a, b) * n + np.maximum(a, b)).ravel()
    uniq, inv = np.unique(key, return_inverse=True)
    nE = len(uniq)
    FE = inv.reshape(m, 3).astype(np.int64)
    cnt = np.bincount(inv, minlength=nE)
    order = np.argsort(inv, kind="stable")
    start = np.concatenate([[0], np.cumsum(cnt)])
    EF = np.full((nE, 2), -1, np.int64)
    ES = np.full((nE, 2), -1, np.int64)
    two = np.flatnonzero(cnt == 2)
    s0, s1 = order[start[two]], order[start[two] + 1]     # flat slot indices f*3 + a
    # flippable only with opposite traversal directions in the two faces (consistent orientation)
    opp = Fv.ravel()[s0] == b.ravel()[s1]
    two, s0, s1 = two[opp], s0[opp], s1[opp]
    EF[two, 0], ES[two, 0] = s0 // 3, s0 % 3
    EF[two, 1], ES[two, 1] = s1 // 3, s1 % 3
    fixed = np.zeros(nE, np.bool_)
    if fixed_pairs is not None and len(fixed_pairs):
        fp = np.asarray(fixed_pairs, np.int64).reshape(-1, 2)
        fk = np.minimum(fp[:, 0], fp[:, 1]) * n + np.maximum(fp[:, 0], fp[:, 1])
        pos = np.clip(np.searchsorted(uniq, fk), 0, nE - 1)
        ok = uniq[pos] == fk
        fixed[pos[ok]] = True
    keys = Dict.empty(key_type=types.int64, value_type=types.int64)
    _fill(keys, uniq)
    if max_flips is None:
        max_flips = 50 * m + 1000
    flips = _flip_loop(Fv, FL, FE, EF, ES, fixed, keys, n, int(max_flips))
    return Fv, FL, int(flips)


@njit(cache=True)
def _fill(d, keys):
    for k in keys:
        d[k] = 1


def layout(lengths: np.ndarray) -> np.ndarray:
    """Per-face planar corner positions (m, 3, 3) from slot lengths (m, 3): v0 at the origin, v1 on +x, v2 above
    (counter-clockwise, normal +z)."""
    l0, l1, l2 = lengths[:, 0], lengths[:, 1], lengths[:, 2]
    x = (l0 * l0 + l2 * l2 - l1 * l1) / (2.0 * l0)
    y = np.sqrt(np.maximum(l2 * l2 - x * x, 0.0))
    P = np.zeros((len(lengths), 3, 3))
    P[:, 1, 0] = l0
    P[:, 2, 0], P[:, 2, 1] = x, y
    return P
