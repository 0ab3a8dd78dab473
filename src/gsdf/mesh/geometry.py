"""Per-face geometry of triangle meshes and soups (vectorized numpy)."""

from __future__ import annotations

import numpy as np


def face_area_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Area-weighted face normals ``a_t n_t`` (half the cross product), shape (m, 3)."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return 0.5 * np.cross(b - a, c - a)


def face_areas(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Triangle areas, shape (m,)."""
    return np.linalg.norm(face_area_normals(V, F), axis=1)


def face_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit face normals, shape (m, 3); degenerate (zero-area) faces get a zero normal."""
    N = face_area_normals(V, F)
    L = np.linalg.norm(N, axis=1, keepdims=True)
    out = np.zeros_like(N)
    np.divide(N, L, out=out, where=L > 0)
    return out


def bounding_box(X: np.ndarray, pad: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounding box of points ``X``, grown by ``pad`` times its diagonal on every side."""
    lo, hi = X.min(axis=0), X.max(axis=0)
    d = float(np.linalg.norm(hi - lo)) or 1.0
    return lo - pad * d, hi + pad * d
