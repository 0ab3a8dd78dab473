"""Every table of RESULTS.md in one command: runs the area scripts, each rewriting its own sections.

    PYTHONPATH=src /work/anchors/bin/python bench/run_all.py --quick     # reduced sizes, speed parts only
    PYTHONPATH=src /work/anchors/bin/python bench/run_all.py             # everything, full sizes (hours)
    PYTHONPATH=src /work/anchors/bin/python bench/run_all.py --only winding,cold-start --load

Each part runs in its own process (the anchors' venv when it exists, so libigl / potpourri3d / signedheat3d
are importable) with this source tree first on PYTHONPATH. The machine and the load average are printed before
and after every part and written, with each part's duration, peak RSS (``wait4``: the part's process; parts that
start a process per case report those in their own sections) and exit status, to the "run-all" section of
RESULTS.md. ``--load`` asks the parts that support it to time everything a second time with two busy processes
that the benchmark starts and stops itself (bench/load.py). A part without a quick mode (``None``) is skipped by
``--quick``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from common import command, heading, machine, table, write_section  # noqa: E402
from load import uptime  # noqa: E402

ANCHORS_PYTHON = "/work/anchors/bin/python"

# name -> (script, quick arguments or None (not in --quick), full arguments, takes --load)
PARTS = {
    "cold-start": ("bench_cold_start.py", ["--only", "demo,sdf"], [], False),
    "winding": ("bench_winding.py", ["--quick"], [], True),
    "distance": ("bench_distance.py", ["--queries", "50000"], [], False),
    "io": ("bench_io.py", ["100"], [], False),
    "tori": ("bench_tori.py", ["--quick"], [], False),
    "heat-surface-speed": ("bench_heat_surface.py", ["--only", "speed", "--quick"], ["--only", "speed"], True),
    "heat-surface": ("bench_heat_surface.py", None, ["--only", "accuracy,polygon-pointcloud,solver-rule,ordering,voxel"],
                     False),
    "heat-volume-speed": ("bench_heat_volume.py", ["--only", "speed", "--quick"], ["--only", "speed,scaling"], True),
    "heat-volume": ("bench_heat_volume.py", None, ["--only", "accuracy,choices,solvers"], False),
    "swn": ("bench_swn.py", None, [], False),
    "recon": ("bench_recon.py", None, [], False),
    "parameters": ("bench_parameters.py", None, [], False),
    "batch": ("bench_batch.py", None, [], False),
}


def run_part(cmd, env):
    """Run ``cmd``; (exit status, seconds, peak RSS in MB of its process tree's largest waited process)."""
    t = time.perf_counter()
    p = subprocess.Popen(cmd, env=env, cwd=ROOT)
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    return p.returncode, time.perf_counter() - t, usage.ru_maxrss / 1024.0


def python_for_benchmarks() -> str:
    return ANCHORS_PYTHON if os.path.exists(ANCHORS_PYTHON) else sys.executable


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="reduced sizes (target: under 20 minutes in all)")
    ap.add_argument("--load", action="store_true", help="also measure under two busy processes where supported")
    ap.add_argument("--only", default="", help=f"comma list of parts (default all): {', '.join(PARTS)}")
    ap.add_argument("--dry-run", action="store_true", help="print the commands only")
    a = ap.parse_args(argv)
    names = [n for n in a.only.split(",") if n] or list(PARTS)
    for n in names:
        if n not in PARTS:
            ap.error(f"unknown part {n!r}; known: {', '.join(PARTS)}")
    py = python_for_benchmarks()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "src"), os.environ.get("PYTHONPATH", "")]))
    info = machine()
    print(f"machine: {info}\n{uptime()}\npython: {py}", flush=True)
    rows, t_all = [], time.perf_counter()
    for n in names:
        script, quick, full, takes_load = PARTS[n]
        if a.quick and quick is None:
            print(f"\n=== {n}: no quick mode, skipped by --quick", flush=True)
            continue
        cmd = [py, os.path.join(HERE, script), *(quick if a.quick else full), *(["--load"] if a.load and takes_load else [])]
        print(f"\n=== {n}: {' '.join(cmd)}\n    before: {uptime()}", flush=True)
        if a.dry_run:
            continue
        before = uptime()
        status, dt, rss = run_part(cmd, env)
        after = uptime()
        print(f"    {n}: exit {status}, {dt:.0f} s, peak RSS {rss:.0f} MB; after: {after}", flush=True)
        rel = os.path.relpath(cmd[1], ROOT)
        rows.append([n, f"`{os.path.basename(py)} {rel} {' '.join(cmd[2:])}`".replace("  ", " "),
                     "ok" if status == 0 else f"exit {status}", f"{dt:.0f}", f"{rss:.0f}", before, after])
    if a.dry_run:
        return 0
    total = time.perf_counter() - t_all
    text = (heading("All benchmarks in one run", command("run_all.py", argv, python=py))
            + f"Total {total / 60:.1f} min. Load averages before and after each part are listed; each part's own "
            "section states what it measured. Peak RSS: the part's process (largest of it and the children it "
            "waited for; per-case figures are in the parts' sections).\n\n"
            + table(["part", "command", "status", "seconds", "peak RSS MB", "uptime before", "uptime after"], rows))
    write_section("run-all", text)
    print("\n" + text)
    return 0 if all(r[2] == "ok" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
