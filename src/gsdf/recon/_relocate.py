"""Vertex relocation of a reconstructed mesh onto the local surface of the samples (geometry only).

The guarantee layer (:mod:`gsdf.recon._grow`) outputs the boundary of a tet region: its vertices are sample points and
Steiner points, so the surface is faceted, and Steiner vertices (and kept outliers) stand off the sampled
surface.  This module moves vertices onto the *local surface* of the samples — a moving-least-squares fit
(Levin 2003; Alexa et al. 2003): around each vertex, the Gaussian-weighted plane of its k nearest samples,
then a weighted least-squares quadric height function z(x, y) over that plane — and smooths them
tangentially, keeping the face list as it is.  The combinatorics, hence the topology (one closed manifold
sphere per region), are untouched; moves that would flip a face are damped and, failing that, undone.

Example
-------
>>> import numpy as np
>>> from gsdf.recon._relocate import local_surface
>>> rng = np.random.default_rng(0)
>>> S = rng.normal(size=(3000, 3)); S /= np.linalg.norm(S, axis=1)[:, None]      # unit sphere samples
>>> foot, normal, height = local_surface(np.array([[0.0, 0.0, 1.1]]), S, spacing=0.04)
>>> bool(abs(np.linalg.norm(foot) - 1.0) < 1e-3), bool(abs(height[0] - 0.1) < 1e-2)
(True, True)
"""

from __future__ import annotations

import numba as nb
import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from gsdf._checks import as_faces, as_points, integer, nonnegative, positive
from gsdf.linalg._eig3 import jacobi_eig3

__all__ = ["local_surface", "relocate_vertices", "subdivide_onto_samples"]


@nb.njit(cache=True)
def _eigh3(A, V, frame, i):
    """Eigenvectors of the symmetric 3 × 3 matrix A (overwritten) by cyclic Jacobi rotations (to rounding),
    written as the rows of frame[i] by descending eigenvalue (t1, t2, n: n the smallest); V: 3 × 3 scratch."""
    jacobi_eig3(A, V)
    # descending order of the eigenvalues A[j, j]
    o0, o1, o2 = 0, 1, 2
    if A[o0, o0] < A[o1, o1]:
        o0, o1 = o1, o0
    if A[o1, o1] < A[o2, o2]:
        o1, o2 = o2, o1
    if A[o0, o0] < A[o1, o1]:
        o0, o1 = o1, o0
    for r in range(3):
        frame[i, 0, r] = V[r, o0]
        frame[i, 1, r] = V[r, o1]
        frame[i, 2, r] = V[r, o2]


_BLOCK = 512          # queries per parallel task of the fit kernels (scratch allocated once per task)


@nb.njit(cache=True, parallel=True)
def _weighted_moments(S, I, d, cnt, spacing):
    """Per query (its neighbours' rows I (q, k) of S and distances d (q, k), ascending as the k-d tree returns
    them; only the first cnt[i] of row i count, the others get weight 0): the scale h = max(1.5 × spacing,
    median of those distances), the normalised Gaussian weights w (q, k), their centroid c (q, 3) and the
    eigenvectors of the weighted covariance of the neighbours about it, as the rows t1, t2, n of frame
    (q, 3, 3) by descending eigenvalue (n: the normal of the local plane)."""
    q, k = d.shape
    h = np.empty(q)
    w = np.empty((q, k))
    c = np.empty((q, 3))
    frame = np.empty((q, 3, 3))
    for blk in nb.prange((q + _BLOCK - 1) // _BLOCK):
        C = np.empty((3, 3))
        Vs = np.empty((3, 3))
        for i in range(blk * _BLOCK, min(q, (blk + 1) * _BLOCK)):
            m = cnt[i]
            med = d[i, m // 2] if m % 2 == 1 else 0.5 * (d[i, m // 2 - 1] + d[i, m // 2])
            hi = max(1.5 * spacing, med)
            h[i] = hi
            tot = 0.0
            for j in range(k):
                r = d[i, j] / hi
                w[i, j] = np.exp(-(r * r)) if j < m else 0.0
                tot += w[i, j]
            tot = max(tot, 1e-300)
            cx = cy = cz = 0.0
            for j in range(k):
                w[i, j] /= tot
                s = I[i, j]
                cx += w[i, j] * S[s, 0]
                cy += w[i, j] * S[s, 1]
                cz += w[i, j] * S[s, 2]
            c[i, 0], c[i, 1], c[i, 2] = cx, cy, cz
            c00 = c01 = c02 = c11 = c12 = c22 = 0.0
            for j in range(k):
                s = I[i, j]
                rx, ry, rz = S[s, 0] - cx, S[s, 1] - cy, S[s, 2] - cz
                wj = w[i, j]
                c00 += wj * rx * rx
                c01 += wj * rx * ry
                c02 += wj * rx * rz
                c11 += wj * ry * ry
                c12 += wj * ry * rz
                c22 += wj * rz * rz
            C[0, 0], C[0, 1], C[0, 2] = c00, c01, c02
            C[1, 0], C[1, 1], C[1, 2] = c01, c11, c12
            C[2, 0], C[2, 1], C[2, 2] = c02, c12, c22
            _eigh3(C, Vs, frame, i)
    return h, w, c, frame


@nb.njit(cache=True, parallel=True)
def _quadric_solve(S, I, w, c, frame, h, Q):
    """Per query: the weighted least-squares quadric height z = a0 + a1 x + a2 y + a3 x² + a4 xy + a5 y² of the
    neighbours (rows I (q, k) of S, weights w) in the frame (rows t1, t2, n) at c, coordinates over h, with a
    small ridge on the quadratic terms (6 × 6 normal equations, LU with partial pivoting).  Returns the
    coefficients (q, 6), the weighted rms residual (q,), and for the query points Q (q, 3) the signed height
    z_q − z(x_q, y_q) (q,) and the foot Q − height · n (q, 3)."""
    q, k = w.shape
    coef = np.empty((q, 6))
    rms = np.empty(q)
    hgt = np.empty(q)
    foot = np.empty((q, 3))
    ridge = np.array([1e-9, 1e-9, 1e-9, 1e-2, 1e-2, 1e-2])
    for blk in nb.prange((q + _BLOCK - 1) // _BLOCK):
        A = np.empty((6, 7))
        bas = np.empty((k, 6))
        zs = np.empty(k)
        for i in range(blk * _BLOCK, min(q, (blk + 1) * _BLOCK)):
            A[:] = 0.0
            hi = h[i]
            for j in range(k):
                s = I[i, j]
                rx, ry, rz = S[s, 0] - c[i, 0], S[s, 1] - c[i, 1], S[s, 2] - c[i, 2]
                x = (rx * frame[i, 0, 0] + ry * frame[i, 0, 1] + rz * frame[i, 0, 2]) / hi
                y = (rx * frame[i, 1, 0] + ry * frame[i, 1, 1] + rz * frame[i, 1, 2]) / hi
                z = rx * frame[i, 2, 0] + ry * frame[i, 2, 1] + rz * frame[i, 2, 2]
                bas[j, 0], bas[j, 1], bas[j, 2], bas[j, 3], bas[j, 4], bas[j, 5] = 1.0, x, y, x * x, x * y, y * y
                zs[j] = z
                wj = w[i, j]
                for a in range(6):
                    wa = wj * bas[j, a]
                    for b in range(6):
                        A[a, b] += wa * bas[j, b]
                    A[a, 6] += wa * z
            for a in range(6):
                A[a, a] += ridge[a]
            for col in range(6):                 # Gaussian elimination with partial pivoting
                p = col
                for r in range(col + 1, 6):
                    if abs(A[r, col]) > abs(A[p, col]):
                        p = r
                if p != col:
                    for b in range(7):
                        A[col, b], A[p, b] = A[p, b], A[col, b]
                for r in range(col + 1, 6):
                    f = A[r, col] / A[col, col]
                    for b in range(col, 7):
                        A[r, b] -= f * A[col, b]
            for a in range(5, -1, -1):
                v = A[a, 6]
                for b in range(a + 1, 6):
                    v -= A[a, b] * coef[i, b]
                coef[i, a] = v / A[a, a]
            e = 0.0
            for j in range(k):
                f = zs[j]
                for a in range(6):
                    f -= bas[j, a] * coef[i, a]
                e += w[i, j] * f * f
            rms[i] = np.sqrt(e)
            rx, ry, rz = Q[i, 0] - c[i, 0], Q[i, 1] - c[i, 1], Q[i, 2] - c[i, 2]
            x = (rx * frame[i, 0, 0] + ry * frame[i, 0, 1] + rz * frame[i, 0, 2]) / hi
            y = (rx * frame[i, 1, 0] + ry * frame[i, 1, 1] + rz * frame[i, 1, 2]) / hi
            z = rx * frame[i, 2, 0] + ry * frame[i, 2, 1] + rz * frame[i, 2, 2]
            zf = coef[i, 0] + coef[i, 1] * x + coef[i, 2] * y + coef[i, 3] * x * x + coef[i, 4] * x * y \
                + coef[i, 5] * y * y
            hgt[i] = z - zf
            for a in range(3):
                foot[i, a] = Q[i, a] - (z - zf) * frame[i, 2, a]
    return coef, rms, hgt, foot


_SIDE_POOL = 3         # one-sided fits pick their k samples among the nearest _SIDE_POOL × k


def _one_sided(I, d, NS, Nq, k, side_cos):
    """The first ``k`` columns of the neighbour lists (I, d) (q, K), K ≥ k ascending, with the samples facing
    the query's side first: those whose oriented normal NS[I] has cosine > ``side_cos`` with the query's
    normal Nq (q, 3), in ascending distance; returns (I, d, cnt) with cnt (q,) the number of such samples
    among the k (rows with fewer than 3 keep all k nearest, cnt = k: too few to fit one side)."""
    ok = np.einsum("qkx,qx->qk", NS[I], Nq) > side_cos
    order = np.argsort(~ok, axis=1, kind="stable")[:, :k]
    Is = np.take_along_axis(I, order, axis=1)
    ds = np.take_along_axis(d, order, axis=1)
    cnt = np.minimum(ok.sum(axis=1), k)
    few = cnt < 3
    Is[few], ds[few], cnt[few] = I[few, :k], d[few, :k], k
    return np.ascontiguousarray(Is), np.ascontiguousarray(ds), cnt.astype(np.int64)


def _mls(Q, S, spacing, k, extra, tree, NS=None, Nq=None, side_cos=0.0):
    """The weighted quadric fits of :func:`local_surface` around each query (the ``k`` nearest samples after
    skipping ``extra``; with sample normals NS and query normals Nq, the ``k`` nearest on the query's side,
    :func:`_one_sided`): centre c (q, 3), frame (q, 3, 3) rows t1, t2, n, scale h (q,), coefficients (q, 6), the
    weighted rms residual of the fit (q,), the query's height over the quadric (q,) and its foot (q, 3)."""
    from gsdf.threads import get_num_threads

    Q = np.ascontiguousarray(Q, dtype=np.float64)
    S = np.ascontiguousarray(S, dtype=np.float64)
    kq = k if NS is None else min(_SIDE_POOL * k, len(S) - extra)
    # threads only for many queries: each query call starts its workers anew
    d, I = tree.query(Q, k=kq + extra, workers=get_num_threads() if len(Q) >= 32768 else 1)
    d = np.ascontiguousarray(d.reshape(len(Q), -1)[:, extra:])
    I = np.ascontiguousarray(I.reshape(len(Q), -1)[:, extra:])
    if NS is None:
        cnt = np.full(len(Q), k, dtype=np.int64)
    else:
        I, d, cnt = _one_sided(I, d, NS, Nq, k, side_cos)
    h, w, c, frame = _weighted_moments(S, I, d, cnt, float(spacing))
    coef, rms, hgt, foot = _quadric_solve(S, I, w, c, frame, h, Q)
    return c, frame, h, coef, rms, hgt, foot


def _fit_quadrics(Q, S, spacing, k, extra, tree):
    """:func:`_mls` without the queries' feet: (c, frame, h, coef, rms)."""
    return _mls(Q, S, spacing, k, extra, tree)[:5]


def local_surface(Q, S, spacing: float, k: int = 12, exclude_self: bool = False, tree=None,
                  return_fit: bool = False, normals=None, query_normals=None, side_cos: float = 0.0):
    """Project queries onto the moving-least-squares quadric of their nearest samples.

    For each query q: the ``k`` nearest samples get Gaussian weights exp(−(d / h)²) with h = max(1.5 ×
    ``spacing``, the median neighbour distance); their weighted centroid c and smallest-eigenvalue direction n
    of the weighted covariance give the local plane; in the frame (t1, t2, n) at c, the weighted least-squares
    quadric z = a0 + a1 x + a2 y + a3 x² + a4 xy + a5 y² (a small ridge on the quadratic terms keeps flat or
    sparse neighbourhoods well posed) is the local surface, and q moves along n onto it.

    Parameters
    ----------
    Q : (q, 3) float — queries.  S : (s, 3) float — samples, s ≥ 3.  spacing : float > 0 — sample spacing.
    k : int ≥ 3 — neighbours per query (clipped to the number of samples).
    exclude_self : bool — drop each query's nearest sample (use when the queries are samples: the
        leave-one-out height then says how far a sample is from its neighbours' surface).
    tree : cKDTree of ``S`` or None (built here).
    return_fit : bool — also return the weighted rms residual of the quadric fit (q,): large where the
        neighbours are not one smooth sheet (creases, both sides of a thin part).
    normals, query_normals : (s, 3), (q, 3) float or None — oriented normals of the samples and of the
        queries (say a mesh's vertex normals), both or neither.  Given: a one-sided fit — the ``k`` samples are
        the nearest among the 3 ``k`` nearest whose normal has cosine > ``side_cos`` with the query's (the
        query's side of a thin part only; the far side's normals point the other way); a query with fewer
        than 3 such samples keeps its ``k`` nearest.

    Returns
    -------
    foot : (q, 3) float — the query moved along n onto the quadric.  normal : (q, 3) float — n (unoriented).
    height : (q,) float — signed offset of the query from the quadric along n.  rms : (q,) float, with
    ``return_fit``.
    """
    Q = np.asarray(Q, dtype=np.float64).reshape(-1, 3)
    S = np.asarray(S, dtype=np.float64).reshape(-1, 3)
    extra = 1 if exclude_self else 0
    k = int(min(k, len(S) - extra))
    if k < 3:
        raise ValueError(f"S: needs at least {3 + extra} samples for a local surface, got {len(S)}")
    tree = cKDTree(S) if tree is None else tree
    NS = Nq = None
    if (normals is None) != (query_normals is None):
        raise ValueError("normals, query_normals: give both or neither")
    if normals is not None:
        NS = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
        Nq = np.asarray(query_normals, dtype=np.float64).reshape(-1, 3)
        if NS.shape != S.shape or Nq.shape != Q.shape:
            raise ValueError(f"normals, query_normals: expected shapes {S.shape} and {Q.shape}, got {NS.shape} "
                             f"and {Nq.shape}")
    _, frame, _, _, rms, hgt, foot = _mls(Q, S, spacing, k, extra, tree, NS, Nq, float(side_cos))
    n = frame[:, 2]
    if not return_fit:
        return foot, n, hgt
    return foot, n, hgt, rms


def _face_normals(V, F):
    return np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])


def relocate_vertices(V, F, S, spacing: float, *, fixed=None, rounds: int = 3, smooth: float = 0.5,
                      k: int = 12, max_step: float = 3.0, fit_tol: float = 0.2,
                      return_report: bool = False):
    """Move the free vertices of a mesh onto the local surface of samples, keeping the faces (and topology).

    Each round: (1) tangential umbrella smoothing of the free vertices — the mean of the mesh neighbours minus
    the vertex, with its component along the vertex normal removed, times ``smooth``; (2) projection of the
    free vertices onto the moving-least-squares quadric of their ``k`` nearest samples
    (:func:`local_surface`), unless that fit's rms residual exceeds ``fit_tol`` × ``spacing`` (the samples
    there are not one smooth sheet: projecting would pull the vertex between two sheets of a thin part or
    round off a crease); a vertex moves at most ``max_step`` × ``spacing`` per round.  (3) Damping: a face
    whose normal turns by more than 90° (or whose area vanishes) in the round or since the start halves the moves of its free
    vertices, up to three times, then those moves are undone — so no face is flipped by the relocation.

    Parameters
    ----------
    V : (v, 3) float — vertices.  F : (f, 3) int — faces (kept as they are).
    S : (s, 3) float — samples of the surface (s ≥ 3).  spacing : float > 0 — their typical spacing.
    fixed : (v,) bool or None — vertices that do not move (say exact samples); None: all move.
    rounds : int ≥ 0; smooth : float in [0, 1]; k : int ≥ 3; max_step, fit_tol : float > 0 (in spacings).
    return_report : bool — also return a dict (``moved``: vertices moved, ``reverted``: moves undone,
        ``damped``: moves halved at least once, ``mean_shift``: mean displacement of the free vertices).

    Returns
    -------
    V : (v, 3) float64 — a new array (the input is not modified); (V, report) with ``return_report``.

    Raises
    ------
    ValueError : bad shapes, NaN / inf, out-of-range faces, a ``fixed`` mask of the wrong shape or type, a
        non-positive spacing, fewer than 3 samples, bad option values.

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.recon._relocate import relocate_vertices
    >>> V = np.array([[0, 0, 0.2], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
    >>> g = np.linspace(-1.2, 1.2, 25); S = np.array([[x, y, 0.0] for x in g for y in g])
    >>> W = relocate_vertices(V, F, S, 0.1, fixed=np.arange(5) > 0)
    >>> bool(abs(W[0, 2]) < 1e-6)
    True
    """
    V = as_points(V, "V")
    F = as_faces(F, len(V), "F")
    S = as_points(S, "S")
    spacing = positive(spacing, "spacing")
    rounds = integer(rounds, "rounds", lo=0)
    k = integer(k, "k", lo=3)
    smooth = nonnegative(smooth, "smooth", most=1.0)
    max_step = positive(max_step, "max_step")
    fit_tol = positive(fit_tol, "fit_tol")
    if fixed is None:
        fixed = np.zeros(len(V), dtype=bool)
    else:
        fixed = np.asarray(fixed)
        if fixed.dtype != np.bool_ or fixed.shape != (len(V),):
            raise ValueError(f"fixed: expected a ({len(V)},) bool mask, got {fixed.dtype} of shape {fixed.shape}")
    if len(S) < 3:
        raise ValueError(f"S: needs at least 3 samples for a local surface, got {len(S)}")
    V = V.copy()
    free = np.flatnonzero(~fixed & np.isin(np.arange(len(V)), F))
    report = {"moved": 0, "reverted": 0, "damped": 0, "mean_shift": 0.0}
    if free.size == 0 or rounds == 0 or len(F) == 0:
        return (V, report) if return_report else V
    tree = cKDTree(S)
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    A = sp.csr_matrix((np.ones(2 * len(E)), (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])),
                      shape=(len(V), len(V)))
    A.data[:] = 1.0                                             # each neighbour once
    deg = np.maximum(np.asarray(A.sum(axis=1)).ravel(), 1.0)
    V0 = V.copy()
    N_in = _face_normals(V0, F)
    ever_damped = np.zeros(len(V), dtype=bool)
    ever_reverted = np.zeros(len(V), dtype=bool)
    for _ in range(rounds):
        Vr = V.copy()
        Nf = _face_normals(Vr, F)
        Nv = np.zeros_like(V)
        np.add.at(Nv, F.ravel(), np.repeat(Nf, 3, axis=0))
        Nv /= np.maximum(np.linalg.norm(Nv, axis=1), 1e-300)[:, None]
        U = (A @ Vr) / deg[:, None] - Vr
        U -= np.einsum("vx,vx->v", U, Nv)[:, None] * Nv
        P = Vr[free] + smooth * U[free]
        P, _, _, rms = local_surface(P, S, spacing, k=k, tree=tree, return_fit=True)
        step = P - Vr[free]
        # no move where the samples are not one smooth sheet (sharp creases; both sides of a thin part
        # within reach, whose fitted surface runs between them)
        step[rms > fit_tol * spacing] = 0.0
        L = np.linalg.norm(step, axis=1)
        cap = max_step * spacing
        step *= np.minimum(1.0, cap / np.maximum(L, 1e-300))[:, None]
        scale = np.ones(len(free))
        pos = -np.ones(len(V), dtype=np.int64)
        pos[free] = np.arange(len(free))
        a0 = np.linalg.norm(Nf, axis=1)
        def flipped():
            """Free-vertex slots on faces that the moves flip or collapse."""
            V[free] = Vr[free] + scale[:, None] * step
            Nn = _face_normals(V, F)
            # flipped against the round's start or against the input (rounds must not add up to a flip)
            bad = (np.einsum("fx,fx->f", Nn, Nf) <= 0) | (np.einsum("fx,fx->f", Nn, N_in) <= 0) \
                | (np.linalg.norm(Nn, axis=1) <= 1e-6 * a0)
            bad &= a0 > 0
            hit = pos[np.unique(F[bad])]
            return hit[hit >= 0]

        for _attempt in range(3):            # damp: halve the moves around flipped faces
            hit = flipped()
            if hit.size == 0:
                break
            scale[hit] *= 0.5
            ever_damped[free[hit]] = True
        while True:                          # then undo them (terminates: all undone = the unflipped start)
            hit = flipped()
            hit = hit[scale[hit] > 0]
            if hit.size == 0:
                break
            scale[hit] = 0.0
            ever_reverted[free[hit]] = True
    shift = np.linalg.norm(V[free] - V0[free], axis=1)
    report.update(moved=int((shift > 0).sum()), reverted=int(ever_reverted.sum()), damped=int(ever_damped.sum()),
                  mean_shift=float(shift.mean()))
    return (V, report) if return_report else V


def subdivide_onto_samples(V, F, S, spacing: float, *, levels: int = 1, k: int = 12, fit_tol: float = 0.2,
                           max_step: float = 1.0, return_report: bool = False):
    """Split every triangle into four and move the new edge midpoints onto the local surface of the samples.

    The output of the guarantee layer interpolates the samples with flat triangles, so between samples it
    cuts the chord of the curved surface (an error of about κ·ℓ²/8 for an edge of length ℓ on curvature κ).
    One 1-to-4 split puts a vertex on each edge midpoint; each moves along the normal of its
    moving-least-squares quadric (:func:`local_surface`) onto it, at most ``max_step`` × ``spacing``, and not at
    all where that fit's rms residual exceeds ``fit_tol`` × ``spacing`` (the samples there are not one smooth
    sheet: a crease, or both sides of a thin part).  A midpoint whose move would turn one of its six new
    faces by more than 90° against its parent face stays at the midpoint.  The split of a closed, edge- and
    vertex-manifold mesh is again one (each edge becomes two, each face four, χ = V − E + F is unchanged), so
    the topology is the input's by construction; only positions of the new vertices are fitted.

    Parameters
    ----------
    V : (v, 3) float; F : (f, 3) int — a triangle mesh (kept vertices stay where they are).
    S : (s, 3) float — samples (s ≥ 3); spacing : float > 0 — their typical spacing.
    levels : int ≥ 0 — how many splits; k, fit_tol, max_step — as in :func:`relocate_vertices`.
    return_report : bool — also return ``{"midpoints": n, "projected": n, "kept_flat": n}`` (summed).

    Returns
    -------
    V2 : (v + e, 3) float64 — the input vertices first, then one vertex per edge; F2 : (4 f, 3) int64 — same
    orientation as F.  With ``return_report``: (V2, F2, report).

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.recon._relocate import subdivide_onto_samples
    >>> t = (1 + 5 ** 0.5) / 2                                        # icosahedron on the unit sphere
    >>> V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
    ...               [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    >>> V /= np.linalg.norm(V, axis=1)[:, None]
    >>> F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
    ...               [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
    ...               [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    >>> rng = np.random.default_rng(0)
    >>> S = rng.normal(size=(20000, 3)); S /= np.linalg.norm(S, axis=1)[:, None]
    >>> V2, F2 = subdivide_onto_samples(V, F, S, 0.2)
    >>> len(V2), len(F2), bool(np.abs(np.linalg.norm(V2, axis=1) - 1).max() < 1e-3)
    (42, 80, True)
    """
    V = as_points(V, "V")
    F = as_faces(F, len(V), "F")
    S = as_points(S, "S")
    spacing = positive(spacing, "spacing")
    levels = integer(levels, "levels", lo=0)
    k = integer(k, "k", lo=3)
    fit_tol = positive(fit_tol, "fit_tol")
    max_step = positive(max_step, "max_step")
    if len(S) < 3:
        raise ValueError(f"S: needs at least 3 samples for a local surface, got {len(S)}")
    tree = cKDTree(S)
    report = {"midpoints": 0, "projected": 0, "kept_flat": 0}
    V = V.copy()
    F = F.astype(np.int64, copy=True)
    for _ in range(levels):
        if len(F) == 0:
            break
        H = np.concatenate([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]])     # edge opposite corner 0, 1, 2
        key = np.sort(H, axis=1)
        uniq, inv = np.unique(key, axis=0, return_inverse=True)
        inv = inv.ravel()
        m = len(V) + inv.reshape(3, len(F)).T                             # (f, 3) midpoint id opposite each corner
        M = 0.5 * (V[uniq[:, 0]] + V[uniq[:, 1]])
        foot, _, _, rms = local_surface(M, S, spacing, k=k, tree=tree, return_fit=True)
        step = foot - M
        step[rms > fit_tol * spacing] = 0.0
        L = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, max_step * spacing / np.maximum(L, 1e-300))[:, None]
        a, b, c = F[:, 0], F[:, 1], F[:, 2]
        ma, mb, mc = m[:, 0], m[:, 1], m[:, 2]
        F2 = np.concatenate([np.stack([a, mc, mb], 1), np.stack([mc, b, ma], 1), np.stack([mb, ma, c], 1),
                             np.stack([ma, mb, mc], 1)])
        parent = np.tile(_face_normals(V, F), (4, 1))
        moved = np.linalg.norm(step, axis=1) > 0
        W = np.concatenate([V, M + step])
        for _attempt in range(len(M) + 1):                 # each pass only reverts moves: terminates
            Nn = _face_normals(W, F2)
            bad = np.einsum("fx,fx->f", Nn, parent) <= 0
            if not bad.any():
                break
            ids = np.unique(F2[bad]) - len(V)
            ids = ids[ids >= 0]
            ids = ids[moved[ids]]
            if ids.size == 0:
                break
            W[len(V) + ids] = M[ids]
            moved[ids] = False
        report["midpoints"] += len(M)
        report["projected"] += int(moved.sum())
        report["kept_flat"] += int(len(M) - moved.sum())
        V, F = W, F2
    return (V, F, report) if return_report else (V, F)
