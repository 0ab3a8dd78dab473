"""Occupancy (inside / outside) at random points: gsdf.inside against the tree walk FastWindingNumber(V, F)(Q) > 0.5
and Open3D's RaycastingScene.compute_occupancy, interleaved in one process, build + query, medians.

Points uniform in the padded box (bounding box + 0.1 x diagonal). Prints per mesh and point count the three
times, the ratios to Open3D, the number of queries where gsdf.inside differs from the walk and, for the soup
(bench_sdf_peers.soup_of of bunny00: 10 % faces deleted, 5 % duplicated, 10 % flipped), the wrong-sign rate
against the intact mesh. Open3D gets its float32 tensors outside the timed call (as in bench_sdf_peers.py).

    PYTHONPATH=src /work/anchors/bin/python bench/bench_occupancy.py --meshes bunny00-soup,bunny00,fandisk,camel
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

import gsdf

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_sdf_peers import MESHES, load_mesh

DEFAULT = "bunny00-soup,bunny00,fandisk,elephant-with-holes,camel,armadillo"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default=DEFAULT, help="names of bench_sdf_peers.MESHES, or CGAL .off files")
    ap.add_argument("--points", default="1e5,1e6")
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    import open3d as o3d

    recipes = {name: recipe for name, recipe, _ in MESHES}
    print(f"load {os.getloadavg()}", flush=True)
    print("| mesh | faces | points | inside s | walk s | open3d s | inside / open3d | walk / open3d | differ | wrong vs intact |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in args.meshes.split(","):
        V, F, V0, F0 = load_mesh(recipes.get(name, name if name.endswith(".off") else name + ".off"))
        lo, hi = V.min(0), V.max(0)
        pad = 0.1 * np.linalg.norm(hi - lo)
        for n in (int(float(x)) for x in args.points.split(",")):
            X = np.random.default_rng(1).uniform(lo - pad, hi + pad, (n, 3))
            V32, F32 = o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(F.astype(np.uint32))
            P = o3d.core.Tensor(X.astype(np.float32))

            def o3docc(V32=V32, F32=F32, P=P):
                s = o3d.t.geometry.RaycastingScene()
                s.add_triangles(V32, F32)
                return s.compute_occupancy(P).numpy() > 0.5

            tools = {"inside": lambda V=V, F=F, X=X: gsdf.inside(V, F, X),
                     "walk": lambda V=V, F=F, X=X: gsdf.FastWindingNumber(V, F)(X) > 0.5, "open3d": o3docc}
            for f in tools.values():  # compile / load every kernel first
                f()
            times = {k: [] for k in tools}
            res = {}
            for _ in range(args.reps):
                for k, f in tools.items():
                    t0 = time.perf_counter()
                    res[k] = f()
                    times[k].append(time.perf_counter() - t0)
            m = {k: float(np.median(v)) for k, v in times.items()}
            wrong = "—"
            if F0 is not F:
                ref = gsdf.FastWindingNumber(V0, F0)(X) > 0.5
                wrong = f"{100 * float((res['inside'] != ref).mean()):.3f} %"
            print(f"| {name} | {len(F)} | {n:.0e} | {m['inside']:.4f} | {m['walk']:.4f} | {m['open3d']:.4f} | "
                  f"{m['inside'] / m['open3d']:.2f} | {m['walk'] / m['open3d']:.2f} | "
                  f"{int((res['inside'] != res['walk']).sum())} | {wrong} |", flush=True)
    print(f"load {os.getloadavg()}")


if __name__ == "__main__":
    main()
