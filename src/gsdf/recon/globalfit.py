"""Global fit of a closed mesh onto its samples: sparse least squares over ALL vertex positions (geometry only).

The guarantee layer (:mod:`.grow`) returns the boundary of a tet region; the local relocation
(:mod:`.relocate`) moves vertices one by one and refuses any move that flips a face, so the pleats of that
boundary — strips where the surface folds back over itself, faces facing against the true normal — stay.  This
pass moves every vertex at once (input points too), alternating

(a) data attachment: every sample s is attached to its closest point on the current mesh (a face and
    barycentric coordinates b_s, :class:`gsdf.distance.TriangleDistance`); every vertex v to its foot f_v
    and normal n_v on the moving-least-squares quadric of its nearest samples (:func:`.relocate.local_surface`);
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
    shrinking of a plain membrane (measured: CD rises by ~30 % without it).

The normal equations are symmetric positive definite (ε > 0); they are solved by conjugate gradients with a
3 × 3 block-Jacobi preconditioner, warm-started at the current positions (:func:`gsdf.linalg.pcg`).

Only vertex positions change — the face list, hence the combinatorial topology (closed, edge- and
vertex-manifold, genus 0, one component), is exactly the input's.  Faces may turn over during the fit (that
is how a pleat unfolds); nothing here depends on their orientation.

Example
-------
>>> import numpy as np
>>> from gsdf.recon.globalfit import fit_to_samples
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

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .._checks import as_faces, as_points, integer, nonnegative, positive

__all__ = ["fit_to_samples"]


def _edges(F, n):
    """(e, 2) unique undirected edges of the faces F (lo < hi)."""
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    E.sort(axis=1)
    key = np.unique(E[:, 0] * np.int64(n) + E[:, 1])
    return np.stack([key // n, key % n], axis=1)


def _block_index(n):
    """Row and column indices (n, 3, 3) of the 3 × 3 diagonal blocks of a 3n × 3n matrix."""
    r = 3 * np.arange(n)[:, None, None] + np.arange(3)[None, :, None]
    c = 3 * np.arange(n)[:, None, None] + np.arange(3)[None, None, :]
    return np.broadcast_to(r, (n, 3, 3)), np.broadcast_to(c, (n, 3, 3))


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
    from ..distance.triangles import TriangleDistance
    from ..linalg import pcg
    from .relocate import local_surface

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
    report = {"iterations": 0, "attached": [], "cg_iterations": [], "mean_shift": 0.0, "max_shift": 0.0}
    if iterations == 0 or len(F) == 0:
        return (X, report) if return_report else X
    k = int(min(k, m))
    tree = cKDTree(S)
    E = _edges(F, n)
    ne = len(E)
    L = sp.csr_matrix((np.r_[np.ones(2 * ne), -np.ones(2 * ne)],
                       (np.r_[E[:, 0], E[:, 1], E[:, 0], E[:, 1]], np.r_[E[:, 0], E[:, 1], E[:, 1], E[:, 0]])),
                      shape=(n, n))
    I3 = sp.identity(3, format="csr")
    bi, bj = _block_index(n)
    rows = np.repeat(np.arange(m), 3)
    for _ in range(iterations):
        # (a) attachment: samples to their closest mesh points, vertices to their quadric feet
        d, face, _, bary = TriangleDistance(X, F).query_barycentric(S)
        a = data * (d <= trim * h)
        B = sp.csr_matrix((bary.ravel(), (rows, F[face].ravel())), shape=(m, n))
        As = (B.T @ sp.diags(a) @ B).tocsr()
        foot, nrm, _, rms = local_surface(X, S, h, k=k, tree=tree, return_fit=True)
        c = surface * (rms <= fit_tol * h)
        blk = c[:, None, None] * nrm[:, :, None] * nrm[:, None, :]
        Pn = sp.csr_matrix((blk.ravel(), (bi.ravel(), bj.ravel())), shape=(3 * n, 3 * n))
        # (b) the normal equations
        M = (sp.kron(As + membrane * L + prox * sp.identity(n), I3, format="csr") + Pn).tocsr()
        eta = nrm * np.einsum("vx,vx->v", nrm, L @ X)[:, None]
        rhs = B.T @ (a[:, None] * S) + (c * np.einsum("vx,vx->v", nrm, foot))[:, None] * nrm \
            + membrane * eta + prox * X
        # 3 × 3 block-Jacobi preconditioner
        D = np.asarray(M[bi.ravel(), bj.ravel()]).reshape(n, 3, 3)
        Dinv = np.linalg.inv(D)
        cnt = [0]

        def psolve(r, Dinv=Dinv, cnt=cnt):
            cnt[0] += 1
            return np.einsum("vij,vj->vi", Dinv, r.reshape(n, 3)).ravel()

        x, _ = pcg(M, rhs.ravel(), M=psolve, x0=X.ravel().copy(), rtol=1e-7, maxiter=2000)
        X = x.reshape(n, 3)
        report["iterations"] += 1
        report["attached"].append(int((a > 0).sum()))
        report["cg_iterations"].append(cnt[0])
    shift = np.linalg.norm(X - V, axis=1)
    report.update(mean_shift=float(shift.mean()), max_shift=float(shift.max()))
    return (X, report) if return_report else X
