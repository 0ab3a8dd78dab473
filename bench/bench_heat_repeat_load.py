"""Why short repeated solves degrade more than potpourri3d's under two busy processes (issue 17, goal 5).

For a few meshes of ``bench_heat_surface.py --speed``: one solver of each library (built and warmed up), then
``--calls`` repeated ``compute_distance`` calls each, idle and with two busy processes (bench/load.py), and per
call the wall time, the CPU time, and the involuntary / voluntary context switches of the process
(getrusage). A call that blocks (waiting for a worker thread, a lock, I/O) shows voluntary switches; a call
that is only preempted shows involuntary ones, and its wall time is its CPU time plus the waits for the
other processes' time slices. Printed per library: median and mean wall, median CPU, the share of calls that
were preempted, and the mean of a batch of calls lasting ≥ 0.1 s.

Run: ``PYTHONPATH=src /work/anchors/bin/python bench/bench_heat_repeat_load.py [--meshes a.off,b.off]
[--calls 60]`` (writes RESULTS section "heat-repeat-load" unless --no-write).
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import batch_mean, data_dir, machine, table, write_section  # noqa: E402
from load import BusyLoad  # noqa: E402

import bench_heat_surface as bhs  # noqa: E402

DEFAULT = ["cow.off", "mech-holes-shark.off", "fandisk.off", "camel.off", "bunny00.off"]


def per_call(fn, calls):
    """(wall, cpu, involuntary switches, voluntary switches) per call, arrays of length ``calls``."""
    out = np.empty((calls, 4))
    for k in range(calls):
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        c0, t0 = time.process_time(), time.perf_counter()
        fn()
        t1, c1 = time.perf_counter(), time.process_time()
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        out[k] = (t1 - t0, c1 - c0, r1.ru_nivcsw - r0.ru_nivcsw, r1.ru_nvcsw - r0.ru_nvcsw)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default=",".join(DEFAULT))
    ap.add_argument("--calls", type=int, default=60)
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    import potpourri3d as pp3d

    from gsdf.heat import SurfaceSignedHeatSolver

    start = os.popen("uptime").read().strip()
    rows = []
    for name in args.meshes.split(","):
        path = os.path.join(bhs.SHM_DATA, name[4:]) if name.startswith("shm:") else \
            os.path.join(data_dir(), "meshes", name)
        V, F, loops = bhs._speed_case(path)
        pp_loops = [[(int(v), []) for v in c] for c in loops]
        g = SurfaceSignedHeatSolver(V, F)
        p = pp3d.MeshSignedHeatSolver(V, F)
        fns = {"gsdf": lambda: g.compute_distance(loops), "pp3d": lambda: p.compute_distance(pp_loops)}
        for f in fns.values():
            f()
        res = {}
        for lab, nbusy in (("idle", 0), ("loaded", 2)):
            with BusyLoad(nbusy):
                for lib, f in fns.items():
                    d = per_call(f, args.calls)
                    res[lab, lib] = (np.median(d[:, 0]), d[:, 0].mean(), np.median(d[:, 1]), np.mean(d[:, 2] > 0),
                                     d[:, 3].mean(), batch_mean(f, min_calls=3))
        for lib in fns:
            i, l_ = res["idle", lib], res["loaded", lib]
            rows.append([name, lib] + [f"{i[0] * 1e3:.2f} / {l_[0] * 1e3:.2f}", f"{i[1] * 1e3:.2f} / {l_[1] * 1e3:.2f}",
                                       f"{i[2] * 1e3:.2f} / {l_[2] * 1e3:.2f}", f"{i[3]:.2f} / {l_[3]:.2f}",
                                       f"{i[4]:.2f} / {l_[4]:.2f}", f"{i[5] * 1e3:.2f} / {l_[5] * 1e3:.2f}",
                                       f"{l_[0] / i[0]:.2f}", f"{l_[5] / i[5]:.2f}"])
        for k in ("idle", "loaded"):
            a, b = res[k, "gsdf"], res[k, "pp3d"]
            rows.append([name, f"ratio gsdf/pp3d {k}", f"{a[0] / b[0]:.2f}", f"{a[1] / b[1]:.2f}", f"{a[2] / b[2]:.2f}",
                         "", "", f"{a[5] / b[5]:.2f}", "", ""])
        print(*rows[-4:], sep="\n", flush=True)
    hdr = ["mesh", "library", "median wall ms idle / loaded", "mean wall ms", "median CPU ms",
           "share of calls preempted", "voluntary switches per call", "batch (≥ 0.1 s) mean ms",
           "loaded / idle (median)", "loaded / idle (batch)"]
    text = (f"Machine: {machine()}; uptime at start: {start}; at end: {os.popen('uptime').read().strip()} (shared "
            f"machine: other helpers' jobs ran alongside). Command: `PYTHONPATH=src /work/anchors/bin/python "
            f"bench/bench_heat_repeat_load.py --calls {args.calls}`. {args.calls} repeated `compute_distance` calls "
            "per library and condition on one warmed-up solver (same curves as --speed); loaded = two busy "
            "processes (bench/load.py BusyLoad(2)).\n\n" + table(hdr, rows))
    print(text)
    if not args.no_write:
        write_section("heat-repeat-load", "## Surface signed heat: repeated solves under two busy processes, "
                      "per call (issue 17, goal 5)\n\n" + text)


if __name__ == "__main__":
    main()
