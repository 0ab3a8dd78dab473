"""Input validation shared by every entry point.

Every public function funnels its array arguments through these helpers so that bad input
(wrong shape, NaN/inf, empty arrays, indices out of range) raises a ``ValueError`` that names
the argument and the problem, instead of crashing inside a numba kernel.
"""

from __future__ import annotations

import numpy as np


def as_points(X, name: str = "points", dim: int | None = 3, allow_empty: bool = False) -> np.ndarray:
    """Return ``X`` as a C-contiguous float64 array of shape (n, dim), or raise ValueError.

    ``dim=None`` accepts 2 or 3 columns.
    """
    try:
        A = np.asarray(X)
    except Exception as exc:  # pragma: no cover - numpy rarely fails here
        raise ValueError(f"{name}: cannot be converted to an array ({exc})") from exc
    if A.dtype == object or not (np.issubdtype(A.dtype, np.number) or A.dtype == bool):
        raise ValueError(f"{name}: expected a numeric array, got dtype {A.dtype}")
    if np.issubdtype(A.dtype, np.complexfloating):
        raise ValueError(f"{name}: complex values are not coordinates")
    if A.ndim == 1 and dim is not None and A.shape[0] == dim:
        A = A.reshape(1, dim)
    if A.ndim != 2:
        want = f"(n, {dim})" if dim is not None else "(n, 2) or (n, 3)"
        raise ValueError(f"{name}: expected shape {want}, got {A.shape}")
    if dim is None:
        if A.shape[1] not in (2, 3):
            raise ValueError(f"{name}: expected 2 or 3 columns, got shape {A.shape}")
    elif A.shape[1] != dim:
        raise ValueError(f"{name}: expected shape (n, {dim}), got {A.shape}")
    if A.shape[0] == 0 and not allow_empty:
        raise ValueError(f"{name}: is empty (0 rows)")
    A = np.ascontiguousarray(A, dtype=np.float64)
    if not np.isfinite(A).all():
        bad = int(np.argmax(~np.isfinite(A).all(axis=1)))
        raise ValueError(f"{name}: contains NaN or infinite coordinates (first at row {bad})")
    return A


def as_faces(F, n_vertices: int, name: str = "F", corners: int | None = 3, allow_empty: bool = False) -> np.ndarray:
    """Return ``F`` as a C-contiguous int64 (m, corners) index array, checking the index range."""
    A = np.asarray(F)
    if A.ndim == 1 and corners is not None and A.shape[0] == corners:
        A = A.reshape(1, corners)
    if A.ndim != 2 or (corners is not None and A.shape[1] != corners):
        raise ValueError(f"{name}: expected shape (m, {corners}), got {A.shape}")
    if A.shape[0] == 0:
        if allow_empty:
            return np.zeros((0, A.shape[1]), dtype=np.int64)
        raise ValueError(f"{name}: is empty (0 faces)")
    if np.issubdtype(A.dtype, np.floating):
        if not np.isfinite(A).all() or not np.all(A == np.round(A)):
            raise ValueError(f"{name}: face indices must be integers, got non-integral floats")
    elif not np.issubdtype(A.dtype, np.integer):
        raise ValueError(f"{name}: expected an integer index array, got dtype {A.dtype}")
    A = np.ascontiguousarray(A, dtype=np.int64)
    lo, hi = int(A.min()), int(A.max())
    if lo < 0:
        raise ValueError(f"{name}: negative vertex index {lo}")
    if hi >= n_vertices:
        raise ValueError(f"{name}: vertex index {hi} out of range for {n_vertices} vertices")
    return A


def as_mesh(V, F, allow_empty_faces: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Validate a triangle mesh/soup ``(V, F)``."""
    V = as_points(V, "V")
    F = as_faces(F, V.shape[0], "F", allow_empty=allow_empty_faces)
    return V, F


def as_normals(N, n: int, name: str = "N", dim: int = 3) -> np.ndarray:
    """Validate normals: shape (n, dim), finite, not all zero. Zero rows are allowed (they contribute nothing)."""
    A = as_points(N, name, dim=dim)
    if A.shape[0] != n:
        raise ValueError(f"{name}: has {A.shape[0]} rows but there are {n} points")
    norms = np.linalg.norm(A, axis=1)
    if not np.any(norms > 0):
        raise ValueError(f"{name}: all normals are zero")
    return A


def as_weights(a, n: int, name: str = "areas") -> np.ndarray:
    """Validate nonnegative per-element weights of length n."""
    A = np.asarray(a)
    if A.ndim != 1 or A.shape[0] != n:
        raise ValueError(f"{name}: expected shape ({n},), got {A.shape}")
    if not np.issubdtype(A.dtype, np.number):
        raise ValueError(f"{name}: expected a numeric array, got dtype {A.dtype}")
    A = np.ascontiguousarray(A, dtype=np.float64)
    if not np.isfinite(A).all():
        raise ValueError(f"{name}: contains NaN or infinite values")
    if (A < 0).any():
        raise ValueError(f"{name}: contains negative values")
    if not (A > 0).any():
        raise ValueError(f"{name}: all values are zero")
    return A


def _real(x, name: str) -> float:
    if isinstance(x, (bool, np.bool_)) or np.ndim(x) != 0 or isinstance(x, (str, bytes)):
        raise ValueError(f"{name}: expected a number, got {x!r}")
    try:
        return float(x)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"{name}: expected a number, got {x!r}") from exc


def positive(x, name: str, most: float = np.inf) -> float:
    """Validate a finite positive scalar (at most ``most``); bools, strings and arrays are refused."""
    v = _real(x, name)
    if not np.isfinite(v) or v <= 0 or v > most:
        rng = "" if most == np.inf else f" <= {most:g}"
        raise ValueError(f"{name}: must be a finite positive number{rng}, got {x!r}")
    return v


def nonnegative(x, name: str, most: float = np.inf) -> float:
    """Validate a finite scalar >= 0 (at most ``most``)."""
    v = _real(x, name)
    if not np.isfinite(v) or v < 0 or v > most:
        rng = "" if most == np.inf else f" and <= {most:g}"
        raise ValueError(f"{name}: must be a finite number >= 0{rng}, got {x!r}")
    return v


def finite(x, name: str) -> float:
    """Validate a finite real scalar."""
    v = _real(x, name)
    if not np.isfinite(v):
        raise ValueError(f"{name}: must be a finite number, got {x!r}")
    return v


#: Largest integer option accepted (beyond 2**53 floats cannot hold it, and numba kernels take int64).
MAX_INT = 2 ** 53


def integer(x, name: str, lo: int = 1, hi: int = MAX_INT) -> int:
    """Validate an integer (not a bool, no fractional part) in ``[lo, hi]``."""
    if isinstance(x, (bool, np.bool_, str, bytes)) or np.ndim(x) != 0:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {x!r}")
    try:
        v = int(x)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {x!r}") from exc
    if v != x or v < lo:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {x!r}")
    if v > hi:
        raise ValueError(f"{name}: expected an integer <= {hi}, got {x!r}")
    return v


def choice(x, name: str, options) -> str:
    """Validate one of a set of (hashable, usually string) options."""
    if not isinstance(x, (str, int)) or isinstance(x, bool) or x not in options:
        raise ValueError(f"{name}: must be one of {sorted(options)}, got {x!r}")
    return x


def progress_callback(progress, name: str = "progress"):
    """The one progress signature of gsdf: ``progress(stage: str, fraction: float)``, fraction in [0, 1].

    Returns ``progress`` itself, or a no-op for None; a ValueError naming the argument when it is not callable.
    """
    if progress is None:
        return _no_progress
    if not callable(progress):
        raise ValueError(f"{name}: expected a callable progress(stage, fraction) or None, got {type(progress).__name__}")
    return progress


def _no_progress(stage: str, fraction: float) -> None:
    return None
