"""Per-face geometry of triangle meshes and soups (vectorized numpy).

Scale invariance: every face's edge vectors are divided by a power of two near their largest component
before the cross product, so normals of triangles of size 1e-200 or 1e200 neither underflow nor overflow
(areas are scaled back exactly and are only inf/0 when the true value is outside float64).
"""

from __future__ import annotations

import numpy as np


def scaled_edges(V: np.ndarray, F: np.ndarray):
    """Edge vectors ``(b − a, c − a)`` of every face divided by ``2**e`` (per face), and ``e`` (m,) int.

    ``2**e`` is the power of two just above the largest |component| (e = 0 for a point-like face), so the
    scaled edges lie in [-1, 1] and their products are well inside float64.
    """
    from gsdf._checks import as_mesh

    V, F = as_mesh(V, F, allow_empty_faces=True)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    u, v = b - a, c - a
    big = np.maximum(np.abs(u).max(axis=1), np.abs(v).max(axis=1))
    e = np.where(big > 0, np.frexp(big)[1], 0).astype(np.int64)
    if not np.isfinite(big).all():  # the difference of two finite coordinates overflowed: redo it scaled
        s = np.ldexp(1.0, -1)
        u, v = b * s - a * s, c * s - a * s
        big = np.maximum(np.abs(u).max(axis=1), np.abs(v).max(axis=1))
        e = np.where(big > 0, np.frexp(big)[1], 0).astype(np.int64)
        return np.ldexp(u, -e[:, None]), np.ldexp(v, -e[:, None]), e + 1
    return np.ldexp(u, -e[:, None]), np.ldexp(v, -e[:, None]), e


def face_area_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Area-weighted face normals ``a_t n_t`` (half the cross product), shape (m, 3)."""
    u, v, e = scaled_edges(V, F)
    return np.ldexp(0.5 * np.cross(u, v), 2 * e[:, None])


def face_areas(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Triangle areas, shape (m,)."""
    u, v, e = scaled_edges(V, F)
    return np.ldexp(0.5 * np.linalg.norm(np.cross(u, v), axis=1), 2 * e)


def face_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit face normals, shape (m, 3); degenerate (zero-area) faces get a zero normal."""
    u, v, _ = scaled_edges(V, F)
    N = np.cross(u, v)
    L = np.linalg.norm(N, axis=1, keepdims=True)
    out = np.zeros_like(N)
    np.divide(N, L, out=out, where=L > 0)
    return out


def bounding_box(X: np.ndarray, pad: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounding box of points ``X``, grown by ``pad`` times its diagonal on every side."""
    from gsdf.grid import diagonal

    lo, hi = X.min(axis=0), X.max(axis=0)
    d = diagonal(lo, hi) or 1.0
    return lo - pad * d, hi + pad * d
