"""Where a cold gsdf command spends its compile time: per-kernel compile seconds and specialisations.

Runs one CLI command in this process with ``NUMBA_CACHE_DIR`` pointed at a new empty folder (what a fresh
install sees) and a numba ``numba:compile`` event listener that times every compilation in CPU seconds of
the compiling thread (so the figures hold on a loaded machine, unlike wall time). A kernel's own
time excludes the kernels it compiled while being compiled (nested events), so the column sums to the
total. ``gsdf demo``'s background compile process is switched off here, so every kernel the command uses
compiles in this process and shows up in the table.

    PYTHONPATH=src python3 bench/profile_compile.py demo            # top 15 kernels of `gsdf demo`
    PYTHONPATH=src python3 bench/profile_compile.py sdf --top 30    # `gsdf sdf` on bunny00.off
    PYTHONPATH=src python3 bench/profile_compile.py demo-cloud      # the demo's background process alone
    PYTHONPATH=src python3 bench/profile_compile.py demo-soup       # the demo's main process alone (its
                                                                    # background job's kernels cached first)

``demo-cloud`` + ``demo-soup`` split ``demo``'s compile into its two processes (the critical path of a cold
demo on >= 2 cores is the longer of the two).

Prints only (the cold-start section of RESULTS.md is bench_cold_start.py's).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("command", choices=["demo", "sdf", "winding", "demo-cloud", "demo-soup"], help="what to run cold")
    ap.add_argument("--top", type=int, default=15)
    a = ap.parse_args(argv)
    cache = tempfile.mkdtemp(prefix="numba-profile-")
    os.environ["NUMBA_CACHE_DIR"] = cache
    sys.path.insert(0, HERE)
    from common import data_dir, machine  # noqa: E402

    from numba.core import event

    stack, own, total, sigs = [], {}, {}, {}

    class Timer(event.Listener):
        def on_start(self, ev):
            stack.append([ev.data.get("dispatcher"), time.thread_time(), 0.0])

        def on_end(self, ev):
            disp, t0, child = stack.pop()
            dt = time.thread_time() - t0
            f = getattr(disp, "py_func", None)
            name = f"{f.__module__}.{f.__qualname__}" if f is not None else repr(disp)
            own[name] = own.get(name, 0.0) + dt - child
            total[name] = total.get(name, 0.0) + dt
            sigs[name] = len(getattr(disp, "signatures", ())) or sigs.get(name, 1)
            if stack:
                stack[-1][2] += dt

    if a.command == "demo-soup":  # the background job's kernels compiled (and cached) in another process first
        import subprocess

        subprocess.run([sys.executable, "-m", "gsdf.cli.main", "warmup", "--only", "demo-cloud,distance", "--jobs", "1"],
                       check=True, stdout=subprocess.DEVNULL, env=dict(os.environ, NUMBA_CACHE_DIR=cache))
    event.register("numba:compile", Timer())
    import gsdf.cli._background as bg

    bg.BackgroundWarmup._start = lambda self: None  # everything compiles here
    from click.testing import CliRunner

    from gsdf.cli.main import main as cli

    out = tempfile.mkdtemp(prefix="gsdf-profile-out-")
    args = {"demo": ["demo", "-o", os.path.join(out, "demo")],
            "demo-soup": ["demo", "-o", os.path.join(out, "demo")],
            "sdf": ["sdf", os.path.join(data_dir(), "meshes", "bunny00.off"), "-o", os.path.join(out, "s.npz"),
                    "-q"]}
    if a.command == "winding":
        import numpy as np

        from gsdf import data
        from gsdf.io import read_mesh
        from gsdf.winding._fast import FastWindingNumber

        t = time.perf_counter()
        V, F = read_mesh(data.path("broken_soup.obj"))
        FastWindingNumber(V, F)(np.random.default_rng(0).random((2000, 3)))
    elif a.command == "demo-cloud":
        from gsdf.cli.warmup import warm

        t = time.perf_counter()
        for _, _, err in warm(["demo-cloud", "distance"], processes=1):  # what gsdf demo's background runs
            if err:
                raise SystemExit(err)
    else:
        t = time.perf_counter()
        res = CliRunner().invoke(cli, args[a.command], catch_exceptions=False)
        if res.exit_code != 0:
            print(res.output)
            raise SystemExit(1)
    wall = time.perf_counter() - t
    cpu = time.process_time()
    print(machine())
    print("load %.2f %.2f %.2f" % os.getloadavg())
    print(f"gsdf {a.command}: wall {wall:.1f} s, process CPU {cpu:.1f} s, compile CPU (sum of own) "
          f"{sum(own.values()):.1f} s in {len(own)} kernels, "
          f"{sum(sigs.values())} specialisations")
    print(f"{'kernel':70s} {'own CPU s':>9s} {'incl s':>7s} {'sigs':>4s}")
    for name in sorted(own, key=own.get, reverse=True)[: a.top]:
        print(f"{name:70s} {own[name]:9.2f} {total[name]:7.2f} {sigs[name]:4d}")
    multi = [n for n in sigs if sigs[n] > 1]
    if multi:
        print("more than one specialisation: " + ", ".join(f"{n} ({sigs[n]})" for n in multi))


if __name__ == "__main__":
    main()
