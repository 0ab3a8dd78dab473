"""Global fit of a closed mesh onto its samples: sparse least squares over ALL vertex positions (geometry only).

The guarantee layer (:mod:`gsdf.recon._grow`) returns the boundary of a tet region; the local relocation
(:mod:`gsdf.recon._relocate`) moves vertices one by one and refuses any move that flips a face, so the pleats of that
boundary — strips where the surface folds back over itself, faces facing against the true normal — stay.  This
pass moves every vertex at once (input points too), alternating

(a) data attachment: every sample s is attached to its closest point on the current mesh (a face and
    barycentric coordinates b_s, :class:`gsdf.distance.TriangleDistance`); every vertex v to its foot f_v
    and normal n_v on the moving-least-squares quadric of its nearest samples (:func:`gsdf.recon._relocate.local_surface`);
(b) one sparse least-squares solve for all positions x (3 unknowns per vertex):

        minimise   β Σ_s a_s |Σ_i b_si x_i − s|²                     samples on the surface (point-to-point)
                 + γ Σ_v c_v (n_v · (x_v − f_v))²                     vertices on the fitted surface (point-to-plane)
                 + μ Σ_(i,j) edges |x_i − x_j|²  − 2μ Σ_v x_v · η_v   membrane, tangential part only
                 + ε Σ_v |x_v − x_v^(t)|²                             proximal (a step, not a jump)

    with a_s = 1 for samples within ``trim`` spacings of the mesh (farther ones are outliers: 0), c_v = 1 where
    the quadric fits its samples (rms ≤ ``fit_tol`` spacings: one smooth sheet) and 0 elsewhere, and
    η_v = n_v n_vᵀ (L x^(t))_v the normal part of the umbrella vector at the current iterate (L: the graph
    Laplacian of the edges).  Moving the membrane's normal force to the right-hand side makes it act along
    the surface only: it spreads the vertices evenly over the surface and so unfolds pleats (on a flat patch
    the minimiser of Σ|x_i − x_j|² with the rim held is Tutte's embedding, which has no folds), without the
    shrinking of a plain membrane.

The normal equations are symmetric positive definite (ε > 0); they are solved by conjugate gradients with a
3 × 3 block-Jacobi preconditioner, warm-started at the current positions, to a relative residual of 1e-7.  They
are never assembled as a 3n × 3n matrix: the system is K ⊗ I₃ + blockdiag(c_v n_v n_vᵀ) with K = Bᵀ diag(a) B +
μ L + ε I a scalar n × n matrix on the pattern of the mesh edges (its values summed per face corner pair, a
bincount per round), so a mat-vec reads K once for all three coordinates and adds the rank-1 blocks, and the
diagonal blocks k_v I₃ + c_v n_v n_vᵀ invert in closed form (Sherman–Morrison); the CG iteration is SciPy's
(:func:`gsdf.linalg._iterative.cg_loop`) in one numba kernel.  Vertices and samples are relabelled along the
Z-order curve inside (the result does not depend on the labels), and the triangle tree of the attachment is
built once and refitted in later rounds (:meth:`gsdf.distance.TriangleDistance.refit`).

Only vertex positions change — the face list, hence the combinatorial topology (closed, edge- and
vertex-manifold, genus 0, one component), is exactly the input's.  Faces may turn over during the fit (that
is how a pleat unfolds); nothing here depends on their orientation.

Example
-------
>>> import numpy as np
>>> from gsdf.recon._globalfit import fit_to_samples
>>> t = (1 + 5 ** 0.5) / 2                                        # icosahedron, radius 1.1, around
>>> # the unit sphere (its best fit in least squares has the vertices outside: the faces are chords)
>>> V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
...               [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
>>> V *= 1.1 / np.linalg.norm(V, axis=1)[:, None]
>>> F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
...               [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
...               [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
>>> i = np.arange(4000) + 0.5                                      # unit sphere samples
>>> phi, th = np.arccos(1 - 2 * i / 4000), np.pi * (1 + 5 ** 0.5) * i
>>> S = np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])
>>> W = fit_to_samples(V, F, S, spacing=0.05)
>>> from gsdf.distance import unsigned_distance          # mean sample-to-mesh distance, before and after
>>> round(float(unsigned_distance(V, F, S).mean()), 2), round(float(unsigned_distance(W, F, S).mean()), 2)
(0.07, 0.03)
"""

from __future__ import annotations

import numba as nb
import numpy as np
from scipy.spatial import cKDTree

from gsdf._checks import as_faces, as_points, integer, nonnegative, positive

__all__ = ["fit_to_samples"]


class _Pattern:
    """The sparsity of the scalar n × n part K of the normal equations (diagonal + mesh edges), as CSR rows with
    each entry's slot known: ``slot[:n]`` the diagonal, ``slot[n:n+e]`` / ``slot[n+e:]`` edge (lo, hi) / (hi, lo);
    ``E`` (e, 2) the unique edges (lo ≤ hi), ``fe`` (f, 3) the edge opposite each corner of each face, ``deg``
    the edge count per vertex (the graph Laplacian's diagonal), ``drow`` / ``dslot`` the rows and slots of all
    entries on the diagonal (a degenerate face's edge (v, v) puts two more there)."""

    def __init__(self, F, n):
        f = len(F)
        H = np.concatenate([F[:, 1], F[:, 2], F[:, 0]]), np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
        key = np.minimum(*H) * np.int64(n) + np.maximum(*H)
        ukey, inv = np.unique(key, return_inverse=True)
        self.E = np.stack([ukey // n, ukey % n], axis=1)
        self.fe = np.ascontiguousarray(inv.reshape(3, f).T)
        ne = len(self.E)
        rows = np.concatenate([np.arange(n), self.E[:, 0], self.E[:, 1]])
        cols = np.concatenate([np.arange(n), self.E[:, 1], self.E[:, 0]])
        self.indptr, self.indices, self.slot = _csr_slots(rows, cols, n)
        on = rows == cols
        self.drow, self.dslot = rows[on], self.slot[on]
        self.deg = np.bincount(self.E.ravel(), minlength=n).astype(np.float64)
        self.n, self.ne = n, ne

    def values(self, diag, edge):
        """CSR values of the symmetric matrix with diagonal ``diag`` (n,) and edge entries ``edge`` (e,)."""
        v = np.empty(len(self.slot))
        v[self.slot[:self.n]] = diag
        v[self.slot[self.n:self.n + self.ne]] = edge
        v[self.slot[self.n + self.ne:]] = edge
        return v

    def diagonal(self, vals):
        return np.bincount(self.drow, weights=vals[self.dslot], minlength=self.n)


@nb.njit(cache=True)
def _csr_slots(rows, cols, n):
    """CSR (indptr, indices) of the entries (rows, cols), each row's entries in input order (a counting sort),
    and the slot of every input entry."""
    indptr = np.zeros(n + 1, np.int64)
    for r in rows:
        indptr[r + 1] += 1
    for v in range(n):
        indptr[v + 1] += indptr[v]
    nxt = indptr[:-1].copy()
    indices = np.empty(len(rows), np.int64)
    slot = np.empty(len(rows), np.int64)
    for e in range(len(rows)):
        p = nxt[rows[e]]
        nxt[rows[e]] += 1
        indices[p] = cols[e]
        slot[e] = p
    return indptr, indices, slot


@nb.njit(cache=True)
def _pcg(indptr, indices, vals, cn, nrm, kd, b, x, rtol, maxiter):
    """Preconditioned conjugate gradients on (K ⊗ I₃ + blockdiag(cn n nᵀ)) x = b (:func:`_apply`) with the
    block-Jacobi preconditioner of :func:`_block_jacobi`, all vectors (n, 3): the iteration of
    :func:`gsdf.linalg._iterative.cg_loop` (SciPy's ``cg``: same updates, stop when ‖r‖ < rtol ‖b‖), its vector
    operations fused into the mat-vec / preconditioner passes.  ``x`` (the start) is updated in place; returns
    (iterations, converged)."""
    n = x.shape[0]
    bn = 0.0
    for v in range(n):
        for i in range(3):
            bn += b[v, i] * b[v, i]
    atol = rtol * np.sqrt(bn)
    if bn == 0.0:
        x[:] = 0.0
        return 0, True
    r = np.empty((n, 3))
    _apply(indptr, indices, vals, cn, nrm, x, r)
    rn = 0.0
    for v in range(n):
        for i in range(3):
            r[v, i] = b[v, i] - r[v, i]
            rn += r[v, i] * r[v, i]
    z = np.empty((n, 3))
    p = np.empty((n, 3))
    q = np.empty((n, 3))
    rho_prev = 1.0
    for it in range(maxiter):
        if np.sqrt(rn) < atol:
            return it, True
        _block_jacobi(kd, cn, nrm, r, z)
        rho = 0.0
        for v in range(n):
            for i in range(3):
                rho += r[v, i] * z[v, i]
        beta = rho / rho_prev if it > 0 else 0.0
        for v in range(n):
            for i in range(3):
                p[v, i] = p[v, i] * beta + z[v, i] if it > 0 else z[v, i]
        _apply(indptr, indices, vals, cn, nrm, p, q)
        pq = 0.0
        for v in range(n):
            for i in range(3):
                pq += p[v, i] * q[v, i]
        alpha = rho / pq
        rn = 0.0
        for v in range(n):
            for i in range(3):
                x[v, i] += alpha * p[v, i]
                r[v, i] -= alpha * q[v, i]
                rn += r[v, i] * r[v, i]
        rho_prev = rho
    return maxiter, np.sqrt(rn) < atol


@nb.njit(cache=True)
def _apply(indptr, indices, vals, cn, nrm, x, y):
    """y = (K ⊗ I₃ + blockdiag(cn_v n_v n_vᵀ)) x for x, y (n, 3): K in CSR (indptr, indices, vals)."""
    for v in nb.prange(len(indptr) - 1):
        sx = sy = sz = 0.0
        for p in range(indptr[v], indptr[v + 1]):
            j = indices[p]
            a = vals[p]
            sx += a * x[j, 0]
            sy += a * x[j, 1]
            sz += a * x[j, 2]
        t = cn[v] * (nrm[v, 0] * x[v, 0] + nrm[v, 1] * x[v, 1] + nrm[v, 2] * x[v, 2])
        y[v, 0] = sx + t * nrm[v, 0]
        y[v, 1] = sy + t * nrm[v, 1]
        y[v, 2] = sz + t * nrm[v, 2]


@nb.njit(cache=True)
def _block_jacobi(kd, cn, nrm, r, z):
    """z = D⁻¹ r with D_v = kd_v I₃ + cn_v n_v n_vᵀ (|n_v| = 1; Sherman–Morrison), r, z (n, 3)."""
    for v in nb.prange(len(kd)):
        t = cn[v] / (kd[v] * (kd[v] + cn[v])) * (nrm[v, 0] * r[v, 0] + nrm[v, 1] * r[v, 1] + nrm[v, 2] * r[v, 2])
        z[v, 0] = r[v, 0] / kd[v] - t * nrm[v, 0]
        z[v, 1] = r[v, 1] / kd[v] - t * nrm[v, 1]
        z[v, 2] = r[v, 2] / kd[v] - t * nrm[v, 2]


def _normal_equations(P, X, F, S, face, bary, a, foot, nrm, c, membrane, prox):
    """The round's normal equations (module text) in operator form: CSR values of K = Bᵀ diag(a) B + μ L + ε I
    on the pattern ``P`` (B: the samples' barycentric rows, (m, n)), the diagonal of K, and the right-hand side
    (n, 3).  The full matrix is K ⊗ I₃ + blockdiag(c_v n_v n_vᵀ) (:func:`_apply`)."""
    n = len(X)
    Ff = F[face]
    b = a[:, None] * bary
    diag = membrane * P.deg + prox + np.bincount(Ff.ravel(), weights=(b * bary).ravel(), minlength=n)
    # the pair of corners across the edge opposite corner 0, 1, 2: (1, 2), (2, 0), (0, 1)
    pw = b[:, [1, 2, 0]] * bary[:, [2, 0, 1]]
    edge = np.bincount(P.fe[face].ravel(), weights=pw.ravel(), minlength=P.ne) - membrane
    vals = P.values(diag, edge)
    LX = np.empty_like(X)
    _apply(P.indptr, P.indices, P.values(P.deg, -np.ones(P.ne)), np.zeros(n), nrm, X, LX)
    rhs = np.stack([np.bincount(Ff.ravel(), weights=(b * S[:, [i]]).ravel(), minlength=n) for i in range(3)], axis=1)
    rhs += (c * np.einsum("vx,vx->v", nrm, foot))[:, None] * nrm
    rhs += nrm * (membrane * np.einsum("vx,vx->v", nrm, LX))[:, None]
    rhs += prox * X
    return vals, P.diagonal(vals), rhs


_STAGES = ("setup", "attach", "surface", "assemble", "solve")


class _Clock:
    """Adds the wall and CPU seconds since the last call to a stage of ``report["seconds"]`` /
    ``report["cpu_seconds"]``."""

    def __init__(self, report):
        import time
        self._pc, self._cpu, self._r = time.perf_counter, time.process_time, report
        self._t, self._c = self._pc(), self._cpu()

    def __call__(self, stage):
        t, c = self._pc(), self._cpu()
        self._r["seconds"][stage] += t - self._t
        self._r["cpu_seconds"][stage] += c - self._c
        self._t, self._c = t, c


def fit_to_samples(V, F, S, spacing: float, *, iterations: int = 4, data: float = 5.0, surface: float = 1.0,
                   membrane: float = 0.2, prox: float = 0.01, trim: float = 3.0, k: int = 8,
                   fit_tol: float = 0.2, return_report: bool = False):
    """Move all vertices of a mesh onto its samples by alternating attachment and a global least-squares solve.

    See the module text for the energy.  The faces are not changed, so the topology is the input's.

    Parameters
    ----------
    V : (v, 3) float; F : (f, 3) int — the mesh (any triangle mesh; the reconstruction passes a closed sphere).
    S : (s, 3) float — samples of the surface, s ≥ 3 (inliers: outliers farther than ``trim`` spacings from the
        mesh are ignored).  spacing : float > 0 — their typical spacing.
    iterations : int ≥ 0 — outer rounds (attachment + solve).
    data, surface, membrane : float ≥ 0 — weights β (per sample), γ (per vertex), μ (per edge).
    prox : float > 0 — ε, per vertex (keeps the system definite and each round a step).
    trim : float > 0 — samples farther than this × ``spacing`` from the mesh get no weight in a round.
    k : int ≥ 3 — samples per local quadric; fit_tol : float > 0 — in spacings, the rms residual above which a
        vertex's quadric is not trusted (two sheets of a thin part, a crease): no surface term there.
    return_report : bool — also return ``{"iterations", "attached" (per round), "cg_iterations" (per round),
        "mean_shift", "max_shift"}``.

    Returns
    -------
    V2 : (v, 3) float64 — new positions (the input is not modified); (V2, report) with ``return_report``.

    Raises
    ------
    ValueError : bad shapes, NaN / inf, out-of-range faces, fewer than 3 samples, bad option values.
    """
    from gsdf.distance._triangles import TriangleDistance
    from gsdf.spatial._morton import morton_order
    from gsdf.recon._relocate import local_surface

    V = as_points(V, "V")
    F = as_faces(F, len(V), "F")
    S = as_points(S, "S")
    spacing = positive(spacing, "spacing")
    iterations = integer(iterations, "iterations", lo=0)
    data = nonnegative(data, "data")
    surface = nonnegative(surface, "surface")
    membrane = nonnegative(membrane, "membrane")
    prox = positive(prox, "prox")
    trim = positive(trim, "trim")
    k = integer(k, "k", lo=3)
    fit_tol = positive(fit_tol, "fit_tol")
    if len(S) < 3:
        raise ValueError(f"S: needs at least 3 samples for a local surface, got {len(S)}")
    n, m, h = len(V), len(S), spacing
    X = V.copy()
    report = {"iterations": 0, "attached": [], "cg_iterations": [], "mean_shift": 0.0, "max_shift": 0.0,
              "seconds": dict.fromkeys(_STAGES, 0.0), "cpu_seconds": dict.fromkeys(_STAGES, 0.0)}
    clock = _Clock(report)
    if iterations == 0 or len(F) == 0:
        return (X, report) if return_report else X
    k = int(min(k, m))
    # vertices and samples relabelled along the Z-order curve (the result does not depend on the labels): the
    # mat-vecs' neighbour reads, the tree queries and the gathers then hit the cache
    pv = morton_order(V)
    X = X[pv]
    rank = np.empty(n, dtype=np.int64)
    rank[pv] = np.arange(n)
    F = rank[F]
    ps = morton_order(S)
    S = S[ps]
    tree = cKDTree(S)
    P = _Pattern(F, n)
    td = None
    for _ in range(iterations):
        # (a) attachment: samples to their closest mesh points, vertices to their quadric feet (the triangle
        # tree of the first round refitted to the moved vertices in the later ones: same answers, no rebuild)
        clock("setup")
        td = TriangleDistance(X, F) if td is None else td.refit(X)
        d, face, _, bary = td.query_barycentric(S)
        clock("attach")
        foot, nrm, _, rms = local_surface(X, S, h, k=k, tree=tree, return_fit=True)
        nrm = np.ascontiguousarray(nrm)
        clock("surface")
        a = data * (d <= trim * h)
        c = surface * (rms <= fit_tol * h)
        # (b) the normal equations, K ⊗ I₃ + blockdiag(c n nᵀ), and a 3 × 3 block-Jacobi preconditioner
        vals, kd, rhs = _normal_equations(P, X, F, S, face, bary, a, foot, nrm, c, membrane, prox)
        clock("assemble")
        X = X.copy()
        its, _ = _pcg(P.indptr, P.indices, vals, c, nrm, kd, rhs, X, 1e-7, 2000)
        clock("solve")
        report["iterations"] += 1
        report["attached"].append(int((a > 0).sum()))
        report["cg_iterations"].append(int(its))
    X = X[rank]
    shift = np.linalg.norm(X - V, axis=1)
    report.update(mean_shift=float(shift.mean()), max_shift=float(shift.max()))
    return (X, report) if return_report else X
