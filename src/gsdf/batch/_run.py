"""The batch driver: items in, one task per item on an executor, the manifest out — resumable and interruptible.

:func:`run_batch` validates everything before any work (inputs, options, output folder, executor), skips items
whose output exists and whose recorded input hash and options still match, keeps a bounded window of items in
flight (2 per worker slot), gathers them as they complete, appends each record to the manifest, resubmits
items lost to a dead worker up to ``BatchOptions.max_retries`` times, and on Ctrl-C cancels what is in flight,
records those items as ``cancelled`` and raises :class:`BatchInterrupted` carrying the partial result.
"""

from __future__ import annotations

import collections
import datetime
import os
import re
import statistics
import tempfile
import time
import uuid
from dataclasses import dataclass, field

from gsdf._checks import flag, integer, positive, progress_callback
from gsdf.batch._inputs import check_output_folder, collect_inputs
from gsdf.batch._manifest import MANIFEST_NAME, ManifestWriter, file_sha256, params_sha256, read_manifest
from gsdf.batch._tasks import check_options, task_name
from gsdf.batch._worker import process_item

LOCK_NAME = ".gsdf-batch.lock"
POLL = 0.5  # seconds between checks of the items in flight
_PART = re.compile(r"^\..+\.npz\..+\.part$")
STATUSES = ("done", "failed", "skipped", "cancelled")


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`run_batch`: in-flight items were cancelled and recorded; ``.result`` holds the rest."""

    def __init__(self, result):
        super().__init__("batch interrupted")
        self.result = result


@dataclass(frozen=True)
class BatchOptions:
    """How :func:`run_batch` runs the items (what each item computes is the task's options).

    Attributes
    ----------
    resume : bool, default True
        Skip items whose output exists and whose input hash and options match their ``done`` record, and items
        that failed by themselves (a malformed or degenerate input) with the same input and options.
    retry_failed : bool, default False
        With ``resume``, run such failed items again (failures of a worker are always retried).
    max_retries : int, default 2
        Resubmissions of an item whose worker died, before it is recorded as failed.
    threads : int, optional
        BLAS/numba threads per item (default: the cores divided by the concurrent workers).
    scheduler_timeout : float, default 10.0
        Seconds to wait for an unreachable Dask scheduler before a ValueError.

    Examples
    --------
    >>> from gsdf import BatchOptions
    >>> BatchOptions(retry_failed=True).resume
    True
    >>> r = run_batch("meshes/", "occupancy", "occ/", batch_options=BatchOptions(threads=2))   # doctest: +SKIP
    """

    resume: bool = True
    retry_failed: bool = False
    max_retries: int = 2
    threads: int | None = None
    scheduler_timeout: float = 10.0

    def __post_init__(self):  # a ValueError naming the attribute, at construction
        flag(self.resume, "resume")
        flag(self.retry_failed, "retry_failed")
        # stored as Python numbers (numpy integers are accepted like their value)
        object.__setattr__(self, "max_retries", integer(self.max_retries, "max_retries", lo=0))
        if self.threads is not None:
            object.__setattr__(self, "threads", integer(self.threads, "threads", lo=1))
        object.__setattr__(self, "scheduler_timeout", positive(self.scheduler_timeout, "scheduler_timeout"))


@dataclass
class BatchResult:
    """What :func:`run_batch` did: one record per item of this run (``status`` in done / failed / skipped /
    cancelled / pending), the output folder and manifest, the executor used and the wall time."""

    out: str
    manifest: str
    records: list = field(default_factory=list)
    executor: str = ""
    seconds: float = 0.0
    interrupted: bool = False

    @property
    def counts(self) -> dict:
        c = collections.Counter(r["status"] for r in self.records)
        return {s: c.get(s, 0) for s in STATUSES + ("pending",) if s != "pending" or c.get(s)}

    @property
    def failed(self) -> list:
        return [r for r in self.records if r["status"] == "failed"]

    def summary(self, max_failures: int = 10) -> str:
        """A plain-text table: items per status, throughput, per-item times, the first failures."""
        c = self.counts
        lines = [f"{'status':<10} {'items':>7}"] + [f"{k:<10} {v:>7}" for k, v in c.items()]
        lines.append(f"{'total':<10} {len(self.records):>7}")
        ran = [r for r in self.records if r["status"] in ("done", "failed") and "seconds" in r]
        if not ran:
            lines.append("nothing to run: every output is up to date")
        elif self.seconds > 0:
            rate = 60.0 * len(ran) / self.seconds
            lines.append(f"wall {self.seconds:.1f} s on {self.executor}: {rate:.1f} items/min")
        done = [r["seconds"]["total"] for r in ran if r["status"] == "done"]
        if done:
            lines.append(f"per item (done): median {statistics.median(done):.2f} s, max {max(done):.2f} s, "
                         f"sum {sum(done):.1f} s")
        tops = [r["topology"] for r in self.records if r.get("topology")]
        if tops:
            n_open = sum(t["open"] for t in tops)
            n_nm = sum(t["non_manifold"] for t in tops)
            n_cc = sum(t["components"] > 1 for t in tops)
            lines.append(f"input meshes: {n_open} open, {n_nm} non-manifold, {n_cc} with several components, of "
                         f"{len(tops)} (manifest field 'topology')")
        again = [r for r in self.records if r["status"] == "skipped" and r.get("previous") == "failed"]
        if again:
            lines.append(f"{len(again)} skipped item(s) had failed before with the same input and options "
                         "(BatchOptions(retry_failed=True) / --retry-failed to run them again)")
        for r in self.failed[:max_failures]:
            lines.append(f"failed: {r['input']}: {r.get('error')}")
        if len(self.failed) > max_failures:
            lines.append(f"... and {len(self.failed) - max_failures} more failures (see {self.manifest})")
        lines.append(f"outputs in {self.out}; manifest {self.manifest}")
        return "\n".join(lines)


def _count(name, value, lo=1):
    if value is None:
        return None
    import numpy as np

    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name}: expected a positive integer, got {value!r}")
    if value < lo:
        raise ValueError(f"{name}: must be >= {lo}, got {value}")
    return int(value)


def _check_out(out) -> str:
    if not isinstance(out, (str, os.PathLike)) or not os.fspath(out):
        raise ValueError(f"out: expected a folder path, got {out!r}")
    out = os.path.abspath(os.fspath(out))
    if os.path.exists(out) and not os.path.isdir(out):
        raise ValueError(f"out: {out} exists and is not a folder")
    return out


def _prepare_output(out: str) -> list:
    """Create ``out`` (and missing parents) and check it is writable; returns the folders this created (deepest
    first), which :func:`_cleanup_output` removes again when the run leaves them empty."""
    created = []
    probe = out
    while not os.path.exists(probe):
        created.append(probe)
        probe = os.path.dirname(probe)
    try:
        os.makedirs(out, exist_ok=True)
        fd, test = tempfile.mkstemp(dir=out, prefix=".gsdf-write-test.")
        os.close(fd)
        os.unlink(test)
    except OSError as exc:
        _cleanup_output(created)
        raise ValueError(f"out: cannot write to the output folder {out} ({exc.strerror or exc})") from None
    return created


def _cleanup_output(created) -> None:
    """Remove the folders this run created if nothing was written into them (a refused or failed start)."""
    for d in created:
        try:
            os.rmdir(d)
        except OSError:
            return  # not empty (or gone): keep it and its parents


class _Lock:
    """An exclusive lock on the output folder (two runs must not write one manifest): ``LOCK_NAME`` held with
    ``flock``, unlinked by :meth:`release` on every exit path (a kill -9 leaves the file, never the lock: the
    next run takes it over). Without ``fcntl`` (Windows) no lock is taken."""

    def __init__(self, out: str):
        self.path = os.path.join(out, LOCK_NAME)
        self.fh = None
        try:
            import fcntl
        except ImportError:  # pragma: no cover - Windows
            return
        while True:
            try:
                fh = open(self.path, "a")
            except OSError as exc:
                raise ValueError(f"out: cannot create the lock file {self.path} ({exc.strerror or exc})") from None
            try:
                fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                fh.close()
                raise ValueError(f"out: another gsdf batch is writing to {out}") from None
            try:  # the file we locked may have been unlinked by the run that held it: lock the current one
                same = os.path.samestat(os.fstat(fh.fileno()), os.stat(self.path))
            except OSError:
                same = False
            if same:
                self.fh = fh
                return
            fh.close()

    def release(self) -> None:
        if self.fh is not None:
            try:
                os.unlink(self.path)  # while still holding it: a waiting run then re-opens a fresh file
            except OSError:
                pass
            self.fh.close()
            self.fh = None


def _remove_stale_parts(out) -> None:
    """Temporary ``.NAME.npz.*.part`` files of workers killed mid-write (we hold the folder's lock)."""
    for base, _, files in os.walk(out):
        for f in files:
            if _PART.match(f):
                try:
                    os.unlink(os.path.join(base, f))
                except OSError:
                    pass


#: Memory of one worker process at rest (Python, numpy, numba and gsdf loaded): a lower bound, so that a worker
#: count the machine cannot start is refused before any process is.
WORKER_BYTES = 100 << 20


def _executor_spec(workers, executor):
    """Validate ``workers`` / ``executor`` before any work; returns a function that builds the executor (None:
    the caller's own executor object)."""
    from gsdf.batch._executors import DaskExecutor, LocalExecutor

    workers = _count("workers", workers)
    if workers is not None:
        from gsdf._memory import check_bytes

        check_bytes(workers * WORKER_BYTES, f"workers: {workers:,} worker processes")
    if isinstance(executor, str) and not executor.strip():
        raise ValueError("executor: expected 'local', 'dask' or a scheduler address like tcp://host:8786, got an "
                         "empty string")
    if executor is None or isinstance(executor, str):
        kind = executor or "local"
        if kind not in ("local", "dask") and workers is not None:
            raise ValueError(f"conflicting options: workers and the scheduler address {kind!r} (the cluster has "
                             "its own workers)")
        return kind
    if not isinstance(executor, (LocalExecutor, DaskExecutor)):
        raise ValueError(f"executor: expected 'local', 'dask', a scheduler address or a LocalExecutor / "
                         f"DaskExecutor, got {type(executor).__name__}")
    if workers is not None:
        raise ValueError("conflicting options: workers and executor (an executor object has its own workers)")
    return None


def _executor(kind, workers, threads, scheduler_timeout):
    from gsdf.batch._executors import DaskExecutor, LocalExecutor

    if kind == "local":
        return LocalExecutor(workers or 1, threads=threads)
    if kind == "dask":
        return DaskExecutor.local(workers or 1, threads=threads)
    return DaskExecutor.connect(kind, timeout=scheduler_timeout, threads=threads)


def _now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def run_batch(inputs, task, out, options=None, *, workers=None, executor=None, progress=None,
              batch_options: BatchOptions | None = None) -> BatchResult:
    """Run ``task`` on every input and write one ``.npz`` per item plus ``manifest.jsonl`` into ``out``.

    Parameters
    ----------
    inputs : str, os.PathLike or list of paths
        A folder, glob, manifest file (txt / CSV / JSON, CSV and JSON with per-item options) or list of paths;
        see :func:`gsdf.batch.collect_inputs`.
    task : {"sdf-samples", "occupancy", "sdf-grid", "surface"}
        See :mod:`gsdf.batch._tasks` for each task's options and arrays.
    out : str or os.PathLike
        Output folder (created); outputs mirror the inputs' folder layout.
    options : dict, optional
        Task options for every item (per-item options from a manifest override them).
    workers : int, optional
        Worker processes of a local executor (default 1).
    executor : str, LocalExecutor or DaskExecutor, optional
        Where items run: ``"local"`` (default: ``workers`` local processes), ``"dask"`` (a Dask ``LocalCluster``
        of ``workers`` processes), a Dask scheduler address (``"tcp://host:8786"``), or an executor built by the
        caller (kept open afterwards). run_batch starts an executor only when there is work, and closes it.
    progress : callable, optional
        ``progress(stage, fraction)`` after every item: ``stage`` is the item's status (``done``, ``failed``,
        ``skipped``), ``fraction`` the share of the items finished so far.
    batch_options : BatchOptions, optional
        Resume, retries, threads per item, scheduler timeout.

    Returns
    -------
    BatchResult
        ``.records``, ``.counts``, ``.summary()``.

    Raises
    ------
    ValueError
        Nothing to do, bad options, conflicting executor options, an unwritable output folder, an unreachable
        scheduler — before any item runs.
    BatchInterrupted
        On Ctrl-C, after cancelling and recording the items in flight (``.result`` holds the partial result).

    Examples
    --------
    >>> r = run_batch("meshes/", "sdf-samples", "out/", {"n_samples": 250000}, workers=2)   # doctest: +SKIP
    >>> print(r.summary())                                                                   # doctest: +SKIP
    """
    bo = BatchOptions() if batch_options is None else batch_options
    if not isinstance(bo, BatchOptions):
        raise ValueError(f"batch_options: expected a gsdf.batch.BatchOptions, got {type(bo).__name__}")
    task = task_name(task)
    user_options = dict(options or {})
    check_options(task, user_options, "options")
    kind = _executor_spec(workers, executor)
    _count("threads", bo.threads)
    _count("max_retries", bo.max_retries, lo=0)
    progress = None if progress is None else progress_callback(progress)
    report = None if progress is None else (lambda rec, counts: progress(
        rec["status"], sum(counts[s] for s in STATUSES) / max(1, counts["total"])))
    items = collect_inputs(inputs)
    jobs_options = [check_options(task, {**user_options, **it.options}, it.path) for it in items]
    out = _check_out(out)
    check_output_folder(inputs, items, out)
    created = _prepare_output(out)
    try:
        lock = _Lock(out)
    except BaseException:
        _cleanup_output(created)
        raise
    ok = False
    try:
        _remove_stale_parts(out)
        manifest = os.path.join(out, MANIFEST_NAME)
        state = read_manifest(manifest) if bo.resume else {}
        run_id = uuid.uuid4().hex[:12]
        result = BatchResult(out, manifest)
        todo = collections.deque()
        for it, opts in zip(items, jobs_options):
            job = {"task": task, "input": it.path, "output": it.output, "out_dir": out, "options": opts,
                   "params_sha256": params_sha256(task, opts), "attempts": 1, "run": run_id, "threads": bo.threads}
            prev = state.get(it.output)
            if _reusable(prev, job, out, bo.retry_failed):
                result.records.append({**{k: job[k] for k in ("task", "input", "output", "run")},
                                       "status": "skipped", "previous": prev["status"],
                                       "input_sha256": prev["input_sha256"], "error": prev.get("error")})
            else:
                todo.append(job)
        if report is not None:
            for r in result.records:
                report(r, _tally(result.records, len(items)))
        own = kind is not None
        t0 = time.perf_counter()
        if todo:
            ex = _executor(kind, workers, bo.threads, bo.scheduler_timeout) if own else executor
            result.executor = ex.describe()
            try:
                with ManifestWriter(manifest) as writer:
                    _drive(ex, todo, writer, result, len(items), bo.max_retries, report, POLL)
            finally:
                if own:
                    ex.close(cancel=result.interrupted)
        result.seconds = time.perf_counter() - t0
        ok = True
        if result.interrupted:
            raise BatchInterrupted(result)
        return result
    finally:
        lock.release()
        if not ok:
            _cleanup_output(created)


def _reusable(prev, job, out, retry_failed) -> bool:
    """An earlier record stands: same options, same input bytes, and either a done output still on disk or
    a failure of the item itself (not of its worker) that ``retry_failed`` does not ask to redo."""
    if not prev or prev.get("params_sha256") != job["params_sha256"] or not prev.get("input_sha256"):
        return False
    if prev.get("status") == "done":
        ok = os.path.isfile(os.path.join(out, job["output"]))
        if prev.get("mesh"):                   # the surface's mesh file written next to the .npz
            ok = ok and os.path.isfile(os.path.join(out, os.path.dirname(job["output"]), prev["mesh"]))
    else:
        ok = prev.get("status") == "failed" and prev.get("failure") == "item" and not retry_failed
    return ok and prev["input_sha256"] == file_sha256(job["input"])


def _tally(records, total) -> dict:
    c = collections.Counter(r["status"] for r in records)
    return {**{s: c.get(s, 0) for s in STATUSES}, "total": total}


def _hint(ex) -> str:
    if ex.kind != "local":
        return ""
    return ("; if every item fails like this from a script, run it under `if __name__ == \"__main__\":` "
            "(workers are spawned and import the main module)")


def _drive(ex, todo, writer, result, total, max_retries, report, poll):
    inflight = {}  # future -> job

    def finish(rec, announce=True):
        rec.setdefault("time", _now())
        writer.write(rec)
        result.records.append(rec)
        if report is not None and announce:
            report(rec, _tally(result.records, total))

    try:
        while todo or inflight:
            window = max(2, 2 * ex.n_slots)  # a Dask cluster may grow or shrink during the run
            while todo and len(inflight) < window:
                job = todo.popleft()
                if job["threads"] is None:  # the executor's share of the cores (or, remote, per worker)
                    job = {**job, "threads": ex.threads, "threads_by_worker": getattr(ex, "threads_by_worker", None)}
                inflight[ex.submit(process_item, job)] = job
            done = ex.wait(inflight, timeout=poll)
            deaths = []
            for fut in done:
                job = inflight.pop(fut)
                try:
                    rec = fut.result()
                except Exception as exc:  # the item did not return: its worker died (or the pool broke)
                    if ex.is_worker_death(exc):
                        deaths.append((job, exc))
                        continue
                    rec = {**{k: job[k] for k in ("task", "input", "output", "options", "params_sha256",
                                                  "attempts", "run")},
                           "status": "failed", "failure": "worker", "error": f"{type(exc).__name__}: {exc}"}
                finish(rec)
            if deaths:
                if ex.kind == "local":  # the broken pool fails every item in flight: collect them all
                    ex.wait_all(inflight, timeout=30.0)
                    for fut in list(inflight):
                        job = inflight.pop(fut)
                        try:
                            finish(fut.result(timeout=0))
                        except Exception as exc:  # broken with the pool (or stuck in it): resubmit
                            deaths.append((job, exc))
                    ex.recover()
                for job, exc in deaths:
                    if job["attempts"] > max_retries:
                        finish({**{k: job[k] for k in ("task", "input", "output", "options", "params_sha256",
                                                       "attempts", "run")},
                                "status": "failed", "failure": "worker",
                                "error": f"worker died {job['attempts']} time(s) running this item "
                                         f"({type(exc).__name__}: {exc}){_hint(ex)}"})
                    else:
                        todo.appendleft({**job, "attempts": job["attempts"] + 1})
    except KeyboardInterrupt:
        result.interrupted = True
        ex.cancel(list(inflight))
        for job in inflight.values():
            finish({**{k: job[k] for k in ("task", "input", "output", "options", "params_sha256", "attempts",
                                           "run")}, "status": "cancelled", "error": "interrupted (Ctrl-C)"},
                   announce=False)
        for job in todo:
            result.records.append({**{k: job[k] for k in ("task", "input", "output", "run")},
                                   "status": "pending"})
