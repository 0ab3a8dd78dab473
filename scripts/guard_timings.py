"""The size guard (docs/decisions.md, "Robustness"): what one unit of each kind of work costs on this machine, and
how fast the guard refuses the sizes that used to run for minutes.

    python scripts/guard_timings.py [--queries 1000000]

Part 1 measures single-thread CPU seconds per item (process time, GSDF_NUM_THREADS=1 advised): a fast winding
number query and a triangle distance query on a 396-triangle sphere and a 40k-triangle sphere, and a node of
``slice_contours`` with a fast winding number — the figures behind ``SECONDS_PER_QUERY`` and ``SECONDS_PER_NODE``
in gsdf/_memory.py. Part 2 times the refusals of 10^9 queries, a 10^12-voxel grid and ``gsdf slice --resolution
8192`` (each in a fresh process, with the default limits; the time of the call that refuses, and of the whole
process with its imports).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

import numpy as np


def sphere(n):
    from scipy.spatial import ConvexHull

    i = np.arange(n) + 0.5
    ph, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    F = ConvexHull(P).simplices.astype(np.int64)
    flip = np.einsum("ij,ij->i", np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]), P[F[:, 0]]) < 0
    F[flip] = F[flip][:, ::-1]
    return P, F


def per_item(n_queries: int) -> None:
    import gsdf

    rng = np.random.default_rng(0)
    Q = rng.uniform(-1.2, 1.2, (n_queries, 3))
    for n in (200, 20000):
        V, F = sphere(n)
        fwn, td = gsdf.FastWindingNumber(V, F), gsdf.TriangleDistance(V, F)
        fwn(Q[:100]), td.query(Q[:100])  # compile / load the kernels
        for name, fn in (("fast winding number", fwn), ("triangle distance", lambda q: td.query(q))):
            t = time.process_time()
            fn(Q)
            print(f"{name:22s} {len(F):6d} triangles: {1e6 * (time.process_time() - t) / len(Q):.2f} µs CPU/query")
    V, F = sphere(200)
    fwn = gsdf.FastWindingNumber(V, F)
    r = int(np.sqrt(n_queries / 2))
    t = time.process_time()
    gsdf.slice_contours(fwn, [-0.3, 0.3], [-1.1] * 3, [1.1] * 3, resolution=r)
    print(f"slice_contours node ({r}x{r} x 2 slices): {1e6 * (time.process_time() - t) / (2 * r * r):.2f} µs CPU")


REFUSALS = {
    "10^9 queries": "V, F = sphere(200); Q = np.broadcast_to(np.array([0.1, 0.2, 0.3]), (10**9, 3))\n"
                    "fn = gsdf.fast_winding_number\nt = time.perf_counter()\ntry:\n    fn(V, F, Q)\n"
                    "except ValueError as e:\n    print(f'{time.perf_counter() - t:.4f} s: {e}')",
    "10^12 voxels": "B = np.broadcast_to(np.array(True), (10000, 10000, 10000))\n"
                    "fn = gsdf.VoxelSurfaceSignedHeatSolver\nt = time.perf_counter()\ntry:\n    fn(B)\n"
                    "except ValueError as e:\n    print(f'{time.perf_counter() - t:.4f} s: {e}')",
}


def _cpu() -> float:
    import resource

    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def refusals() -> None:
    import os
    import tempfile

    head = "import time, numpy as np, gsdf\nfrom scripts.guard_timings import sphere\n"
    for name, body in REFUSALS.items():
        t, c = time.perf_counter(), _cpu()
        out = subprocess.run([sys.executable, "-c", head + body], capture_output=True, text=True,
                             cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        print(f"{name}: the call {(out.stdout or out.stderr).strip()[:160]} (whole process with imports: "
              f"{time.perf_counter() - t:.1f} s wall, {_cpu() - c:.2f} s CPU)")
    d = tempfile.mkdtemp()
    V, F = sphere(200)
    import gsdf

    gsdf.write_mesh(os.path.join(d, "s.off"), V, F)
    t, c = time.perf_counter(), _cpu()
    out = subprocess.run([sys.executable, "-c", "from gsdf.cli.main import main; main()", "slice",
                          os.path.join(d, "s.off"), "-o", os.path.join(d, "s.svg"), "-q", "--resolution", "8192"],
                         capture_output=True, text=True)
    print(f"gsdf slice --resolution 8192: exit {out.returncode} (whole process: {time.perf_counter() - t:.1f} s "
          f"wall, {_cpu() - c:.2f} s CPU): {out.stderr.strip()[:160]}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--queries", type=int, default=1_000_000)
    ap.add_argument("--skip-costs", action="store_true")
    a = ap.parse_args()
    if not a.skip_costs:
        per_item(a.queries)
    refusals()
