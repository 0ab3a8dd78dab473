"""Background compilation for ``gsdf demo``: a second process compiles (and caches) one warm-up job's kernels
while this process compiles its own. Kept apart from :mod:`gsdf.cli.warmup`, which imports the command group,
so that subcommands can use it without an import cycle."""

from __future__ import annotations

import sys
import threading


class BackgroundWarmup:
    """Compile ``jobs`` in one background process, started only if this process compiles a kernel.

    On a cold cache and with >= 2 threads, the background process compiles (and caches) the kernels of
    ``jobs`` while this process compiles its own; when this process reaches them they load from the cache.
    On a warm cache nothing is started. The jobs run one after the other; :meth:`wait_for` waits until one
    of them is done (the process prints a line per finished job) or a timeout passes, :meth:`close` waits
    for the process (it is short-lived), or stops it after ``timeout`` seconds.

    Example
    -------
    >>> with BackgroundWarmup(["demo-cloud", "distance"]) as bg:     # doctest: +SKIP
    ...     run_the_soup_part(); bg.wait_for("demo-cloud"); run_the_cloud_part()
    """

    def __init__(self, jobs):
        from gsdf._jit import install_compile_notice, on_first_compile
        from gsdf.threads import get_num_threads

        self.jobs, self.proc, self.done = list(jobs), None, set()
        self._reader, self._changed = None, threading.Condition()
        if self.jobs and get_num_threads() >= 2:
            if install_compile_notice().printed:  # a kernel compiled already (cold cache): start now
                self._start()
            else:
                on_first_compile(self._start)

    def _start(self):
        import subprocess

        from gsdf.threads import get_num_threads

        # this process's thread count: kernels that pick a serial or a parallel driver by it pick the same
        cmd = [sys.executable, "-m", "gsdf.cli.main", "--threads", str(get_num_threads()), "warmup", "--only",
               ",".join(self.jobs), "--workers", "1"]
        try:
            proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                    stdin=subprocess.DEVNULL, text=True)
        except OSError:  # pragma: no cover - no subprocesses here: compile in this process only
            return
        self._attach(proc)

    def _attach(self, proc):
        """Follow ``proc``: a thread reads its output (so it never blocks on a full pipe) and records each
        job it reports as finished; when the output ends, every job counts as finished."""
        self.proc = proc
        self._reader = threading.Thread(target=self._read, args=(proc.stdout,), daemon=True)
        self._reader.start()

    def _read(self, stream):
        for line in stream:  # :func:`gsdf.cli.warmup.warm` prints one line per finished job, its name first
            words = line.split()
            if words and words[0] in self.jobs:
                with self._changed:
                    self.done.add(words[0])
                    self._changed.notify_all()
        with self._changed:  # the process ended (every job done, or it failed): the caller compiles the rest
            self.done.update(self.jobs)
            self._changed.notify_all()

    def wait_for(self, job: str, timeout: float = 120.0) -> None:
        """Return once background job ``job`` has finished, the process has ended or ``timeout`` seconds
        have passed (at once if no process runs); the caller then compiles whatever is not cached yet."""
        if job not in self.jobs:
            raise ValueError(f"job: {job!r} is not one of this background process's jobs {self.jobs}")
        if self.proc is None:
            return
        with self._changed:
            self._changed.wait_for(lambda: job in self.done, timeout)

    def close(self, timeout: float = 120.0):
        from gsdf._jit import cancel_first_compile

        cancel_first_compile(self._start)  # warm cache: nothing was started, and nothing will be
        if self.proc is None:
            return
        import subprocess

        try:
            self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:  # pragma: no cover
            self.proc.kill()
            self.proc.wait()
        if self._reader is not None:
            self._reader.join()  # the output ends with the process
            self._reader = None
        if self.proc.stdout is not None:
            self.proc.stdout.close()
        self.proc = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close(timeout=0.0 if exc[0] is not None else 120.0)
