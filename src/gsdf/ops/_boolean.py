"""Mesh booleans by trimming each operand against the winding field of the other.

Barill et al. 2018, *Fast Winding Numbers for Soups and Clouds*, §4 "Booleans" (Figs. 12-15): "rather than
intersect the triangles, we trim each mesh against the winding field of the other [Jacobson 2016]". The
generalized winding number ``w_B`` of operand B is evaluated at the vertices of A (and ``w_A`` at those of
B); the part of each surface on the wanted side of the ``1/2`` level set of the other's field is kept:

================  =========================  ==============================================
operation         part of A kept             part of B kept
================  =========================  ==============================================
``union``         ``w_B < 1/2`` (outside B)  ``w_A < 1/2`` (outside A)
``intersection``  ``w_B > 1/2`` (inside B)   ``w_A > 1/2`` (inside A)
``difference``    ``w_B < 1/2`` (outside B)  ``w_A > 1/2`` (inside A), faces flipped
================  =========================  ==============================================

Triangles whose vertices lie on both sides are cut with a vectorized "marching triangles" table: the
crossing point on each cut edge is found by bisection of the other operand's winding field along the edge,
computed once per undirected edge so that neighbouring triangles share it (the trimmed surface stays
watertight where the input was). Because both fields are generalized winding numbers, the operation is
meaningful for holey, non-manifold or self-intersecting inputs (Figs. 12-14), and the field of an operand
can come from an oriented point cloud instead (Fig. 15).

Finally (optional, on by default) the two trim curves are *stitched*: each closed cut loop of A is zipped
to the matching closed cut loop of B with a strip of (thin) triangles, so that the result of closed inputs
is a closed, consistently oriented surface. The paper leaves these seams open ("Triangle edges are not
stitched in the few areas where they do touch. While this is possible, it is insignificant"); pass
``BooleanOptions(stitch=False)`` for that behaviour.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from gsdf._checks import as_mesh, choice, flag, integer, positive

__all__ = ["mesh_boolean", "trim_mesh", "BooleanOptions"]


@dataclasses.dataclass(frozen=True)
class BooleanOptions:
    """How :func:`mesh_boolean` evaluates the winding fields and joins the trimmed operands.

    Attributes
    ----------
    beta : float, default 2.0
        Accuracy of the fast winding number (Barill et al. 2018 §3.4); ignored with ``exact=True`` and for
        winding fields passed in.
    exact : bool, default False
        The exact winding number (O(m) per query) instead of the fast tree approximation.
    bisection_steps : int, default 12
        Bisection iterations locating each crossing point on a cut edge (error <= edge length / 2**steps).
    stitch : bool, default True
        Zip the closed trim loops of A and B together with thin triangle strips, so that closed inputs give
        a closed, consistently oriented result; ``False`` leaves the seams open, as in the paper. Open trim
        curves (where the other operand has holes) are left as they are.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1.0]])  # a tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> opts = gsdf.BooleanOptions(exact=True, stitch=False)
    >>> gsdf.mesh_boolean(V, F, V + 5.0, F, "union", options=opts)[1].shape
    (8, 3)
    """

    beta: float = 2.0
    exact: bool = False
    bisection_steps: int = 12
    stitch: bool = True

    def __post_init__(self):  # a ValueError naming the attribute, at construction
        positive(self.beta, "beta", most=1e150)
        flag(self.exact, "exact")
        _steps(self.bisection_steps)
        flag(self.stitch, "stitch")

_OPS = ("union", "intersection", "difference")


# ----------------------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------------------


def _refine_on_edges_fallback(func, A, B, fa, fb, level, steps):
    """Vectorized bisection for ``func = level`` on segments ``A -> B`` whose end values straddle ``level``."""
    lo = np.array(A, dtype=np.float64, copy=True)
    hi = np.array(B, dtype=np.float64, copy=True)
    sa = np.asarray(fa, dtype=np.float64) >= level
    for _ in range(int(steps)):
        mid = 0.5 * (lo + hi)
        sm = np.asarray(func(mid), dtype=np.float64).reshape(-1) >= level
        same = sm == sa
        lo[same] = mid[same]
        hi[~same] = mid[~same]
    return 0.5 * (lo + hi)


def _refine_on_edges():
    try:
        from gsdf.contour._isosurface import refine_on_edges
    except ImportError:  # the contour module is optional here
        return _refine_on_edges_fallback
    return refine_on_edges


def _checked_field(f, name):
    """Wrap a user-provided winding callable so its output is validated (shape (q,), finite)."""
    if not callable(f):
        raise ValueError(f"{name}: expected a callable Q (q, 3) -> (q,), got {type(f).__name__}")

    def g(Q):
        w = np.asarray(f(Q), dtype=np.float64)
        if w.size != Q.shape[0]:
            raise ValueError(f"{name}: returned shape {w.shape} for {Q.shape[0]} query points")
        w = w.reshape(-1)
        if not np.isfinite(w).all():
            raise ValueError(f"{name}: returned NaN or infinite winding numbers")
        return w

    return g


def _default_field(V, F, beta, exact):
    if exact:
        from gsdf.winding import winding_number

        return lambda Q: winding_number(V, F, Q)
    from gsdf.winding import FastWindingNumber

    return FastWindingNumber(V, F, beta=beta)


# ----------------------------------------------------------------------------------------------------------
# trimming (marching triangles)
# ----------------------------------------------------------------------------------------------------------


def _trim(V, F, field, keep_inside, steps, refine):
    """Keep the part of (V, F) where ``field > 1/2`` (keep_inside) or ``field < 1/2``.

    Returns ``(V_out, F_out, cut)`` where ``cut`` (k, 2) are the directed cut segments (half-edges of
    ``F_out`` lying on the trim curve), in output vertex indices.
    """
    nV = V.shape[0]
    used = np.zeros(nV, dtype=bool)
    used[F.ravel()] = True
    w = np.full(nV, 0.5)
    uidx = np.flatnonzero(used)
    w[uidx] = field(V[uidx])
    kept = (w > 0.5) if keep_inside else (w < 0.5)
    kept &= used

    K = kept[F]
    nk = K.sum(axis=1)
    full = F[nk == 3]
    ar = np.arange(3)
    # one kept corner: rotate it to position 0 -> (a, b, c), keep triangle (a, X_ab, X_ca)
    F1, K1 = F[nk == 1], K[nk == 1]
    T1 = np.take_along_axis(F1, (np.argmax(K1, axis=1)[:, None] + ar) % 3, axis=1)
    # two kept corners: rotate the dropped one to position 0 -> (a, b, c), keep quad (X_ab, b, c, X_ca)
    F2, K2 = F[nk == 2], K[nk == 2]
    T2 = np.take_along_axis(F2, (np.argmin(K2, axis=1)[:, None] + ar) % 3, axis=1)

    n1, n2 = T1.shape[0], T2.shape[0]
    # the cut edges, ab and ca of every straddling triangle, keyed by the undirected edge (min, max)
    E = np.concatenate((T1[:, [0, 1]], T1[:, [2, 0]], T2[:, [0, 1]], T2[:, [2, 0]]))
    E.sort(axis=1)
    if E.shape[0]:
        Eu, inv = np.unique(E, axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        X = refine(field, V[Eu[:, 0]], V[Eu[:, 1]], w[Eu[:, 0]], w[Eu[:, 1]], 0.5, steps)
        X = np.asarray(X, dtype=np.float64).reshape(-1, 3)
    else:
        inv = np.zeros(0, dtype=np.int64)
        X = np.zeros((0, 3))

    # output vertices: kept original vertices, then the crossing points
    kidx = np.flatnonzero(kept)
    remap = np.full(nV, -1, dtype=np.int64)
    remap[kidx] = np.arange(kidx.shape[0])
    nk_out = kidx.shape[0]
    xid = nk_out + inv
    x1_ab, x1_ca = xid[:n1], xid[n1:2 * n1]
    x2_ab, x2_ca = xid[2 * n1:2 * n1 + n2], xid[2 * n1 + n2:]

    faces = [
        remap[full],
        np.column_stack((remap[T1[:, 0]], x1_ab, x1_ca)),
        np.column_stack((x2_ab, remap[T2[:, 1]], remap[T2[:, 2]])),
        np.column_stack((x2_ab, remap[T2[:, 2]], x2_ca)),
    ]
    Fo = np.concatenate(faces).astype(np.int64).reshape(-1, 3)
    Vo = np.concatenate((V[kidx], X)).reshape(-1, 3)
    cut = np.concatenate((np.column_stack((x1_ab, x1_ca)), np.column_stack((x2_ca, x2_ab)))).astype(np.int64)
    return Vo, Fo, cut.reshape(-1, 2)


def trim_mesh(V, F, winding, keep="outside", bisection_steps=12):
    """Trim a mesh/soup against a winding field: keep the part where ``winding < 1/2`` or ``> 1/2``.

    The building block of :func:`mesh_boolean` (Barill et al. 2018, §4 "Booleans", after Jacobson 2016).
    Triangles straddling the 1/2 level are cut along edges; crossing points are found by bisection of
    ``winding`` and shared between neighbouring triangles through their undirected edge.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    winding : callable
        ``winding(Q (q, 3)) -> (q,)``, e.g. a :class:`gsdf.winding.FastWindingNumber` of another shape.
    keep : {"outside", "inside"}
        Keep where ``winding < 1/2`` ("outside") or ``winding > 1/2`` ("inside").
    bisection_steps : int
        Bisection iterations per cut edge (error <= edge length / 2**bisection_steps).

    Returns
    -------
    V_out : (n', 3) float64
    F_out : (m', 3) int64
        Empty ``(0, 3)`` arrays when nothing is kept.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.ops import trim_mesh
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    >>> inside_half = lambda Q: (Q[:, 0] < 0.5).astype(float)   # "winding number" of the half-space x < 1/2
    >>> Vt, Ft = trim_mesh(V, [[0, 1, 2]], inside_half, keep="inside")   # a quad: 2 triangles
    >>> Ft.shape
    (2, 3)
    >>> Vt, Ft = trim_mesh(V, [[0, 1, 2]], inside_half, keep="outside")  # the corner at x = 1
    >>> Ft.shape, round(float(Vt[:, 0].min()), 3)
    ((1, 3), 0.5)
    """
    V, F = as_mesh(V, F)
    choice(keep, "keep", ("outside", "inside"))
    steps = _steps(bisection_steps)
    Vo, Fo, _ = _trim(V, F, _checked_field(winding, "winding"), keep == "inside", steps, _refine_on_edges())
    return _compact(Vo, Fo)


def _steps(bisection_steps):
    return integer(bisection_steps, "bisection_steps", 0, hi=60)


def _compact(V, F):
    if F.shape[0] == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return V, F


# ----------------------------------------------------------------------------------------------------------
# stitching the two trim curves
# ----------------------------------------------------------------------------------------------------------


def _closed_loops(H):
    """Closed loops of a set of directed segments H (k, 2); vertices of in/out degree != 1 are skipped."""
    if H.shape[0] == 0:
        return []
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    verts, Hc = np.unique(H, return_inverse=True)
    Hc = Hc.reshape(-1, 2)
    n = verts.shape[0]
    outd = np.bincount(Hc[:, 0], minlength=n)
    ind = np.bincount(Hc[:, 1], minlength=n)
    G = coo_matrix((np.ones(Hc.shape[0]), (Hc[:, 0], Hc[:, 1])), shape=(n, n))
    ncomp, lab = connected_components(G, directed=False)
    bad = np.zeros(ncomp, dtype=bool)
    bad[lab[(outd != 1) | (ind != 1)]] = True
    nxt = np.full(n, -1, dtype=np.int64)
    ok = outd == 1
    first = np.full(n, -1, dtype=np.int64)
    first[Hc[::-1, 0]] = np.arange(Hc.shape[0])[::-1]
    nxt[ok] = Hc[first[ok], 1]
    loops = []
    starts = np.full(ncomp, -1, dtype=np.int64)
    starts[lab[::-1]] = np.arange(n)[::-1]
    for c in np.flatnonzero(~bad):
        s = int(starts[c])
        seq = [s]
        v = int(nxt[s])
        while v != s:
            seq.append(v)
            v = int(nxt[v])
        if len(seq) >= 3:
            loops.append(verts[np.array(seq, dtype=np.int64)])
    return loops


def _zip_loops(V, P, Q):
    """Triangle strip between loop P (order of the kept faces' half-edges) and loop Q (the other operand).

    The strip contains every P segment reversed (p_{i+1} -> p_i) so it glues consistently to the faces that
    carry p_i -> p_{i+1}; Q is walked in the same geometric direction as P (and so is reversed relative to its
    own faces when the inputs are consistently oriented).
    """
    XP, XQ = V[P], V[Q]
    from scipy.spatial import cKDTree

    _, near = cKDTree(XQ).query(XP)
    tP = np.roll(XP, -1, axis=0) - np.roll(XP, 1, axis=0)
    tQ = np.roll(XQ, -1, axis=0) - np.roll(XQ, 1, axis=0)
    if np.einsum("ij,ij->", tP, tQ[near]) < 0:
        Q = Q[::-1]
        XQ = XQ[::-1]
        near = Q.shape[0] - 1 - near
    j0 = int(near[0])
    Q = np.roll(Q, -j0)
    XQ = np.roll(XQ, -j0, axis=0)
    m, n = P.shape[0], Q.shape[0]
    out = np.empty((m + n, 3), dtype=np.int64)
    i = j = 0
    t = 0
    while i < m or j < n:
        if j == n or (i < m and np.sum((XP[(i + 1) % m] - XQ[j % n]) ** 2)
                      <= np.sum((XP[i % m] - XQ[(j + 1) % n]) ** 2)):
            out[t] = (P[(i + 1) % m], P[i % m], Q[j % n])
            i += 1
        else:
            out[t] = (Q[j % n], Q[(j + 1) % n], P[i % m])
            j += 1
        t += 1
    return out


def _stitch(V, cutA, cutB):
    """Zip every closed cut loop of A to the closed cut loop of B that runs along it."""
    loopsA, loopsB = _closed_loops(cutA), _closed_loops(cutB)
    if not loopsA or not loopsB:
        return np.zeros((0, 3), dtype=np.int64)
    from scipy.spatial import cKDTree

    def seg_len(L):
        X = V[L]
        return float(np.linalg.norm(np.roll(X, -1, axis=0) - X, axis=1).max())

    def match(src, dst):
        pts = np.concatenate(dst)
        lab = np.repeat(np.arange(len(dst)), [len(L) for L in dst])
        tree = cKDTree(V[pts])
        res = []
        for L in src:
            d, k = tree.query(V[L])
            cnt = np.bincount(lab[k], minlength=len(dst))
            b = int(np.argmax(cnt))
            tol = max(seg_len(L), seg_len(dst[b]))
            # every point of L must be near the same loop of the other curve (same topology), within a segment
            res.append(b if (cnt[b] == len(L) and d.max() <= tol) else -1)
        return res

    ab, ba = match(loopsA, loopsB), match(loopsB, loopsA)
    strips = [_zip_loops(V, loopsA[a], loopsB[b]) for a, b in enumerate(ab) if b >= 0 and ba[b] == a]
    if not strips:
        return np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(strips)


# ----------------------------------------------------------------------------------------------------------
# public entry point
# ----------------------------------------------------------------------------------------------------------


def mesh_boolean(VA, FA, VB, FB, op, winding_a=None, winding_b=None, options: BooleanOptions | None = None):
    """Boolean of two meshes or triangle soups by trimming each against the other's winding field.

    Barill et al. 2018, §4 "Booleans" (Figs. 12-15), after Jacobson 2016: no triangle-triangle intersection
    is computed; A is trimmed against the 1/2 level set of the generalized winding number ``w_B`` of B, and B
    against that of ``w_A``. Works on holey, non-manifold, self-intersecting inputs ("where triangles exist,
    the cut lines follow them, and where they do not, something sensible happens").

    Parameters
    ----------
    VA, VB : (nA, 3), (nB, 3) float
        Vertex positions.
    FA, FB : (mA, 3), (mB, 3) int
        Triangles. Crossing points are shared through vertex indices, so weld duplicated vertices first if
        the trimmed surface should stay connected.
    op : {"union", "intersection", "difference"}
        ``difference`` is A minus B (the kept part of B is flipped so the result faces outward).
    winding_a, winding_b : callable, optional
        Override the winding field of A (evaluated at B's vertices) or of B (evaluated at A's vertices):
        ``f(Q (q, 3)) -> (q,)``. E.g. pass ``FastWindingNumberPoints(P, N)`` of an oriented point cloud and,
        as ``VB, FB``, a surface reconstructed from it (e.g. its winding isosurface) — the hybrid
        point/mesh boolean of Fig. 15.
    options : BooleanOptions, optional
        Winding accuracy (``beta``, ``exact``), ``bisection_steps`` and ``stitch``.

    Returns
    -------
    V : (n, 3) float64
        Kept vertices of A, crossing points on A, kept vertices of B, crossing points on B (each crossing
        point once).
    F : (m, 3) int64
        Triangles. When the result is empty (e.g. the intersection of disjoint shapes), ``V`` and ``F`` are
        empty arrays of shape ``(0, 3)``.

    Raises
    ------
    ValueError
        Unknown ``op``, NaN/inf coordinates, out-of-range or non-integer faces, bad options, or a winding
        override that is not callable or returns bad values.

    Notes
    -----
    * Each trimmed operand is watertight wherever its input was (crossing points are keyed by the
      undirected edge). The two trim curves both lie on the intersection curve but have different vertices;
      ``stitch=True`` zips each closed trim loop of A to the closed trim loop of B that follows it (matched
      when every point of each loop is within one segment length of the other). Where the two trim curves
      have different topology — the surfaces meet in features smaller than the triangles, e.g. a cube corner
      poking through a single coarse triangle — or a curve is open (a hole of the other operand crosses it),
      that seam is left open, as in the paper.
    * Coincident (coplanar, overlapping) faces are degenerate: their vertices have winding number 1/2 up to
      round-off, so such faces may be kept twice or dropped. Perturb one operand slightly.
    * Crossing points are shared through vertex *indices*: weld duplicated vertices of a soup first if its
      trimmed copy should stay connected.
    * Cost: one winding evaluation at every vertex of each operand plus ``bisection_steps`` evaluations at
      the cut edges, i.e. O((n + k * steps) log m) with the fast winding number (§3).

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.ops import mesh_boolean
    >>> V = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1.0]])  # a tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> Vu, Fu = mesh_boolean(V, F, V + 5.0, F, "union")   # disjoint: union is both
    >>> Fu.shape
    (8, 3)
    >>> mesh_boolean(V, F, V + 5.0, F, "intersection")[1].shape
    (0, 3)
    """
    choice(op, "op", _OPS)
    VA, FA = as_mesh(VA, FA)
    VB, FB = as_mesh(VB, FB)
    o = BooleanOptions() if options is None else options
    if not isinstance(o, BooleanOptions):
        raise ValueError(f"options: expected a gsdf.BooleanOptions, got {type(o).__name__}")
    beta, exact, stitch = positive(o.beta, "beta"), o.exact, o.stitch
    for name, flag in (("exact", exact), ("stitch", stitch)):
        if not isinstance(flag, (bool, np.bool_)):
            raise ValueError(f"{name}: expected True or False, got {flag!r}")
    steps = _steps(o.bisection_steps)
    # scale invariance: trim and stitch in the normalised frame of both operands (gsdf._normalize)
    from gsdf._normalize import Frame

    frame = Frame.of(np.concatenate((VA, VB)))
    VA, VB = frame.geometry(VA, "VA"), frame.geometry(VB, "VB")
    fA = _checked_field(winding_a, "winding_a") if winding_a is not None else _default_field(VA, FA, beta, exact)
    fB = _checked_field(winding_b, "winding_b") if winding_b is not None else _default_field(VB, FB, beta, exact)
    if not frame.identity:  # user winding fields take input coordinates
        fA = (lambda f: lambda Q: f(frame.point(Q)))(fA) if winding_a is not None else fA
        fB = (lambda f: lambda Q: f(frame.point(Q)))(fB) if winding_b is not None else fB
    refine = _refine_on_edges()

    keepA_inside = op == "intersection"
    keepB_inside = op in ("intersection", "difference")
    FBo = FB[:, ::-1].copy() if op == "difference" else FB
    VAo, FAo, cutA = _trim(VA, FA, fB, keepA_inside, steps, refine)
    VBo, FBo, cutB = _trim(VB, FBo, fA, keepB_inside, steps, refine)
    off = VAo.shape[0]
    V = np.concatenate((VAo, VBo))
    F = np.concatenate((FAo, FBo + off))
    if stitch and cutA.shape[0] and cutB.shape[0]:
        S = _stitch(V, cutA, cutB + off)
        F = np.concatenate((F, S))
    if F.shape[0] == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    # drop vertices no face uses (only possible for vertices of degenerate input)
    used, Fc = np.unique(F, return_inverse=True)
    if used.shape[0] != V.shape[0]:
        V, F = V[used], Fc.reshape(-1, 3)
    return np.ascontiguousarray(frame.point(V), dtype=np.float64), np.ascontiguousarray(F, dtype=np.int64)
