"""Angle-weighted pseudonormals of faces, edges and vertices (Bærentzen & Aanæs 2005).

For a closed, consistently oriented 2-manifold triangle mesh, the sign of ``(q - c) . n`` -- with ``c``
the closest point of the mesh to ``q`` and ``n`` the pseudonormal of the feature (face interior, edge
or vertex) that contains ``c`` -- is positive outside and negative inside. The pseudonormals are:

* face: the unit face normal;
* edge: the sum of the unit normals of the faces sharing the edge (each weighted by the angle pi),
  normalized;
* vertex: the sum over incident faces of the interior angle at the vertex times the unit face normal,
  normalized.

Degenerate (zero-area) faces have a zero normal and contribute nothing. On non-manifold edges all
incident faces are summed, which is a heuristic: the sign test is only guaranteed on closed manifolds.
Features whose weighted sum vanishes get a zero pseudonormal.

Everything is vectorized numpy; cost O(n + m log m) (the edge table is built with a sort).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from gsdf._checks import as_mesh
from gsdf.mesh._geometry import face_normals

__all__ = ["Pseudonormals", "corner_angles", "vertex_pseudonormals", "edge_pseudonormals", "pseudonormals"]


class Pseudonormals(NamedTuple):
    """Angle-weighted pseudonormals of a triangle mesh.

    face : (m, 3)
        Unit face normals (zero for degenerate faces).
    edge : (m, 3, 3)
        ``edge[f, k]`` is the pseudonormal of the edge of face ``f`` opposite its corner ``k``
        (i.e. the edge ``F[f, k+1], F[f, k+2]``).
    vertex : (n, 3)
        Vertex pseudonormals.
    """

    face: np.ndarray
    edge: np.ndarray
    vertex: np.ndarray


def _normalize(X: np.ndarray) -> np.ndarray:
    L = np.linalg.norm(X, axis=-1, keepdims=True)
    out = np.zeros_like(X)
    np.divide(X, L, out=out, where=L > 0)
    return out


def corner_angles(V, F) -> np.ndarray:
    """Interior angle (radians) of every face corner, shape (m, 3); ``atan2(|u x v|, u . v)`` so it is
    accurate for needle and cap triangles. Corners with a zero-length side get angle 0."""
    V, F = as_mesh(V, F)
    P = V[F]  # (m, 3, 3)
    u = np.roll(P, -1, axis=1) - P  # corner k -> k+1
    v = np.roll(P, -2, axis=1) - P  # corner k -> k+2
    # angles are scale-invariant: divide each corner's sides by a power of two near their size first, so
    # |u x v| and u . v neither underflow (1e-200 triangles) nor overflow (1e200)
    big = np.maximum(np.abs(u).max(axis=2), np.abs(v).max(axis=2))
    if np.isfinite(big).all():
        ex = np.where(big > 0, np.frexp(big)[1], 0)[:, :, None]
        u, v = np.ldexp(u, -ex), np.ldexp(v, -ex)
    s = np.linalg.norm(np.cross(u, v), axis=-1)
    c = np.einsum("mkd,mkd->mk", u, v)
    return np.arctan2(s, c)


def vertex_pseudonormals(V, F) -> np.ndarray:
    """Angle-weighted vertex pseudonormals, shape (n, 3) (zero at unreferenced vertices)."""
    V, F = as_mesh(V, F)
    N = face_normals(V, F)
    W = corner_angles(V, F)[:, :, None] * N[:, None, :]  # (m, 3, 3)
    idx = F.ravel()
    acc = np.stack([np.bincount(idx, weights=W[:, :, d].ravel(), minlength=V.shape[0]) for d in range(3)], axis=1)
    return _normalize(acc)


def edge_pseudonormals(V, F):
    """Edge pseudonormals.

    Returns
    -------
    edges : (k, 2) int64
        Unique undirected edges (sorted vertex pairs).
    normals : (k, 3)
        Unit sum of the normals of the faces incident to each edge.
    face_edges : (m, 3) int64
        ``face_edges[f, j]`` indexes the edge of face ``f`` opposite its corner ``j``.
    """
    V, F = as_mesh(V, F)
    m = F.shape[0]
    N = face_normals(V, F)
    # edge opposite corner j joins corners j+1 and j+2
    E = np.stack([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]], axis=1).reshape(-1, 2)  # (3m, 2)
    E.sort(axis=1)
    edges, inv = np.unique(E, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    W = np.repeat(N, 3, axis=0)  # (3m, 3) face normal of each half-edge
    acc = np.stack([np.bincount(inv, weights=W[:, d], minlength=edges.shape[0]) for d in range(3)], axis=1)
    return edges.astype(np.int64), _normalize(acc), inv.reshape(m, 3).astype(np.int64)


def pseudonormals(V, F) -> Pseudonormals:
    """Face, edge (per face corner) and vertex pseudonormals; see :class:`Pseudonormals`."""
    V, F = as_mesh(V, F)
    _, en, fe = edge_pseudonormals(V, F)
    return Pseudonormals(face=face_normals(V, F), edge=en[fe], vertex=vertex_pseudonormals(V, F))
