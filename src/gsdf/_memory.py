"""Size guard: estimate the memory AND the work of a size-driven request before starting it, refuse with numbers.

Every entry point whose cost grows with a size it is given (query points, grid or voxel counts, slice heights ×
resolution, sample counts, neighbour counts k) calls the two checks of this module before its first pass over
the data, so that an absurd size is a ``ValueError`` in well under a second instead of a ``MemoryError``
traceback, a swapping machine or a run that never ends:

* :func:`check_bytes` — the bytes the request will allocate, against what the machine can give now:
  ``MemAvailable`` of ``/proc/meminfo`` (Linux), else ``os.sysconf`` physical pages, and never more than the
  address space left under ``RLIMIT_AS`` (``ulimit -v``); the environment variable ``GSDF_MEMORY_LIMIT`` (bytes,
  or with a K/M/G/T suffix, e.g. ``2G``) overrides it.
* :func:`check_work` — the wall time the request will take, estimated as items × the optimistic single-thread
  seconds per item (the ``SECONDS_PER_*`` constants below) divided by gsdf's thread count, against
  ``GSDF_WORK_LIMIT`` (seconds, or with an s/m/h/d suffix, e.g. ``2h``; ``none`` disables the check; default
  5 minutes, :data:`WORK_LIMIT`). The estimates are lower bounds: what is refused would take at least that long.

A refused request is a ``ValueError`` naming what was asked (the size), its estimate and the limit, and the
variable that changes the limit.

Example
-------
>>> import os
>>> os.environ["GSDF_MEMORY_LIMIT"] = "1M"
>>> try:
...     check_bytes(grid_bytes((1000, 1000, 1000), 8), "resolution=1000 grid")
... except ValueError as e:
...     print(str(e).split(";")[0])
resolution=1000 grid: needs about 7.5 GB, more than the 1.0 MB allowed
>>> del os.environ["GSDF_MEMORY_LIMIT"]
"""

from __future__ import annotations

import math
import os

ENV = "GSDF_MEMORY_LIMIT"
WORK_ENV = "GSDF_WORK_LIMIT"
_SUFFIX = {"": 1, "B": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def _parse(text: str) -> int:
    t = text.strip().upper().removesuffix("IB").removesuffix("B")
    unit = t[-1:] if t[-1:] in _SUFFIX else ""
    num = t[: len(t) - len(unit)] if unit else t
    try:
        v = float(num) * _SUFFIX[unit]
    except ValueError:
        raise ValueError(f"{ENV}: expected bytes like 2000000000 or 2G, got {text!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise ValueError(f"{ENV}: expected a positive size, got {text!r}")
    return int(v)


#: Share of the available memory one request may take when GSDF_MEMORY_LIMIT is not set.
SHARE = 0.8


def available_bytes() -> int:
    """Bytes a new allocation may use: ``GSDF_MEMORY_LIMIT`` if set, else 80 % of ``MemAvailable`` (Linux),
    else of physical memory; 2**62 when none can be read."""
    env = os.environ.get(ENV)
    if env:
        return _parse(env)
    return min(_machine_bytes(), _address_space_left())


def check_environment() -> None:
    """Read ``GSDF_MEMORY_LIMIT`` and ``GSDF_WORK_LIMIT`` now: a ValueError naming the variable when either is
    set to something that is not a size / a time, so that a command refuses it before any work even when its
    request is too small to consult the limits."""
    env = os.environ.get(ENV)
    if env:
        _parse(env)
    work_limit()


def _machine_bytes() -> int:
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(SHARE * int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(SHARE * int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES")))
    except (ValueError, OSError, AttributeError):
        return 1 << 62


def _address_space_left() -> int:
    """Bytes of address space this process may still map under ``RLIMIT_AS`` (2**62 without a limit)."""
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    except (ImportError, OSError, ValueError, AttributeError):  # pragma: no cover - not POSIX
        return 1 << 62
    if soft == resource.RLIM_INFINITY or soft <= 0:
        return 1 << 62
    used = 0
    try:
        with open("/proc/self/statm") as f:
            used = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        pass
    return max(0, int(SHARE * (soft - used)))


def human(n: float) -> str:
    """``8.0 GB`` style size (powers of 1024)."""
    for unit in ("B", "KB", "MB", "GB", "TB", "PB"):
        if abs(n) < 1024 or unit == "PB":
            return f"{n:.1f} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024.0
    return f"{n:.1f} PB"  # pragma: no cover


def grid_bytes(shape, bytes_per_node: float) -> int:
    """Bytes of a grid of ``shape`` nodes (Python integers: no overflow) at ``bytes_per_node``."""
    n = 1
    for s in shape:
        n *= int(s)
    return int(n * bytes_per_node)


def check_bytes(nbytes: float, what: str, limit: int | None = None) -> None:
    """Raise ``ValueError`` when ``nbytes`` exceeds ``limit`` (default :func:`available_bytes`).

    ``what`` names the request (e.g. ``"voxelize: resolution=4000 grid (4000×4000×4000 cells)"``) and should
    say what to lower.
    """
    limit = available_bytes() if limit is None else int(limit)
    if nbytes > limit:
        raise ValueError(f"{what}: needs about {human(nbytes)}, more than the {human(limit)} allowed; "
                         f"lower the resolution/size, or set {ENV} (bytes) to change the limit")


#: Default of ``GSDF_WORK_LIMIT``: the estimated wall time (seconds) above which a request is refused.
WORK_LIMIT = 300.0

#: Optimistic single-thread seconds per item of the kinds of work gsdf does (what is refused would take at
#: least items × this / threads). Measured on the sphere of the tests and a 40k-triangle mesh, one thread: the
#: fast winding number took 1.1–2.0 µs per query, the triangle distance 1.5–4 µs, ``gsdf slice`` 1.3 µs per
#: slice node (see docs/decisions.md, "Size guard").
SECONDS_PER_QUERY = 1e-6         #: a tree query: fast winding number, distance, nearest neighbours, PAT
SECONDS_PER_NODE = 2e-7          #: a node of a grid solve, a field evaluation, an isosurface or voxel pass
SECONDS_PER_PAIR = 2e-9          #: one query × element term of a direct sum (exact winding numbers)
SECONDS_PER_CELL = 1e-9          #: one voxel of an elementwise pass over a boolean grid
SECONDS_PER_FACE_STEP = 5e-8     #: one face in one step of an iterative sweep over a mesh (two sparse products)
SECONDS_PER_SLICE = 3e-4         #: one slice of slice_contours beyond its nodes (marching squares, bisection; serial)

_TIME_SUFFIX = {"": 1.0, "S": 1.0, "M": 60.0, "H": 3600.0, "D": 86400.0}


def seconds_per_point(func, default: float = SECONDS_PER_NODE) -> float:
    """Single-thread seconds of one evaluation of the field ``func`` at one point: its ``_seconds_per_point``
    attribute (gsdf's evaluators — fast winding numbers, distances, Points as Tori — carry one), else
    ``default`` (a lower bound for any Python function on arrays)."""
    v = getattr(func, "_seconds_per_point", default)
    try:
        v = float(v)
    except (TypeError, ValueError):
        return default
    return v if math.isfinite(v) and v >= 0 else default


def work_limit() -> float:
    """Seconds of estimated wall time a request may take: ``GSDF_WORK_LIMIT`` (seconds, or ``30m``, ``2h``,
    ``1d``; ``none``/``inf`` for no limit), else :data:`WORK_LIMIT`."""
    text = os.environ.get(WORK_ENV)
    if not text or not text.strip():
        return WORK_LIMIT
    t = text.strip().upper()
    if t in ("NONE", "INF", "OFF", "UNLIMITED"):
        return math.inf
    unit = t[-1:] if t[-1:] in _TIME_SUFFIX else ""
    try:
        v = float(t[: len(t) - len(unit)] if unit else t) * _TIME_SUFFIX[unit]
    except ValueError:
        raise ValueError(f"{WORK_ENV}: expected seconds like 600, 30m, 2h or none, got {text!r}") from None
    if not v > 0 or math.isnan(v):
        raise ValueError(f"{WORK_ENV}: expected a positive time or none, got {text!r}")
    return v


def _threads() -> int:
    try:  # threads beyond the cores do not shorten the work
        from gsdf.threads import available_cpus, get_num_threads

        return max(1, min(int(get_num_threads()), available_cpus()))
    except Exception:  # pragma: no cover - thread setting unreadable: assume one
        return 1


def human_time(s: float) -> str:
    """``45 s`` / ``12 min`` / ``3.2 h`` / ``5.1 days`` style duration."""
    if s < 120:
        return f"{s:.0f} s"
    if s < 7200:
        return f"{s / 60:.0f} min"
    if s < 172800:
        return f"{s / 3600:.1f} h"
    return f"{s / 86400:.3g} days"


def check_work(items: float, seconds_per_item: float, what: str, limit: float | None = None,
               parallel: bool = True) -> None:
    """Raise ``ValueError`` when ``items`` × ``seconds_per_item`` (one thread; divided by gsdf's thread count
    when ``parallel``) exceeds ``limit`` seconds (default :func:`work_limit`).

    ``what`` names the request and its size (e.g. ``"fast_winding_number: 1,000,000,000 queries"``).

    Example
    -------
    >>> try:
    ...     check_work(10**12, SECONDS_PER_QUERY, "10^12 queries", limit=60, parallel=False)
    ... except ValueError as e:
    ...     print(str(e).split(";")[0])
    10^12 queries: would take at least 11.6 days (estimated), more than the 60 s allowed
    """
    limit = work_limit() if limit is None else float(limit)
    if not math.isfinite(limit):
        return
    est = float(items) * float(seconds_per_item) / (_threads() if parallel else 1)
    if est > limit:
        raise ValueError(f"{what}: would take at least {human_time(est)} (estimated), more than the "
                         f"{human_time(limit)} allowed; lower the size, or set {WORK_ENV} (seconds, e.g. 2h; none "
                         "for no limit) to change the limit")


def rows(x) -> int:
    """Number of rows (length of the first axis) of an array-like, without copying it (0 for a scalar)."""
    shape = getattr(x, "shape", None)
    if shape is None:
        try:
            return len(x)
        except TypeError:
            return 0
    return int(shape[0]) if len(shape) else 0


def size_of(x) -> int:
    """Number of elements of an array-like, without copying an ndarray (Python integers: no overflow)."""
    shape = getattr(x, "shape", None)
    if shape is None:
        return 0
    n = 1
    for s in shape:
        n *= int(s)
    return n


def chunk_rows(bytes_per_row: float, total: int, budget: float | None = None) -> int:
    """Rows per chunk so one chunk uses at most ``budget`` bytes (default: 1/8 of the available memory,
    capped at 256 MB); at least 1 and at most ``total``."""
    if budget is None:
        budget = min(available_bytes() / 8, 256 << 20)
    return int(max(1, min(max(total, 1), budget // max(bytes_per_row, 1))))


#: Most bytes of one reused scratch buffer (:func:`scratch`); larger requests get a fresh array each time.
SCRATCH_BYTES = 32 << 20

_scratch_local = None


def scratch(name: str, shape, dtype="float64"):
    """An uninitialised array of ``shape`` that the calling thread reuses across calls under ``name``.

    For the temporaries of a build (element rows being sorted, node rows before they are copied out, the
    lane map of the wide view): a fresh ``np.empty`` of a few MB is a fresh mapping whose every page faults on first
    touch (measured: 1221 faults, ~3.7 ms of system time, in a 14 ms build of the shared triangle tree over
    13k faces). The buffer is kept per thread (so concurrent builds never share one) and grown when too short;
    a request over :data:`SCRATCH_BYTES` is a plain ``np.empty``. The caller must be done with the array
    before it asks for the same ``name`` again on the same thread.

    Example
    -------
    >>> a = scratch("doc", (4, 3))
    >>> a.shape, scratch("doc", (2, 3)).base is a.base
    ((4, 3), True)
    """
    import numpy as np

    global _scratch_local
    dtype = np.dtype(dtype)
    shape = tuple(int(s) for s in (shape if isinstance(shape, tuple) else (shape,)))
    nbytes = dtype.itemsize * math.prod(shape)
    if nbytes > SCRATCH_BYTES:
        return np.empty(shape, dtype)
    if _scratch_local is None:
        import threading

        _scratch_local = threading.local()
    pool = getattr(_scratch_local, "pool", None)
    if pool is None:
        pool = _scratch_local.pool = {}
    buf = pool.get(name)
    if buf is None or buf.nbytes < nbytes:
        buf = pool[name] = np.empty(max(nbytes, 64), np.uint8)
    return buf[:nbytes].view(dtype).reshape(shape)
