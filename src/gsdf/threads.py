"""One thread setting for the whole package: numba's parallel kernels and the BLAS under sparse solves.

gsdf runs two kinds of threaded code: numba ``parallel=True`` kernels (threading layer: OpenMP, TBB or
numba's workqueue) and the BLAS that sparse factorizations call (SuperLU/CHOLMOD supernodes, dense
updates). Both default to one thread per core. Run together, or in several gsdf processes at once, they
oversubscribe the cores: OpenBLAS's idle threads spin for a while after each call, OpenMP's likewise, so
a numba kernel right after a solve (or three processes side by side) fights threads that do no work.

The rule this module enforces: **gsdf never runs BLAS threads and numba threads against each other.**

- one setting, ``n`` threads: :func:`set_num_threads` (process-wide), :func:`limit` (a ``with`` block),
  the environment variable ``GSDF_NUM_THREADS``, or ``gsdf --threads N`` on the command line;
- numba's parallel kernels use ``n`` threads (capped at numba's pool size, ``NUMBA_NUM_THREADS``, which is
  fixed when numba starts); while they run BLAS is idle, so nothing else needs limiting;
- around sparse factorizations and solves (:func:`blas_region`) BLAS is limited by threadpoolctl and
  restored afterwards: to ``n`` threads when the setting was made explicitly, else to **one** thread
  (:func:`blas_solve_threads`): the supernodes of gsdf's sparse factorizations are too small for BLAS
  threads to pay, and idle BLAS threads spin under contention (figures in docs/decisions.md, "Trees and
  threads"). The ``gsdf`` command applies this default process-wide at start (:func:`apply_cli_default`).

Where it applies: the factorizations and solves of :mod:`gsdf.linalg` run inside :func:`blas_region` (one
wrapper in each factorization object's construction and ``solve``, which covers every signed heat
discretization); the grid method's DCT Poisson solves pass ``workers=get_num_threads()`` to scipy.fft; numba
kernels follow :func:`numba_threads`.

Example
-------
>>> import gsdf
>>> gsdf.set_num_threads(1)                      # every later kernel and solve on one thread
>>> with gsdf.threads.limit(2):                  # ... or only inside a block
...     pass
>>> gsdf.threads.get_num_threads()
1
"""

from __future__ import annotations

import os
import sys
import threading
from contextlib import contextmanager

ENV_VAR = "GSDF_NUM_THREADS"

_setting: int | None = None   # set by set_num_threads / limit; None: the environment variable or all cores


#: Most threads accepted: more than a process can start on common systems (Linux's default pid_max is 32768);
#: BLAS would try to start that many.
MAX_THREADS = 1 << 16


def parse_num_threads(value, name: str = "threads") -> int:
    """Validate a thread count: a positive integer (or a string of one, as from the environment).

    Parameters
    ----------
    value : int or str
        The requested number of threads.
    name : str
        What to call the value in the error message.

    Returns
    -------
    int
        ``value`` as a positive ``int``.

    Raises
    ------
    ValueError
        ``value`` is a bool, not an integer, < 1 or more than :data:`MAX_THREADS`.

    Example
    -------
    >>> parse_num_threads("4")
    4
    """
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a positive integer, got the bool {value!r}")
    if isinstance(value, str):
        text = value.strip()
        try:
            n = int(text)
        except ValueError:
            raise ValueError(f"{name} must be a positive integer, got {value!r}") from None
    else:
        try:
            import operator

            n = operator.index(value)
        except TypeError:
            raise ValueError(f"{name} must be a positive integer, got {value!r} "
                             f"({type(value).__name__})") from None
    if n < 1:
        raise ValueError(f"{name} must be a positive integer (>= 1), got {n}")
    if n > MAX_THREADS:
        raise ValueError(f"{name} must be at most {MAX_THREADS} (more threads than a process can start), got {n}")
    return int(n)


def available_cpus() -> int:
    """Cores this process may run on (the affinity mask where the platform has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - macOS / Windows
        return max(1, os.cpu_count() or 1)


def _from_env() -> int | None:
    value = os.environ.get(ENV_VAR)
    if value is None or value.strip() == "":
        return None
    return parse_num_threads(value, name=f"the environment variable {ENV_VAR}")


def get_num_threads() -> int:
    """The thread setting in force: :func:`set_num_threads` / :func:`limit`, else ``GSDF_NUM_THREADS``,
    else the number of available cores.

    Raises
    ------
    ValueError
        ``GSDF_NUM_THREADS`` is set to something that is not a positive integer.

    Examples
    --------
    >>> import gsdf
    >>> gsdf.get_num_threads() >= 1
    True
    """
    if _setting is not None:
        return _setting
    env = _from_env()
    return env if env is not None else available_cpus()


_pool_lock = threading.Lock()
_pool_executor = None
_pool_size = 0


def _reset_pool_after_fork() -> None:  # a forked child has none of the parent's worker threads
    global _pool_executor, _pool_size, _pool_lock
    _pool_executor, _pool_size, _pool_lock = None, 0, threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_reset_pool_after_fork)


def _workers(n: int):
    """The process's one pool of ``n`` or more idle Python worker threads (created on first use, grown on
    demand), reused across calls."""
    global _pool_executor, _pool_size
    with _pool_lock:
        if _pool_executor is None or _pool_size < n:
            from concurrent.futures import ThreadPoolExecutor

            old = _pool_executor
            _pool_executor = ThreadPoolExecutor(max_workers=n, thread_name_prefix="gsdf")
            _pool_size = n
            if old is not None:
                old.shutdown(wait=False)
        return _pool_executor


def run_tasks(fn, items, threads: int | None = None) -> None:
    """Call ``fn(item)`` for every item of ``items`` on ``threads`` Python threads (numba's current number
    by default): the calling thread and ``threads − 1`` pool workers each take the next item until none is
    left, in the order given (list the largest first, so the threads finish together). For serial
    ``nogil=True`` numba kernels: one pool submission per thread instead of one per item (a build of a tree
    over 89k triangles submitted ~120). One thread or one item: a plain loop on the calling thread.
    Exceptions propagate (the first one raised; the other threads stop taking items).

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.threads import run_tasks
    >>> out = np.zeros(8)
    >>> def fill(i):
    ...     out[i] = i
    >>> run_tasks(fill, range(8), threads=2)
    >>> out.tolist()
    [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
    """
    items = list(items)
    if threads is None:
        import numba

        threads = numba.get_num_threads()
    threads = min(int(threads), len(items))
    if threads <= 1:
        for it in items:
            fn(it)
        return
    it = iter(items)
    lock = threading.Lock()
    failed = []

    def work():
        while not failed:
            with lock:
                item = next(it, it)
            if item is it:
                return
            try:
                fn(item)
            except BaseException:
                failed.append(True)
                raise

    futures = [_workers(threads - 1).submit(work) for _ in range(threads - 1)]
    try:
        work()
    finally:
        # a submission still queued (the pool busy with another caller's items, or a nested call) is
        # cancelled: this thread has done its share, and waiting for it could wait on the other caller
        futures = [f for f in futures if not f.cancel()]
        for f in futures:
            f.exception()  # wait for every started worker before returning (or re-raising)
    for f in futures:
        f.result()


def run_ranges(fn, n: int, grain: int = 512, per_thread: int = 4) -> None:
    """Call ``fn(s, e)`` on contiguous ranges covering ``0 <= i < n``, on numba's current number of threads.

    For serial ``nogil=True`` numba kernels over row ranges: the ranges run on Python threads (the kernels
    release the GIL), so the kernel needs no ``parallel=True`` loop, whose compilation costs about a second
    per kernel on a cold start. ``n <= grain`` or one thread: one call on the calling thread.
    About ``per_thread`` ranges per thread (at least ``grain`` rows each; 4 balance uneven rows, 1 suits rows
    of equal cost) taken in turn by the threads of :func:`run_tasks`. Exceptions propagate.

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.threads import run_ranges
    >>> out = np.zeros(10_000)
    >>> def fill(s, e):
    ...     out[s:e] = np.arange(s, e)
    >>> run_ranges(fill, out.shape[0])
    >>> bool((out == np.arange(10_000)).all())
    True
    """
    import numba

    threads = numba.get_num_threads()
    if threads <= 1 or n <= grain:
        if n > 0:
            fn(0, n)
        return
    size = max(grain, -(-n // (per_thread * threads)))
    run_tasks(lambda b: fn(*b), [(s, min(n, s + size)) for s in range(0, n, size)], threads)


def _numba_loaded() -> bool:
    return "numba" in sys.modules


def _apply_numba(n: int) -> None:
    """numba's kernels use min(n, pool size) threads (the pool is sized once, when numba starts)."""
    import numba

    numba.set_num_threads(max(1, min(n, numba.config.NUMBA_NUM_THREADS)))


def numba_threads() -> int:
    """Threads numba's parallel kernels get under the current setting (``min(setting, NUMBA_NUM_THREADS)``)."""
    import numba

    return max(1, min(get_num_threads(), numba.config.NUMBA_NUM_THREADS))


def set_num_threads(n) -> None:
    """Set the number of threads for every later numba kernel and sparse solve in this process.

    Parameters
    ----------
    n : int
        Positive number of threads, at most 65536. numba's share is capped at its pool size (``NUMBA_NUM_THREADS``,
        the cores by default); every BLAS in the process (loaded now or later) gets ``n`` threads.

    Raises
    ------
    ValueError
        ``n`` is not a positive integer.

    Examples
    --------
    >>> import gsdf
    >>> gsdf.set_num_threads(1)
    """
    global _setting
    _setting = parse_num_threads(n)
    _apply_numba(_setting)
    _apply_blas_process_wide(_setting)


_BLAS_ENV = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")
_process_limiter = None


def _apply_blas_process_wide(n: int) -> None:
    """BLAS libraries loaded now get ``n`` threads (threadpoolctl); ones loaded later read the env vars."""
    global _process_limiter
    for var in _BLAS_ENV:
        os.environ[var] = str(n)
    if not any(m in sys.modules for m in ("numpy", "scipy")):
        return  # nothing loaded yet: the environment variables cover it
    from threadpoolctl import threadpool_limits

    _process_limiter = threadpool_limits(limits=n, user_api="blas")


_env_applied = False


def apply_env() -> int | None:
    """Apply ``GSDF_NUM_THREADS`` (once per process) when no explicit setting was made; returns it.

    Called by the entry points (CLI start; winding, distance and tori constructors), so that the
    environment variable takes effect without a :func:`set_num_threads` call. Without the variable, or
    after :func:`set_num_threads`, it does nothing (numba and BLAS keep their defaults: all cores).

    Raises
    ------
    ValueError
        ``GSDF_NUM_THREADS`` is set to something that is not a positive integer.
    """
    global _env_applied
    if _setting is not None:
        return _setting
    n = _from_env()
    if n is None or _env_applied:
        return n
    _env_applied = True
    _apply_numba(n)
    _apply_blas_process_wide(n)
    return n


@contextmanager
def limit(n):
    """Inside the block, numba kernels and sparse solves use at most ``n`` threads; restored afterwards.

    Parameters
    ----------
    n : int
        Positive number of threads.

    Example
    -------
    >>> import gsdf, numpy as np
    >>> with gsdf.threads.limit(1):
    ...     w = gsdf.fast_winding_number(V, F, Q)       # doctest: +SKIP
    """
    global _setting
    n = parse_num_threads(n)
    import numba

    previous_setting, previous_numba = _setting, numba.get_num_threads()
    _setting = n
    _apply_numba(n)
    try:
        with blas_region():
            yield n
    finally:
        _setting = previous_setting
        numba.set_num_threads(previous_numba)


def blas_solve_threads() -> int:
    """BLAS threads for sparse solves: the explicit setting (set_num_threads / limit / GSDF_NUM_THREADS /
    --threads), else 1 (see the module docstring for the measurement)."""
    if _setting is not None:
        return _setting
    env = _from_env()
    return env if env is not None else 1


def apply_cli_default() -> None:
    """The ``gsdf`` command without ``--threads`` / ``GSDF_NUM_THREADS``: BLAS on one thread process-wide
    (numba keeps all cores). A library user's process is left alone: there only :func:`blas_region` limits."""
    if _setting is None and _from_env() is None:
        _apply_blas_process_wide(1)


@contextmanager
def blas_region(n=None):
    """Limit BLAS (OpenBLAS, MKL, BLIS: every loaded one, via threadpoolctl) to the setting in the block.

    Wrap sparse factorizations and solves in it (see the module docstring for which). Numba's threads are
    idle while BLAS runs, and vice versa, so the two never compete.

    Parameters
    ----------
    n : int, optional
        Thread count for this block; default :func:`blas_solve_threads` (the explicit setting, else 1).

    Example
    -------
    >>> from gsdf import threads
    >>> with threads.blas_region():
    ...     lu = scipy.sparse.linalg.splu(A)             # doctest: +SKIP
    """
    n = blas_solve_threads() if n is None else parse_num_threads(n)
    stack = _region_stack()
    if stack and stack[-1] == n:          # nested in a block with the same limit: nothing to set or restore
        yield n
        return
    with _blas_controller().limit(limits=n, user_api="blas"):
        stack.append(n)
        try:
            yield n
        finally:
            stack.pop()


_LOCAL = threading.local()


def _region_stack() -> list:
    """The limits of the :func:`blas_region` blocks this thread is inside (innermost last)."""
    st = getattr(_LOCAL, "stack", None)
    if st is None:
        st = _LOCAL.stack = []
    return st


_CONTROLLER = None


def _blas_controller():
    """threadpoolctl's view of the loaded thread pools, built once (a fresh scan per solve costs ~ms)."""
    global _CONTROLLER
    if _CONTROLLER is None:
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER


def blas_threads() -> list[tuple[str, int]]:
    """(library, threads) for every BLAS loaded in this process (threadpoolctl's view), for reports."""
    from threadpoolctl import threadpool_info

    return [(d.get("internal_api", "?"), int(d.get("num_threads", 0)))
            for d in threadpool_info() if d.get("user_api") == "blas"]
