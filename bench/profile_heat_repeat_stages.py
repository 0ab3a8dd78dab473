"""Per-stage wall and CPU time of the surface signed heat method's *repeated* solve, idle vs two busy processes.

Issue 17 goal 5 asks that gsdf/potpourri3d ratios under load stay within 1.25× of the idle ones. This looks for a
stage of the repeated ``compute_distance`` (step I back-substitution, step II gather, divergence, step III
Dirichlet solve) whose CPU time grows under bench/load.py's BusyLoad(2), i.e. one that waits or thrashes rather
than just sharing the cores: per mesh, one warmed-up solver of each library, ``R`` rounds alternating idle /
loaded (order flipping per round), each round a batch ≥ 0.2 s of repeated calls per library; per stage the
median over rounds of the per-call wall and CPU time (stage timers of profile_heat_surface_load.instrument,
inclusive of nested stages). The numba thread count (``NT``, default 2) is set with numba.set_num_threads; the
surface path has no numba parallel kernel, so it should not matter.

    NT=1 R=7 PYTHONPATH=src /work/anchors/bin/python bench/profile_heat_repeat_stages.py cow.off,shm:fish-unsigned.obj

Prints only (no RESULTS section).
"""

from __future__ import annotations

import os
import sys
import time
from collections import defaultdict

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import profile_heat_surface_load as P  # noqa: E402
from common import data_dir  # noqa: E402
from load import BusyLoad, uptime  # noqa: E402

import bench_heat_surface as bhs  # noqa: E402


def batch(fn, min_s=0.2):
    """(wall, CPU, {stage: (wall, CPU)}) per call of ``fn`` over a batch of ≥ ``min_s`` s and ≥ 3 calls."""
    P.REC.clear()
    k, c0, t0 = 0, time.process_time(), time.perf_counter()
    while True:
        fn()
        k += 1
        t = time.perf_counter() - t0
        if t >= min_s and k >= 3:
            break
    c = time.process_time() - c0
    st = {n: np.sum(v, axis=0)[:2] / k for n, v in P.REC.items()}
    P.REC.clear()
    return t / k, c / k, st


def main():
    import numba
    import potpourri3d as pp3d

    from gsdf.heat import SurfaceSignedHeatSolver

    P.instrument()
    numba.set_num_threads(int(os.environ.get("NT", "2")))
    rounds = int(os.environ.get("R", "5"))
    meshes = sys.argv[1].split(",") if len(sys.argv) > 1 else ["ChineseDragon-10kv.off", "turbine.off",
                                                                "shm:fish-unsigned.obj"]
    print("start", uptime(), "numba threads", numba.get_num_threads(), flush=True)
    for name in meshes:
        path = os.path.join(bhs.SHM_DATA, name[4:]) if name.startswith("shm:") else \
            os.path.join(data_dir(), "meshes", name)
        V, F, loops = bhs._speed_case(path)
        ppl = [[(int(v), []) for v in c] for c in loops]
        g = SurfaceSignedHeatSolver(V, F)
        g.compute_distance(loops)
        p = pp3d.MeshSignedHeatSolver(V, F)
        p.compute_distance(ppl)
        res = defaultdict(list)
        for r in range(rounds):
            for lab in (("idle", "load") if r % 2 == 0 else ("load", "idle")):
                with BusyLoad(2 if lab == "load" else 0):
                    res[lab, "g"].append(batch(lambda: g.compute_distance(loops)))
                    res[lab, "p"].append(batch(lambda: p.compute_distance(ppl)))

        def med(lab, lib, i):
            return np.median([x[i] for x in res[lab, lib]])

        print(f"== {name} n={len(V)}  {uptime()}")
        for lib, label in (("g", "gsdf"), ("p", "pp3d")):
            wi, wl, ci, cl = med("idle", lib, 0), med("load", lib, 0), med("idle", lib, 1), med("load", lib, 1)
            print(f"{label}: wall ms {wi*1e3:.2f}/{wl*1e3:.2f} x{wl/wi:.2f}  cpu ms {ci*1e3:.2f}/{cl*1e3:.2f} "
                  f"x{cl/ci:.2f}")
        ri, rl = med("idle", "g", 0) / med("idle", "p", 0), med("load", "g", 0) / med("load", "p", 0)
        print(f"ratio gsdf/pp3d idle {ri:.3f} loaded {rl:.3f} -> loaded/idle {rl / ri:.2f}")
        for k in res["idle", "g"][0][2]:
            wi = np.median([x[2][k][0] for x in res["idle", "g"]])
            wl = np.median([x[2][k][0] for x in res["load", "g"]])
            ci = np.median([x[2][k][1] for x in res["idle", "g"]])
            cl = np.median([x[2][k][1] for x in res["load", "g"]])
            if wi > 5e-5:
                print(f"   {k:28s} wall ms {wi*1e3:7.3f}/{wl*1e3:7.3f} x{wl/wi:.2f} cpu ms {ci*1e3:7.3f}/"
                      f"{cl*1e3:7.3f} x{cl/max(ci, 1e-9):.2f}", flush=True)
    print("end", uptime())


if __name__ == "__main__":
    main()
