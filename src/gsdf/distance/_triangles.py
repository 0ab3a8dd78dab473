"""Exact unsigned distance from points to triangle meshes and soups.

Two layers:

* :func:`closest_point_triangle` -- the closest point on one triangle to a point, region based (the
  Voronoi regions of Ericson, *Real-Time Collision Detection*, §5.1.5), returning the squared distance,
  the closest point and its barycentric coordinates. The region tests and the face-region projection use
  cross products computed directly (not Ericson's products of dot products, whose cancellation squares
  the condition number on slivers), and zero-area triangles -- a repeated vertex, three collinear
  vertices -- fall back to the closest point on their three segments (a zero-length segment is a point).
  The result is never NaN for finite input.
* :class:`TriangleDistance` -- the volume-split tree of :mod:`gsdf.spatial._triangle_tree` (shared with the
  fast winding number by :func:`gsdf.signed_distance`) viewed 4 children per node, built once, then walked by a
  ``numba`` kernel in parallel over the queries. A query keeps a stack of nodes and leaves ordered by the
  distance to their box (nearest popped first) and drops every box not nearer than the best triangle found
  so far; a node's 4 child boxes are tested in one branch-free loop over SIMD lanes, and the triangles of a
  leaf, stored 4 to a packet, likewise (the same arithmetic as :func:`closest_point_triangle`, so the same
  squared distance). Queries are visited in a coarse Morton order (:func:`gsdf.spatial._morton.cell_order`),
  so consecutive queries share cached nodes, and each one starts from the previous query's nearest triangle
  as an upper bound; results are written back in input order.

Cost: building is O(m log m) for m triangles; one query is O(log m) for well-spread geometry (it
degrades towards O(m) only when many triangles are nearly equidistant, e.g. the centre of a sphere).
Memory is O(m) for the tree plus O(chunk) per query batch.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numba import njit, prange

from gsdf._checks import as_mesh, as_points, flag, integer, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf._normalize import Frame
from gsdf.spatial._morton import cell_order
from gsdf.spatial._triangle_tree import PARALLEL_BUILD_FACES, TriangleTree, single_thread, triangle_tree
from gsdf.threads import apply_env, run_ranges

__all__ = ["TriangleDistance", "unsigned_distance", "closest_point_triangle", "brute_force_distance"]

#: Triangles with ``|(b - a) x (c - a)| <= _DEGENERATE * (longest edge)^2`` are treated as degenerate and
#: handled through their three segments. Both the segment fallback (error at most the triangle height,
#: ``<= _DEGENERATE * longest edge``) and the plane projection (error ~ machine epsilon / sin(angle)) are
#: then accurate to about ``1e-8`` of the triangle size; for well-shaped triangles the result is exact up
#: to rounding.
_DEGENERATE = 1e-8

#: Queries are processed in chunks of this many points so that temporaries stay bounded.
CHUNK = 1 << 20

#: Queries per range of the walk on the threads (each range allocates one traversal stack).
_BLOCK = 256

#: Fewer queries than this are answered on the calling thread (a parallel launch costs more than they take).
SERIAL_QUERIES = 4096


# ----------------------------------------------------------------------------------------------------
# point - segment / point - triangle
# ----------------------------------------------------------------------------------------------------


@njit(cache=True)
def _segment(px, py, pz, ax, ay, az, bx, by, bz):
    """Closest point on segment ab to p: returns (squared distance, t) with the point a + t (b - a)."""
    ex, ey, ez = bx - ax, by - ay, bz - az
    wx, wy, wz = px - ax, py - ay, pz - az
    ee = ex * ex + ey * ey + ez * ez
    t = 0.0
    if ee > 0.0:
        t = (wx * ex + wy * ey + wz * ez) / ee
        if t <= 0.0:
            t = 0.0
        elif t >= 1.0:
            t = 1.0
    dx = wx - t * ex
    dy = wy - t * ey
    dz = wz - t * ez
    return dx * dx + dy * dy + dz * dz, t


@njit(cache=True)
def _closest_point_triangle(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point on triangle abc to p.

    Returns ``(d2, qx, qy, qz, u, v, w)``: squared distance, closest point, and barycentric coordinates
    ``q = u a + v b + w c`` (exact zeros/ones on edges and vertices).
    """
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    bcx, bcy, bcz = cx - bx, cy - by, cz - bz
    nx = aby * acz - abz * acy
    ny = abz * acx - abx * acz
    nz = abx * acy - aby * acx
    n2 = nx * nx + ny * ny + nz * nz
    lab = abx * abx + aby * aby + abz * abz
    lac = acx * acx + acy * acy + acz * acz
    lbc = bcx * bcx + bcy * bcy + bcz * bcz
    lmax = max(lab, max(lac, lbc))
    thr = _DEGENERATE * lmax
    if n2 > thr * thr:
        # signed sub-areas (times |n|^2 scale) opposite a, b, c, from cross products relative to p
        pax, pay, paz = ax - px, ay - py, az - pz
        pbx, pby, pbz = bx - px, by - py, bz - pz
        pcx, pcy, pcz = cx - px, cy - py, cz - pz
        # va = n . (pb x pc), vb = n . (pc x pa), vc = n . (pa x pb)
        va = nx * (pby * pcz - pbz * pcy) + ny * (pbz * pcx - pbx * pcz) + nz * (pbx * pcy - pby * pcx)
        vb = nx * (pcy * paz - pcz * pay) + ny * (pcz * pax - pcx * paz) + nz * (pcx * pay - pcy * pax)
        vc = nx * (pay * pbz - paz * pby) + ny * (paz * pbx - pax * pbz) + nz * (pax * pby - pay * pbx)
        if va >= 0.0 and vb >= 0.0 and vc >= 0.0:
            # face region: orthogonal projection onto the plane
            s = -(pax * nx + pay * ny + paz * nz) / n2  # (p - a) . n / |n|^2
            qx = px - s * nx
            qy = py - s * ny
            qz = pz - s * nz
            tot = va + vb + vc
            if tot > 0.0:
                u = va / tot
                v = vb / tot
                w = vc / tot
            else:  # pragma: no cover - cannot happen for n2 > 0
                u = v = w = 1.0 / 3.0
            return s * s * n2, qx, qy, qz, u, v, w
        # outside: the closest point lies on an edge opposite a negative coordinate
        best = np.inf
        u = v = w = 0.0
        if va < 0.0:
            d2, t = _segment(px, py, pz, bx, by, bz, cx, cy, cz)
            best = d2
            u, v, w = 0.0, 1.0 - t, t
        if vb < 0.0:
            d2, t = _segment(px, py, pz, cx, cy, cz, ax, ay, az)
            if d2 < best:
                best = d2
                u, v, w = t, 0.0, 1.0 - t
        if vc < 0.0:
            d2, t = _segment(px, py, pz, ax, ay, az, bx, by, bz)
            if d2 < best:
                best = d2
                u, v, w = 1.0 - t, t, 0.0
        qx = u * ax + v * bx + w * cx
        qy = u * ay + v * by + w * cy
        qz = u * az + v * bz + w * cz
        # exact endpoints when the segment parameter clamps
        if u == 1.0:
            qx, qy, qz = ax, ay, az
        elif v == 1.0:
            qx, qy, qz = bx, by, bz
        elif w == 1.0:
            qx, qy, qz = cx, cy, cz
        return best, qx, qy, qz, u, v, w
    # degenerate (zero or negligible area): closest point on the three segments
    best, t = _segment(px, py, pz, ax, ay, az, bx, by, bz)
    u, v, w = 1.0 - t, t, 0.0
    d2, t = _segment(px, py, pz, bx, by, bz, cx, cy, cz)
    if d2 < best:
        best = d2
        u, v, w = 0.0, 1.0 - t, t
    d2, t = _segment(px, py, pz, cx, cy, cz, ax, ay, az)
    if d2 < best:
        best = d2
        u, v, w = t, 0.0, 1.0 - t
    qx = u * ax + v * bx + w * cx
    qy = u * ay + v * by + w * cy
    qz = u * az + v * bz + w * cz
    if u == 1.0:
        qx, qy, qz = ax, ay, az
    elif v == 1.0:
        qx, qy, qz = bx, by, bz
    elif w == 1.0:
        qx, qy, qz = cx, cy, cz
    return best, qx, qy, qz, u, v, w


@njit(parallel=True, cache=True)
def _closest_point_triangles_kernel(P, A, B, C, d2, Q, bary):
    for i in prange(P.shape[0]):
        r = _closest_point_triangle(
            P[i, 0], P[i, 1], P[i, 2], A[i, 0], A[i, 1], A[i, 2], B[i, 0], B[i, 1], B[i, 2], C[i, 0], C[i, 1], C[i, 2]
        )
        d2[i] = r[0]
        Q[i, 0] = r[1]
        Q[i, 1] = r[2]
        Q[i, 2] = r[3]
        bary[i, 0] = r[4]
        bary[i, 1] = r[5]
        bary[i, 2] = r[6]


def closest_point_triangle(P, A, B, C):
    """Closest points on triangles ``(A[i], B[i], C[i])`` to points ``P[i]`` (all (n, 3), broadcastable rows).

    Returns ``(d, closest (n, 3), bary (n, 3))`` with ``closest = bary[:, :1] * A + bary[:, 1:2] * B +
    bary[:, 2:] * C`` (up to rounding).
    """
    P = as_points(P, "P")
    A, B, C = (as_points(X, name) for X, name in ((A, "A"), (B, "B"), (C, "C")))
    n = max(X.shape[0] for X in (P, A, B, C))
    try:
        P, A, B, C = (np.ascontiguousarray(np.broadcast_to(X, (n, 3))) for X in (P, A, B, C))
    except ValueError as exc:
        raise ValueError(f"P, A, B, C: row counts do not broadcast ({exc})") from exc
    frame = Frame.of(np.concatenate([A, B, C]))  # scale invariance (gsdf._normalize)
    A, B, C = (frame.geometry(X, name) for X, name in ((A, "A"), (B, "B"), (C, "C")))
    P, excess = frame.queries(P, "P", want_excess=True)
    d2 = np.empty(n)
    Q = np.empty((n, 3))
    bary = np.empty((n, 3))
    _closest_point_triangles_kernel(P, A, B, C, d2, Q, bary)
    return frame.length(np.sqrt(d2) + excess), frame.point(Q), bary


# ----------------------------------------------------------------------------------------------------
# BVH nearest-triangle query
# ----------------------------------------------------------------------------------------------------


#: Lanes per triangle packet and children per wide node (the kernels' lane loops are unrolled over them).
_LANES = 4

#: Padding lanes of a packet hold a degenerate triangle at this coordinate: farther than any query (frame
#: coordinates of queries are at most 2^64, gsdf._normalize.FAR), its squared distance ~1e70 stays finite.
_FAR_CORNER = 1e35


@njit(cache=True, inline="always")
def _seg_d2(px, py, pz, ax, ay, az, bx, by, bz):
    """Squared distance from p to segment ab (the arithmetic of :func:`_segment`, written with selects)."""
    ex, ey, ez = bx - ax, by - ay, bz - az
    wx, wy, wz = px - ax, py - ay, pz - az
    ee = ex * ex + ey * ey + ez * ez
    t = (wx * ex + wy * ey + wz * ez) / (ee if ee > 0.0 else 1.0)
    t = 0.0 if (ee <= 0.0 or t <= 0.0) else (1.0 if t >= 1.0 else t)
    dx = wx - t * ex
    dy = wy - t * ey
    dz = wz - t * ez
    return dx * dx + dy * dy + dz * dz


@njit(cache=True, inline="always")
def _lane_d2(px, py, pz, PK, p, c):
    """Squared distance from p to lane c of triangle packet p (:func:`_packets`): the arithmetic of
    :func:`_closest_point_triangle` (so the same value, bit for bit), without branches so that a loop over the
    4 lanes runs as SIMD."""
    ax, ay, az = PK[p, 0, c], PK[p, 1, c], PK[p, 2, c]
    bx, by, bz = PK[p, 3, c], PK[p, 4, c], PK[p, 5, c]
    cx, cy, cz = PK[p, 6, c], PK[p, 7, c], PK[p, 8, c]
    nx, ny, nz, n2 = PK[p, 9, c], PK[p, 10, c], PK[p, 11, c], PK[p, 12, c]
    pax, pay, paz = ax - px, ay - py, az - pz
    pbx, pby, pbz = bx - px, by - py, bz - pz
    pcx, pcy, pcz = cx - px, cy - py, cz - pz
    va = nx * (pby * pcz - pbz * pcy) + ny * (pbz * pcx - pbx * pcz) + nz * (pbx * pcy - pby * pcx)
    vb = nx * (pcy * paz - pcz * pay) + ny * (pcz * pax - pcx * paz) + nz * (pcx * pay - pcy * pax)
    vc = nx * (pay * pbz - paz * pby) + ny * (paz * pbx - pax * pbz) + nz * (pax * pby - pay * pbx)
    s = -(pax * nx + pay * ny + paz * nz) / (n2 if n2 > 0.0 else 1.0)
    face = s * s * n2
    dbc = _seg_d2(px, py, pz, bx, by, bz, cx, cy, cz)
    dca = _seg_d2(px, py, pz, cx, cy, cz, ax, ay, az)
    dab = _seg_d2(px, py, pz, ax, ay, az, bx, by, bz)
    degenerate = n2 <= 0.0
    e = min(dbc if (va < 0.0 or degenerate) else np.inf, dca if (vb < 0.0 or degenerate) else np.inf)
    e = min(e, dab if (vc < 0.0 or degenerate) else np.inf)
    inside = (va >= 0.0) and (vb >= 0.0) and (vc >= 0.0) and not degenerate
    return face if inside else e


@njit(cache=True, inline="always")
def _lane_box_d2(px, py, pz, BX, n, c):
    """Squared distance from p to the box of child lane c of wide node n (0 inside; +inf for an empty lane)."""
    a, b = BX[n, 0, c] - px, px - BX[n, 3, c]
    dx = a if a > b else b
    dx = dx if dx > 0.0 else 0.0
    a, b = BX[n, 1, c] - py, py - BX[n, 4, c]
    dy = a if a > b else b
    dy = dy if dy > 0.0 else 0.0
    a, b = BX[n, 2, c] - pz, pz - BX[n, 5, c]
    dz = a if a > b else b
    dz = dz if dz > 0.0 else 0.0
    return dx * dx + dy * dy + dz * dz


@njit(cache=True, nogil=True)
def _nearest_range(Q, perm, k0, k1, PK, BX, CH, PS, PE, stack_size, out_d2, out_p, out_c):
    """Nearest triangle for the queries ``Q[perm[k]]``, k0 <= k < k1, processed in that order.

    The walk over the wide tree (:func:`_distance_lanes`) keeps a stack of entries (a wide node, or the packets
    of one leaf child) with the squared distance to their box, pushed farthest first so that the nearest is
    expanded next; an entry is dropped when its box is not nearer than the best triangle found so far. A wide
    node's 4 child boxes and a packet's 4 triangles are each evaluated in one branch-free loop over the lanes
    (SIMD: 39 against 171 ns per packet unrolled, which LLVM does not vectorise). ``perm`` orders the queries along a space-filling curve: each query starts from the previous one's
    nearest triangle as an upper bound, and consecutive queries share cached nodes.
    """
    stack = np.empty(stack_size, np.int64)
    stack_d = np.empty(stack_size)
    d4 = np.empty(_LANES)
    o4 = np.empty(_LANES, np.int64)
    lanes = PK.shape[2]  # == _LANES
    bp = np.int64(-1)
    bl = np.int64(0)
    for k in range(k0, k1):
        qi = perm[k]
        px, py, pz = Q[qi, 0], Q[qi, 1], Q[qi, 2]
        best = np.inf
        if bp >= 0:  # warm start: the previous query's nearest triangle
            best = _lane_d2(px, py, pz, PK, bp, bl)
        stack[0] = 0
        stack_d[0] = 0.0
        sp = 1
        while sp > 0:
            sp -= 1
            if stack_d[sp] >= best:
                continue
            e = stack[sp]
            if e < 0:  # the packets of a leaf: lane c of wide node n
                n = (-e - 1) // _LANES
                c = (-e - 1) % _LANES
                for p in range(PS[n, c], PE[n, c]):
                    for j in range(lanes):  # a trip count unknown at compile time: LLVM's loop vectoriser
                        d4[j] = _lane_d2(px, py, pz, PK, p, j)  # then runs it as SIMD (numba's SLP is off)
                    for j in range(_LANES):
                        if d4[j] < best:
                            best = d4[j]
                            bp = p
                            bl = j
                continue
            for j in range(lanes):
                d4[j] = _lane_box_d2(px, py, pz, BX, e, j)
            # the lanes nearer than the best, sorted by distance (insertion sort of at most 4)
            m = 0
            for j in range(_LANES):
                dj = d4[j]
                if dj < best and CH[e, j] != -2:
                    i = m
                    while i > 0 and d4[o4[i - 1]] < dj:
                        o4[i] = o4[i - 1]
                        i -= 1
                    o4[i] = j
                    m += 1
            for i in range(m):  # farthest first: the nearest is popped next
                j = o4[i]
                ch = CH[e, j]
                stack[sp] = ch if ch >= 0 else -(e * _LANES + j) - 1
                stack_d[sp] = d4[j]
                sp += 1
        out_d2[qi] = best
        out_p[qi] = bp
        out_c[qi] = bl


@njit(cache=True, nogil=True)
def _finish_range(Q, k0, k1, PK, PF, best_p, best_c, out_d2, out_face, out_c, out_bary):
    """Closest point, face and barycentric coordinates of the nearest triangles found by :func:`_nearest_range`
    (by :func:`_closest_point_triangle`, whose squared distance equals the walk's)."""
    for qi in range(k0, k1):
        p = best_p[qi]
        c = best_c[qi]
        res = _closest_point_triangle(Q[qi, 0], Q[qi, 1], Q[qi, 2], PK[p, 0, c], PK[p, 1, c], PK[p, 2, c],
                                      PK[p, 3, c], PK[p, 4, c], PK[p, 5, c], PK[p, 6, c], PK[p, 7, c], PK[p, 8, c])
        out_d2[qi] = res[0]
        out_face[qi] = PF[p, c]
        out_c[qi, 0] = res[1]
        out_c[qi, 1] = res[2]
        out_c[qi, 2] = res[3]
        out_bary[qi, 0] = res[4]
        out_bary[qi, 1] = res[5]
        out_bary[qi, 2] = res[6]


@njit(cache=True)
def _leaf_packets(start, end, right):
    """First packet of every node (leaves: ceil(n / 4) packets each, in tree order) and the packet count."""
    k = start.shape[0]
    first = np.zeros(k, np.int64)
    count = 0
    for i in range(k):
        first[i] = count
        if right[i] < 0:
            count += (end[i] - start[i] + _LANES - 1) // _LANES
    return first, count


@njit(cache=True, nogil=True)
def _packets(V, F, order, start, end, right, first, degenerate, PK, PF, i0, i1):
    """Triangle packets of the leaves among nodes i0..i1: 4 triangles per packet in lanes (PK (p, 13, 4): corners
    a, b, c, normal n = (b − a) × (c − a) and |n|² — zero for a degenerate triangle, as :func:`_pack` —; PF (p, 4)
    the face ids); a packet's unused lanes hold a far degenerate triangle."""
    for i in range(i0, i1):
        if right[i] >= 0:
            continue
        for jj in range(start[i], start[i] + (end[i] - start[i] + _LANES - 1) // _LANES * _LANES):
            p = first[i] + (jj - start[i]) // _LANES
            c = (jj - start[i]) % _LANES
            if jj >= end[i]:
                for d in range(9):
                    PK[p, d, c] = _FAR_CORNER
                for d in range(9, 13):
                    PK[p, d, c] = 0.0
                PF[p, c] = -1
                continue
            f = order[jj]
            PF[p, c] = f
            for v in range(3):
                for d in range(3):
                    PK[p, 3 * v + d, c] = V[F[f, v], d]
            abx, aby, abz = PK[p, 3, c] - PK[p, 0, c], PK[p, 4, c] - PK[p, 1, c], PK[p, 5, c] - PK[p, 2, c]
            acx, acy, acz = PK[p, 6, c] - PK[p, 0, c], PK[p, 7, c] - PK[p, 1, c], PK[p, 8, c] - PK[p, 2, c]
            bcx, bcy, bcz = PK[p, 6, c] - PK[p, 3, c], PK[p, 7, c] - PK[p, 4, c], PK[p, 8, c] - PK[p, 5, c]
            nx = aby * acz - abz * acy
            ny = abz * acx - abx * acz
            nz = abx * acy - aby * acx
            n2 = nx * nx + ny * ny + nz * nz
            lmax = max(abx * abx + aby * aby + abz * abz, max(acx * acx + acy * acy + acz * acz,
                                                               bcx * bcx + bcy * bcy + bcz * bcz))
            thr = degenerate * lmax
            ok = n2 > thr * thr
            PK[p, 9, c] = nx if ok else 0.0
            PK[p, 10, c] = ny if ok else 0.0
            PK[p, 11, c] = nz if ok else 0.0
            PK[p, 12, c] = n2 if ok else 0.0


@njit(cache=True, nogil=True)
def _distance_lanes(kids, child, lo, hi, first, start, end, BX, PS, PE, i0, i1):
    """Wide nodes i0..i1 for the distance walk: BX (w, 6, 4) the children's boxes (lo, hi; +inf / −inf for an
    empty slot), PS, PE (w, 4) the packet range of a leaf child."""
    for n in range(i0, i1):
        for c in range(_LANES):
            b = kids[n, c]
            if b < 0:
                for d in range(3):
                    BX[n, d, c] = np.inf
                    BX[n, 3 + d, c] = -np.inf
                PS[n, c] = 0
                PE[n, c] = 0
                continue
            for d in range(3):
                BX[n, d, c] = lo[b, d]
                BX[n, 3 + d, c] = hi[b, d]
            PS[n, c] = first[b]
            PE[n, c] = first[b] + (end[b] - start[b] + _LANES - 1) // _LANES if child[n, c] == -1 else first[b]


class TriangleDistance:
    """Unsigned distance to a triangle mesh or soup, with the tree built once.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles (any soup: duplicated, degenerate, non-manifold or unreferenced elements are fine).
    leaf_size : int, default 4
        Maximum triangles per leaf of the bounding volume hierarchy (>= 1); changes speed only.

    Attributes
    ----------
    V, F
        The mesh, as given (float64, int64).
    n_faces : int
        Number of triangles.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    >>> td = gsdf.TriangleDistance(V, [[0, 1, 2]])           # build once ...
    >>> d, face, closest = td.query([[0.2, 0.2, 0.5]])       # ... query many times
    >>> float(d[0]), int(face[0]), closest[0].tolist()
    (0.5, 0, [0.2, 0.2, 0.0])
    """

    def __init__(self, V, F, leaf_size: int = 4):
        V, F = as_mesh(V, F)
        leaf = integer(leaf_size, "leaf_size", 1)
        self._setup(V, F, triangle_tree(V, F, leaf))

    @classmethod
    def _of_tree(cls, V, F, tt: TriangleTree) -> "TriangleDistance":
        """The distance structure on an already built tree of the validated mesh (V, F) (shared with
        :class:`gsdf.FastWindingNumber` by :func:`gsdf.signed_distance`)."""
        self = cls.__new__(cls)
        self._setup(V, F, tt)
        return self

    def _setup(self, V, F, tt: TriangleTree):
        """Triangle packets and wide lanes of the tree ``tt`` (which lives in the normalised frame of the mesh:
        scale invariance, gsdf._normalize)."""
        self.V = V
        self.F = F
        self._frame = tt.frame
        self.bvh = tt.bvh
        self._wide = tt.wide
        self._pack(tt.Vf)

    def _pack(self, Vf):
        b, w = self.bvh, self._wide
        first, npk = _leaf_packets(b.start, b.end, b.right)
        self._PK = np.empty((npk, 13, _LANES))
        self._PF = np.empty((npk, _LANES), np.int64)
        nw = w.kids.shape[0]
        self._BX = np.empty((nw, 6, _LANES))
        self._PS = np.empty((nw, _LANES), np.int64)
        self._PE = np.empty((nw, _LANES), np.int64)
        self._CH = w.child
        self._stack = 4 * w.depth + 8
        k = b.start.shape[0]
        with single_thread(self.F.shape[0] < PARALLEL_BUILD_FACES):
            run_ranges(lambda i0, i1: _packets(Vf, self.F, b.order, b.start, b.end, b.right, first, _DEGENERATE,
                                               self._PK, self._PF, i0, i1), k, 1 << 14, 1)
            run_ranges(lambda i0, i1: _distance_lanes(w.kids, w.child, b.lo, b.hi, first, b.start, b.end,
                                                      self._BX, self._PS, self._PE, i0, i1), nw, 1 << 14, 1)

    @property
    def n_faces(self) -> int:
        """Number of triangles."""
        return int(self.F.shape[0])

    def _query(self, Q, chunk: int = CHUNK, want_bary: bool = True):
        """Validated queries -> (d, face, closest, bary) in input units; ``bary`` is None unless ``want_bary``."""
        apply_env()  # GSDF_NUM_THREADS
        fr = self._frame
        Q, excess = fr.queries(Q, want_excess=True)
        d2, face, closest, bary = self._query_frame(Q, chunk, want_bary)
        d = np.sqrt(d2, out=d2)
        d += excess
        return fr.length(d), face, fr.point(closest), bary

    def _nearest(self, Q, perm=None):
        """Squared distance, packet and lane of the nearest triangle of every query ``Q`` (frame coordinates),
        the queries walked in the order ``perm`` (a coarse Morton order when None)."""
        nq = Q.shape[0]
        d2 = np.empty(nq)
        bp = np.empty(nq, np.int64)
        bc = np.empty(nq, np.int64)
        if nq == 0:
            return d2, bp, bc
        if perm is None:
            perm = cell_order(Q)
        args = (self._PK, self._BX, self._CH, self._PS, self._PE, self._stack, d2, bp, bc)
        with single_thread(nq < SERIAL_QUERIES):
            run_ranges(lambda k0, k1: _nearest_range(Q, perm, k0, k1, *args), nq, _BLOCK, 8)
        return d2, bp, bc

    def _query_frame(self, Q, chunk: int, want_bary: bool):
        nq = Q.shape[0]
        d2 = np.empty(nq)
        face = np.empty(nq, np.int64)
        closest = np.empty((nq, 3))
        bary = np.empty((nq, 3)) if want_bary else None
        scratch = None if want_bary else np.empty((min(nq, chunk), 3))
        for s in range(0, nq, chunk):
            e = min(nq, s + chunk)
            Qc = Q[s:e]
            _, bp, bc = self._nearest(Qc)
            out = (d2[s:e], face[s:e], closest[s:e], bary[s:e] if want_bary else scratch[: e - s])
            with single_thread(e - s < SERIAL_QUERIES):
                run_ranges(lambda k0, k1: _finish_range(Qc, k0, k1, self._PK, self._PF, bp, bc, *out), e - s,
                           _BLOCK, 2)
        return d2, face, closest, bary

    def refit(self, V):
        """Move the vertices (same faces) and keep the tree.

        The tree's element order and splits stay, the boxes are recomputed bottom-up from the new triangles
        (O(n), against the build's O(n log n)). Queries stay exact (every box bounds its triangles); a tree
        refitted after large moves only prunes less well. For meshes whose vertices move a little per round (an
        iterative fit).

        Parameters
        ----------
        V : (n, 3) float
            The new vertex positions, as many as before.

        Returns
        -------
        TriangleDistance
            ``self``.

        Raises
        ------
        ValueError
            A different number of vertices, NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float); F = np.array([[0, 1, 2]])
        >>> td = TriangleDistance(V, F).refit(V + [0.0, 0.0, 1.0])
        >>> float(td.query([[0.2, 0.2, 0.0]])[0][0])
        1.0
        """
        V = as_points(V, "V")
        if V.shape != self.V.shape:
            raise ValueError(f"V: expected {self.V.shape[0]} vertices (the tree's), got {V.shape[0]}")
        self.V = V
        self._frame = Frame.of_mesh(V, self.F)
        Vf = np.ascontiguousarray(self._frame.geometry(V))
        b = self.bvh
        lo, hi = _refit_boxes(Vf, self.F, b.order, b.start, b.end, b.right)
        self.bvh = dataclasses.replace(b, lo=lo, hi=hi)
        self._pack(Vf)
        return self

    @query_shaped()
    def query(self, Q):
        """Unsigned distance from each query point to the nearest triangle.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        d : (q,) float64
            Euclidean distance.
        face : (q,) int64
            Index into ``F`` of a nearest triangle (ties broken arbitrarily).
        closest : (q, 3) float64
            The closest point on that triangle.

        Raises
        ------
        ValueError
            ``Q`` of the wrong shape or with NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
        >>> d, face, closest = gsdf.TriangleDistance(V, [[0, 1, 2]]).query([[2.0, 0.0, 0.0]])
        >>> float(d[0]), closest[0].tolist()
        (1.0, [1.0, 0.0, 0.0])
        """
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        d, face, closest, _ = self._query(Q, want_bary=False)
        return d, face, closest

    @query_shaped()
    def query_barycentric(self, Q):
        """Like :meth:`query`, and the barycentric coordinates of each closest point in its triangle.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        d : (q,) float64
            Euclidean distance.
        face : (q,) int64
            Index into ``F`` of a nearest triangle.
        closest : (q, 3) float64
            The closest point on that triangle.
        bary : (q, 3) float64
            Its barycentric coordinates in ``F[face]`` (exact zeros on edges, an exact one at vertices).

        Raises
        ------
        ValueError
            ``Q`` of the wrong shape or with NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
        >>> d, face, closest, bary = gsdf.TriangleDistance(V, [[0, 1, 2]]).query_barycentric([[2.0, 0.0, 0.0]])
        >>> bary[0].tolist()
        [0.0, 1.0, 0.0]
        """
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        return self._query(Q)


@njit(cache=True)
def _refit_boxes(V, F, order, start, end, right):
    """Node boxes (k, 3) lo, hi of a preorder tree (left child i + 1, right child ``right[i]``, −1 for leaves)
    over the triangles ``F[order]`` of ``V``, bottom-up, as the build computes them."""
    k = start.shape[0]
    lo = np.empty((k, 3))
    hi = np.empty((k, 3))
    for i in range(k - 1, -1, -1):
        r = right[i]
        if r < 0:
            for d in range(3):
                lo[i, d] = np.inf
                hi[i, d] = -np.inf
            for j in range(start[i], end[i]):
                f = order[j]
                for v in range(3):
                    for d in range(3):
                        x = V[F[f, v], d]
                        lo[i, d] = min(lo[i, d], x)
                        hi[i, d] = max(hi[i, d], x)
        else:
            for d in range(3):
                lo[i, d] = min(lo[i + 1, d], lo[r, d])
                hi[i, d] = max(hi[i + 1, d], hi[r, d])
    return lo, hi


@query_shaped()
def unsigned_distance(V, F, Q, return_closest: bool = False):
    """Unsigned distance from points ``Q`` to the triangle mesh/soup ``(V, F)``.

    To query the same geometry repeatedly, build a :class:`TriangleDistance` once.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions, model units.
    F : (m, 3) int
        Triangles (any soup).
    Q : (q, 3) float
        Query points.
    return_closest : bool, default False
        Also return the nearest triangle and the closest point on it.

    Returns
    -------
    d : (q,) float64
        Distance to the nearest triangle.
    face : (q,) int64
        Only with ``return_closest``: index into ``F`` of a nearest triangle.
    closest : (q, 3) float64
        Only with ``return_closest``: the closest point on it.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    >>> F = np.array([[0, 1, 2]])
    >>> d = gsdf.unsigned_distance(V, F, [[0.2, 0.2, 0.5], [0.2, 0.2, -0.5]])
    >>> np.round(d, 3).tolist()
    [0.5, 0.5]
    """
    return_closest = flag(return_closest, "return_closest")
    V, F = as_mesh(V, F)
    Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
    d, face, closest = TriangleDistance(V, F).query(Q)
    if return_closest:
        return d, face, closest
    return d


@njit(parallel=True, cache=True)
def _brute_kernel(Q, T, out_d2, out_face):
    for i in prange(Q.shape[0]):
        best = np.inf
        bj = 0
        for j in range(T.shape[0]):
            r = _closest_point_triangle(
                Q[i, 0], Q[i, 1], Q[i, 2],
                T[j, 0], T[j, 1], T[j, 2], T[j, 3], T[j, 4], T[j, 5], T[j, 6], T[j, 7], T[j, 8],
            )
            if r[0] < best:
                best = r[0]
                bj = j
        out_d2[i] = best
        out_face[i] = bj


def brute_force_distance(V, F, Q):
    """O(q m) reference: distance from every query to every triangle. Returns ``(d, face)``. For testing."""
    V, F = as_mesh(V, F)
    Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
    frame = Frame.of_mesh(V, F)
    T = np.ascontiguousarray(frame.geometry(V)[F].reshape(-1, 9))
    Q, excess = frame.queries(Q, want_excess=True)
    d2 = np.empty(Q.shape[0])
    face = np.empty(Q.shape[0], np.int64)
    _brute_kernel(Q, T, d2, face)
    return frame.length(np.sqrt(d2) + excess), face
