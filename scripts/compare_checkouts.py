"""Run the same workloads on two checkouts of gsdf side by side: outputs compared, times interleaved.

    python scripts/compare_checkouts.py OLD_SRC NEW_SRC [--rounds 5] [--only a,b]

Each workload runs in its own process per checkout (``PYTHONPATH=<src>``, numba caches kept apart), once to
warm the compilation cache, then ``--rounds`` times alternating old / new, timing the second of two runs in each
process (``--cold``: the first, kernels loaded from the cache inside the clock); the table prints the median wall
time of each side, their ratio, and the largest relative difference of the outputs (0 = bit-identical). Only the
public API (``gsdf.<name>`` and the options both checkouts accept) is called, so the two layouts can differ.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile

import numpy as np

#: name -> code; the code defines ``out`` (a dict of arrays) and ``seconds`` (the timed part).
WORKLOADS = {
    "fast winding (soup, 2e5 queries)": """
V, F = shapes["soup"]
Q = rng.uniform(-1.3, 1.3, (200_000, 3))
t = time.perf_counter(); w = gsdf.fast_winding_number(V, F, Q); seconds = time.perf_counter() - t
out = {"w": w}
""",
    "signed distance (sphere, 1e5)": """
V, F = shapes["sphere"]
Q = rng.uniform(-1.3, 1.3, (100_000, 3))
t = time.perf_counter(); s = gsdf.signed_distance(V, F, Q); seconds = time.perf_counter() - t
out = {"s": s}
""",
    "signed_distance_grid (soup, 64)": """
V, F = shapes["soup"]
lo, hi = V.min(0) - 0.2, V.max(0) + 0.2
grid = gsdf.Grid.fit((lo, hi), 64) if hasattr(gsdf, "Grid") else None
t = time.perf_counter()
S = gsdf.signed_distance_grid(V, F, resolution=grid) if grid is not None else \
    gsdf.signed_distance_grid(V, F, resolution=64, bbox_min=lo, bbox_max=hi)
seconds = time.perf_counter() - t
out = {"S": np.asarray(S.values)}
""",
    "surface signed heat (sphere, curve)": """
V, F = shapes["sphere"]
ring = np.flatnonzero((V[:, 2] > 0) & (V[:, 2] < 0.05))        # one row of the sphere's vertices: joined by edges
ring = ring[np.argsort(np.arctan2(V[ring, 1], V[ring, 0]))][:30]  # an open arc of it
t = time.perf_counter()
solver = gsdf.SurfaceSignedHeatSolver(V, F)
phi = solver.compute_distance([gsdf.Curve(ring, signed=False)], points=[int(ring[-1])])
seconds = time.perf_counter() - t
out = {"phi": phi}
""",
    "volume signed heat (soup, grid 32)": """
V, F = shapes["soup"]
t = time.perf_counter()
f = gsdf.signed_heat_volume(mesh=(V, F), resolution=32)
seconds = time.perf_counter() - t
out = {"phi": np.asarray(f.values)}
""",
    "Points as Tori (cloud, 5e4 queries)": """
P, N = shapes["cloud"]
Q = rng.uniform(-1.2, 1.2, (50_000, 3))
t = time.perf_counter(); pat = gsdf.PointsAsTori(P, N); d = pat.signed_distance(Q); seconds = time.perf_counter() - t
out = {"d": d}
""",
    "surface winding numbers (torus, broken meridian)": """
V, F, idx = shapes["torus"]
t = time.perf_counter()
r = gsdf.surface_winding_number(V, F, [idx[5, :17], idx[30, 3:15]], method="lp")
seconds = time.perf_counter() - t
out = {"labels": np.asarray(r.face_labels), "u": np.asarray(r.u)}
""",
    "reconstruction (ellipsoid, 600 points)": """
P = shapes["ellipsoid"]
t = time.perf_counter(); V2, F2 = gsdf.reconstruct_simply_connected(P); seconds = time.perf_counter() - t
out = {"V": V2, "F": F2.astype(np.float64)}
""",
    # the peers' workloads and dataset-scale jobs on real meshes (skipped without the CGAL data)
    "build (bunny00, 75k faces)": """
V, F = cgal("bunny00.off")
t = time.perf_counter(); s = gsdf.signed_distance(V, F, V[:1] + 1.0); seconds = time.perf_counter() - t
out = {"s": s}
""",
    "signed distance (bunny00, 1e6)": """
V, F = cgal("bunny00.off")
Q = box_points(V, 1_000_000)
t = time.perf_counter(); s = gsdf.signed_distance(V, F, Q); seconds = time.perf_counter() - t
out = {"s": s}
""",
    "occupancy (bunny00 soup, 1e6)": """
V, F = soup(*cgal("bunny00.off"))
Q = box_points(V, 1_000_000)
t = time.perf_counter(); inside = gsdf.FastWindingNumber(V, F)(Q) > 0.5; seconds = time.perf_counter() - t
out = {"inside": inside.astype(np.float64)}
""",
    "occupancy (fandisk, 1e5)": """
V, F = cgal("fandisk.off")
Q = box_points(V, 100_000)
t = time.perf_counter(); inside = gsdf.FastWindingNumber(V, F)(Q) > 0.5; seconds = time.perf_counter() - t
out = {"inside": inside.astype(np.float64)}
""",
    "inside/outside, the library's fastest call (bunny00, 1e6)": """
V, F = cgal("bunny00.off")
Q = box_points(V, 1_000_000)
fastest = getattr(gsdf, "inside", None) or (lambda V, F, Q: gsdf.FastWindingNumber(V, F)(Q) > 0.5)
t = time.perf_counter(); inside = fastest(V, F, Q); seconds = time.perf_counter() - t
out = {"inside": inside.astype(np.float64)}
""",
    "inside/outside, the library's fastest call (fandisk, 1e5)": """
V, F = cgal("fandisk.off")
Q = box_points(V, 100_000)
fastest = getattr(gsdf, "inside", None) or (lambda V, F, Q: gsdf.FastWindingNumber(V, F)(Q) > 0.5)
t = time.perf_counter(); inside = fastest(V, F, Q); seconds = time.perf_counter() - t
out = {"inside": inside.astype(np.float64)}
""",
    "signed_distance_grid (bunny00, 128)": """
V, F = cgal("bunny00.off")
t = time.perf_counter(); S = gsdf.signed_distance_grid(V, F, resolution=128); seconds = time.perf_counter() - t
out = {"S": np.asarray(S.values)}
""",
    "batch sdf-samples (6 meshes, 250k)": """
import tempfile, glob
with tempfile.TemporaryDirectory() as d:
    t = time.perf_counter()
    gsdf.run_batch(batch_inputs(), "sdf-samples", d, {"n_samples": 250_000}, workers=2)
    seconds = time.perf_counter() - t
    out = {os.path.basename(f): np.load(f)["sdf"] for f in sorted(glob.glob(os.path.join(d, "**", "*.npz"), recursive=True))}
""",
    "batch sdf-grid (6 meshes, 128^3)": """
import tempfile, glob
with tempfile.TemporaryDirectory() as d:
    t = time.perf_counter()
    gsdf.run_batch(batch_inputs(), "sdf-grid", d, {"resolution": 128}, workers=2)
    seconds = time.perf_counter() - t
    out = {os.path.basename(f): np.load(f)["sdf"] for f in sorted(glob.glob(os.path.join(d, "**", "*.npz"), recursive=True))}
""",
}

PRELUDE = r'''
import os, sys, time, json
import numpy as np
import gsdf
rng = np.random.default_rng(0)

def _sphere(n=40):
    u, v = np.meshgrid(np.linspace(0, np.pi, n), np.linspace(0, 2 * np.pi, 2 * n, endpoint=False), indexing="ij")
    V = np.stack([np.sin(u) * np.cos(v), np.sin(u) * np.sin(v), np.cos(u)], -1).reshape(-1, 3)
    idx = np.arange(n * 2 * n).reshape(n, 2 * n)
    F = []
    for i in range(n - 1):
        for j in range(2 * n):
            a, b, c, d = idx[i, j], idx[i, (j + 1) % (2 * n)], idx[i + 1, j], idx[i + 1, (j + 1) % (2 * n)]
            F += [[a, c, b], [b, c, d]]
    V, F = np.asarray(V), np.asarray(F)
    # weld the poles
    key = np.round(V, 9)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    F = inv.ravel()[F]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]
    return V[first], F

def _torus(nu=48, nv=24, R=1.0, r=0.4):
    u = 2 * np.pi * np.arange(nu) / nu
    v = 2 * np.pi * np.arange(nv) / nv
    U, W = np.meshgrid(u, v, indexing="ij")
    V = np.stack([(R + r * np.cos(W)) * np.cos(U), (R + r * np.cos(W)) * np.sin(U), r * np.sin(W)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = i * nv + j; b = ((i + 1) % nu) * nv + j; c = ((i + 1) % nu) * nv + (j + 1) % nv; d = i * nv + (j + 1) % nv
    F = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return V, F, a

Vs, Fs = _sphere()
g = np.random.default_rng(1)
keep = g.random(len(Fs)) > 0.1
Fsoup = np.concatenate([Fs[keep], Fs[keep][g.random(keep.sum()) < 0.05]])
flip = g.random(len(Fsoup)) < 0.1
Fsoup[flip] = Fsoup[flip][:, ::-1]
Pc = g.normal(size=(20_000, 3)); Pc /= np.linalg.norm(Pc, axis=1, keepdims=True)
Pe = g.normal(size=(600, 3)) * [1.0, 0.7, 0.5]; Pe /= np.linalg.norm(Pe / [1.0, 0.7, 0.5], axis=1)[:, None]
CGAL = os.path.join(os.environ.get("GSDF_CGAL_DATA", "/work/cgal/data"), "meshes")

def cgal(name):
    return gsdf.read_mesh(os.path.join(CGAL, name))

def soup(V, F, seed=0):  # 10 % of the faces deleted, 5 % duplicated, 10 % flipped (bench/bench_sdf_peers.py)
    r = np.random.default_rng(seed)
    F = F[r.random(len(F)) >= 0.10]
    F = np.vstack([F, F[r.random(len(F)) < 0.05]])
    f = r.random(len(F)) < 0.10
    F[f] = F[f][:, ::-1]
    return V, np.ascontiguousarray(F)

def box_points(V, n):  # uniform in the bounding box grown by 0.1 of its diagonal
    lo, hi = V.min(0), V.max(0)
    pad = 0.1 * np.linalg.norm(hi - lo)
    return np.random.default_rng(2).uniform(lo - pad, hi + pad, (n, 3))

def batch_inputs():
    return [os.path.join(CGAL, f) for f in ("bunny00.off", "camel.off", "elephant-with-holes.off", "fandisk.off",
                                            "holes.off", "mech-holes-shark.off")]

shapes = {"sphere": (Vs, Fs), "soup": (Vs, Fsoup), "cloud": (Pc, Pc.copy()), "torus": _torus(), "ellipsoid": Pe}
'''

EPILOGUE = r'''
np.savez(sys.argv[1], **out)
print(json.dumps({"seconds": seconds}))
'''


def run(src, code, path, cache, cold=False):
    env = dict(os.environ, PYTHONPATH=src, NUMBA_CACHE_DIR=cache, PYTHONDONTWRITEBYTECODE="1")
    body = code if cold else code + code        # warm: the second run in the process is timed
    r = subprocess.run([sys.executable, "-c", PRELUDE + body + EPILOGUE, path], env=env, capture_output=True,
                       text=True)
    if r.returncode:
        raise RuntimeError(r.stderr[-2000:])
    return json.loads(r.stdout.strip().splitlines()[-1])["seconds"]


def rel_diff(a, b):
    if a.shape != b.shape:
        return float("inf")
    if a.size == 0:
        return 0.0
    scale = max(float(np.abs(a).max()), 1e-300)
    return float(np.abs(a - b).max()) / scale


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--only", default=None, help="comma-separated substrings of workload names")
    ap.add_argument("--cold", action="store_true",
                    help="time the first run in each process (kernels loaded from the cache inside the clock)")
    args = ap.parse_args(argv)
    names = [n for n in WORKLOADS if not args.only or any(s in n for s in args.only.split(","))]
    tmp = tempfile.mkdtemp(prefix="gsdf-compare-")
    caches = {side: os.path.join(tmp, f"numba-{side}") for side in ("old", "new")}
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"load {os.getloadavg()[0]:.1f}; rounds {args.rounds}; {'cold' if args.cold else 'warm'} calls")
    print(f"| workload | old s (median) | new s (median) | new / old | max relative output difference |")
    print("|---|---|---|---|---|")
    for name in names:
        code = WORKLOADS[name]
        paths = {side: os.path.join(tmp, f"{side}.npz") for side in ("old", "new")}
        for side, src in (("old", args.old), ("new", args.new)):
            run(src, code, paths[side], caches[side])            # compile / warm
        times = {"old": [], "new": []}
        for _ in range(args.rounds):
            for side, src in (("old", args.old), ("new", args.new)):
                times[side].append(run(src, code, paths[side], caches[side], args.cold))
        a, b = np.load(paths["old"]), np.load(paths["new"])
        diff = max(rel_diff(a[k], b[k]) for k in a.files) if sorted(a.files) == sorted(b.files) else float("inf")
        to, tn = statistics.median(times["old"]), statistics.median(times["new"])
        print(f"| {name} | {to:.3f} | {tn:.3f} | {tn / to:.2f} | {diff:.1e} |", flush=True)
    print(f"load at the end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
