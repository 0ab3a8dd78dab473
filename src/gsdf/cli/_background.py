"""Background compilation for ``gsdf demo``: a second process compiles (and caches) one warm-up job's kernels
while this process compiles its own. Kept apart from :mod:`gsdf.cli.warmup`, which imports the command group,
so that subcommands can use it without an import cycle."""

from __future__ import annotations

import sys


class BackgroundWarmup:
    """Compile ``jobs`` in one background process, started only if this process compiles a kernel.

    On a cold cache and with >= 2 threads, the background process compiles (and caches) the kernels of
    ``jobs`` while this process compiles its own; when this process reaches them they load from the cache.
    On a warm cache nothing is started. The jobs run one after the other; :meth:`wait_for` waits until one
    of them is done (the process prints a line per finished job), :meth:`close` waits for the process (it is
    short-lived), or stops it after ``timeout`` seconds.

    Example
    -------
    >>> with BackgroundWarmup(["demo-cloud", "distance"]) as bg:     # doctest: +SKIP
    ...     run_the_soup_part(); bg.wait_for("demo-cloud"); run_the_cloud_part()
    """

    def __init__(self, jobs):
        from .._jit import install_compile_notice, on_first_compile
        from ..threads import get_num_threads

        self.jobs, self.proc, self.done = list(jobs), None, set()
        if self.jobs and get_num_threads() >= 2:
            if install_compile_notice().printed:  # a kernel compiled already (cold cache): start now
                self._start()
            else:
                on_first_compile(self._start)

    def _start(self):
        import subprocess

        from ..threads import get_num_threads

        # this process's thread count: kernels that pick a serial or a parallel driver by it pick the same
        cmd = [sys.executable, "-m", "gsdf.cli.main", "--threads", str(get_num_threads()), "warmup", "--only",
               ",".join(self.jobs), "--jobs", "1"]
        try:
            self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                         stdin=subprocess.DEVNULL, text=True)
        except OSError:  # pragma: no cover - no subprocesses here: compile in this process only
            self.proc = None

    def wait_for(self, job: str) -> None:
        """Return once background job ``job`` has finished (or the process has ended; at once if none runs).

        :func:`gsdf.cli.warmup.warm` prints one line per finished job, starting with its name."""
        if job not in self.jobs:
            raise ValueError(f"job: {job!r} is not one of this background process's jobs {self.jobs}")
        while self.proc is not None and job not in self.done:
            line = self.proc.stdout.readline()
            if not line:  # the process ended (every job done, or it failed): the caller compiles what is left
                self.done.update(self.jobs)
                break
            words = line.split()
            if words and words[0] in self.jobs:
                self.done.add(words[0])

    def close(self, timeout: float = 120.0):
        from .._jit import cancel_first_compile

        cancel_first_compile(self._start)  # warm cache: nothing was started, and nothing will be
        if self.proc is None:
            return
        import subprocess

        try:
            self.proc.communicate(timeout=timeout)  # reads what is left of its output, then waits
        except subprocess.TimeoutExpired:  # pragma: no cover
            self.proc.kill()
            self.proc.communicate()
        self.proc = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close(timeout=0.0 if exc[0] is not None else 120.0)
