"""Geometry, connectivity and sparse operators of a triangle mesh: the one set that discrete exterior calculus
(:mod:`gsdf.dec`), the signed heat method (:mod:`gsdf.heat`: triangle, intrinsic and polygon domains) and surface
winding numbers (:mod:`gsdf.swn`, through :class:`gsdf.dec.TriangleDEC`) build on.

Everything is assembled per face with vectorized numpy and summed into scipy.sparse matrices, so the operators are
oblivious to nonmanifold edges and vertices and to boundary (Feng & Crane 2024, §9.4): an edge shared by k faces
receives k contributions.

Conventions (shared with :mod:`gsdf.mesh._connectivity`)
-------------------------------------------------------
* face slot ``k`` of face ``f`` is the edge ``F[f, k] -> F[f, k+1]``, opposite the corner ``k+2``;
* per-corner quantities (``cot``, ``angles``) are indexed by the corner's vertex slot ``k``;
* edge ``e`` runs ``edges[e, 0] -> edges[e, 1]`` with ``edges[e, 0] < edges[e, 1]``; ``face_edge_signs`` is +1
  where a slot runs along that direction.

Formulas
--------
* cotangents by Feng & Crane 2024, Eq. 5: ``cot θ_i^{jk} = (|ij|² − |jk|² + |ki|²) / (4 |ijk|)``;
* cotan Laplacian, Eq. 10 (the weak Laplacian of P1 elements); lumped (barycentric) vertex masses, §9.1;
* Crouzeix–Raviart mass, Eq. 7 (one third of the area of the faces around every edge);
* the coboundaries d0, d1 and the diagonal Hodge stars they pair with (Feng 2026, thesis §2.2);
* the per-face gradient of P1 functions and the integrated divergence of face vectors (§5.5, the weak form of
  Eq. 3).

Example
-------
>>> import numpy as np
>>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]); F = np.array([[0, 1, 3], [0, 3, 2]])
>>> ops = TriangleOperators(V, F)
>>> float(abs(ops.d1 @ ops.d0).max()), float(abs(ops.cotan_laplacian() @ np.ones(4)).max())
(0.0, 0.0)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf.linalg._assembly import coo_to_csr
from gsdf.mesh._connectivity import unique_edges

__all__ = ["NEXT", "PREV", "TriangleOperators", "d0_matrix"]

NEXT = np.array([1, 2, 0])
PREV = np.array([2, 0, 1])


def d0_matrix(edges: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    """The coboundary d0 (nE × n) of oriented edges ``edges[e] = (a, b)``: ``(d0 u)_e = u_b − u_a``.

    Example
    -------
    >>> d0_matrix(np.array([[0, 1], [1, 2]]), 3).toarray().tolist()
    [[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]]
    """
    nE = len(edges)
    r = np.arange(nE)
    return sp.csr_matrix((np.concatenate([-np.ones(nE), np.ones(nE)]),
                          (np.concatenate([r, r]), np.asarray(edges).T.ravel())), shape=(nE, n_vertices))


class TriangleOperators:
    """Geometry, connectivity and operators of a triangle mesh, built once (module docs).

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64, validated (every index in range, no face repeating a vertex)
    P : (m, 3, 3) float64, optional
        Per-face corner positions to use instead of ``V[F]``: the planar layouts of an intrinsic triangulation
        (:mod:`gsdf.heat.intrinsic._kernels`). Every operator needs only per-face corner positions.
    edges : bool
        False: the vertex operators only (``cotan_laplacian``, ``vertex_mass``, ``divergence``, ``gradient``) and
        the per-face geometry — no edge connectivity (the refined meshes of polygon Laplacians).
    topology : MeshTopology, optional
        Connectivity to take the edges from (built lazily by :attr:`topology` when omitted).

    Attributes
    ----------
    V, F, P; n_vertices, n_faces; intrinsic : bool (``P`` given)
    areas : (m,); normals : (m, 3) unit; slot_len : (m, 3) length of every slot;
    cot : (m, 3) cotangent of the corner angle at ``F[:, k]`` (Eq. 5), not finite on zero-area faces;
    angles : (m, 3) corner angles (computed on first use)
    edges : (nE, 2); face_edges : (m, 3) edge of every slot; face_edge_signs : (m, 3) int8 ±1; n_edges;
    edge_keys : (nE,) ``lo * n + hi`` (sorted); edge_len : (nE,)

    Example
    -------
    >>> import numpy as np
    >>> ops = TriangleOperators(np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    >>> ops.cot.round(12).tolist(), ops.vertex_mass().round(4).tolist()
    ([[0.0, 1.0, 1.0]], [0.1667, 0.1667, 0.1667])
    """

    def __init__(self, V: np.ndarray, F: np.ndarray, P: np.ndarray | None = None, edges: bool = True,
                 topology=None):
        self.V, self.F = V, F
        self.intrinsic = P is not None
        n, m = len(V), len(F)
        self.n_vertices, self.n_faces = n, m
        P = V[F] if P is None else P                           # (m, 3, 3) corner positions
        self.P = P
        E = P[:, NEXT] - P                                     # slot vectors v_k -> v_{k+1}
        cr = np.cross(E[:, 0], -E[:, 2])                       # (v1 - v0) x (v2 - v0)
        dbl = np.linalg.norm(cr, axis=1)
        self.areas = 0.5 * dbl
        L2 = np.einsum("fij,fij->fi", E, E)
        self.slot_len = np.sqrt(L2)
        with np.errstate(divide="ignore", invalid="ignore"):   # zero-area faces: nan normals, non-finite cot
            self.normals = cr / dbl[:, None]
            # cot of the angle at corner k (opposite slot k+1), Eq. 5: (|ki|² + |ij|² − |jk|²) / (4 area)
            self.cot = (L2[:, PREV] + L2 - L2[:, NEXT]) / (4.0 * self.areas[:, None])
        self._topology = topology
        self._vf = self._angles = self._d0 = self._d1 = self._div_G = None
        if not edges:
            return
        if topology is not None:
            self.edges, self.face_edges, self.face_edge_signs = (topology.edges, topology.face_edges,
                                                                 topology.face_edge_signs)
        else:
            self.edges, self.face_edges, self.face_edge_signs = unique_edges(F, n)
        self.n_edges = len(self.edges)
        self.edge_keys = self.edges[:, 0] * n + self.edges[:, 1]
        self.edge_len = np.zeros(self.n_edges)
        self.edge_len[self.face_edges.ravel()] = self.slot_len.ravel()

    # ------------------------------------------------------------------------------------------- geometry
    @property
    def angles(self) -> np.ndarray:
        """(m, 3) interior angle at every corner, ``arccos`` of the normalized dot product of its two slots
        (0 where a slot has zero length)."""
        if self._angles is None:
            E, ln = self.P[:, NEXT] - self.P, self.slot_len
            den = ln * ln[:, PREV]
            with np.errstate(divide="ignore", invalid="ignore"):
                cosang = np.einsum("fij,fij->fi", E, -E[:, PREV]) / den
            cosang = np.where(den > 0, cosang, 1.0)
            self._angles = np.arccos(np.clip(cosang, -1.0, 1.0))
        return self._angles

    @property
    def topology(self):
        """The :class:`~gsdf.mesh._connectivity.MeshTopology` of ``F`` (the one given, or built on first use)."""
        if self._topology is None:
            from gsdf.mesh._connectivity import MeshTopology

            self._topology = MeshTopology(self.F, self.n_vertices)
        return self._topology

    # ------------------------------------------------------------------------------------- connectivity
    @property
    def d0(self) -> sp.csr_matrix:
        """(nE, n) coboundary of vertex functions, ``(d0 u)_e = u_hi − u_lo`` (:func:`d0_matrix`)."""
        if self._d0 is None:
            self._d0 = d0_matrix(self.edges, self.n_vertices)
        return self._d0

    @property
    def d1(self) -> sp.csr_matrix:
        """(m, nE) coboundary of edge chains, ``(d1 ω)_f = Σ_k sign_fk ω_{e_fk}``."""
        if self._d1 is None:
            m = self.n_faces
            self._d1 = sp.csr_matrix((self.face_edge_signs.ravel().astype(np.float64),
                                      (np.repeat(np.arange(m), 3), self.face_edges.ravel())),
                                     shape=(m, self.n_edges))
        return self._d1

    def edge_lookup(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Edge index of vertex pairs (i, j), or -1 where there is no such edge."""
        i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
        key = np.minimum(i, j) * self.n_vertices + np.maximum(i, j)
        pos = np.searchsorted(self.edge_keys, key)
        pos = np.clip(pos, 0, self.n_edges - 1)
        return np.where(self.edge_keys[pos] == key, pos, -1)

    def vertex_faces(self) -> sp.csr_matrix:
        """Sparse incidence (n, m): row i lists the faces containing vertex i (value = slot + 1)."""
        if self._vf is None:
            m = self.n_faces
            rows = self.F.ravel()
            cols = np.repeat(np.arange(m), 3)
            vals = np.tile(np.arange(1, 4), m)
            self._vf = sp.csr_matrix((vals, (rows, cols)), shape=(self.n_vertices, m))
        return self._vf

    # ---------------------------------------------------------------------------------------- operators
    def cotan_laplacian(self, cot: np.ndarray | None = None, exclude: np.ndarray | None = None) -> sp.csr_matrix:
        """Positive semidefinite cotan Laplacian C (Eq. 10): ``C_ij = −½ Σ cot θ_k``, ``C_ii = −Σ_j C_ij``.

        Parameters
        ----------
        cot : (m, 3), optional
            Per-corner cotangents to use instead of :attr:`cot` (e.g. clamped ones, :class:`gsdf.dec.TriangleDEC`).
        exclude : (n,) bool, optional
            Drop the edge terms touching these vertices (their rows and columns are then empty).
        """
        F = self.F
        i, j = F[:, NEXT].ravel(), F[:, PREV].ravel()          # slot opposite corner k: (v_{k+1}, v_{k+2})
        w = 0.5 * (self.cot if cot is None else cot).ravel()
        if exclude is not None and exclude.any():
            keep = ~(exclude[i] | exclude[j])
            i, j, w = i[keep], j[keep], w[keep]
        rows = np.concatenate([i, j, i, j])
        cols = np.concatenate([j, i, i, j])
        vals = np.concatenate([-w, -w, w, w])
        n = self.n_vertices
        return coo_to_csr(rows, cols, vals, (n, n))

    def vertex_mass(self) -> np.ndarray:
        """Lumped (barycentric) vertex areas ``A_i = ⅓ Σ |ijk|`` (§9.1; thesis §2.2 ⋆0), shape (n,)."""
        return np.bincount(self.F.ravel(), weights=np.repeat(self.areas / 3.0, 3), minlength=self.n_vertices)

    def cr_mass_diagonal(self) -> np.ndarray:
        """Diagonal of the Crouzeix–Raviart mass matrix, Eq. 7: ⅓ of the area of the faces around every edge."""
        return np.bincount(self.face_edges.ravel(), weights=np.repeat(self.areas / 3.0, 3), minlength=self.n_edges)

    def cr_mass(self) -> sp.csr_matrix:
        """The diagonal Crouzeix–Raviart mass matrix, Eq. 7 (:meth:`cr_mass_diagonal`)."""
        return sp.diags(self.cr_mass_diagonal()).tocsr()

    def gradient(self) -> sp.csr_matrix:
        """Per-face gradient of vertex functions, (3m, n): rows 3f..3f+2 give ∇φ on face f,
        ``∇φ_f = Σ_k φ_k ∇λ_k`` with ``∇λ_k = n × (v_{k+2} − v_{k+1}) / (2 |f|)``."""
        F = self.F
        E = self.P[:, NEXT] - self.P                           # slot vectors (per-face layouts if intrinsic)
        G = np.cross(self.normals[:, None, :], E[:, NEXT]) / (2 * self.areas[:, None, None])
        m = len(F)
        rows = (3 * np.arange(m)[:, None, None] + np.arange(3)[None, None, :]).repeat(3, axis=1)  # (m, k, d)
        cols = np.broadcast_to(F[:, :, None], (m, 3, 3))
        return sp.csr_matrix((G.ravel(), (rows.ravel(), cols.ravel())), shape=(3 * m, self.n_vertices))

    def divergence(self, Y: np.ndarray) -> np.ndarray:
        """Integrated divergence ``b_i = Σ_f |f| ∇λ_i · Y_f`` of a face vector field Y (m, 3) (§5.5, the weak form
        of Eq. 3; the boundary term n·Y is omitted as in the paper). With the PSD cotan Laplacian C, ``C φ = b``
        is the least-squares fit ∇φ ≈ Y of Eq. 2."""
        if self._div_G is None:                                 # per mesh, kept for repeated solves
            E = self.P[:, NEXT] - self.P
            # |f| ∇λ_k = ½ n × (v_{k+2} - v_{k+1}) = ½ n × E[:, k+1]
            self._div_G = 0.5 * np.cross(self.normals[:, None, :], E[:, NEXT])
        contrib = np.einsum("fkj,fj->fk", self._div_G, Y)
        return np.bincount(self.F.ravel(), weights=contrib.ravel(), minlength=self.n_vertices)
