"""The Crouzeix–Raviart vector heat operators of the signed heat method on triangle meshes (Feng & Crane 2024,
§5.2–5.4): the complex edge bases, the CR connection Laplacian (Eqs. 8–9), the vector heat matrix (Eq. 12), and
the maps between edge vectors and face vectors. Geometry, connectivity, the cotan Laplacian, masses and the
divergence come from :class:`gsdf.mesh._triangle_ops.TriangleOperators`.

Conventions
-----------
* Face slot ``a`` (0, 1, 2) of face ``f = (v0, v1, v2)`` is the edge ``(v_a, v_{a+1})``, opposite ``v_{a+2}``.
* Edge ``e`` has the canonical direction ``edges[e, 0] -> edges[e, 1]`` with ``edges[e, 0] < edges[e, 1]``.
* The complex edge basis of §5.2: in face ``f`` the real axis at edge ``e`` is the unit canonical direction
  ``u``, the imaginary axis ``n_f × u`` (90° counter-clockwise in the face). On a consistently oriented mesh the
  two faces of an edge agree on this basis. Where two faces traverse their shared edge in the *same* direction
  (inconsistent orientation: nonorientable meshes, or orientable meshes with flipped faces) the imaginary axis
  of one is minus that of the other, so the coordinates of one vector are complex conjugates of each other —
  a reflection, which no complex factor e^{iθ} can express. Every edge therefore stores its vectors in the
  basis of a *reference* face (its first face in the face list); ``slot_sigma`` (m, 3) is +1 where a face's
  basis agrees with the reference and -1 where it is conjugated. When some ``slot_sigma`` is -1, the
  connection Laplacian is assembled as a real symmetric 2|E|×2|E| matrix of 2×2 blocks
  (:meth:`TriangleMeshOperators.cr_connection_laplacian_real`); otherwise the complex one is exact and faster.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf.linalg._assembly import coo_to_csr
from gsdf.mesh._triangle_ops import NEXT, TriangleOperators

__all__ = ["TriangleMeshOperators"]


class TriangleMeshOperators(TriangleOperators):
    """:class:`~gsdf.mesh._triangle_ops.TriangleOperators` with the Crouzeix–Raviart vector heat operators.

    ``point_weight`` (class default 1.0) is the length a vertex point source (App. A.1, Eq. 19: unit
    vectors, no length) weighs against the length-weighted curve sources, in these operators' units: the
    front-end running in a frame of scale s sets 1/s, so that a point keeps weighing one input unit.

    Parameters
    ----------
    V, F, P, edges : as for :class:`~gsdf.mesh._triangle_ops.TriangleOperators` (``F`` validated, no degenerate
        faces; ``edges=False``: the vertex operators only, no CR operators).

    Attributes
    ----------
    slot_sign : (m, 3) float ±1 (``face_edge_signs``); h : mean spacing of edge midpoints (half the mean edge
    length, §6); slot_u, slot_w : (m, 3, 3) unit canonical direction of every slot's edge and ``n × u``;
    slot_rho : (m, 3) complex direction of ``u`` in the face frame; edge_ref_slot : (nE,) flat slot of every
    edge's reference face; slot_sigma : (m, 3) ±1; consistent : bool (every ``slot_sigma`` is +1)

    Example
    -------
    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
    >>> ops = TriangleMeshOperators(V, F)
    >>> float(abs(ops.cotan_laplacian().toarray().sum())) < 1e-12
    True
    """

    point_weight = 1.0

    def __init__(self, V: np.ndarray, F: np.ndarray, P: np.ndarray | None = None, edges: bool = True):
        super().__init__(V, F, P=P, edges=edges)
        if not edges:
            return
        m = self.n_faces
        E = self.P[:, NEXT] - self.P
        self.slot_sign = self.face_edge_signs.astype(np.float64)
        self.h = 0.5 * float(self.edge_len.mean())
        # per slot: unit canonical edge direction u, in-face perpendicular w = n x u, and the complex direction
        # rho of u in a face frame (x = slot-0 direction, y = n x x), used for the rotations of Eq. 8
        U = E / self.slot_len[..., None] * self.slot_sign[..., None]
        self.slot_u = U
        self.slot_w = np.cross(self.normals[:, None, :], U)
        x = E[:, 0] / self.slot_len[:, :1]
        y = np.cross(self.normals, x)
        self.slot_rho = np.einsum("fij,fj->fi", U, x) + 1j * np.einsum("fij,fj->fi", U, y)
        # orientation of every slot's edge basis relative to the edge's reference slot (its first occurrence):
        # faces that traverse the edge in the same direction as the reference have the opposite orientation
        fe = self.face_edges.ravel()
        order = np.argsort(fe, kind="stable")
        first = order[np.searchsorted(fe[order], np.arange(self.n_edges))]   # first slot of every edge
        self.edge_ref_slot = first
        ss = self.slot_sign.ravel()
        self.slot_sigma = np.where(np.arange(3 * m) == first[fe], 1.0,
                                   np.where(ss == ss[first[fe]], -1.0, 1.0)).reshape(m, 3)
        self.consistent = bool((self.slot_sigma > 0).all())

    # ------------------------------------------------------------------ Crouzeix–Raviart operators (§5.3–5.4)
    def cr_connection_laplacian(self) -> sp.csr_matrix:
        """Complex Hermitian PSD CR connection Laplacian, Eqs. 8–9 (Alg. 5).

        For slots a and b = a+1 of a face (meeting at vertex ``v_{a+1}``, angle θ), with w = 2 cot θ:
        diagonal += w, and L[e_a, e_b] = -w ρ̄_a ρ_b, where ρ is the direction of each edge's real axis in a
        common face frame (the rotation r of Eq. 8, including the orientation sign s).
        """
        rows, cols, vals = self._cr_connection_triplets()
        return coo_to_csr(rows, cols, vals, (self.n_edges, self.n_edges))

    def cr_vector_heat_matrix(self, t: float) -> sp.csr_matrix:
        """``M + t L∇`` (Eq. 12: CR mass, Eq. 7, plus t times the complex connection Laplacian) assembled in
        one pass (the triplets of both, summed), complex (|E|, |E|)."""
        rows, cols, vals = self._cr_connection_triplets()
        nE = self.n_edges
        d = np.arange(nE)
        mass = self.cr_mass_diagonal()
        return coo_to_csr(np.concatenate([d, rows]), np.concatenate([d, cols]),
                          np.concatenate([mass.astype(np.complex128), t * vals]), (nE, nE))

    def _cr_connection_triplets(self):
        a = np.arange(3)
        b = NEXT
        w = 2.0 * self.cot[:, b]                                # angle at the shared vertex v_{a+1}
        ea, eb = self.face_edges[:, a], self.face_edges[:, b]
        off = -w * np.conj(self.slot_rho[:, a]) * self.slot_rho[:, b]
        rows = np.concatenate([ea.ravel(), eb.ravel(), ea.ravel(), eb.ravel()])
        cols = np.concatenate([ea.ravel(), eb.ravel(), eb.ravel(), ea.ravel()])
        vals = np.concatenate([w.ravel(), w.ravel(), off.ravel(), np.conj(off).ravel()]).astype(np.complex128)
        return rows, cols, vals

    def cr_connection_laplacian_real(self) -> sp.csr_matrix:
        """Real symmetric PSD CR connection Laplacian (2|E|, 2|E|) of 2×2 blocks, for any orientation.

        Unknown ``2e, 2e+1`` are the (real, imaginary) coordinates of the vector at edge e in the basis of the
        edge's reference face. In face f the local coordinates are ``S_a x_e`` with ``S_a = diag(1, σ_a)``
        (``slot_sigma``, a reflection where f's orientation disagrees with the reference), and the per-corner
        energy of Eq. 8–9 is ``w |R(ρ_a) S_a x_a - R(ρ_b) S_b x_b|²`` (R = rotation). Hence diagonal blocks
        ``w I`` and off-diagonal blocks ``-w (R_a S_a)ᵀ R_b S_b``. With every σ = +1 this is exactly the real
        form ``[[Re, -Im], [Im, Re]]`` of :meth:`cr_connection_laplacian`.
        """
        a = np.arange(3)
        b = NEXT
        w = (2.0 * self.cot[:, b]).ravel()
        ea, eb = self.face_edges[:, a].ravel(), self.face_edges[:, b].ravel()

        def block(rho, sig):                                  # R(ρ) S, shape (k, 2, 2)
            c, s = rho.real.ravel(), rho.imag.ravel()
            sg = sig.ravel()
            return np.stack([np.stack([c, -s * sg], -1), np.stack([s, c * sg], -1)], -2)

        Aa = block(self.slot_rho[:, a], self.slot_sigma[:, a])
        Ab = block(self.slot_rho[:, b], self.slot_sigma[:, b])
        off = -w[:, None, None] * np.einsum("kji,kjl->kil", Aa, Ab)          # -w Aaᵀ Ab
        r2, c2 = np.meshgrid(np.arange(2), np.arange(2), indexing="ij")
        rows = np.concatenate([(2 * ea[:, None, None] + r2).ravel(), (2 * eb[:, None, None] + r2).ravel(),
                               2 * ea, 2 * ea + 1, 2 * eb, 2 * eb + 1])
        cols = np.concatenate([(2 * eb[:, None, None] + c2).ravel(), (2 * ea[:, None, None] + c2).ravel(),
                               2 * ea, 2 * ea + 1, 2 * eb, 2 * eb + 1])
        vals = np.concatenate([off.ravel(), off.transpose(0, 2, 1).ravel(), w, w, w, w])
        n2 = 2 * self.n_edges
        return sp.csr_matrix((vals, (rows, cols)), shape=(n2, n2))

    # ------------------------------------------------------------------ edge vectors <-> face vectors
    def edge_to_face_vectors(self, X: np.ndarray) -> np.ndarray:
        """Sum over the three edges of each face of the edge vectors X (complex, edge basis) as 3D vectors
        (face averaging of §6 up to the factor ⅓, Alg. 3), shape (m, 3)."""
        z = X[self.face_edges]                                   # (m, 3), reference-face coordinates
        if not self.consistent:
            z = np.where(self.slot_sigma > 0, z, np.conj(z))     # to this face's basis
        return (np.einsum("fi,fij->fj", z.real, self.slot_u) + np.einsum("fi,fij->fj", z.imag, self.slot_w))

    def slot_coords(self, faces: np.ndarray, N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Edge indices (k, 3) and complex coordinates (k, 3), in the edges' reference bases, of face vectors
        N (k, 3) at the 3 edges of ``faces`` (Eq. 11 without the φ factor, as the paper recommends)."""
        u, w = self.slot_u[faces], self.slot_w[faces]
        z = np.einsum("kij,kj->ki", u, N) + 1j * np.einsum("kij,kj->ki", w, N)
        if not self.consistent:
            z = np.where(self.slot_sigma[faces] > 0, z, np.conj(z))   # to the edges' reference bases
        return self.face_edges[faces], z
