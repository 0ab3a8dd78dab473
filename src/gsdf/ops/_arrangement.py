"""The arrangement of a triangle soup: every triangle cut along its exact intersections with the others.

The construction :func:`gsdf.ops.mesh_boolean` classifies (the "mesh arrangement" of Zhou et al. 2016, *Mesh
Arrangements for Solid Geometry*, which libigl's and CGAL's booleans compute): for every pair of triangles whose
boxes overlap, their intersection — empty, a point, a segment, or for coplanar triangles the parts of each one's
edges inside the other — is computed in exact rational arithmetic from the input floats; each triangle is then
re-triangulated with these points and segments as constraints (in its own plane, exactly). Points are exact
rationals, so a point found from different triangles (an edge crossing a plane, three planes meeting) is the same
value everywhere and the pieces share their vertices: the arrangement is conforming. Pairs are filtered first in
floating point with an error bound (a triangle whose vertices are all certainly on one side of the other's plane,
apart from shared vertices, is not intersected); only the rest is computed exactly.

The result keeps, for every piece, the triangle it came from and the triangles coplanar with it, which the
classification needs for pieces covered by more than one input triangle.
"""

from __future__ import annotations

from fractions import Fraction
from math import gcd

import numpy as np

__all__ = ["Arrangement", "arrange"]


class Arrangement:
    """Pieces of the input triangles.

    Attributes
    ----------
    V : (n, 3) float64
        Vertices: the input vertices (welded: equal coordinates share one index), then the new points rounded to
        the nearest floats.
    F : (m, 3) int64
        Pieces, oriented as the triangle they come from.
    parent : (m,) int64
        Input triangle of each piece.
    covered_by : dict
        Piece index -> input triangles other than its parent that contain the piece (coplanar and overlapping).
    """

    def __init__(self, V, F, parent, covered_by):
        self.V, self.F, self.parent, self.covered_by = V, F, parent, covered_by


# ------------------------------------------------------------------------------------------------ exact kernels
#
# Input coordinates are scaled by one power of two D to integers (exactly); a point is a tuple of integers
# (X, Y, Z, W), W > 0, meaning (X, Y, Z) / W, reduced by their gcd (so equal points are equal tuples); a point in
# a triangle's projection is (x, y, w). Predicates are integer determinants (Python integers: exact).


def _canon(X, Y, Z, W):
    if W < 0:
        X, Y, Z, W = -X, -Y, -Z, -W
    g = gcd(gcd(X, Y), gcd(Z, W))
    if g > 1:
        X, Y, Z, W = X // g, Y // g, Z // g, W // g
    return (X, Y, Z, W)


def _orient3d(a, b, c, d):
    """Six times the signed volume of (a, b, c, d) for points with W = 1 (input vertices)."""
    adx, ady, adz = a[0] - d[0], a[1] - d[1], a[2] - d[2]
    bdx, bdy, bdz = b[0] - d[0], b[1] - d[1], b[2] - d[2]
    cdx, cdy, cdz = c[0] - d[0], c[1] - d[1], c[2] - d[2]
    return adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) + cdx * (ady * bdz - adz * bdy)


def _orient2d(a, b, c):
    """Sign-exact orientation of homogeneous 2-D points (x, y, w), w > 0: the determinant |x y w|."""
    return (a[0] * (b[1] * c[2] - c[1] * b[2]) - a[1] * (b[0] * c[2] - c[0] * b[2])
            + a[2] * (b[0] * c[1] - c[0] * b[1]))


def _incircle(a, b, c, d):
    """> 0 when d is inside the circle through the counter-clockwise a, b, c (homogeneous 2-D points)."""
    rows = []
    for p in (a, b, c):
        dx, dy = p[0] * d[2] - d[0] * p[2], p[1] * d[2] - d[1] * p[2]
        s = p[2] * d[2]
        rows.append((dx * s, dy * s, dx * dx + dy * dy))
    (ax, ay, aw), (bx, by, bw), (cx, cy, cw) = rows
    return ax * (by * cw - bw * cy) - ay * (bx * cw - bw * cx) + aw * (bx * cy - by * cx)


def _sign(x):
    return (x > 0) - (x < 0)


def _lerp3(p, q, num, den):
    """p + (q - p) num / den for homogeneous 3-D points (den > 0)."""
    wp, wq = p[3], q[3]
    a, b = wq * (den - num), wp * num
    return _canon(p[0] * a + q[0] * b, p[1] * a + q[1] * b, p[2] * a + q[2] * b, wp * wq * den)


def _ratio(num, den):
    return (-num, -den) if den < 0 else (num, den)


def _normal(T):
    a, b, c = T
    u = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    v = (c[0] - a[0], c[1] - a[1], c[2] - a[2])
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


class _Plane:
    """An input triangle's plane (vertices with W = 1) and the projection dropping its normal's largest
    component."""

    def __init__(self, T):
        self.a = T[0]
        self.n = _normal(T)
        self.k = max(range(3), key=lambda i: abs(self.n[i]))
        self.i, self.j = [d for d in range(3) if d != self.k]

    def to2d(self, p):
        return (p[self.i], p[self.j], p[3])

    def lift(self, q):
        """The point of the plane whose projection is q (exact)."""
        n, a = self.n, self.a
        x, y, w = q
        X = [0, 0, 0]
        X[self.i], X[self.j] = x * n[self.k], y * n[self.k]
        X[self.k] = a[self.k] * w * n[self.k] - n[self.i] * (x - a[self.i] * w) - n[self.j] * (y - a[self.j] * w)
        return _canon(X[0], X[1], X[2], w * n[self.k])


def _plane_cut(T, o):
    """The part of input triangle T in a plane, given the orientations o of its vertices against it: [] or 1 or
    2 points (a touching vertex, a crossing segment, or an edge lying in the plane)."""
    out = [T[i] for i in range(3) if o[i] == 0]
    for i, j in ((0, 1), (1, 2), (2, 0)):
        if o[i] * o[j] < 0:
            p, q = T[i], T[j]
            oi, oj = o[i], o[j]  # the point q o_i - p o_j over o_i - o_j
            out.append(_canon(q[0] * oi - p[0] * oj, q[1] * oi - p[1] * oj, q[2] * oi - p[2] * oj, oi - oj))
    return out


def _segment_in_triangle_2d(p, q, tri, s):
    """Parameters ((lo_num, lo_den), (hi_num, hi_den)) of the part of segment pq (2-D, w = 1) inside the closed
    2-D triangle ``tri`` (orientation sign ``s``), or None."""
    ln, ld, hn, hd = 0, 1, 1, 1
    for e in range(3):
        a, b = tri[e], tri[(e + 1) % 3]
        f0, f1 = s * _orient2d(a, b, p), s * _orient2d(a, b, q)
        if f0 < 0 and f1 < 0:
            return None
        if f0 < 0:  # enters at f0 / (f0 - f1)
            n, d = -f0, f1 - f0
            if n * ld > ln * d:
                ln, ld = n, d
        elif f1 < 0:  # leaves at f0 / (f0 - f1)
            n, d = f0, f0 - f1
            if n * hd < hn * d:
                hn, hd = n, d
        if ln * hd > hn * ld:
            return None
    return (ln, ld), (hn, hd)


def _inside_closed_2d(x, tri, s):
    return all(s * _orient2d(tri[e], tri[(e + 1) % 3], x) >= 0 for e in range(3))


def _key(p, k):
    """p[k] / W as a Fraction (to sort points along a line)."""
    return Fraction(p[k], p[3])


# ------------------------------------------------------------------------------------------------ candidates


def _candidate_pairs(lo, hi):
    """Pairs (i < j) of boxes [lo, hi] that overlap (closed), by sweep and prune along the widest axis."""
    m = len(lo)
    if m < 2:
        return np.zeros((0, 2), np.int64)
    ax = int(np.argmax(hi.max(axis=0) - lo.min(axis=0)))
    order = np.argsort(lo[:, ax], kind="stable")
    slo, shi = lo[order], hi[order]
    # for each i: the boxes after it in the sweep order whose start is within its extent
    end = np.searchsorted(slo[:, ax], shi[:, ax], side="right")
    out = []
    step = 4096
    for c in range(0, m, step):
        i = np.arange(c, min(m, c + step))
        cnt = np.maximum(end[i] - i - 1, 0)
        if cnt.sum() == 0:
            continue
        I = np.repeat(i, cnt)
        J = I + 1 + (np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt))
        ok = np.all((slo[I] <= shi[J]) & (slo[J] <= shi[I]), axis=1)
        out.append(np.column_stack([order[I[ok]], order[J[ok]]]))
    if not out:
        return np.zeros((0, 2), np.int64)
    P = np.concatenate(out)
    return np.sort(P, axis=1)


def _orient_float(A, B, C, D):
    """Float orient3d of rows and an error bound: the sign is certain where |det| > bound."""
    ad, bd, cd = A - D, B - D, C - D
    t1 = bd[:, 1] * cd[:, 2] - bd[:, 2] * cd[:, 1]
    t2 = cd[:, 1] * ad[:, 2] - cd[:, 2] * ad[:, 1]
    t3 = ad[:, 1] * bd[:, 2] - ad[:, 2] * bd[:, 1]
    det = ad[:, 0] * t1 + bd[:, 0] * t2 + cd[:, 0] * t3
    perm = (np.abs(ad[:, 0]) * (np.abs(bd[:, 1] * cd[:, 2]) + np.abs(bd[:, 2] * cd[:, 1]))
            + np.abs(bd[:, 0]) * (np.abs(cd[:, 1] * ad[:, 2]) + np.abs(cd[:, 2] * ad[:, 1]))
            + np.abs(cd[:, 0]) * (np.abs(ad[:, 1] * bd[:, 2]) + np.abs(ad[:, 2] * bd[:, 1])))
    return det, 1e-14 * perm


def _separated(V, F, I, J):
    """Pairs certainly meeting in nothing more than their shared vertices: the unshared vertices of one are all
    certainly on one side of the other's plane."""
    out = np.zeros(len(I), bool)
    big = float(np.abs(V).max()) if V.size else 0.0
    if big > 0.0:  # a power of two (exact, signs unchanged): no overflow of the products at 1e150
        V = np.ldexp(V, -int(np.frexp(big)[1]))
    for X, Y in ((I, J), (J, I)):
        T, U = F[X], F[Y]
        pos = np.ones(len(X), bool)
        neg = np.ones(len(X), bool)
        unshared = np.zeros(len(X), bool)
        for c in range(3):
            det, bound = _orient_float(V[T[:, 0]], V[T[:, 1]], V[T[:, 2]], V[U[:, c]])
            shared = (U[:, [c]] == T).any(axis=1)
            unshared |= ~shared
            pos &= shared | (det > bound)
            neg &= shared | (det < -bound)
        out |= (pos | neg) & unshared  # (identical triangles are coplanar partners: not separated)
    return out


# ------------------------------------------------------------------------------------------------ one triangle


class _Cut:
    """Constraints collected on one input triangle and its re-triangulation in its plane."""

    def __init__(self, T):
        self.T = T
        self.plane = _Plane(T)
        self.points = []
        self.segments = []

    def triangulate(self):
        """Pieces as triples of exact 3-D points, oriented as the triangle."""
        pl = self.plane
        key = {}
        P3, P2 = [], []

        def pid(p):
            v = key.get(p)
            if v is None:
                v = key[p] = len(P2)
                P2.append(pl.to2d(p))
                P3.append(p)
            return v

        for p in self.T:
            pid(p)
        s = _sign(_orient2d(P2[0], P2[1], P2[2]))
        segs = set()
        for p, q in self.segments:
            a, b = pid(p), pid(q)
            if a != b:
                segs.add((min(a, b), max(a, b)))
        for p in self.points:
            pid(p)
        segs = self._split(segs, P2, P3, pid)
        tris = [(0, 1, 2) if s > 0 else (0, 2, 1)]
        for v in range(3, len(P2)):
            tris = self._insert(tris, v, P2)
        for a, b in sorted(segs):
            tris = self._recover(tris, a, b, P2)
        out = []
        for a, b, c in tris:
            out.append((P3[a], P3[b], P3[c]) if s > 0 else (P3[a], P3[c], P3[b]))
        return out

    @staticmethod
    def _split(segs, P2, P3, pid):
        """Split the segments at the points on them and at their crossings until none crosses another."""
        changed = True
        while changed:
            changed = False
            out = set()
            for a, b in segs:
                pa, pb = P2[a], P2[b]
                # the coordinate along which a -> b runs farther (compared as x / w by cross-multiplication)
                c = 0 if abs(pb[0] * pa[2] - pa[0] * pb[2]) >= abs(pb[1] * pa[2] - pa[1] * pb[2]) else 1
                inner = []
                for v, x in enumerate(P2):
                    if v == a or v == b or _orient2d(pa, pb, x) != 0:
                        continue
                    ta = x[c] * pa[2] - pa[c] * x[2]  # sign of x_c - a_c
                    tb = pb[c] * x[2] - x[c] * pb[2]  # sign of b_c - x_c
                    if (ta > 0 and tb > 0) or (ta < 0 and tb < 0):
                        inner.append((Fraction(x[c], x[2]), v))
                if inner:
                    inner.sort(reverse=Fraction(pb[c], pb[2]) < Fraction(pa[c], pa[2]))
                chain = [a] + [v for _, v in inner] + [b]
                for u, w in zip(chain[:-1], chain[1:]):
                    out.add((min(u, w), max(u, w)))
            segs = out
            S = sorted(segs)
            for i in range(len(S)):
                a, b = S[i]
                for j in range(i + 1, len(S)):
                    c, d = S[j]
                    if len({a, b, c, d}) < 4:
                        continue
                    pa, pb, pc, pd = P2[a], P2[b], P2[c], P2[d]
                    o1, o2 = _orient2d(pa, pb, pc), _orient2d(pa, pb, pd)
                    if o1 == 0 or o2 == 0 or (o1 > 0) == (o2 > 0):
                        continue
                    o3, o4 = _orient2d(pc, pd, pa), _orient2d(pc, pd, pb)
                    if o3 == 0 or o4 == 0 or (o3 > 0) == (o4 > 0):
                        continue
                    # parameter along a -> b: (o3 / w_a) / (o3 / w_a - o4 / w_b)
                    num, den = _ratio(o3 * pb[2], o3 * pb[2] - o4 * pa[2])
                    pid(_lerp3(P3[a], P3[b], num, den))  # the lift is linear along the segment
                    changed = True
                    break
                if changed:
                    break
        return segs

    @staticmethod
    def _insert(tris, v, P2):
        p = P2[v]
        for n, (a, b, c) in enumerate(tris):
            o = (_orient2d(P2[b], P2[c], p), _orient2d(P2[c], P2[a], p), _orient2d(P2[a], P2[b], p))
            if min(o) < 0:
                continue
            zero = [i for i in range(3) if o[i] == 0]
            if not zero:
                return tris[:n] + tris[n + 1:] + [(a, b, v), (b, c, v), (c, a, v)]
            if len(zero) >= 2:
                return tris  # a vertex already
            # on the edge opposite corner zero[0]: split this triangle and the one across the edge
            t = (a, b, c)
            k = zero[0]
            u, w = t[(k + 1) % 3], t[(k + 2) % 3]  # the edge u -> w, opposite t[k]
            out = [x for i, x in enumerate(tris) if i != n] + [(t[k], u, v), (v, w, t[k])]
            for m, (x, y, z) in enumerate(out[:-2]):
                s3 = (x, y, z)
                for e in range(3):
                    if s3[e] == w and s3[(e + 1) % 3] == u:
                        opp = s3[(e + 2) % 3]
                        return [q for i, q in enumerate(out) if i != m] + [(opp, w, v), (v, u, opp)]
            return out
        raise AssertionError("point outside the triangle")

    @staticmethod
    def _recover(tris, a, b, P2):
        """Make a-b an edge: remove the triangles the open segment crosses and re-triangulate both sides."""
        for t in tris:
            if a in t and b in t:
                return tris
        pa, pb = P2[a], P2[b]
        crossed, keep = [], []
        for t in tris:
            x, y, z = (P2[i] for i in t)
            oa = [_orient2d(pa, pb, q) for q in (x, y, z)]
            if max(oa) <= 0 or min(oa) >= 0:
                keep.append(t)
                continue
            sep = False
            for e in range(3):
                u, w = P2[t[e]], P2[t[(e + 1) % 3]]
                if _orient2d(u, w, pa) <= 0 and _orient2d(u, w, pb) <= 0:
                    sep = True
                    break
            (keep if sep else crossed).append(t)
        edges = {}
        for t in crossed:
            for e in range(3):
                edges[(t[e], t[(e + 1) % 3])] = True
        nxt = {}
        for (u, w) in edges:
            if (w, u) not in edges:
                nxt[u] = w
        right = []
        v = nxt[a]
        while v != b:
            right.append(v)
            v = nxt[v]
        left = []
        v = nxt[b]
        while v != a:
            left.append(v)
            v = nxt[v]
        return keep + _Cut._polygon([b, a] + right, P2) + _Cut._polygon([a, b] + left, P2)

    @staticmethod
    def _polygon(poly, P2):
        """Triangulate a counter-clockwise pseudo-polygon with base edge poly[0] -> poly[1] (Delaunay choice of
        the apex, so no triangle crosses the boundary)."""
        if len(poly) < 3:
            return []
        p0, p1, rest = poly[0], poly[1], poly[2:]
        c = 0
        for i in range(1, len(rest)):
            if _incircle(P2[p0], P2[p1], P2[rest[c]], P2[rest[i]]) > 0:
                c = i
        apex = rest[c]
        return ([(p0, p1, apex)] + _Cut._polygon([apex, p1] + rest[:c], P2)
                + _Cut._polygon([p0, apex] + rest[c + 1:], P2))


# ------------------------------------------------------------------------------------------------ arrangement


def arrange(V, F) -> Arrangement:
    """The arrangement of the triangles ``F`` of ``V`` (float64; degenerate triangles are dropped)."""
    V = np.asarray(V, np.float64)
    F = np.asarray(F, np.int64).reshape(-1, 3)
    Vw, inv = np.unique(V, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    Fw = inv[F]
    nondeg = (Fw[:, 0] != Fw[:, 1]) & (Fw[:, 1] != Fw[:, 2]) & (Fw[:, 2] != Fw[:, 0])
    X = Vw[Fw]
    nrm = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    nondeg &= np.abs(nrm).max(axis=1) > 0
    live = np.flatnonzero(nondeg)
    D = _common_denominator(Vw)
    cache = {}

    def vx(i):
        p = cache.get(i)
        if p is None:
            r = [float(x).as_integer_ratio() for x in Vw[i]]
            p = cache[i] = tuple(n * (D // d) for n, d in r) + (1,)
        return p

    def tri(f):
        return tuple(vx(int(i)) for i in Fw[f])

    # exact collinearity check of the triangles the float test could not tell apart from degenerate
    lo, hi = X[live].min(axis=1), X[live].max(axis=1)
    pairs = live[_candidate_pairs(lo, hi)] if len(live) > 1 else np.zeros((0, 2), np.int64)
    if len(pairs):
        pairs = pairs[~_separated(Vw, Fw, pairs[:, 0], pairs[:, 1])]
    cuts = {}
    coplanar = {}

    def cut(f):
        c = cuts.get(f)
        if c is None:
            c = cuts[f] = _Cut(tri(f))
        return c

    for t, u in pairs.tolist():
        T, U = tri(t), tri(u)
        ou = [_orient3d(T[0], T[1], T[2], q) for q in U]
        if all(o > 0 for o in ou) or all(o < 0 for o in ou):
            continue
        if all(o == 0 for o in ou):
            _coplanar(t, u, T, U, cut, coplanar)
            continue
        ot = [_orient3d(U[0], U[1], U[2], q) for q in T]
        if all(o > 0 for o in ot) or all(o < 0 for o in ot):
            continue
        SU, ST = _plane_cut(U, ou), _plane_cut(T, ot)
        if not SU or not ST:
            continue
        d = _normal_cross(T, U)
        k = max(range(3), key=lambda i: abs(d[i]))
        sgn = 1 if d[k] > 0 else -1
        SU.sort(key=lambda p: sgn * _key(p, k))
        ST.sort(key=lambda p: sgn * _key(p, k))
        a = SU[0] if sgn * _key(SU[0], k) >= sgn * _key(ST[0], k) else ST[0]
        b = SU[-1] if sgn * _key(SU[-1], k) <= sgn * _key(ST[-1], k) else ST[-1]
        if sgn * _key(a, k) > sgn * _key(b, k):
            continue
        for f in (t, u):
            c = cut(f)
            if a == b:
                c.points.append(a)
            else:
                c.segments.append((a, b))
    # pieces
    nV = len(Vw)
    ids = {}
    newV = []
    vindex = None

    def gid(p, hint):
        nonlocal vindex
        g = ids.get(p)
        if g is None:
            if p[3] == 1:  # maybe an input vertex that no cut triangle has
                if vindex is None:
                    vindex = {tuple(r): i for i, r in enumerate(Vw.tolist())}
                g = vindex.get(tuple(x / D for x in p[:3]))
            if g is None:
                g = len(newV) + nV
                newV.append(p)
            ids[p] = g
        return g

    for f, c in cuts.items():
        for i, p in zip(Fw[f].tolist(), c.T):
            ids[p] = i
    Fo, parent = [], []
    for f in live.tolist():
        if f not in cuts:
            Fo.append(Fw[f].tolist())
            parent.append(f)
            continue
        for a, b, c in cuts[f].triangulate():
            Fo.append([gid(a, f), gid(b, f), gid(c, f)])
            parent.append(f)
    Vout = np.concatenate([Vw, np.array([[x / (p[3] * D) for x in p[:3]] for p in newV], np.float64).reshape(-1, 3)])
    Fo = np.array(Fo, np.int64).reshape(-1, 3)
    parent = np.array(parent, np.int64)
    covered = {}
    if coplanar:
        exact_of = {g: p for p, g in ids.items()}
        for n in np.flatnonzero(np.isin(parent, list(coplanar))).tolist():
            f = int(parent[n])
            p, q, r = [exact_of[g] if g in exact_of else vx(g) for g in Fo[n].tolist()]
            wp, wq, wr = p[3], q[3], r[3]
            cen = tuple(p[i] * wq * wr + q[i] * wp * wr + r[i] * wp * wq for i in range(3)) + (3 * wp * wq * wr,)
            pl = _Plane(tri(f))
            cov = []
            for u in coplanar[f]:
                U2 = [pl.to2d(p) for p in tri(u)]
                su = _sign(_orient2d(*U2))
                if _inside_closed_2d(pl.to2d(cen), U2, su):
                    cov.append(u)
            if cov:
                covered[n] = cov
    return Arrangement(Vout, Fo, parent, covered)


def _normal_cross(T, U):
    n, m = _normal(T), _normal(U)
    return (n[1] * m[2] - n[2] * m[1], n[2] * m[0] - n[0] * m[2], n[0] * m[1] - n[1] * m[0])


def _coplanar(t, u, T, U, cut, coplanar):
    """Coplanar triangles: each one's edges, clipped to the other, constrain the other; both are recorded as
    coplanar partners (the classification needs to know which pieces more than one triangle covers)."""
    shared = len(set(T) & set(U))
    if shared == 3:  # the same triangle: it covers the other, its edges are already there
        coplanar.setdefault(t, set()).add(u)
        coplanar.setdefault(u, set()).add(t)
        return
    pl = _Plane(T)
    T2, U2 = [pl.to2d(p) for p in T], [pl.to2d(p) for p in U]
    sT, sU = _sign(_orient2d(*T2)), _sign(_orient2d(*U2))
    if shared == 2:  # an edge in common: only touching when the third vertices are on opposite sides of it
        a, b = [p for p in T2 if p in U2]
        c = next(p for p in T2 if p not in U2)
        d = next(p for p in U2 if p not in T2)
        if _orient2d(a, b, c) * _orient2d(a, b, d) < 0:
            return
    touched = False
    for (A3, B2, sB, target, other) in ((U, T2, sT, t, u), (T, U2, sU, u, t)):
        A2 = [pl.to2d(p) for p in A3]
        for e in range(3):
            span = _segment_in_triangle_2d(A2[e], A2[(e + 1) % 3], B2, sB)
            if span is None:
                continue
            touched = True
            (ln, ld), (hn, hd) = span
            P = [_lerp3(A3[e], A3[(e + 1) % 3], ln, ld)]
            if ln * hd != hn * ld:
                P.append(_lerp3(A3[e], A3[(e + 1) % 3], hn, hd))
            if len(P) == 1:
                cut(target).points.append(P[0])
            else:
                cut(target).segments.append((P[0], P[1]))
            cut(other).points.extend(P)  # where the edge enters and leaves the other triangle
    if touched:
        coplanar.setdefault(t, set()).add(u)
        coplanar.setdefault(u, set()).add(t)


def _common_denominator(V):
    """The power of two that makes every coordinate of V an integer."""
    X = np.asarray(V, np.float64).ravel()
    X = X[X != 0]
    if X.size == 0:
        return 1
    m, e = np.frexp(np.abs(X))
    M = (m * 2.0 ** 53).astype(np.int64)  # X = M 2^(e - 53), M < 2^53 (subnormals: fewer bits, still exact)
    tz = np.zeros_like(M)
    low = M & -M
    tz = np.round(np.log2(low.astype(np.float64))).astype(np.int64)
    k = int((53 - e - tz).max())
    return 1 << max(k, 0)
