"""Intrinsic Delaunay triangulations by edge flipping (Feng & Crane 2024, §9.4, Fig. 22; Sharp et al. 2019).

Source points inside faces are carried through the flips (:func:`locate_points`: the logged flips are redone
and every point, with a tangent vector, is re-expressed in the planar layout of each flipped quad), and
straight source segments are re-split along the intrinsic edges by tracing (:func:`trace_paths`: unfold face
by face along the segment), so curves need not run along edges.

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
:class:`~gsdf.mesh._triangle_ops.TriangleOperators` (which only need per-face corner positions) work
unchanged in these per-face frames.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gsdf.mesh._connectivity import unique_edges
from gsdf.mesh._triangle_ops import NEXT


@njit(cache=True)
def _cot_opp(a, b, c):
    """cot of the angle opposite side c in a triangle with sides a, b, c."""
    s = 0.5 * (a + b + c)
    ar2 = s * (s - a) * (s - b) * (s - c)
    if ar2 <= 0.0:
        ar2 = 1e-300
    return (a * a + b * b - c * c) / (4.0 * np.sqrt(ar2))


@njit(cache=True)
def _quad(FL, f0, a0, f1, a1):
    """Planar layout of the quad of edge ij (slot a0 of f0 = (i, j, k), slot a1 of f1 = (j, i, l)): i = (0, 0),
    j = (lij, 0), k above, l below. Returns lij, xk, yk, xl, yl."""
    b0, c0 = (a0 + 1) % 3, (a0 + 2) % 3
    b1, c1 = (a1 + 1) % 3, (a1 + 2) % 3
    lij = FL[f0, a0]
    ljk, lki = FL[f0, b0], FL[f0, c0]
    lil, llj = FL[f1, b1], FL[f1, c1]
    xk = (lij * lij + lki * lki - ljk * ljk) / (2.0 * lij)
    yk = np.sqrt(max(lki * lki - xk * xk, 0.0))
    xl = (lij * lij + lil * lil - llj * llj) / (2.0 * lij)
    yl = -np.sqrt(max(lil * lil - xl * xl, 0.0))
    return lij, xk, yk, xl, yl


@njit(cache=True)
def _do_flip(e, Fv, FL, FE, EF, ES, lkl):
    """Replace the faces (i, j, k), (j, i, l) of edge e by (l, j, k), (k, i, l) (new edge kl of length lkl,
    slot 2 of both) and re-point the four outer edges. Returns the four outer edge ids."""
    f0, a0 = EF[e, 0], ES[e, 0]
    f1, a1 = EF[e, 1], ES[e, 1]
    b0, c0 = (a0 + 1) % 3, (a0 + 2) % 3
    b1, c1 = (a1 + 1) % 3, (a1 + 2) % 3
    ljk, lki = FL[f0, b0], FL[f0, c0]
    lil, llj = FL[f1, b1], FL[f1, c1]
    i, j, k = Fv[f0, a0], Fv[f0, b0], Fv[f0, c0]
    l = Fv[f1, c1]
    e_jk, e_ki = FE[f0, b0], FE[f0, c0]
    e_il, e_lj = FE[f1, b1], FE[f1, c1]
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
    return e_lj, e_jk, e_ki, e_il


@njit(cache=True)
def _flip_loop(Fv, FL, FE, EF, ES, fixed, pairs_keys, n, max_flips, log):
    """Lawson flips in place. Fv (m,3) vertices, FL (m,3) slot lengths, FE (m,3) slot edge ids,
    EF/ES (nE,2) the two (face, slot) of every edge (-1 if not flippable), ``pairs_keys``: typed dict whose keys
    are the existing vertex-pair keys. The flipped edge ids go to ``log`` (replayed by :func:`_replay` to move
    points along). Returns the number of flips."""
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
        lij, xk, yk, xl, yl = _quad(FL, f0, a0, f1, a1)
        lkl = np.sqrt((xk - xl) ** 2 + (yk - yl) ** 2)
        # both new triangles (l, j, k) and (k, i, l) must be nondegenerate (always true for a non-Delaunay edge
        # up to round-off)
        if lkl >= llj + ljk or lkl >= lki + lil or lkl <= 0.0:
            continue
        oldkey = min(i, j) * n + max(i, j)
        if oldkey in pairs_keys:
            pairs_keys.pop(oldkey)
        pairs_keys[key] = 1
        outer = _do_flip(e, Fv, FL, FE, EF, ES, lkl)
        log[flips] = e
        for ee in outer:
            if not inq[ee] and EF[ee, 1] >= 0 and not fixed[ee]:
                stack[top] = ee
                top += 1
                inq[ee] = True
        flips += 1
    return flips


@njit(cache=True)
def _face_layout(FL, f):
    """Corner positions (3, 2) of face f laid out from its slot lengths (v0 at 0, v1 on +x, v2 above)."""
    l0, l1, l2 = FL[f, 0], FL[f, 1], FL[f, 2]
    x = (l0 * l0 + l2 * l2 - l1 * l1) / (2.0 * l0)
    P = np.zeros((3, 2))
    P[1, 0] = l0
    P[2, 0] = x
    P[2, 1] = np.sqrt(max(l2 * l2 - x * x, 0.0))
    return P


@njit(cache=True)
def _bary2(P, q):
    """Barycentric coordinates of the 2D point q in the triangle P (3, 2)."""
    d = (P[1, 0] - P[0, 0]) * (P[2, 1] - P[0, 1]) - (P[2, 0] - P[0, 0]) * (P[1, 1] - P[0, 1])
    b = np.empty(3)
    b[1] = ((q[0] - P[0, 0]) * (P[2, 1] - P[0, 1]) - (P[2, 0] - P[0, 0]) * (q[1] - P[0, 1])) / d
    b[2] = ((P[1, 0] - P[0, 0]) * (q[1] - P[0, 1]) - (q[0] - P[0, 0]) * (P[1, 1] - P[0, 1])) / d
    b[0] = 1.0 - b[1] - b[2]
    return b


@njit(cache=True)
def _rot(P0, P1, Q0, Q1):
    """Unit complex rotation (cos, sin) taking the direction P0->P1 to Q0->Q1."""
    a = complex(P1[0] - P0[0], P1[1] - P0[1])
    b = complex(Q1[0] - Q0[0], Q1[1] - Q0[1])
    r = b / a
    r = r / abs(r)
    return r.real, r.imag


@njit(cache=True)
def _replay(Fv, FL, FE, EF, ES, log, pf, pb, pv):
    """Redo the logged flips on the initial triangulation (arrays modified in place) and carry points along:
    point p lies in face pf[p] with barycentric pb[p] (slot order) and a tangent vector pv[p] (2D, in the
    face's layout of :func:`_face_layout`). Every flip re-expresses the points of its two faces in the planar
    layout of the quad and locates them in one of the two new faces (exact up to round-off)."""
    m = Fv.shape[0]
    npt = pf.shape[0]
    head = -np.ones(m, np.int64)
    nxt = -np.ones(npt, np.int64)
    for p in range(npt):
        nxt[p] = head[pf[p]]
        head[pf[p]] = p
    buf = np.empty(npt, np.int64)
    Q = np.zeros((4, 2))                                   # quad positions of i, j, k, l
    for t in range(log.shape[0]):
        e = log[t]
        f0, a0 = EF[e, 0], ES[e, 0]
        f1, a1 = EF[e, 1], ES[e, 1]
        cnt = 0
        for f in (f0, f1):
            p = head[f]
            while p >= 0:
                buf[cnt] = p
                cnt += 1
                p = nxt[p]
            head[f] = -1
        lij, xk, yk, xl, yl = _quad(FL, f0, a0, f1, a1)
        Q[0, 0], Q[0, 1] = 0.0, 0.0
        Q[1, 0], Q[1, 1] = lij, 0.0
        Q[2, 0], Q[2, 1] = xk, yk
        Q[3, 0], Q[3, 1] = xl, yl
        # old corners -> quad positions: f0 (a0, b0, c0) = (i, j, k); f1 (a1, b1, c1) = (j, i, l)
        C0 = np.zeros((3, 2))
        C1 = np.zeros((3, 2))
        C0[a0], C0[(a0 + 1) % 3], C0[(a0 + 2) % 3] = Q[0], Q[1], Q[2]
        C1[a1], C1[(a1 + 1) % 3], C1[(a1 + 2) % 3] = Q[1], Q[0], Q[3]
        P0, P1 = _face_layout(FL, f0), _face_layout(FL, f1)
        r0 = _rot(P0[a0], P0[(a0 + 1) % 3], Q[0], Q[1])
        r1 = _rot(P1[a1], P1[(a1 + 1) % 3], Q[1], Q[0])
        pos = np.zeros((cnt, 2))
        vec = np.zeros((cnt, 2))
        for u in range(cnt):
            p = buf[u]
            C = C0 if pf[p] == f0 else C1
            r = r0 if pf[p] == f0 else r1
            for c in range(3):
                pos[u, 0] += pb[p, c] * C[c, 0]
                pos[u, 1] += pb[p, c] * C[c, 1]
            vec[u, 0] = r[0] * pv[p, 0] - r[1] * pv[p, 1]
            vec[u, 1] = r[1] * pv[p, 0] + r[0] * pv[p, 1]
        lkl = np.sqrt((xk - xl) ** 2 + (yk - yl) ** 2)
        _do_flip(e, Fv, FL, FE, EF, ES, lkl)
        # new f0 = (l, j, k), new f1 = (k, i, l)
        N0 = np.zeros((3, 2))
        N1 = np.zeros((3, 2))
        N0[0], N0[1], N0[2] = Q[3], Q[1], Q[2]
        N1[0], N1[1], N1[2] = Q[2], Q[0], Q[3]
        L0, L1 = _face_layout(FL, f0), _face_layout(FL, f1)
        s0 = _rot(N0[0], N0[1], L0[0], L0[1])
        s1 = _rot(N1[0], N1[1], L1[0], L1[1])
        for u in range(cnt):
            p = buf[u]
            b0 = _bary2(N0, pos[u])
            b1 = _bary2(N1, pos[u])
            if b0.min() >= b1.min():
                f, b, s = f0, b0, s0
            else:
                f, b, s = f1, b1, s1
            tot = 0.0
            for c in range(3):
                if b[c] < 0.0:
                    b[c] = 0.0
                tot += b[c]
            for c in range(3):
                pb[p, c] = b[c] / tot
            pf[p] = f
            v0, v1 = vec[u, 0], vec[u, 1]
            pv[p, 0] = s[0] * v0 - s[1] * v1
            pv[p, 1] = s[1] * v0 + s[0] * v1
            nxt[p] = head[f]
            head[f] = p


@njit(cache=True)
def _trace(Fv, Lay, nbr_f, nbr_s, f, b, d, tol, max_steps, out_f, out_b):
    """Walk the straight path from barycentric point b of face f along the 2D vector d (in f's layout) across
    the triangulation. Crossing points go to out_f/out_b (face before the crossing, barycentric with a zero);
    the end point is appended last. ``nbr_f/nbr_s`` (m, 3): face and slot across every slot (-1: none).
    Returns the number of points written (the path stops early at a boundary)."""
    cnt = 0
    entry = -1
    for _ in range(max_steps):
        P = Lay[f]
        q = np.empty(2)
        q[0] = b[0] * P[0, 0] + b[1] * P[1, 0] + b[2] * P[2, 0] + d[0]
        q[1] = b[0] * P[0, 1] + b[1] * P[1, 1] + b[2] * P[2, 1] + d[1]
        bq = _bary2(P, q)
        if bq.min() >= -tol:
            out_f[cnt] = f
            out_b[cnt] = bq
            return cnt + 1
        # exit through the edge whose opposite barycentric coordinate reaches 0 first
        best, cb = 2.0, -1
        for c in range(3):
            if c == (entry + 2) % 3 and entry >= 0:
                continue
            db = bq[c] - b[c]
            if db < 0.0:
                tau = -b[c] / db
                if tau < best:
                    best, cb = tau, c
        if cb < 0:                                           # round-off: stay in this face
            out_f[cnt] = f
            out_b[cnt] = bq
            return cnt + 1
        tau = min(max(best, 0.0), 1.0)
        x = b + tau * (bq - b)
        x[cb] = 0.0
        for c in range(3):
            if x[c] < 0.0:
                x[c] = 0.0
        x = x / x.sum()
        out_f[cnt] = f
        out_b[cnt] = x
        cnt += 1
        a = (cb + 1) % 3                                     # exit slot: v_a -> v_{a+1}
        g, sg = nbr_f[f, a], nbr_s[f, a]
        if g < 0:
            return cnt
        # remaining displacement in f's edge frame, then in g's
        rem = (1.0 - tau)
        ex = P[(a + 1) % 3] - P[a]
        ln = np.sqrt(ex[0] ** 2 + ex[1] ** 2)
        ex = ex / ln
        al = rem * (d[0] * ex[0] + d[1] * ex[1])              # along v_a -> v_{a+1}
        be = rem * (-d[0] * ex[1] + d[1] * ex[0])             # along the in-face perpendicular (into f)
        Pg = Lay[g]
        eg = Pg[(sg + 1) % 3] - Pg[sg]
        eg = eg / np.sqrt(eg[0] ** 2 + eg[1] ** 2)
        same = Fv[g, sg] == Fv[f, a]                         # g runs the edge in f's direction (orientation flip)
        sgn = 1.0 if same else -1.0
        # d' = al (sgn e_g) - be perp(e_g)   (perp = 90° counter-clockwise, into g)
        d = np.empty(2)
        d[0] = sgn * al * eg[0] + be * eg[1]
        d[1] = sgn * al * eg[1] - be * eg[0]
        nb = np.zeros(3)
        if same:
            nb[sg], nb[(sg + 1) % 3] = x[a], x[(a + 1) % 3]
        else:
            nb[sg], nb[(sg + 1) % 3] = x[(a + 1) % 3], x[a]
        f, b, entry = g, nb, sg
    return cnt


def _initial_state(V, F):
    """Arrays of the flip algorithm for the input mesh: Fv, FL, FE, EF, ES, the sorted edge keys."""
    n = len(V)
    Fv = np.array(F, dtype=np.int64, copy=True)
    FL = np.linalg.norm(V[F[:, NEXT]] - V[F], axis=2)
    b = Fv[:, NEXT]
    edges, FE, _ = unique_edges(Fv, n)
    uniq = edges[:, 0] * n + edges[:, 1]                   # sorted edge keys lo * n + hi
    inv = FE.ravel()
    nE = len(uniq)
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
    return Fv, FL, FE, EF, ES, uniq


def intrinsic_delaunay(V: np.ndarray, F: np.ndarray, fixed_pairs=None, max_flips: int | None = None,
                       return_log: bool = False):
    """Flip the triangle mesh (V, F) to an intrinsic Delaunay triangulation.

    Parameters
    ----------
    V, F : the input mesh (validated, no degenerate faces).
    fixed_pairs : (k, 2) int array of vertex pairs (edges of F) that must not be flipped.
    max_flips : safety bound (default 50·|F| + 1000).
    return_log : also return the flipped edge ids in order (for :func:`locate_points`).

    Returns
    -------
    F_int : (m, 3) int64 faces of the intrinsic triangulation (same vertices, same face count).
    lengths : (m, 3) intrinsic length of slot a = (v_a, v_{a+1}) of every face.
    flips : number of flips done.
    log : (flips,) int64, only with ``return_log``.

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
    Fv, FL, FE, EF, ES, uniq = _initial_state(V, F)
    nE = len(uniq)
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
    log = np.empty(int(max_flips), np.int64)
    flips = int(_flip_loop(Fv, FL, FE, EF, ES, fixed, keys, n, int(max_flips), log))
    if return_log:
        return Fv, FL, flips, log[:flips].copy()
    return Fv, FL, flips


def face_coords(V, F, faces, D):
    """2D coordinates (k, 2) of 3D tangent vectors D (k, 3) of the input faces ``faces`` in their layouts (slot 0
    along +x, the face normal as +z): the frame in which :func:`locate_points` takes tangent vectors."""
    P = V[F[faces]]
    x = P[:, 1] - P[:, 0]
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    n = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    y = np.cross(n / np.linalg.norm(n, axis=1, keepdims=True), x)
    return np.stack([np.einsum("kj,kj->k", D, x), np.einsum("kj,kj->k", D, y)], 1)


def locate_points(V, F, log, faces, bary, vecs=None):
    """Where input surface points are in the intrinsic triangulation reached by the flips ``log``
    (:func:`intrinsic_delaunay` with ``return_log``): the flips are redone on the input and every point (and its
    tangent vector, 2D in the layout of its face, see :func:`face_coords`) is carried along in the planar layout
    of each flipped quad (Sharp et al. 2019's point tracking through flips). Returns faces (k,), barycentric
    (k, 3) in the slot order of the intrinsic faces, and vectors (k, 2) in the intrinsic faces' layouts.

    Example
    -------
    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0.5, 0.1, 0], [0.5, -0.1, 0]])
    >>> F = np.array([[0, 1, 2], [1, 0, 3]])
    >>> Fi, L, nf, log = intrinsic_delaunay(V, F, return_log=True)
    >>> f, b, _ = locate_points(V, F, log, np.array([0]), np.array([[0.25, 0.25, 0.5]]))   # (0.5, 0.05)
    >>> bool(np.allclose(b[0] @ V[Fi[f[0]]], [0.5, 0.05, 0]))
    True
    """
    faces = np.array(faces, np.int64).ravel()
    bary = np.array(bary, np.float64).reshape(-1, 3)
    vecs = np.zeros((len(faces), 2)) if vecs is None else np.array(vecs, np.float64).reshape(-1, 2)
    Fv, FL, FE, EF, ES, _ = _initial_state(V, F)
    if len(faces) and len(log):
        _replay(Fv, FL, FE, EF, ES, np.asarray(log, np.int64), faces, bary, vecs)
    return faces, bary, vecs


def face_neighbours(Fi):
    """Across every slot (m, 3) of a triangulation: the face and slot on the other side (-1 at boundary and
    nonmanifold edges)."""
    m = len(Fi)
    n = int(Fi.max()) + 1
    a, b = Fi, Fi[:, NEXT]
    key = (np.minimum(a, b) * n + np.maximum(a, b)).ravel()
    order = np.argsort(key, kind="stable")
    ks = key[order]
    nf = -np.ones(3 * m, np.int64)
    ns = -np.ones(3 * m, np.int64)
    same = ks[1:] == ks[:-1]
    ok = same.copy()                                       # only edges with exactly two slots
    ok[1:] &= ~same[:-1]
    ok[:-1] &= ~same[1:]
    pair = np.flatnonzero(ok)
    s0, s1 = order[pair], order[pair + 1]
    nf[s0], ns[s0] = s1 // 3, s1 % 3
    nf[s1], ns[s1] = s0 // 3, s0 % 3
    return nf.reshape(m, 3), ns.reshape(m, 3)


def trace_paths(Fi, L, faces, bary, vecs, tol: float = 1e-9, max_steps: int | None = None):
    """Trace straight paths on the triangulation (Fi, lengths L): from barycentric point ``bary[p]`` of face
    ``faces[p]`` along the 2D vector ``vecs[p]`` (face layout), unfolding face by face. Returns, per path, the
    list of points ``(face, barycentric)``: every edge crossing (in the face before it) and the end point."""
    Lay = np.ascontiguousarray(layout(L)[:, :, :2])
    nbf, nbs = face_neighbours(Fi)
    if max_steps is None:
        max_steps = 4 * int(np.sqrt(len(Fi))) + 64
    out = []
    of = np.empty(max_steps + 1, np.int64)
    ob = np.empty((max_steps + 1, 3))
    for f, b, d in zip(np.asarray(faces, np.int64), np.asarray(bary, np.float64), np.asarray(vecs, np.float64)):
        k = _trace(Fi, Lay, nbf, nbs, int(f), b.copy(), d.copy(), tol, max_steps, of, ob)
        bb = ob[:k].copy()
        bb[bb < tol] = 0.0
        bb /= bb.sum(1, keepdims=True)
        out.append((of[:k].copy(), bb))
    return out


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
