"""Thread limits of one batch worker: BLAS (threadpoolctl) and numba share the worker's slice of the cores.

N workers each running numba kernels and BLAS with one thread per core would put N × cores threads on the
machine; every worker therefore gets ``cores // N`` threads (at least one) for both. This is the only place
the batch package touches thread settings, so it can be switched to the package-wide setting
(``gsdf.threads``) in one line.
"""

from __future__ import annotations

import os

_BLAS_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
             "VECLIB_MAXIMUM_THREADS")
_limiter = None  # keeps threadpoolctl's process-wide limit alive


def available_cpus() -> int:
    """Cores this process may run on (its affinity mask where the platform has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - macOS / Windows
        return max(1, os.cpu_count() or 1)


def threads_per_worker(workers: int, cores: int | None = None) -> int:
    """The share of ``cores`` (default: this machine's) of each of ``workers`` concurrent workers, >= 1."""
    cores = available_cpus() if cores is None else cores
    return max(1, cores // max(1, workers))


def set_environment(n: int) -> None:
    """Thread variables read by BLAS/OpenMP libraries that load later (call before importing numpy)."""
    for var in _BLAS_ENV:
        os.environ[var] = str(n)


def limit_threads(n: int) -> int:
    """Limit this process's BLAS and the calling thread's numba kernels to ``n`` threads; returns ``n``.

    numba's setting is per thread (it applies to kernels launched from the calling thread), so workers call
    this at the start of every item, from the thread that runs it; threadpoolctl's BLAS limit is process-wide.
    """
    global _limiter
    set_environment(n)
    import numba
    from threadpoolctl import threadpool_limits

    numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))
    if _limiter is None or getattr(_limiter, "_gsdf_n", None) != n:
        _limiter = threadpool_limits(limits=int(n), user_api="blas")
        _limiter._gsdf_n = n
    return int(n)
