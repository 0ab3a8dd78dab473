"""Discrete exterior calculus on tetrahedral meshes: Hodge stars, the jump Laplace solve and jump fields.

Owns: positive diagonal Hodge stars (the P1 FEM edge weights clamped positive, barycentric dual volumes, dual
edge over face area); per-corner jump coordinates of an oriented face chain, its Darboux derivative, and the jump
Laplace solve of Chen, Li & Huang 2026 (seed 003, §4.1–4.2, Eqs. 2–6 and 10) with the fixes of the implementation
notes (wave2 §2(b).1, .3): c is per corner (a walk in each vertex star), weights are FEM weights clamped positive.
The geometry, connectivity, d0/d1/d2 and the FEM weights come from :class:`gsdf.mesh._tet_ops.TetOperators`
(its module docs give the orientation conventions).

An oriented face chain ``G`` (one integer per face) carries the jump of the winding field: crossing face ``f``
along its canonical normal, the value drops by ``G[f]`` (inside = 1, outside = 0 for a chain whose normals point
out of the shape).

Example
-------
>>> import numpy as np
>>> from gsdf.dec._tet import TetComplex
>>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
>>> K = TetComplex(V, np.array([[0, 1, 2, 3]]))
>>> K.d0.shape, K.d1.shape, K.d2.shape
((6, 4), (4, 6), (1, 4))
>>> float(abs(K.d1 @ K.d0).sum()), float(abs(K.d2 @ K.d1).sum())
(0.0, 0.0)
"""

from __future__ import annotations

import numba as nb
import numpy as np
import scipy.sparse as sp

from gsdf._checks import as_points
from gsdf.mesh._tet_ops import EDGE_PAIRS, TetOperators

__all__ = ["TetComplex", "chain_boundary_vertices", "correction_chain"]


def _as_tets(T, n_vertices: int) -> np.ndarray:
    A = np.asarray(T)
    if A.ndim != 2 or A.shape[1] != 4:
        raise ValueError(f"T: expected shape (m, 4), got {A.shape}")
    if A.shape[0] == 0:
        raise ValueError("T: is empty (0 tets)")
    if A.dtype == bool or not np.issubdtype(A.dtype, np.integer):
        raise ValueError(f"T: expected an integer index array, got dtype {A.dtype}")
    A = np.ascontiguousarray(A, dtype=np.int64)
    if A.min() < 0 or A.max() >= n_vertices:
        raise ValueError(f"T: indices must lie in [0, {n_vertices}), got range [{A.min()}, {A.max()}]")
    if (np.sort(A, axis=1)[:, 1:] == np.sort(A, axis=1)[:, :-1]).any():
        raise ValueError("T: a tet repeats a vertex")
    return A


class TetComplex(TetOperators):
    """A tetrahedral mesh as a cell complex with DEC operators.

    Parameters
    ----------
    V : (n, 3) float array
        Vertex positions.
    T : (m, 4) int array
        Tets; reordered in a copy so that every tet is positively oriented.  Tets of zero volume are allowed
        (Qhull slivers); their FEM weights are zero and the clamp of :attr:`star1` keeps stars positive.

    Attributes
    ----------
    Those of :class:`~gsdf.mesh._tet_ops.TetOperators` (``V``, ``T`` positively oriented, ``volumes``, ``edges``,
    ``faces``, ``tet_edges``, ``tet_faces``, ``tet_face_sign``, ``face_tets``, ``d0``, ``d1``, ``d2``,
    :meth:`~gsdf.mesh._tet_ops.TetOperators.edge_weights`), built at once; ``star0``, ``star1``, ``star2``.
    """

    def __init__(self, V, T):
        V = as_points(V, "V")
        super().__init__(V, _as_tets(T, V.shape[0]))
        self._build_edges()
        self._build_faces()                                     # checks that no two tets overlap at a face
        self._star1 = None

    @property
    def star1(self) -> np.ndarray:
        """(nE,) positive diagonal ⋆1: summed FEM weights clamped to [1e-3, 1e3] × their positive median.

        The lower clamp makes ⋆1 positive (notes 2(b).3); the upper one bounds the conditioning of the face
        Laplacian ``d1 ⋆1⁻¹ d1ᵀ``, which sliver tets (dihedral angles near 0 or π) would otherwise ruin.  Any
        positive diagonal keeps the Hodge decomposition exact.
        """
        if self._star1 is None:
            w = np.bincount(self.tet_edges.ravel(), self.edge_weights().ravel(), minlength=self.n_edges)
            pos = w[w > 0]
            med = np.median(pos) if pos.size else 1.0
            self._star1 = np.clip(w, 1e-3 * med, 1e3 * med)
        return self._star1

    @property
    def star0(self) -> np.ndarray:
        """(nV,) barycentric dual volumes (a quarter of each incident tet); isolated vertices get a tiny floor."""
        s = self.vertex_mass()
        pos = s[s > 0]
        return np.maximum(s, 1e-12 * (pos.mean() if pos.size else 1.0))

    @property
    def star2(self) -> np.ndarray:
        """(nF,) positive ⋆2 = |dual edge| / |face|, dual edge through the centroids of the adjacent tets."""
        Fc = self.faces
        area = self.face_areas()
        cen_t = self.V[self.T].mean(axis=1)
        cen_f = self.V[Fc].mean(axis=1)
        L = np.zeros(len(Fc))
        for s in (0, 1):
            t = self.face_tets[:, s]
            ok = t >= 0
            L[ok] += np.linalg.norm(cen_t[t[ok]] - cen_f[ok], axis=1)
        s = L / np.maximum(area, 1e-300)
        pos = s[s > 0]
        return np.maximum(s, 1e-3 * (np.median(pos) if pos.size else 1.0))

    def laplacian(self) -> sp.csr_matrix:
        """(nV, nV) positive semidefinite ``L0 = d0ᵀ ⋆1 d0`` (seed 003 Eq. 5, with clamped FEM weights)."""
        d0 = self.d0
        return (d0.T @ sp.diags(self.star1) @ d0).tocsr()

    # ------------------------------------------------------------------ jump fields
    def _vertex_stars(self):
        order = np.argsort(self.T.ravel(), kind="stable")
        counts = np.bincount(self.T.ravel(), minlength=self.n_vertices)
        ptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        return ptr, order.astype(np.int64)  # order // 4 = tet, order % 4 = local corner

    def jump_coordinates(self, G, exclude=None) -> tuple[np.ndarray, np.ndarray]:
        """Per-corner jump coordinates ``c[t, k]`` of the chain ``G`` (seed 003 Eqs. 2–3, notes 2(b).1).

        In the star of each vertex ``v`` (the tets containing it) a breadth-first walk across the faces that
        contain ``v`` starts at 0 on the first tet and adds the jump of every crossed face.  When ``v`` lies on
        the boundary curve of the chain, the walk is path dependent; such vertices (``exclude``, default
        :func:`chain_boundary_vertices`) get ``c = 0`` on all their corners.

        Parameters
        ----------
        G : (nF,) int or float array — jump per face along its canonical orientation.
        exclude : (nV,) bool array or None.

        Returns
        -------
        c : (m, 4) float64; excluded : (nV,) bool.
        """
        G = np.asarray(G, dtype=np.float64)
        if G.shape != (self.n_faces,) or not np.isfinite(G).all():
            raise ValueError(f"G: expected a finite array of shape ({self.n_faces},), got {G.shape}")
        if exclude is None:
            exclude = chain_boundary_vertices(self, G)
        exclude = np.asarray(exclude, dtype=bool)
        ptr, order = self._vertex_stars()
        c = np.zeros((self.n_tets, 4))
        _star_walk(self.T, self.tet_faces, self.tet_face_sign, self.face_tets, G, ptr, order, exclude, c)
        return c, exclude

    def darboux_derivative(self, c: np.ndarray) -> np.ndarray:
        """(nE,) ω_ab = mean over the tets around edge ab of ``c[t, b] - c[t, a]`` (seed 003 Eq. 4, sign fixed)."""
        i, j = EDGE_PAIRS[:, 0], EDGE_PAIRS[:, 1]
        # orient each tet-edge difference along the canonical edge (lower index → higher)
        Ti, Tj = self.T[:, i], self.T[:, j]
        diff = c[:, j] - c[:, i]
        diff = np.where(Ti < Tj, diff, -diff)
        s = np.bincount(self.tet_edges.ravel(), diff.ravel(), minlength=self.n_edges)
        n = np.bincount(self.tet_edges.ravel(), minlength=self.n_edges)
        return s / np.maximum(n, 1)

    def jump_laplace(self, G, exclude=None, solver=None) -> tuple[np.ndarray, dict]:
        """Solve the jump Laplace problem of the chain ``G``; return per-corner values ``u`` (m, 4).

        ``u[t, k] = u0[T[t, k]] + c[t, k]`` with ``u0`` the least-squares (⋆1-weighted) potential whose gradient
        cancels the exact part of the Darboux derivative ω: ``L0 u0 = -d0ᵀ ⋆1 ω`` (seed 003 Eqs. 5, 10–11).
        The gauge is fixed by the median of the corner values on hull tets being 0 (notes 2(b).7).

        Returns
        -------
        u : (m, 4) float64 corner values; info : dict with ``c``, ``omega``, ``u0``, ``excluded``.
        """
        c, excluded = self.jump_coordinates(G, exclude)
        omega = self.darboux_derivative(c)
        L = self.laplacian()
        rhs = -(self.d0.T @ (self.star1 * omega))
        # pin u0 at vertex 0 to 0 (the system is singular by constants); the gauge is fixed afterwards
        keep = np.arange(1, self.n_vertices)
        u0 = np.zeros(self.n_vertices)
        A = L[keep][:, keep].tocsc()
        if solver is None:
            from gsdf.linalg import Factorization
            u0[keep] = Factorization(A).solve(rhs[keep])
        else:
            u0[keep] = solver(A, rhs[keep])
        u = u0[self.T] + c
        hull_t = np.unique(np.concatenate([self.face_tets[self.face_tets[:, 1] < 0, 0],
                                           self.face_tets[self.face_tets[:, 0] < 0, 1]]))
        hull_t = hull_t[hull_t >= 0]
        off = np.median(u[hull_t]) if hull_t.size else 0.0
        u -= off
        return u, {"c": c, "omega": omega, "u0": u0 - off, "excluded": excluded}


    def hodge(self):
        """A :class:`gsdf.dec._hodge.HodgeDecomposition` of 1-forms on this complex (⋆1 = clamped FEM weights)."""
        from gsdf.dec._hodge import HodgeDecomposition
        return HodgeDecomposition(self.d0, self.d1, self.star1, self.star0, self.star2)


def correction_chain(K: TetComplex, gamma, eps_start: float = 1.0, eps_end: float = 1e-2, eps_factor: float = 4.0,
                     max_iter: int = 30, tol: float = 1e-4) -> tuple[np.ndarray, dict]:
    """The L0 correction chain Λ of a harmonic 1-form γ (seed 003 §4.2.2, Eqs. 7–9, notes 2(b).2).

    A per-tet potential ``v^T = vInit^T + σ_T`` integrates γ: ``vInit`` along the edges from the tet's first
    vertex (exact inside one tet, as γ is closed), the per-tet constant σ is free.  Across an interior face f
    from ``t0 = face_tets[f, 0]`` (the face points out of it) to ``t1`` the potential jumps by
    ``Λ_f = d_f + σ_t1 − σ_t0`` with ``d_f = vInit^t1_a − vInit^t0_a`` at a shared vertex a, so ``D σ = γ``
    holds by construction.  ``Σ_f |f| |Λ_f|⁰`` is minimised by IRLS: weighted dual-graph Laplacian solves of
    ``Σ_f |f| w_f Λ_f²`` with ``w_f = ε² / (ε² + Λ_f²)``, ε decreasing from ``eps_start`` to ``eps_end``, until
    ``max |Δσ| < tol`` or ``max_iter`` solves (one tet fixed: σ_0 = 0).

    Parameters
    ----------
    K : TetComplex; gamma : (nE,) closed 1-form (the harmonic part of a Darboux derivative).

    Returns
    -------
    Lam : (nF,) float — jump of the potential along each face's canonical normal (0 on hull faces);
    info : dict with ``sigma`` (nT,), ``iterations``, ``d`` (nF,).

    Subtracting the potential from the winding field changes the face chain G to ``G + Λ`` (a drop by G along
    the normal becomes a drop by G + Λ), whose Darboux derivative has no harmonic part.
    """
    import scipy.sparse.linalg as spla

    gamma = np.asarray(gamma, dtype=np.float64)
    if gamma.shape != (K.n_edges,) or not np.isfinite(gamma).all():
        raise ValueError(f"gamma: expected a finite array of shape ({K.n_edges},), got {gamma.shape}")
    T = K.T
    vinit = np.zeros((K.n_tets, 4))
    for k in (1, 2, 3):  # edges (0,1), (0,2), (0,3) are tet_edges[:, 0..2]
        g = gamma[K.tet_edges[:, k - 1]]
        vinit[:, k] = np.where(T[:, 0] < T[:, k], g, -g)
    ft = K.face_tets
    interior = np.flatnonzero((ft >= 0).all(axis=1))
    t0, t1 = ft[interior, 0], ft[interior, 1]
    a = K.faces[interior, 0]
    k0 = np.argmax(T[t0] == a[:, None], axis=1)
    k1 = np.argmax(T[t1] == a[:, None], axis=1)
    d = vinit[t1, k1] - vinit[t0, k0]
    area = K.face_areas()[interior]
    area = area / max(area.mean(), 1e-300)
    nI = len(interior)
    B = sp.csr_matrix((np.concatenate([np.ones(nI), -np.ones(nI)]),
                       (np.concatenate([np.arange(nI)] * 2), np.concatenate([t1, t0]))), shape=(nI, K.n_tets))
    sigma = np.zeros(K.n_tets)
    wf = np.ones(nI)
    eps = eps_start
    it = 0
    for it in range(1, max_iter + 1):
        W = sp.diags(area * wf)
        A = (B.T @ W @ B).tocsc()[1:, 1:]
        rhs = -(B.T @ (area * wf * d))[1:]
        new = np.zeros(K.n_tets)
        if A.shape[0] <= 60000:
            new[1:] = spla.spsolve(A, rhs)
        else:  # pragma: no cover - large complexes: Jacobi CG
            new[1:] = spla.cg(A, rhs, rtol=1e-10, maxiter=5000, M=sp.diags(1.0 / A.diagonal()))[0]
        change = np.abs(new - sigma).max()
        sigma = new
        lam = d + B @ sigma
        wf = eps * eps / (eps * eps + lam * lam)
        if change < tol and eps <= eps_end:
            break
        eps = max(eps / eps_factor, eps_end)
    Lam = np.zeros(K.n_faces)
    Lam[interior] = d + B @ sigma
    return Lam, {"sigma": sigma, "iterations": it, "d": np.concatenate([d])}


def chain_boundary_vertices(K: TetComplex, G) -> np.ndarray:
    """(nV,) bool: vertices of interior edges where the boundary ``d1ᵀ G`` of the chain is nonzero.

    Boundary edges of the chain that lie on the hull of the complex do not make a star walk path dependent
    (the star of a hull vertex is a half-ball, cut by the chain into pieces), so they are not counted.
    """
    b = K.d1.T @ np.asarray(G, dtype=np.float64)
    hull_f = (K.face_tets < 0).any(axis=1)
    on_hull = np.zeros(K.n_edges, dtype=bool)
    if hull_f.any():
        on_hull[np.unique(np.abs(K.d1[np.flatnonzero(hull_f)]).indices)] = True
    bad = (np.abs(b) > 1e-9) & ~on_hull
    out = np.zeros(K.n_vertices, dtype=bool)
    out[K.edges[bad].ravel()] = True
    return out


@nb.njit(cache=True, parallel=True)
def _star_walk(T, tet_faces, tet_face_sign, face_tets, G, ptr, order, exclude, c):
    nV = ptr.shape[0] - 1
    for v in nb.prange(nV):
        a, b = ptr[v], ptr[v + 1]
        n = b - a
        if n == 0 or exclude[v]:
            continue
        queue = np.empty(n, dtype=np.int64)
        seen = np.zeros(n, dtype=np.bool_)
        # local index in this star of a tet: linear search over a small star is fine (stars ~ 20–30 tets)
        queue[0] = 0
        seen[0] = True
        head, tail = 0, 1
        while head < tail:
            s = queue[head]
            head += 1
            code = order[a + s]
            t, kv = code // 4, code % 4
            val = c[t, kv]
            for k in range(4):
                if k == kv:
                    continue  # the face opposite v does not contain v
                f = tet_faces[t, k]
                sg = tet_face_sign[t, k]
                t2 = face_tets[f, 1] if sg > 0 else face_tets[f, 0]
                if t2 < 0:
                    continue
                # find t2 in the star
                s2 = -1
                for q in range(n):
                    if order[a + q] // 4 == t2:
                        s2 = q
                        break
                if s2 < 0 or seen[s2]:
                    continue
                seen[s2] = True
                # leaving t through f: along the canonical normal if f points out of t (sg > 0): drop by G
                c[t2, order[a + s2] % 4] = val - sg * G[f]
                queue[tail] = s2
                tail += 1
