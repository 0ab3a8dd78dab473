"""Geometry, connectivity and sparse operators of a tetrahedral mesh: the one set that discrete exterior calculus
on tets (:class:`gsdf.dec._tet.TetComplex`, reconstruction) and the tet domain of the signed heat method
(:mod:`gsdf.heat.tet`) build on.

Conventions
-----------
* Tets are stored positively oriented (``det[v1 − v0, v2 − v0, v3 − v0] > 0``): :class:`TetOperators` keeps a
  copy of ``T`` with vertices 2 and 3 swapped where needed.
* Local edge ``k`` of a tet joins its local vertices ``EDGE_PAIRS[k]``; local face ``k`` is ``FACE_LOCAL[k]``,
  opposite local vertex ``k``, ordered so that its right-hand normal points out of the tet.
* Edge ``e = (a, b)`` with ``a < b`` points from ``a`` to ``b``: ``(d0 u)_e = u_b − u_a``. Face ``(a, b, c)``
  with ``a < b < c`` has the right-hand normal ``(b − a) × (c − a)`` and boundary ``ab + bc − ac``;
  ``d2[t, f] = +1`` when that normal points out of ``t``.

Formulas (P1 finite elements, the tet analogue of the cotan Laplacian: Feng & Crane 2024, §8.1 and App. B; Chen,
Li & Huang 2026, Eq. 5)
-------------------------------------------------------------------------------------------------------------
* ``A_k`` = outward area vector of the face opposite vertex k (½ the cross product of two of its edges); the
  barycentric gradients are ``∇λ_k = −A_k / (3 |T|)``;
* edge weights ``w_ij = −|T| ∇λ_i · ∇λ_j = −A_i · A_j / (9 |T|)`` (= ``|e_kl| cot θ_kl / 6``, θ the dihedral
  angle at the opposite edge); the stiffness (cotan Laplacian) ``K_ij = −Σ_T w_ij``, ``K_ii = −Σ_j K_ij``;
* weak divergence of tet vectors ``b_i = Σ_T |T| ∇λ_i · Y_T = −Σ_T A_i · Y_T / 3`` (Eq. 22 against the hat
  functions); lumped vertex masses ``Σ_T |T| / 4``.

Example
-------
>>> import numpy as np
>>> ops = TetOperators(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]), np.array([[0, 2, 1, 3]]))
>>> ops.T.tolist(), float(ops.volumes[0] * 6)                         # reoriented
([[0, 2, 3, 1]], 1.0)
>>> float(abs(ops.d1 @ ops.d0).sum()), float(abs(ops.d2 @ ops.d1).sum())
(0.0, 0.0)
>>> bool(abs(ops.cotan_laplacian() @ np.ones(4)).max() < 1e-15)
True
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.sparse as sp

from gsdf.linalg._assembly import coo_to_csr
from gsdf.mesh._triangle_ops import d0_matrix

__all__ = ["EDGE_PAIRS", "FACE_LOCAL", "TetOperators", "signed_volumes", "unique_rows"]

# local vertex pairs of the 6 edges of a tet
EDGE_PAIRS = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])
# outward-oriented faces of a positively oriented tet, face k opposite local vertex k (from ∂[v0v1v2v3])
FACE_LOCAL = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def signed_volumes(V: np.ndarray, T: np.ndarray) -> np.ndarray:
    """``det[v1 − v0, v2 − v0, v3 − v0]`` of every tet (six times its signed volume), shape (m,)."""
    a, b, c, d = (V[T[:, k]] for k in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)


def _perm_sign(A: np.ndarray) -> np.ndarray:
    """Sign of the permutation sorting each row of ``A`` (rows of 3 distinct values)."""
    inv = (A[:, 0] > A[:, 1]).astype(np.int64) + (A[:, 0] > A[:, 2]) + (A[:, 1] > A[:, 2])
    return 1 - 2 * (inv % 2)


def unique_rows(R: np.ndarray, n: int):
    """``np.unique(R, axis=0, return_inverse=True)`` for rows of k ≤ 3 vertex ids < ``n``, same result.

    Each row is packed into one int64 (base ``n`` digits), whose numeric order is the rows' lexicographic
    order, so a 1-D unique gives the same rows, order and inverse — ~10× faster than the row-wise unique
    (a structured-view sort) on millions of rows.  Falls back to it when the key would overflow.
    """
    k = R.shape[1]
    if n ** k >= 2 ** 63:
        u, inv = np.unique(R, axis=0, return_inverse=True)
        return u, inv.ravel()
    key = np.zeros(len(R), dtype=np.int64)
    for j in range(k):
        key = key * n + R[:, j].astype(np.int64)
    uk, inv = np.unique(key, return_inverse=True)
    u = np.empty((len(uk), k), dtype=R.dtype)
    for j in range(k - 1, -1, -1):
        u[:, j] = uk % n
        uk = uk // n
    return u, inv.ravel()


class TetOperators:
    """Geometry, connectivity and operators of a tet mesh (module docs); connectivity is built on first use.

    Parameters
    ----------
    V : (n, 3) float
    T : (m, 4) int, validated (indices in range, no tet repeating a vertex); copied and reordered so that every
        tet is positively oriented. Tets of zero volume are allowed; their edge weights are zero.

    Attributes
    ----------
    V, T; n_vertices, n_tets; volumes : (m,)
    area_vectors : (m, 4, 3) outward area vector of the face opposite each vertex
    edges : (nE, 2), ``edges[:, 0] < edges[:, 1]``; tet_edges : (m, 6) edge ids in the order of ``EDGE_PAIRS``
    faces : (nF, 3) increasing per row; tet_faces : (m, 4) face ids, face k opposite local vertex k;
    tet_face_sign : (m, 4) ±1; face_tets : (nF, 2) the tet the canonical normal points out of and the one it
    points into (-1 on the hull); n_edges, n_faces
    """

    def __init__(self, V: np.ndarray, T: np.ndarray):
        T = np.array(T, dtype=np.int64)
        det = signed_volumes(V, T)
        neg = det < 0
        T[neg, 2], T[neg, 3] = T[neg, 3].copy(), T[neg, 2].copy()
        self.V, self.T = V, T
        self.volumes = np.abs(det) / 6.0
        self.n_vertices, self.n_tets = V.shape[0], T.shape[0]
        self._edges = self._faces = None

    # ------------------------------------------------------------------------------------------- geometry
    @cached_property
    def area_vectors(self) -> np.ndarray:
        """(m, 4, 3) outward area vectors ``A_k`` of the faces opposite each vertex (``∇λ_k = −A_k / 3|T|``)."""
        V, T = self.V, self.T
        A = np.empty((self.n_tets, 4, 3))
        for k in range(4):
            i, j, l = FACE_LOCAL[k]
            p = V[T[:, i]]
            A[:, k] = 0.5 * np.cross(V[T[:, j]] - p, V[T[:, l]] - p)
        return A

    def edge_weights(self) -> np.ndarray:
        """(m, 6) P1 FEM edge weights of each tet, ``w_ij = −|T| ∇λ_i·∇λ_j = −A_i·A_j / (9|T|)`` =
        ``|e_kl| cot θ_kl / 6`` (θ_kl the dihedral angle at the edge opposite ij), in the order of ``EDGE_PAIRS``.
        They can be negative (obtuse dihedral angles); 0 on tets of zero volume."""
        A = self.area_vectors
        dots = np.einsum("tkx,tkx->tk", A[:, EDGE_PAIRS[:, 0]], A[:, EDGE_PAIRS[:, 1]])
        vol = self.volumes
        out = np.zeros_like(dots)
        ok = vol > 1e-300
        out[ok] = -dots[ok] / (9.0 * vol[ok, None])
        return out

    def face_areas(self) -> np.ndarray:
        """(nF,) triangle areas of :attr:`faces`."""
        V, Fc = self.V, self.faces
        return 0.5 * np.linalg.norm(np.cross(V[Fc[:, 1]] - V[Fc[:, 0]], V[Fc[:, 2]] - V[Fc[:, 0]]), axis=1)

    # ------------------------------------------------------------------------------------- connectivity
    def _build_edges(self):
        Eall = np.sort(self.T[:, EDGE_PAIRS].reshape(-1, 2), axis=1)
        edges, inv = unique_rows(Eall, self.n_vertices)
        self._edges = edges, inv.reshape(self.n_tets, 6).astype(np.int64)

    def _build_faces(self):
        m = self.n_tets
        Floc = self.T[:, FACE_LOCAL].reshape(-1, 3)
        sign = _perm_sign(Floc)
        faces, finv = unique_rows(np.sort(Floc, axis=1), self.n_vertices)
        nF = faces.shape[0]
        ft = -np.ones((nF, 2), dtype=np.int64)
        side = (sign < 0).astype(np.int64)  # 0: face points out of this tet
        if (np.bincount(finv * 2 + side, minlength=2 * nF) > 1).any():
            raise ValueError("T: a face is shared by two tets on the same side (overlapping or inconsistent tets)")
        ft[finv, side] = np.repeat(np.arange(m), 4)
        self._faces = faces, finv.reshape(m, 4).astype(np.int64), sign.reshape(m, 4).astype(np.int64), ft

    @property
    def edges(self) -> np.ndarray:
        if self._edges is None:
            self._build_edges()
        return self._edges[0]

    @property
    def tet_edges(self) -> np.ndarray:
        if self._edges is None:
            self._build_edges()
        return self._edges[1]

    @property
    def faces(self) -> np.ndarray:
        if self._faces is None:
            self._build_faces()
        return self._faces[0]

    @property
    def tet_faces(self) -> np.ndarray:
        if self._faces is None:
            self._build_faces()
        return self._faces[1]

    @property
    def tet_face_sign(self) -> np.ndarray:
        if self._faces is None:
            self._build_faces()
        return self._faces[2]

    @property
    def face_tets(self) -> np.ndarray:
        if self._faces is None:
            self._build_faces()
        return self._faces[3]

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @cached_property
    def d0(self) -> sp.csr_matrix:
        """(nE, nV) gradient: ``(d0 u)_ab = u_b − u_a``."""
        return d0_matrix(self.edges, self.n_vertices)

    @cached_property
    def d1(self) -> sp.csr_matrix:
        """(nF, nE) curl: face (a, b, c) → ab + bc − ac."""
        Fc, n = self.faces, self.n_vertices
        key = self.edges[:, 0] * n + self.edges[:, 1]
        cols = np.stack([np.searchsorted(key, Fc[:, a] * n + Fc[:, b]) for a, b in ((0, 1), (1, 2), (0, 2))], axis=1)
        vals = np.tile([1.0, 1.0, -1.0], (len(Fc), 1))
        rows = np.repeat(np.arange(len(Fc)), 3)
        return sp.csr_matrix((vals.ravel(), (rows, cols.ravel())), shape=(len(Fc), self.n_edges))

    @cached_property
    def d2(self) -> sp.csr_matrix:
        """(nT, nF) divergence: +1 where the canonical face normal points out of the tet."""
        rows = np.repeat(np.arange(self.n_tets), 4)
        return sp.csr_matrix((self.tet_face_sign.ravel().astype(float), (rows, self.tet_faces.ravel())),
                             shape=(self.n_tets, self.n_faces))

    # ---------------------------------------------------------------------------------------- operators
    def cotan_laplacian(self) -> sp.csr_matrix:
        """(nV, nV) P1 stiffness (the cotan Laplacian of tets), positive semidefinite: ``K_ij = −Σ_T w_ij``,
        ``K_ii = −Σ_j K_ij`` (:meth:`edge_weights`), assembled per tet without the edge connectivity; exactly
        symmetric (``K_ij`` and ``K_ji`` sum the same terms in the same order)."""
        a, b = self.T[:, EDGE_PAIRS[:, 0]].ravel(), self.T[:, EDGE_PAIRS[:, 1]].ravel()
        i, j = np.minimum(a, b), np.maximum(a, b)
        w = self.edge_weights().ravel()
        n = self.n_vertices
        return coo_to_csr(np.concatenate([i, j, i, j]), np.concatenate([j, i, i, j]),
                          np.concatenate([-w, -w, w, w]), (n, n))

    def vertex_mass(self) -> np.ndarray:
        """(nV,) lumped (barycentric) vertex volumes: a quarter of every incident tet."""
        return np.bincount(self.T.ravel(), np.repeat(self.volumes / 4.0, 4), minlength=self.n_vertices)

    def divergence(self, Y: np.ndarray) -> np.ndarray:
        """Weak divergence ``b_i = Σ_T |T| ∇λ_i · Y_T = −Σ_T A_i · Y_T / 3`` of tet vectors Y (m, 3), shape (nV,)."""
        contrib = np.einsum("tax,tx->ta", self.area_vectors, Y) / -3.0
        return np.bincount(self.T.ravel(), weights=contrib.ravel(), minlength=self.n_vertices)
