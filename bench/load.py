"""Artificial load for the benchmarks: busy processes that the benchmark starts and stops itself.

Speed ratios are measured both on the (shared, never really idle) machine and with two extra busy processes
competing for the two cores. :class:`BusyLoad` starts ``n`` pure-Python spinning processes
(no I/O, no memory) and stops them, by their own pids, on exit from the ``with`` block; a spinner whose
parent died (the benchmark was killed) stops by itself.

    with BusyLoad(2):
        t = time_something()
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

# each spinner exits by itself once its parent is gone (a benchmark killed before its ``with`` block ended)
_SPIN = ("import os, sys\nparent = int(sys.argv[1])\nwhile os.getppid() == parent:\n"
         "    sum(i * i for i in range(10000))\n")


class BusyLoad:
    """``with BusyLoad(n):`` runs ``n`` CPU-bound processes for the duration of the block."""

    def __init__(self, n: int = 2):
        if not isinstance(n, int) or isinstance(n, bool) or n < 0:
            raise ValueError(f"n: expected a non-negative int, got {n!r}")
        self.n, self.procs = n, []

    def __enter__(self):
        self.procs = [subprocess.Popen([sys.executable, "-c", _SPIN, str(os.getpid())], stdin=subprocess.DEVNULL,
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                      for _ in range(self.n)]
        time.sleep(0.5)  # let them reach the loop
        return self

    def __exit__(self, *exc):
        for p in self.procs:
            p.terminate()
        for p in self.procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        self.procs = []


def uptime() -> str:
    """The 1/5/15-minute load averages, as `uptime` prints them."""
    return "load %.2f %.2f %.2f" % os.getloadavg()
