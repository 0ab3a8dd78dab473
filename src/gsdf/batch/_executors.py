"""Where batch items run: local worker processes, or a Dask cluster — behind one small interface.

The driver (:mod:`gsdf.batch._run`) only calls ``submit(fn, job)``, ``wait(futures, timeout)`` (the finished
ones), ``is_worker_death(exc)``, ``recover()``, ``close(cancel)``: the same submit / gather-as-completed code
path for both executors.

- :class:`LocalExecutor` — a ``concurrent.futures.ProcessPoolExecutor`` (spawned processes, Ctrl-C ignored in
  the workers so only the driver handles it; each worker dies with the driver, even when the driver is killed
  with SIGKILL). A worker's death breaks the whole pool: every item in flight
  fails with ``BrokenProcessPool``; ``recover()`` builds a new pool and the driver resubmits those items.
- :class:`DaskExecutor` — a ``dask.distributed.Client`` on a ``LocalCluster`` it starts (``--dask-local N``) or
  on an existing scheduler (``--scheduler ADDR``: a plain cluster, dask-jobqueue, Kubernetes — anything with a
  scheduler address). Dask reschedules the tasks of a dead worker itself (up to its
  ``distributed.scheduler.allowed-failures``, then ``KilledWorker``). ``dask.distributed`` is imported only here,
  only when asked for.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import signal
import sys
import threading
import time

from gsdf.batch import _threads


def _die_with_parent(parent: int) -> None:
    """End this worker when the driver process ``parent`` dies (even by kill -9), so that no orphan finishes
    items and writes outputs the manifest never records: on Linux the kernel sends SIGKILL at the parent's death
    (``prctl(PR_SET_PDEATHSIG)``); everywhere a daemon thread checks once a second that the parent is still ours
    (``os.getppid()``; it needs the GIL, which a long native kernel may hold: the prctl is the sure way)."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):  # pragma: no cover - no libc prctl: the thread below remains
            pass
    if os.getppid() != parent:  # the parent died before the prctl took effect
        os._exit(1)

    def watch():
        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="gsdf-parent-watch", daemon=True).start()


def _init_local_worker(threads: int, parent: int | None = None) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the driver's: it cancels and shuts us down
    if parent is not None:
        _die_with_parent(parent)
    _threads.set_environment(threads)


class LocalExecutor:
    """``workers`` local processes, each limited to ``threads`` BLAS/numba threads.

    Example
    -------
    >>> ex = LocalExecutor(2)                         # doctest: +SKIP
    >>> fut = ex.submit(pow, 2, 10); ex.close()        # doctest: +SKIP
    """

    kind = "local"

    def __init__(self, workers: int, threads: int | None = None):
        self.workers = int(workers)
        self.threads = threads or _threads.threads_per_worker(self.workers)
        self._pool = self._new_pool()

    def _new_pool(self):
        return cf.ProcessPoolExecutor(max_workers=self.workers, mp_context=multiprocessing.get_context("spawn"),
                                      initializer=_init_local_worker, initargs=(self.threads, os.getpid()))

    @property
    def n_slots(self) -> int:
        return self.workers

    def describe(self) -> str:
        return f"{self.workers} local process{'es' if self.workers > 1 else ''} × {self.threads} thread(s)"

    def submit(self, fn, job):
        return self._pool.submit(fn, job)

    def wait(self, futures, timeout: float):
        done, _ = cf.wait(list(futures), timeout=timeout, return_when=cf.FIRST_COMPLETED)
        return done

    @staticmethod
    def wait_all(futures, timeout: float):
        cf.wait(list(futures), timeout=timeout)

    @staticmethod
    def is_worker_death(exc) -> bool:
        return isinstance(exc, (cf.process.BrokenProcessPool, cf.TimeoutError))

    def worker_pids(self) -> list[int]:
        return [p.pid for p in (self._pool._processes or {}).values()]

    def recover(self) -> None:
        """After a worker died: a fresh pool (the broken one accepts no more work)."""
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = self._new_pool()

    def cancel(self, futures) -> None:
        for f in futures:
            f.cancel()

    def close(self, cancel: bool = False) -> None:
        if cancel:
            procs = list((self._pool._processes or {}).values())  # the pool has no public "terminate"
            self._pool.shutdown(wait=False, cancel_futures=True)
            for p in procs:
                if p.is_alive():
                    p.terminate()
            for p in procs:
                p.join(5)
        else:
            self._pool.shutdown(wait=True)


def _import_distributed():
    try:
        import distributed
    except ImportError:
        raise ValueError("the Dask executor needs dask.distributed: pip install 'gsdf[dask]'") from None
    return distributed


def _share_hosts(client) -> dict:
    """Worker address -> BLAS/numba threads, so that the Dask threads of all workers on one host share its cores
    (a host with 16 cores and 4 one-thread workers gives each item 4 threads). Workers that join later
    fall back to their own cores / their own Dask threads."""
    try:
        cores = client.run(_threads.available_cpus, wait=True)
        workers = client.scheduler_info().get("workers", {})
    except Exception:  # pragma: no cover - a scheduler without workers yet, or a refused run()
        return {}
    per_host: dict = {}
    for addr, w in workers.items():
        per_host[w.get("host")] = per_host.get(w.get("host"), 0) + int(w.get("nthreads", 1))
    return {addr: _threads.threads_per_worker(per_host[w.get("host")], cores.get(addr))
            for addr, w in workers.items() if addr in cores}


class DaskExecutor:
    """Items as Dask futures on ``client``; one thread of each Dask worker runs one item.

    Use :meth:`local` or :meth:`connect` to build one.

    Example
    -------
    >>> ex = DaskExecutor.local(2)                     # doctest: +SKIP
    >>> ex.connect("tcp://scheduler:8786")             # doctest: +SKIP
    """

    kind = "dask"

    def __init__(self, client, cluster=None, threads: int | None = None):
        self.client, self.cluster, self.threads = client, cluster, threads
        self.threads_by_worker = None
        self._distributed = _import_distributed()

    @classmethod
    def local(cls, n_workers: int, threads: int | None = None):
        """Start a ``LocalCluster`` of ``n_workers`` processes (one Dask thread each, no dashboard)."""
        import logging

        distributed = _import_distributed()
        threads = threads or _threads.threads_per_worker(n_workers)
        cluster = distributed.LocalCluster(n_workers=int(n_workers), threads_per_worker=1, processes=True,
                                           dashboard_address=None, silence_logs=logging.ERROR,
                                           env={v: str(threads) for v in _threads._BLAS_ENV})
        return cls(distributed.Client(cluster), cluster, threads)

    @classmethod
    def connect(cls, address: str, timeout: float = 10.0, threads: int | None = None):
        """Connect to a running scheduler; ValueError (not a hang) when it is unreachable within ``timeout`` s."""
        distributed = _import_distributed()
        if not isinstance(address, str) or not address.strip():
            raise ValueError(f"scheduler: expected an address like tcp://host:8786, got {address!r}")
        address = address.strip()
        if "://" not in address:
            address = "tcp://" + address
        t0 = time.monotonic()
        try:
            client = distributed.Client(address, timeout=f"{timeout}s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise ValueError(f"scheduler: cannot reach the Dask scheduler at {address} "
                             f"(gave up after {time.monotonic() - t0:.1f} s: {exc})") from None
        ex = cls(client, None, threads)
        if threads is None:
            ex.threads_by_worker = _share_hosts(client)
        return ex

    @property
    def n_slots(self) -> int:
        info = self.client.scheduler_info()
        return max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))

    def describe(self) -> str:
        info = self.client.scheduler_info()
        n = len(info.get("workers", {}))
        where = "LocalCluster" if self.cluster is not None else self.client.scheduler.address
        return f"Dask {where}: {n} worker(s), {self.n_slots} thread(s)"

    def submit(self, fn, job):
        return self.client.submit(fn, job, pure=False, retries=0)

    def wait(self, futures, timeout: float):
        futures = list(futures)
        try:
            self._distributed.wait(futures, timeout=timeout, return_when="FIRST_COMPLETED")
        except TimeoutError:
            pass
        return {f for f in futures if f.done()}

    def is_worker_death(self, exc) -> bool:
        from distributed import KilledWorker

        comm_closed = getattr(getattr(self._distributed, "comm", None), "CommClosedError", ())
        return isinstance(exc, (KilledWorker, comm_closed, OSError))

    def worker_pids(self) -> list[int]:
        return list(self.client.run(os.getpid).values())

    def recover(self) -> None:
        """Nothing to rebuild: the scheduler replaces lost workers (the nanny restarts them)."""

    def cancel(self, futures) -> None:
        futures = list(futures)
        if futures:
            self.client.cancel(futures, force=True)

    def close(self, cancel: bool = False) -> None:
        try:
            self.client.close()
        finally:
            if self.cluster is not None:
                self.cluster.close()
