"""Per-face polygonal discrete exterior calculus of de Goes, Butts & Desbrun 2020 ("Discrete differential
operators on polygonal meshes"), vectorized over faces of one degree k.

Used by the signed heat method on digital surfaces (Feng & Crane 2024 §8.5, through Coeurjolly & Lachaud 2022,
who apply these operators to a *corrected* embedding of each quad). For a face with corners X (k, 3), in order:

* D: cyclic difference ``(D φ)_i = φ_{i+1} − φ_i`` (vertex 0-form → edge 1-form); A: edge average
  ``(A φ)_i = (φ_i + φ_{i+1}) / 2``; E = D X the edge vectors;
* vector area ``a = ½ Σ x_i × x_{i+1}``, unit normal n = a / |a|, centroid c (corner mean), edge midpoints B = A X;
* gradient ``G = −|a|⁻¹ [n]_× Eᵀ A`` (3 × k): exact for linear functions on a planar face;
* flat ``V = E (I − n nᵀ)`` (k × 3): a vector as its integrals along the edges;
* sharp ``U = |a|⁻¹ [n]_× (Bᵀ − c 1ᵀ)`` (3 × k), with ``U V = I`` on the face plane and ``U D = G``;
* projection ``P = I − V U`` (k × k) onto the 1-forms that no constant vector reproduces;
* inner product on edge 1-forms ``M = |a| Uᵀ U + λ Pᵀ P`` (λ = 1 here, as in DGtal);
* Laplacian ``D ᵀ M D`` (k × k) — positive semidefinite here (gsdf's sign convention; de Goes and DGtal use
  its negative) — and the 1-form divergence ``Dᵀ M`` (so ``Dᵀ M V G φ = Dᵀ M D φ`` for linear φ);
* lumped vertex mass: every corner gets |a| / k.

Everything is a batch of small dense matrices (einsum over the face axis); no loop over faces.

Example
-------
>>> import numpy as np
>>> X = np.array([[[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]])     # one unit square
>>> ops = face_operators(X)
>>> bool(np.allclose(ops.laplacian[0] @ np.ones(4), 0))
True
>>> (ops.gradient[0] @ np.array([0., 1, 1, 0])).round(12).tolist()    # φ = x
[1.0, 0.0, 0.0]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _cross_matrix(n: np.ndarray) -> np.ndarray:
    """[n]_× (m, 3, 3) with [n]_× v = n × v for vectors n (m, 3)."""
    K = np.zeros(n.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2] = -n[..., 2], n[..., 1]
    K[..., 1, 0], K[..., 1, 2] = n[..., 2], -n[..., 0]
    K[..., 2, 0], K[..., 2, 1] = -n[..., 1], n[..., 0]
    return K


@dataclass
class FaceOperators:
    """The per-face operators of a batch of m faces with k corners (shapes in brackets).

    Attributes
    ----------
    area : (m,) |a_f|; normal : (m, 3) n_f; centroid : (m, 3) c_f;
    D : (k, k) cyclic difference (the same for every face);
    gradient : (m, 3, k) G_f; flat : (m, k, 3) V_f; sharp : (m, 3, k) U_f; projection : (m, k, k) P_f;
    inner : (m, k, k) M_f (λ-weighted); laplacian : (m, k, k) Dᵀ M_f D (PSD); divergence : (m, k, k) Dᵀ M_f.
    """

    area: np.ndarray
    normal: np.ndarray
    centroid: np.ndarray
    D: np.ndarray
    gradient: np.ndarray
    flat: np.ndarray
    sharp: np.ndarray
    projection: np.ndarray
    inner: np.ndarray
    laplacian: np.ndarray
    divergence: np.ndarray


def face_operators(X: np.ndarray, lam: float = 1.0) -> FaceOperators:
    """de Goes et al. 2020 operators of m polygons with k corners each, ``X`` (m, k, 3) (module docs).

    Faces of zero vector area get zero operators (no stiffness, no mass).
    """
    X = np.asarray(X, dtype=np.float64)
    m, k, _ = X.shape
    D = np.roll(np.eye(k), 1, axis=1) - np.eye(k)              # (Dφ)_i = φ_{i+1} − φ_i
    A = 0.5 * (np.roll(np.eye(k), 1, axis=1) + np.eye(k))      # (Aφ)_i = (φ_i + φ_{i+1}) / 2
    Xn = np.roll(X, -1, axis=1)
    E = Xn - X                                                  # (m, k, 3) edge vectors, = D X
    a = 0.5 * np.cross(X, Xn).sum(axis=1)                       # vector area
    area = np.linalg.norm(a, axis=1)
    good = area > 0
    inv = np.where(good, 1.0 / np.where(good, area, 1.0), 0.0)
    n = a * inv[:, None]
    c = X.mean(axis=1)
    B = 0.5 * (X + Xn)                                          # edge midpoints, = A X
    Kn = _cross_matrix(n)
    # G = −|a|⁻¹ [n]_× Eᵀ A  (de Goes et al. 2020 §3, gradient of the piecewise-linear-on-edges function)
    G = -inv[:, None, None] * np.einsum("mij,mlj,lk->mik", Kn, E, A)
    # V = E (I − n nᵀ)  (flat), U = |a|⁻¹ [n]_× (Bᵀ − c 1ᵀ)  (sharp)
    V = E - np.einsum("mkj,mj,mi->mki", E, n, n)
    U = inv[:, None, None] * np.einsum("mij,mkj->mik", Kn, B - c[:, None, :])
    P = np.eye(k)[None] - np.einsum("mki,mil->mkl", V, U)
    M = area[:, None, None] * np.einsum("mik,mil->mkl", U, U) + lam * np.einsum("mik,mil->mkl", P, P)
    DM = np.einsum("ik,mil->mkl", D, M)                         # Dᵀ M
    Lf = np.einsum("mkl,lj->mkj", DM, D)                        # Dᵀ M D
    Lf = 0.5 * (Lf + np.transpose(Lf, (0, 2, 1)))
    return FaceOperators(area=area, normal=n, centroid=c, D=D, gradient=G, flat=V, sharp=U, projection=P,
                         inner=M, laplacian=Lf, divergence=DM)


__all__ = ["FaceOperators", "face_operators"]
