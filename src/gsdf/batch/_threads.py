"""Thread limits of one batch worker: BLAS and numba share the worker's slice of the cores (via gsdf.threads).

N workers each running numba kernels and BLAS with one thread per core would put N × cores threads on the
machine; every worker therefore gets ``cores // N`` threads (at least one) for both, set through the package's
one thread setting, :mod:`gsdf.threads` (threadpoolctl for BLAS, ``numba.set_num_threads``).
"""

from __future__ import annotations

import os

from gsdf import threads as _gsdf_threads

_BLAS_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
             "VECLIB_MAXIMUM_THREADS", _gsdf_threads.ENV_VAR)

available_cpus = _gsdf_threads.available_cpus


def threads_per_worker(workers: int, cores: int | None = None) -> int:
    """The share of ``cores`` (default: this machine's) of each of ``workers`` concurrent workers, >= 1."""
    cores = available_cpus() if cores is None else cores
    return max(1, cores // max(1, workers))


def set_environment(n: int) -> None:
    """Thread variables read by BLAS/OpenMP libraries (and gsdf) that load later: call before importing numpy."""
    for var in _BLAS_ENV:
        os.environ[var] = str(n)


def limit_threads(n: int) -> int:
    """Limit this process's BLAS and the calling thread's numba kernels to ``n`` threads; returns ``n``.

    numba's setting applies to kernels launched from the calling thread, so workers call this at the start of
    every item, from the thread that runs it; the BLAS limit is process-wide.
    """
    _gsdf_threads.set_num_threads(int(n))
    return int(n)
