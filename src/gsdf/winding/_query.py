"""Chunked evaluation of a kernel over query points, so memory stays bounded for very many queries."""

from __future__ import annotations

import numpy as np

from gsdf._checks import _array, _dtype_words, progress_callback
from gsdf._memory import SECONDS_PER_QUERY, check_bytes, check_work
from gsdf.spatial._morton import cell_order, gather_rows
from gsdf.threads import apply_env

CHUNK = 1 << 20


def map_queries(kernel, Q, dim: int = 3, chunk: int = CHUNK, progress=None, coherent: bool = False,
                frame=None, cost: float = SECONDS_PER_QUERY) -> np.ndarray:
    """Validate ``Q`` chunk by chunk and call ``kernel(q_chunk, out_chunk)`` on each.

    Only one float64 copy of one chunk exists at a time, so 10^8 float32 queries need ~chunk×24 bytes of
    scratch beyond the output. ``progress(stage, fraction)`` is called after each chunk when given.
    ``coherent=True`` evaluates each chunk grouped by cells of a coarse Morton grid
    (:func:`gsdf.spatial._morton.cell_order`: tree walks of neighbouring queries then share cached nodes) and
    scatters the results back. ``frame`` (a :class:`gsdf._normalize.Frame`) maps each
    validated chunk into the geometry's normalised frame first (the kernel's geometry lives there). ``cost``:
    single-thread seconds per query, for the size guard (:func:`gsdf._memory.check_work`, with the output's
    memory checked by :func:`gsdf._memory.check_bytes`) run before the first pass over ``Q``.
    """
    apply_env()  # GSDF_NUM_THREADS
    say = progress_callback(progress)
    A = query_array(Q, dim, cost, chunk)
    n = A.shape[0]
    out = np.empty(n, dtype=np.float64)
    for s in range(0, n, chunk):
        e = min(n, s + chunk)
        q = np.ascontiguousarray(A[s:e], dtype=np.float64)
        if not np.isfinite(q).all():
            bad = s + int(np.argmax(~np.isfinite(q).all(axis=1)))
            raise ValueError(f"Q: contains NaN or infinite coordinates (first at row {bad})")
        if frame is not None:
            q = frame.queries(q, row0=s)
        if coherent and e - s > 4096 and not _already_coherent(q):
            o = cell_order(q)
            tmp = np.empty(e - s)
            kernel(gather_rows(q, o) if dim == 3 else np.ascontiguousarray(q[o]), tmp)
            out[s:e][o] = tmp
        else:
            kernel(q, out[s:e])
        say("winding numbers", e / n)
    return out


def query_array(Q, dim: int = 3, cost: float = SECONDS_PER_QUERY, chunk: int = CHUNK) -> np.ndarray:
    """``Q`` as an (q, dim) numeric array (not yet copied or checked for finiteness), after the size guard: the
    output's memory (:func:`gsdf._memory.check_bytes`) and ``q × cost`` seconds of work
    (:func:`gsdf._memory.check_work`). One-call functions run it before building their tree, so that 10^9
    queries are refused at once."""
    A = _array(Q, "Q")
    if A.ndim == 1 and A.shape[0] == dim:
        A = A.reshape(1, dim)
    if A.ndim != 2 or A.shape[1] != dim:
        raise ValueError(f"Q: expected shape (q, {dim}), got {A.shape}")
    if A.dtype.kind not in "fiu":
        raise ValueError(f"Q: expected numeric coordinates, got {_dtype_words(A)}")
    n = A.shape[0]
    if n > 1000:
        check_bytes(8 * n + 48 * min(n, chunk), f"Q: winding numbers at {n:,} query points")
        check_work(n, cost, f"Q: winding numbers at {n:,} query points")
    return A


def _already_coherent(q: np.ndarray) -> bool:
    """True when consecutive queries are already close (grids in C order, scanlines): sorting would not pay."""
    step = max(1, q.shape[0] // 2048)
    a = q[: -1 : step]
    b = q[1::step][: a.shape[0]]
    diag = float(np.linalg.norm(a.max(axis=0) - a.min(axis=0))) or 1.0  # of the sample: cheap, close enough
    return float(np.median(np.linalg.norm(a - b, axis=1))) < 0.01 * diag
