"""Cold start: wall and CPU time of gsdf commands with an empty numba cache (first run after install) and warm.

Each command runs in a fresh process; "cold" points NUMBA_CACHE_DIR at a new empty folder (what a fresh
install sees: every kernel compiles), "warm" runs again with that folder filled. CPU seconds (the process
and its children) are reported beside wall time because the machine is shared: with other processes
running, wall time measures the load more than gsdf, CPU time does not.

    PYTHONPATH=src python3 bench/bench_cold_start.py                 # all commands, this source tree
    PYTHONPATH=src python3 bench/bench_cold_start.py --src /old/src --label before --no-write

Writes the "cold-start" section of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import command, data_dir, heading, machine, table, write_section  # noqa: E402


def inputs(d: str) -> dict:
    """bunny00.off and a level-set loop on it (heat-surface), the bundled torus cloud (tori)."""
    import numpy as np

    from gsdf.contour._surface_curves import level_set_curves
    from gsdf.io import read_mesh
    from gsdf.io._curves import write_curves

    bunny = os.path.join(data_dir(), "meshes", "bunny00.off")
    V, F = read_mesh(bunny)
    loop = os.path.join(d, "loop.txt")
    write_curves(loop, level_set_curves(V, F, V[:, 1] - np.median(V[:, 1])))
    from gsdf import data

    return {"bunny": bunny, "loop": loop, "cloud": data.path("torus_cloud.xyz"), "dir": d}


def commands(f: dict) -> dict:
    o = lambda n: os.path.join(f["dir"], n)  # noqa: E731
    return {
        "demo": ["demo", "-o", o("demo")],
        "sdf": ["sdf", f["bunny"], "-o", o("s.npz"), "-q"],
        "tori": ["tori", f["cloud"], "-o", o("t.ply"), "-q"],
        "heat-surface": ["heat-surface", f["bunny"], "--curves", f["loop"], "-o", o("h.ply")],
    }


def run(args, src: str, cache: str) -> tuple[float, float, bool, bool]:
    """(wall s, CPU s of the process tree, exit ok, compile notice printed)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=src)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "gsdf.cli.main", *args], env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if p.returncode != 0:
        print(p.stderr[-2000:], file=sys.stderr)
    return wall, cpu, p.returncode == 0, "compiling kernels" in p.stderr


def load() -> str:
    return "load %.2f %.2f %.2f" % os.getloadavg()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", default=os.path.join(HERE, "..", "src"), help="gsdf source tree to run")
    ap.add_argument("--label", default="this branch")
    ap.add_argument("--only", default=None, help="comma-separated subset of demo,sdf,tori,heat-surface")
    ap.add_argument("--no-write", action="store_true", help="print only, do not rewrite RESULTS.md")
    a = ap.parse_args(argv)
    argv = sys.argv[1:] if argv is None else argv
    src = os.path.abspath(a.src)
    print(machine())
    rows = []
    with tempfile.TemporaryDirectory(prefix="gsdf-cold-") as d:
        f = inputs(d)
        cmds = commands(f)
        names = list(cmds) if a.only is None else a.only.split(",")
        for name in names:
            cache = tempfile.mkdtemp(prefix="numba-", dir=d)
            l0 = load()
            cw, cc, ok1, notice = run(cmds[name], src, cache)
            ww, wc, ok2, notice2 = run(cmds[name], src, cache)
            row = [f"`gsdf {name}`", a.label, f"{cw:.1f}", f"{cc:.1f}", f"{ww:.1f}", f"{wc:.1f}",
                   "yes" if notice and not notice2 else ("no" if not notice else "also warm"),
                   "ok" if ok1 and ok2 else "FAILED", f"{l0} / {load()}"]
            print(" | ".join(row), flush=True)
            rows.append(row)
    header = ["command", "source", "cold wall s", "cold CPU s", "warm wall s", "warm CPU s", "notice (cold only)",
              "exit", "uptime load before / after"]
    text = (heading("Cold start of the command line", command("bench_cold_start.py", argv))
            + "Cold = an empty NUMBA_CACHE_DIR (a fresh install: every kernel compiles), warm = the same command "
            "again. Wall time depends on the load (column), CPU time (process and children, e.g. the background "
            "compile of `gsdf demo`) does not.\n\n" + table(header, rows))
    print(text)
    if not a.no_write:
        write_section("cold-start", text)
    return rows


if __name__ == "__main__":
    main()
