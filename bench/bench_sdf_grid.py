"""Signed distance on a grid: gsdf (two source trees, e.g. before / after a change) against pysdf and mesh2sdf.

    PYTHONPATH=src /work/anchors/bin/python bench/bench_sdf_grid.py --before /work/main/src --after src \\
        --meshes bunny00-soup,bunny00,fandisk,elephant-with-holes,camel --res 64,128 --reps 3

Each gsdf tree runs in its own worker process (``PYTHONPATH=<tree>``) that times
``gsdf.signed_distance_grid(V, F, resolution=grid)`` (tree build, winding numbers and distances) on the n^3 grid
over the padded box made cubic (bench_sdf_peers.cube_grid); pysdf (build + query of every node, float32) and
mesh2sdf (``mesh2sdf.compute(..., fix=False)``) run in this process. Every (mesh, resolution) runs every tool
``--reps`` times, the order rotating between repetitions (interleaved), and prints the medians, the ratios and
the load (``uptime``). The two gsdf results are compared: max | |s_before| - |s_after| | / max |s| and the
number of nodes whose sign differs (with min |w - 1/2| there, w the fast winding number).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
if "GSDF_CGAL_DATA" not in os.environ and os.path.isdir("/work/cgal/data/meshes"):
    os.environ["GSDF_CGAL_DATA"] = "/work/cgal/data"

RECIPES = {"bunny00-soup": "soup:bunny00.off", "loop2": "loop2:bunny00.off"}

WORKER = r"""
import sys, time, json, numpy as np
sys.path.insert(0, {bench!r})
import gsdf
from bench_sdf_peers import load_mesh, cube_grid
cache = {{}}
for line in sys.stdin:
    recipe, n, out = line.split()
    n = int(n)
    if recipe not in cache:
        V, F, _, _ = load_mesh(recipe)
        cache[recipe] = (V, F)
        gsdf.signed_distance_grid(V, F, resolution=cube_grid(V, 24))  # compile / load kernels, untimed
        gsdf.signed_distance_grid(V, F, resolution=cube_grid(V, 24))
    V, F = cache[recipe]
    g = cube_grid(V, n)
    t0 = time.perf_counter()
    S = gsdf.signed_distance_grid(V, F, resolution=g)
    t = time.perf_counter() - t0
    if out != "-":
        np.save(out, S.values.ravel())
    print(json.dumps({{"t": t}}), flush=True)
"""


class Worker:
    def __init__(self, src):
        env = dict(os.environ, PYTHONPATH=os.path.abspath(src))
        code = WORKER.format(bench=os.path.dirname(os.path.abspath(__file__)))
        self.p = subprocess.Popen([sys.executable, "-u", "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True, env=env)

    def run(self, recipe, n, out="-"):
        self.p.stdin.write(f"{recipe} {n} {out}\n")
        self.p.stdin.flush()
        line = self.p.stdout.readline()
        if not line:
            raise RuntimeError("worker died")
        return json.loads(line)["t"]

    def close(self):
        self.p.stdin.close()
        self.p.wait()


def uptime():
    with open("/proc/loadavg") as f:
        return "load " + " ".join(f.read().split()[:3])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", default="/work/main/src")
    ap.add_argument("--after", default="src")
    ap.add_argument("--meshes", default="bunny00-soup,bunny00,fandisk,elephant-with-holes,camel")
    ap.add_argument("--res", default="64,128")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--tools", default="before,after,pysdf,mesh2sdf")
    ap.add_argument("--out", default="/tmp/bench_sdf_grid")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    from bench_sdf_peers import cube_grid, load_mesh

    tools = a.tools.split(",")
    workers = {t: Worker(getattr(a, t)) for t in ("before", "after") if t in tools}
    print(f"# {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC, {os.cpu_count()} CPUs, {uptime()}", flush=True)
    print("# " + " ".join(sys.argv), flush=True)
    rows = []
    for name in a.meshes.split(","):
        recipe = RECIPES.get(name, name + ".off")
        V, F, _, _ = load_mesh(recipe)
        for n in (int(x) for x in a.res.split(",")):
            g = cube_grid(V, n)
            P32 = np.ascontiguousarray(g.points(), np.float32)
            V32, F32 = np.ascontiguousarray(V, np.float32), np.ascontiguousarray(F, np.uint32)
            lo, _ = g.box
            h = float(g.spacing[0])
            Vm = -1.0 + (V - lo) / (h * n / 2.0)

            def run(tool, first):
                if tool in workers:
                    out = os.path.join(a.out, f"{tool}_{name}_{n}.npy") if first else "-"
                    return workers[tool].run(recipe, n, out)
                t0 = time.perf_counter()
                if tool == "pysdf":
                    import pysdf

                    pysdf.SDF(V32, F32)(P32)
                elif tool == "mesh2sdf":
                    import mesh2sdf

                    mesh2sdf.compute(Vm, F, n, fix=False, level=2.0 / n)
                return time.perf_counter() - t0

            for t in tools:  # warm-up (workers compile, peers load)
                if t in workers:
                    run(t, False) if n > 200 else None
            times = {t: [] for t in tools}
            for r in range(a.reps):
                order = tools[r % len(tools):] + tools[: r % len(tools)]
                for t in order:
                    times[t].append(run(t, r == 0))
            med = {t: float(np.median(v)) for t, v in times.items()}
            acc = ""
            if "before" in workers and "after" in workers:
                sb = np.load(os.path.join(a.out, f"before_{name}_{n}.npy"))
                sa = np.load(os.path.join(a.out, f"after_{name}_{n}.npy"))
                derr = float(np.max(np.abs(np.abs(sb) - np.abs(sa))) / np.max(np.abs(sb)))
                ds = int(np.sum((sb < 0) != (sa < 0)))
                acc = f" | after vs before: dist {derr:.1e}, sign diffs {ds}"
            ref = med.get("after", med.get("before"))
            ratios = " ".join(f"{t}/after={med[t] / ref:.2f}" for t in tools if t != "after" and "after" in med)
            print(f"{name:20s} {n:4d}^3 F={len(F):6d} " + " ".join(f"{t} {med[t]:.3f}" for t in tools)
                  + f" | {ratios}{acc} | {uptime()}", flush=True)
            rows.append(dict(mesh=name, n=n, faces=int(len(F)), times=times, median=med))
    for w in workers.values():
        w.close()
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
