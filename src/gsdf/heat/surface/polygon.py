"""The signed heat method on polygon meshes (Feng & Crane 2024, §8.3) with the polygon Laplacian of Bunge,
Herholz, Kazhdan & Botsch 2020 ("Polygon Laplacian made simple").

Operators (Bunge et al. §3–4):

* every polygon f with more than three corners gets a virtual vertex ``x_f = Σ_i w_i x_i`` whose affine weights
  w minimize the sum of squared areas of the fan triangles (x_f, x_i, x_{i+1}) (the minimizer x_f is unique; of
  the weights reproducing it the minimum-norm ones are taken, as geometry-central does);
* the polygon is split into that fan; on the refined triangle mesh the cotan stiffness C_fan, the lumped mass and
  the gradient/divergence of piecewise-linear functions are the usual ones (:mod:`.operators`);
* the prolongation P ((n + #virtual) × n) is the identity on original vertices and the weights w on virtual ones;
  ``L = Pᵀ C_fan P`` and ``M = lump(Pᵀ M_fan P)`` (row sums; Bunge et al. §4.2 use the lumped mass), i.e.
  ``M = Pᵀ A_fan`` with A_fan the barycentric areas of the refined mesh, since the rows of P sum to one.

  Triangles are left unrefined: for a triangle the optimal virtual vertex is the centroid, and the prolonged fan
  operators equal the triangle's cotan stiffness and barycentric mass exactly (linear precision), so on a
  triangle mesh L is the cotan Laplacian.

Signed heat method on top (§8.3): tangent planes at the vertices from the area-weighted sum of the fine triangle
normals (an arbitrary basis in each plane); the vertex connection Laplacian multiplies the off-diagonal entries of
L by the rotation between the tangent bases of the two vertices (the smallest rotation aligning their normals,
as in Eq. 9 and Sharp et al. 2019 §6.2.2); X⁰ at a curve vertex accumulates the in-plane curve normals of its
incident edges times half their lengths (the "average edge normal times half the sum of incident edge lengths"
of §8.3, averaged by length); step I solves ``(M + t L∇) X = X⁰``; for step II X is prolonged to the fine
vertices (virtual vertex = Σ w_i X_i as 3D vectors), averaged onto the fine triangles, projected into them and
normalized; step III applies the fine divergence and restricts by Pᵀ (Bunge et al. §4.5, D = -Pᵀ Gᵀ M_T), then
solves ``L φ = b`` with the level-set constraints of §7.1. The diffusion time is ``t = t_coef · ℓ̄²`` with ℓ̄
the mean polygon edge length (geometry-central's choice for polygon meshes).

Curves run along polygon edges (vertex-index polylines). Sign convention as everywhere in gsdf: the left of a
curve (the inside of a counter-clockwise loop seen from the normal side) is negative, the opposite of
potpourri3d.

:class:`VertexSignedHeat` holds the vertex-based steps I–III shared with the point-cloud solver (§8.4).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ... import _checks
from ...linalg import Factorization, HermitianFactorization, cached_factorization, saddle_matrix
from .operators import TriangleMeshOperators
from .sources import vertex_polyline

LEVEL_SETS = ("zero", "multiple", "none")


# --------------------------------------------------------------------------------------------- geometry helpers
def _parse_polygons(polygons, n: int) -> dict:
    """Validate polygons; return {degree: (q, degree) int64 array} (vectorized per degree)."""
    import itertools

    if isinstance(polygons, np.ndarray) and polygons.ndim == 2 and polygons.dtype != object:
        arr = polygons
        if not np.issubdtype(arr.dtype, np.integer):
            if not (np.issubdtype(arr.dtype, np.floating) and np.all(arr == np.round(arr))):
                raise ValueError(f"polygons: vertex indices must be integers, got dtype {arr.dtype}")
        sizes = np.full(len(arr), arr.shape[1], np.int64)
        flat = arr.astype(np.int64).ravel()
    else:
        try:
            polygons = [np.asarray(p).ravel() if isinstance(p, np.ndarray) else p for p in polygons]
            sizes = np.fromiter(map(len, polygons), np.int64, count=len(polygons))
            flat = np.asarray(list(itertools.chain.from_iterable(polygons)))
        except TypeError as exc:
            raise ValueError("polygons: expected a list of vertex-index sequences or an (m, k) int array") from exc
        if flat.size and not np.issubdtype(flat.dtype, np.integer):
            if not (np.issubdtype(flat.dtype, np.number) and np.all(flat == np.round(flat))):
                raise ValueError(f"polygons: vertex indices must be integers, got dtype {flat.dtype}")
        flat = flat.astype(np.int64)
    if len(sizes) == 0:
        raise ValueError("polygons: is empty (0 faces)")
    if (sizes < 3).any():
        k = int(np.flatnonzero(sizes < 3)[0])
        raise ValueError(f"polygons[{k}]: a polygon needs at least 3 vertices, got {int(sizes[k])}")
    start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    bad = (flat < 0) | (flat >= n)
    if bad.any():
        k = int(np.searchsorted(start, np.flatnonzero(bad)[0], side="right") - 1)
        raise ValueError(f"polygons[{k}]: vertex index out of range for {n} vertices")
    out = {}
    for s in np.unique(sizes):
        sel = np.flatnonzero(sizes == s)
        Q = flat[start[sel][:, None] + np.arange(s)]
        S = np.sort(Q, axis=1)
        rep = (S[:, 1:] == S[:, :-1]).any(1)
        if rep.any():
            k = int(sel[np.flatnonzero(rep)[0]])
            raise ValueError(f"polygons[{k}]: repeats a vertex ({Q[np.flatnonzero(rep)[0]].tolist()})")
        out[int(s)] = Q
    return out


def virtual_vertex_weights(X: np.ndarray) -> np.ndarray:
    """Affine weights (q, s) of the virtual vertices of q polygons with s corners ``X`` (q, s, 3).

    The virtual vertex minimizes Σ_i |(x_i - x) × (x_{i+1} - x)|² (twice the squared fan-triangle areas, Bunge et
    al. 2020 §3): a 3×3 linear least-squares problem per polygon. Its weights are the minimum-norm affine ones
    reproducing it (``Σ w = 1``, ``Σ w_i x_i = x``); degenerate polygons get uniform weights.

    Example
    -------
    >>> X = np.array([[[0., 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]]])
    >>> virtual_vertex_weights(X).round(6).tolist()
    [[0.25, 0.25, 0.25, 0.25]]
    """
    q, s, _ = X.shape
    c = X.mean(axis=1, keepdims=True)
    A = X - c                                                   # centred corners (translation invariance)
    B = np.roll(A, -1, axis=1)
    D = B - A
    # (a - x) × (b - x) = a × b - x × (b - a) = a × b + [d]_× x   (d = b - a)
    Dx = np.zeros((q, s, 3, 3))
    Dx[..., 0, 1], Dx[..., 0, 2] = -D[..., 2], D[..., 1]
    Dx[..., 1, 0], Dx[..., 1, 2] = D[..., 2], -D[..., 0]
    Dx[..., 2, 0], Dx[..., 2, 1] = -D[..., 1], D[..., 0]
    H = np.einsum("qsij,qsik->qjk", Dx, Dx)
    rhs = -np.einsum("qsij,qsi->qj", Dx, np.cross(A, B))
    scale = np.trace(H, axis1=1, axis2=2)
    ok = scale > 0
    lam, U = np.linalg.eigh(H)                                   # H is symmetric PSD: a safe pseudo-inverse
    keep = lam > 1e-10 * np.maximum(scale, 1e-300)[:, None]
    inv = np.where(keep, 1.0 / np.where(keep, lam, 1.0), 0.0)
    x = np.einsum("qij,qj,qkj,qk->qi", U, inv, U, rhs)
    ok &= keep.sum(1) == 3                                       # collinear corners: no unique minimizer
    # minimum-norm affine weights: w = K⁺ r with K = [Aᵀ; 1ᵀ] (4 × s), r = [x; 1]
    K = np.concatenate([np.transpose(A, (0, 2, 1)), np.ones((q, 1, s))], axis=1)
    r = np.concatenate([x, np.ones((q, 1))], axis=1)
    w = np.einsum("qij,qj->qi", np.linalg.pinv(K, rcond=1e-10), r)
    ok &= np.isfinite(w).all(1) & (np.abs(w.sum(1) - 1) < 1e-6)
    w[~ok] = 1.0 / s
    return w


def virtual_vertex_refinement(V: np.ndarray, polygons):
    """Refine polygons by virtual-vertex fans (Bunge et al. 2020).

    Returns ``(V_refined, F_refined, P)``: the first ``len(V)`` refined vertices are the input ones, the others the
    virtual vertices of the polygons with more than three corners; triangles are kept as they are. ``P`` is the
    sparse prolongation (len(V_refined), len(V)): identity rows for original vertices, affine weights for virtual
    ones.

    Example
    -------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    >>> Vr, Fr, P = virtual_vertex_refinement(V, [[0, 1, 2, 3]])
    >>> (Vr[4].round(3) + 0.0).tolist(), len(Fr), P.shape
    ([0.5, 0.5, 0.0], 4, (5, 4))
    """
    V = np.asarray(V, dtype=np.float64)
    groups = polygons if isinstance(polygons, dict) else _parse_polygons(polygons, len(V))
    n = len(V)
    tris = [groups[3]] if 3 in groups else []
    newV, fans, prow, pcol, pval = [], [], [np.arange(n)], [np.arange(n)], [np.ones(n)]
    nv = n
    for s, Q in groups.items():
        if s == 3:
            continue
        w = virtual_vertex_weights(V[Q])                                # (q, s) polygons of this degree
        ids = nv + np.arange(len(Q))
        nv += len(Q)
        newV.append(np.einsum("qs,qsj->qj", w, V[Q]))
        fans.append(np.stack([np.repeat(ids, s), Q.ravel(), np.roll(Q, -1, axis=1).ravel()], 1))
        prow.append(np.repeat(ids, s))
        pcol.append(Q.ravel())
        pval.append(w.ravel())
    Vr = np.concatenate([V] + newV) if newV else V.copy()
    Fr = np.concatenate(tris + fans) if (tris or fans) else np.zeros((0, 3), np.int64)
    P = sp.csr_matrix((np.concatenate(pval), (np.concatenate(prow), np.concatenate(pcol))), shape=(nv, n))
    return Vr, Fr, P


def tangent_frames(N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """An arbitrary orthonormal tangent basis (e1, e2) per unit normal N (n, 3), e1 × e2 = N."""
    a = np.where(np.abs(N[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    e1 = a - N * np.einsum("ij,ij->i", a, N)[:, None]
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(N, e1)


def frame_transport(N, e1, e2, i, j) -> np.ndarray:
    """Unit complex r_ij expressing the basis vector e1_j in the basis of i after the smallest rotation taking
    N_j to N_i (Sharp et al. 2019 §6.2.2; geometry-central ``transportBetween(j, i)``): a tangent vector z_j in
    frame j is ``r_ij z_j`` in frame i; r_ji = conj(r_ij)."""
    a, b, v = N[j], N[i], e1[j]
    c = np.einsum("kj,kj->k", a, b)
    w = np.cross(a, b)
    # R v = v + w × v + w × (w × v) / (1 + c)  (Rodrigues, rotation taking a to b); antiparallel: skip
    den = np.where(1 + c > 1e-12, 1 + c, np.inf)
    wv = np.cross(w, v)
    Rv = v + wv + np.cross(w, wv) / den[:, None]
    z = np.einsum("kj,kj->k", Rv, e1[i]) + 1j * np.einsum("kj,kj->k", Rv, e2[i])
    mag = np.abs(z)
    return np.where(mag > 0, z / np.where(mag > 0, mag, 1.0), 1.0)


def connection_laplacian(L: sp.spmatrix, N, e1, e2) -> sp.csr_matrix:
    """Vertex connection Laplacian: off-diagonal entries of the real Laplacian L times the frame rotations
    r_ij (Eq. 9 / §8.3–8.4), the diagonal unchanged; Hermitian by construction (upper part, conjugated)."""
    L = sp.coo_matrix(L)
    up = L.row < L.col
    i, j, v = L.row[up], L.col[up], L.data[up]
    r = frame_transport(N, e1, e2, i, j)
    d = L.diagonal()
    n = L.shape[0]
    rows = np.concatenate([i, j, np.arange(n)])
    cols = np.concatenate([j, i, np.arange(n)])
    vals = np.concatenate([v * r, v * np.conj(r), d.astype(np.complex128)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


# --------------------------------------------------------------------------------------------- shared solver
class VertexSignedHeat:
    """Vertex-based steps I–III of the signed heat method (§3, §7.1) for a domain given by a PSD Laplacian L
    (n × n), lumped masses Mv (n,), tangent frames (N, e1, e2) and a connection Laplacian (used by the polygon
    (§8.3) and point-cloud (§8.4) solvers). ``divergence(Xv)`` maps per-vertex 3D vectors to the integrated
    divergence b with the convention ``L φ = b`` ⇔ ∇φ ≈ Y."""

    def __init__(self, X, L, Mv, Lconn, t, N, e1, e2, divergence):
        self.X, self.n = X, len(X)
        self.L = sp.csr_matrix(L)
        Mv = np.asarray(Mv, dtype=np.float64)
        self.Mv = np.where(Mv > 0, Mv, Mv[Mv > 0].mean() if (Mv > 0).any() else 1.0)
        self.Lconn, self.t = Lconn, float(t)
        self.N, self.e1, self.e2 = N, e1, e2
        self._divergence = divergence
        self._eps = 1e-10 * float(np.abs(self.L.diagonal()).mean()) / float(self.Mv.mean())
        self._vec = None
        self._poisson = None
        self._cache: dict = {}

    # ---------------------------------------------------------------- sources
    def parse_curves(self, curves, edge_check=None) -> list:
        if curves is None:
            return []
        if isinstance(curves, np.ndarray) and curves.ndim == 1:
            curves = [curves]
        out = []
        for k, c in enumerate(curves):
            a = vertex_polyline(c, self.n, f"curves[{k}]")
            a = a[np.concatenate([[True], a[1:] != a[:-1]])]
            if len(a) < 2:
                raise ValueError(f"curves[{k}]: a curve needs at least 2 distinct points")
            if edge_check is not None:
                edge_check(a, k)
            out.append(a)
        return out

    def parse_points(self, points) -> np.ndarray:
        if points is None:
            return np.zeros(0, np.int64)
        p = np.asarray(points).ravel() if not isinstance(points, (list, tuple)) else np.asarray(list(points))
        if p.size == 0:
            return np.zeros(0, np.int64)
        if p.ndim != 1 or not np.issubdtype(p.dtype, np.integer):
            raise ValueError("points: expected vertex indices (1-D int array)")
        if p.min() < 0 or p.max() >= self.n:
            raise ValueError(f"points: vertex index {int(p[(p < 0) | (p >= self.n)][0])} out of range for "
                             f"{self.n} vertices")
        return np.unique(p.astype(np.int64))

    def curve_source(self, curves, X0, normals=None):
        """Accumulate ½ ℓ · (in-plane curve normal) of every segment at both its end points (§8.3, §8.4);
        the normal is the segment projected into the end point's tangent plane, turned clockwise (T × n, left
        negative). ``normals`` (n, 3): the normals n to use (default: the frame normals)."""
        Nn = self.N if normals is None else normals
        for g in curves:
            a, b = g[:-1], g[1:]
            T = self.X[b] - self.X[a]
            ell = np.linalg.norm(T, axis=1)
            for v in (a, b):
                Tv = T - self.N[v] * np.einsum("kj,kj->k", T, self.N[v])[:, None]
                nrm = np.linalg.norm(Tv, axis=1)
                nv = np.cross(Tv / np.maximum(nrm, 1e-300)[:, None], Nn[v]) * (0.5 * ell)[:, None]
                z = np.einsum("kj,kj->k", nv, self.e1[v]) + 1j * np.einsum("kj,kj->k", nv, self.e2[v])
                np.add.at(X0, v, z)

    def point_source(self, ids, X0):
        """Isolated vertex sources (App. A.1 on a vertex discretization): at every Laplacian neighbour j of a
        source v the vector -L_vj (x_j - x_v), in j's tangent plane — radially outward, and balanced (Σ = 0 on
        flat regions by the linear precision of L), so no net vector dominates the far field after diffusion."""
        if len(ids) == 0:
            return
        Lr = self.L[ids].tocoo()
        v, j, w = ids[Lr.row], Lr.col, -Lr.data
        keep = (j != v) & (w > 0)
        v, j, w = v[keep], j[keep], w[keep]
        d = self.X[j] - self.X[v]
        d -= self.N[j] * np.einsum("kj,kj->k", d, self.N[j])[:, None]
        d *= w[:, None]
        z = np.einsum("kj,kj->k", d, self.e1[j]) + 1j * np.einsum("kj,kj->k", d, self.e2[j])
        np.add.at(X0, j, z)

    # ---------------------------------------------------------------- steps
    @property
    def vector_heat_factorization(self) -> HermitianFactorization:
        """The factorization of ``M + t L∇`` (Eq. 12 with vertex unknowns), built on first use."""
        if self._vec is None:
            self._vec = HermitianFactorization(sp.diags(self.Mv.astype(np.complex128)) + self.t * self.Lconn)
        return self._vec

    def to_3d(self, X) -> np.ndarray:
        return X.real[:, None] * self.e1 + X.imag[:, None] * self.e2

    def solve(self, X0, curves, points, mode, lam) -> np.ndarray:
        if not np.any(X0):
            raise ValueError("curves: the sources have zero total length / weight")
        X = self.vector_heat_factorization.solve(X0)
        b = self._divergence(self.to_3d(X))
        src = np.unique(np.concatenate([np.concatenate(curves) if curves else np.zeros(0, np.int64), points]))
        if mode == "none":
            phi = self._poisson_fact().solve(b)
        elif lam is not None:
            A = self._difference_rows(curves, points, single=(mode != "multiple"))
            key = ("soft", lam, A.indptr.tobytes(), A.indices.tobytes())
            phi = self._cached(key, lambda: Factorization(
                (self.L + lam * (A.T @ A) + sp.diags(self._eps * self.Mv)).tocsc())).solve(b)
        elif mode == "zero":
            phi = np.zeros(self.n)
            free = np.setdiff1d(np.arange(self.n), src)
            key = ("zero", src.tobytes())
            fact = self._cached(key, lambda: Factorization(
                (self.L[free][:, free] + sp.diags(self._eps * self.Mv[free])).tocsc()))
            phi[free] = fact.solve(b[free])
        else:
            A = self._difference_rows(curves, points, single=False)
            if A.shape[0] == 0:
                phi = self._poisson_fact().solve(b)
            else:
                key = ("multiple", A.indptr.tobytes(), A.indices.tobytes())
                delta = 1e-12 * float(self.L.diagonal().mean())
                fact = self._cached(key, lambda: Factorization(
                    saddle_matrix(self.L + sp.diags(self._eps * self.Mv), A, delta)))
                phi = fact.solve(np.concatenate([b, np.zeros(A.shape[0])]))[: self.n]
        return self._shift(phi, curves)

    def _poisson_fact(self) -> Factorization:
        if self._poisson is None:
            self._poisson = Factorization((self.L + sp.diags(self._eps * self.Mv)).tocsc())
        return self._poisson

    def _cached(self, key, build):
        return cached_factorization(self._cache, key, build)

    def _difference_rows(self, curves, points, single):
        """Rows φ(v) - φ(v0) = 0 per connected curve component (curves sharing vertices), or over all sources."""
        from scipy.sparse.csgraph import connected_components

        groups = []
        if single:
            allv = np.unique(np.concatenate(list(curves) + [points]))
            groups = [allv]
        elif curves:
            k = len(curves)
            r = np.concatenate([np.full(len(c), i) for i, c in enumerate(curves)])
            c = np.concatenate(curves)
            G = sp.csr_matrix((np.ones(len(r)), (r, k + c)), shape=(k + self.n, k + self.n))
            lab = connected_components(G, directed=False)[1][:k]
            groups = [np.unique(np.concatenate([curves[i] for i in np.flatnonzero(lab == g)]))
                      for g in np.unique(lab)]
        rows, cols, vals, m = [], [], [], 0
        for g in groups:
            if len(g) < 2:
                continue
            q = len(g) - 1
            rows += [np.arange(m, m + q)] * 2
            cols += [g[1:], np.full(q, g[0])]
            vals += [np.ones(q), -np.ones(q)]
            m += q
        if m == 0:
            return sp.csr_matrix((0, self.n))
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(m, self.n))

    def _shift(self, phi, curves):
        """Alg. 13: subtract the length-weighted mean of φ along the curves (min over points without curves)."""
        if curves:
            a = np.concatenate([c[:-1] for c in curves])
            b = np.concatenate([c[1:] for c in curves])
            ell = np.linalg.norm(self.X[b] - self.X[a], axis=1)
            if ell.sum() > 0:
                return phi - float((0.5 * (phi[a] + phi[b]) * ell).sum() / ell.sum())
        return phi - float(phi.min())


def solve_vertex_sources(core: VertexSignedHeat, curves, points, curve_signs, level_set_constraint, soft_weight,
                         edge_check=None, normals=None) -> np.ndarray:
    """Validate vertex sources and run steps I–III (shared by the polygon and point-cloud solvers)."""
    mode = _checks.choice(level_set_constraint, "level_set_constraint", LEVEL_SETS)
    lam = None if soft_weight is None else _checks.positive(soft_weight, "soft_weight")
    curves = core.parse_curves(curves, edge_check)
    pts = core.parse_points(points)
    if not curves and len(pts) == 0:
        raise ValueError("curves: no sources given (empty curve list and no points)")
    if curve_signs is None:
        signs = [True] * len(curves)
    else:
        signs = [bool(s) for s in curve_signs]
        if len(signs) != len(curves):
            raise ValueError(f"curve_signs: expected {len(curves)} entries (one per curve), got {len(signs)}")
    X0 = np.zeros(core.n, np.complex128)
    core.curve_source([c for c, s in zip(curves, signs) if s], X0, normals)
    # unsigned curves (App. A.2, vertex version): their vertices act as point sources
    unsigned = [c for c, s in zip(curves, signs) if not s]
    core.point_source(np.unique(np.concatenate(unsigned + [pts])), X0)
    return core.solve(X0, curves, pts, mode, lam)


# --------------------------------------------------------------------------------------------- polygon solver
class PolygonMeshSignedHeatSolver:
    """Signed heat method on a polygon mesh (§8.3) with the Bunge et al. 2020 polygon Laplacian (module docs).

    Parameters
    ----------
    V : (n, 3) float; polygons : list of int sequences (or an (m, k) array), any mix of degrees, planar or not;
    t_coef : float, diffusion time ``t = t_coef · (mean polygon edge length)²``.

    Attributes
    ----------
    L : (n, n) PSD polygon Laplacian ``Pᵀ C_fan P``; M : (n,) lumped mass; P : prolongation;
    V_refined, F_refined : the virtual-vertex refinement; N, e1, e2 : vertex tangent frames.

    Example
    -------
    >>> solver = PolygonMeshSignedHeatSolver(V, quads)                  # doctest: +SKIP
    >>> phi = solver.compute_distance([loop_along_edges])               # doctest: +SKIP
    """

    def __init__(self, V, polygons, t_coef: float = 1.0):
        V = _checks.as_points(V, "V")
        t_coef = _checks.positive(t_coef, "t_coef")
        self.n_vertices = n = len(V)
        self.V = V
        polys = _parse_polygons(polygons, n)
        self.V_refined, F, self.P = virtual_vertex_refinement(V, polys)
        # fan triangles of zero area (nonconvex / degenerate polygons) carry no stiffness or mass: drop them
        dbl = np.linalg.norm(np.cross(self.V_refined[F[:, 1]] - self.V_refined[F[:, 0]],
                                      self.V_refined[F[:, 2]] - self.V_refined[F[:, 0]]), axis=1)
        E = self._edges(polys)
        self._edge_keys, first = np.unique(np.minimum(E[:, 0], E[:, 1]) * n + np.maximum(E[:, 0], E[:, 1]),
                                           return_index=True)
        ell = np.linalg.norm(V[E[first, 1]] - V[E[first, 0]], axis=1)      # unique polygon edges
        self.mean_edge = float(ell.mean())
        good = dbl > 1e-12 * self.mean_edge ** 2
        if not good.any():
            raise ValueError("polygons: all polygons have zero area")
        self.F_refined = F[good]
        ops = TriangleMeshOperators(self.V_refined, self.F_refined)
        self.fine_ops = ops
        Pt = self.P.T.tocsr()
        L = (Pt @ ops.cotan_laplacian() @ self.P).tocsr()               # Bunge et al. 2020 §4: L = Pᵀ L_fan P
        self.L = (0.5 * (L + L.T)).tocsr()
        self.M = Pt @ ops.vertex_mass()                                  # lumped Pᵀ M_fan P (rows of P sum to 1)
        # vertex normals: area-weighted fine triangle normals (§8.3)
        An = np.zeros((len(self.V_refined), 3))
        for k in range(3):
            np.add.at(An, self.F_refined[:, k], ops.normals * ops.areas[:, None])
        An = An[:n]
        nrm = np.linalg.norm(An, axis=1)
        An[nrm == 0] = [0, 0, 1.0]
        self.N = An / np.maximum(nrm, 1e-300)[:, None]
        self.e1, self.e2 = tangent_frames(self.N)
        self.Lconn = connection_laplacian(self.L, self.N, self.e1, self.e2)
        self.t = t_coef * self.mean_edge ** 2
        self.core = VertexSignedHeat(V, self.L, self.M, self.Lconn, self.t, self.N, self.e1, self.e2,
                                     self._divergence)

    @staticmethod
    def _edges(groups) -> np.ndarray:
        return np.concatenate([np.stack([Q.ravel(), np.roll(Q, -1, axis=1).ravel()], 1) for Q in groups.values()])

    def _divergence(self, Xv: np.ndarray) -> np.ndarray:
        """§8.3: prolong vertex vectors to the fine vertices, average onto fine triangles, project into them,
        normalize, apply the fine divergence and restrict with Pᵀ (Bunge et al. §4.5)."""
        ops = self.fine_ops
        Xf = self.P @ Xv                                                 # (n + #virtual, 3)
        Y = Xf[ops.F].sum(axis=1)
        Y -= ops.normals * np.einsum("fj,fj->f", Y, ops.normals)[:, None]
        nrm = np.linalg.norm(Y, axis=1)
        out = np.zeros_like(Y)
        np.divide(Y, nrm[:, None], out=out, where=nrm[:, None] > 0)
        return self.P.T @ ops.divergence(out)

    def _check_edges(self, a, k):
        n = self.n_vertices
        key = np.minimum(a[:-1], a[1:]) * n + np.maximum(a[:-1], a[1:])
        pos = np.clip(np.searchsorted(self._edge_keys, key), 0, len(self._edge_keys) - 1)
        bad = self._edge_keys[pos] != key
        if bad.any():
            q = int(np.flatnonzero(bad)[0])
            raise ValueError(f"curves[{k}]: vertices {a[q]} and {a[q + 1]} (points {q}, {q + 1}) are not joined by "
                             "a polygon edge (curves must run along polygon edges)")

    def compute_distance(self, curves, points=(), curve_signs=None, level_set_constraint="zero",
                         soft_weight=None) -> np.ndarray:
        """Generalized signed distance (n,) at the vertices.

        Parameters
        ----------
        curves : list of 1-D int arrays, vertex polylines along polygon edges (closed: first = last); a
            counter-clockwise loop (seen from the normal side) encloses the negative region.
        points : vertex indices of isolated point sources (unsigned).
        curve_signs : per curve True (signed, default) or False (unsigned: its vertices act as point sources).
        level_set_constraint : "zero" (φ = 0 on all source vertices), "multiple" (φ constant along every
            connected curve component) or "none"; φ is then shifted to mean zero along the curves (Alg. 13).
        soft_weight : replaces the hard constraint by the penalty λ Σ (φ(v) - φ(v0))² (§7.1).
        """
        return solve_vertex_sources(self.core, curves, points, curve_signs, level_set_constraint, soft_weight,
                                    edge_check=self._check_edges)


__all__ = ["PolygonMeshSignedHeatSolver", "VertexSignedHeat", "virtual_vertex_refinement", "virtual_vertex_weights",
           "connection_laplacian", "tangent_frames"]
