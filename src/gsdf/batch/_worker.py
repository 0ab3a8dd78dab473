"""What a worker does with one item: limit its threads, hash and read the input, run the task, write the
``.npz`` atomically, and return the manifest record. Errors of the item become a ``failed`` record; only the
worker's death (or an interrupt) escapes to the executor.

The same function runs in local processes and on Dask workers (it must stay importable and picklable).
"""

from __future__ import annotations

import os
import socket
import tempfile
import time
import traceback

import numpy as np

from gsdf.batch import _threads
from gsdf.batch._manifest import file_sha256
from gsdf.batch._tasks import input_topology, load_geometry, run_task


def write_npz_atomic(path, arrays: dict) -> None:
    """Write ``arrays`` to ``path`` (.npz) atomically: a temporary file in the target folder, fsync'ed, given the
    mode every gsdf output gets (``0666 & ~umask``, :mod:`gsdf.io._safe_write`; ``mkstemp`` alone gives 0600),
    then ``os.replace`` onto the final name. An interruption at any point leaves no file under ``path`` (a hidden
    ``.NAME.*.part`` file may remain after a hard kill; it never counts as an output and the next run on the
    folder removes it).

    Examples
    --------
    >>> write_npz_atomic("out/a.npz", {"sdf": np.zeros(3)})      # doctest: +SKIP
    """
    from gsdf.io._safe_write import _FILE_MODE

    path = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(path))
    created = []  # folders of the mirrored layout made for this file: removed again if it is not written
    probe = folder
    while not os.path.exists(probe):
        created.append(probe)
        probe = os.path.dirname(probe)
    for attempt in range(3):  # another worker's failed write may remove a folder it just made
        try:
            os.makedirs(folder, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".part")
            break
        except FileNotFoundError:
            if attempt == 2:
                raise
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, _FILE_MODE)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        for d in created:  # deepest first; stops at the first folder another item uses
            try:
                os.rmdir(d)
            except OSError:
                break
        raise


def write_mesh_atomic(npz_path, fmt: str, arrays: dict) -> str:
    """Write the ``vertices``/``faces`` of ``arrays`` as ``<npz_path without .npz>.<fmt>`` (ply, obj, off, stl;
    :func:`gsdf.write_mesh`), atomically; returns its name relative to the ``.npz``'s folder."""
    from gsdf.io import write_mesh
    from gsdf.io._safe_write import atomic_output

    path = os.path.splitext(os.fspath(npz_path))[0] + "." + fmt
    with atomic_output(path, extensions=("." + fmt,), make_parents=True) as tmp:
        write_mesh(tmp, np.asarray(arrays["vertices"], np.float64), arrays["faces"])
    return os.path.basename(path)


def worker_threads(requested, by_worker=None) -> int:
    """Threads of this item: ``requested``; else, on a Dask worker, its entry in ``by_worker`` (worker address ->
    threads, measured by the driver when it connected) or its host's cores divided by its own Dask threads;
    else all cores of this machine."""
    if requested:
        return int(requested)
    import sys

    if "distributed" in sys.modules:
        try:
            from distributed import get_worker

            w = get_worker()
            if by_worker and w.address in by_worker:
                return int(by_worker[w.address])
            return _threads.threads_per_worker(w.state.nthreads)
        except (ValueError, AttributeError):
            pass
    return _threads.available_cpus()


def process_item(job: dict) -> dict:
    """Run one item; returns its manifest record (never raises for a bad input).

    ``job`` holds ``task``, ``input`` (path), ``output`` (relative), ``out_dir``, ``options`` (validated),
    ``threads`` (or None), and the bookkeeping fields copied into the record (``params_sha256``, ``attempts``,
    ``run``).
    """
    t0 = time.perf_counter()
    rec = {k: job[k] for k in ("task", "input", "output", "options", "params_sha256", "attempts", "run")}
    rec["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    seconds = {}
    try:
        rec["threads"] = _threads.limit_threads(worker_threads(job.get("threads"), job.get("threads_by_worker")))
        rec["input_sha256"] = file_sha256(job["input"])
        geo = load_geometry(job["input"], job["options"].get("estimate_normals", False))
        rec["counts"] = geo.counts()
        rec["topology"] = input_topology(geo)
        t1 = time.perf_counter()
        seconds["read"] = t1 - t0
        arrays = run_task(job["task"], geo, job["options"])
        t2 = time.perf_counter()
        seconds["compute"] = t2 - t1
        write_npz_atomic(os.path.join(job["out_dir"], job["output"]), arrays)
        fmt = job["options"].get("surface_format")
        if fmt:                                # the surface also as a mesh file next to the .npz
            rec["mesh"] = write_mesh_atomic(os.path.join(job["out_dir"], job["output"]), fmt, arrays)
        seconds["write"] = time.perf_counter() - t2
        rec["arrays"] = {k: list(np.shape(v)) for k, v in arrays.items()}
        rec["status"], rec["error"] = "done", None
    except Exception as exc:  # a bad item: record it, the run goes on
        rec["status"], rec["failure"] = "failed", "item"
        rec["error"] = f"{type(exc).__name__}: {exc}"
        if not isinstance(exc, (ValueError, FileNotFoundError, MemoryError)):
            rec["traceback"] = traceback.format_exc(limit=6)
    seconds["total"] = time.perf_counter() - t0
    rec["seconds"] = seconds
    return rec
