"""How much Points as Tori and its k-nearest-neighbour anchor gain from a second thread (issue 17, goal 5).

    PYTHONPATH=src python3 bench/bench_tori_threads.py [--points 50000] [--queries 30000]

Times ``PointsAsTori(P, N).signed_distance(Q)`` at 1 and 2 numba threads and
``cKDTree(P).query(Q, k=64, workers=1 / -1)`` on the same queries (half uniform in the padded box, half
near the surface), medians of 5, on elephant.off resampled. A process that uses both cores well loses more
when two busy processes take them away; this prints the machine, the load and each speed-up, so the
loaded / idle ratio of bench_tori.py can be read against it.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import data_dir, machine  # noqa: E402
from load import uptime  # noqa: E402


def _median_rate(f, n, repeat=5):
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return n / float(np.median(ts))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=50000)
    ap.add_argument("--queries", type=int, default=30000)
    args = ap.parse_args()
    import numba
    import trimesh
    from scipy.spatial import cKDTree

    import gsdf

    V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "elephant.off"))
    mesh = trimesh.Trimesh(V, F, process=False)
    P, fi = trimesh.sample.sample_surface(mesh, args.points, seed=0)
    N = mesh.face_normals[fi]
    rng = np.random.default_rng(0)
    lo, hi = P.min(0), P.max(0)
    pad = 0.1 * np.linalg.norm(hi - lo)
    h = args.queries // 2
    Q = np.vstack([rng.uniform(lo - pad, hi + pad, (args.queries - h, 3)),
                   P[rng.integers(0, len(P), h)] + 0.01 * pad * rng.standard_normal((h, 3))])
    tree = cKDTree(P)
    pat = gsdf.PointsAsTori(P, N)
    pat.signed_distance(Q)  # kernels loaded outside the timings
    print(f"machine: {machine()}; {uptime()}")
    knn = {w: _median_rate(lambda: tree.query(Q, k=64, workers=w), len(Q)) for w in (1, -1)}
    rates = {}
    for th in (1, 2):
        numba.set_num_threads(min(th, numba.config.NUMBA_NUM_THREADS))
        rates[th] = _median_rate(lambda: pat.signed_distance(Q), len(Q))
    print(f"cKDTree k=64 queries/s: workers=1 {knn[1]:.3g}, workers=-1 {knn[-1]:.3g} "
          f"(second worker: {knn[-1] / knn[1]:.2f}x)")
    print(f"PointsAsTori queries/s: 1 thread {rates[1]:.3g}, 2 threads {rates[2]:.3g} "
          f"(second thread: {rates[2] / rates[1]:.2f}x)")
    print(f"end: {uptime()}")


if __name__ == "__main__":
    main()
