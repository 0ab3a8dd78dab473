"""Winding numbers: gsdf against libigl on the CGAL meshes and clouds, in one process run.

Run in a Python that has gsdf and the anchors (``../shared/tools/install-anchors VENV``):

    VENV/bin/python bench/bench_winding.py            # full run (~15 min on 2 cores)
    VENV/bin/python bench/bench_winding.py --quick    # fewer queries, no 100^3 voxel check

    VENV/bin/python bench/bench_winding.py --only triangles --load   # also under two busy processes

Parts (``--only``, default all), each writing its own section of bench/RESULTS.md:

* ``triangles`` ("winding-triangles"): exact and fast winding numbers of 13 CGAL meshes (scans, CAD, meshes with
  holes): RMS of the fast evaluation against the exact one, 100³ voxel misclassification, time of build + 10⁶
  queries against libigl (with ``--load``: also alternating idle / loaded rounds, common.alternating_rounds);
* ``points`` ("winding-points"): point clouds, gsdf's point areas given to both; point areas on sphere_20k
  against 4πr² (and the plain 3D k-NN rule);
* ``growth`` ("winding-growth"): build and per-query time against element count (icosphere meshes).

Speed is a ratio of medians of 3 runs in this process; accuracy is against exact winding numbers (gsdf's
hierarchical exact evaluation, cross-checked against igl.winding_number).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import alternating_rounds, command, data_dir, heading, machine, median_time, table, write_section  # noqa: E402
from load import uptime  # noqa: E402

import gsdf  # noqa: E402

# triangle inputs of different kinds: scans, CAD parts, soups / meshes with holes
MESHES = ["bunny00.off", "refined_elephant.off", "armadillo.off", "man.off", "ChineseDragon-10kv.off",   # scans
          "fandisk.off", "blade.off", "couplingdown.off", "cheese.off", "rotor.off",                     # CAD
          "holes.off", "elephant-with-holes.off", "mech-holes-shark.off"]                               # holes
CLOUDS = ["kitten.xyz", "oni.pwn", "sphere_20k_normal.xyz"]


#: Rounds of the loaded protocol (common.alternating_rounds).
LOAD_ROUNDS = 7

LOAD_NOTE = (" \"loaded\" columns: build + query of gsdf and libigl, each timed as the mean of a "
             f"batch of calls lasting ≥ 0.1 s, in {LOAD_ROUNDS} rounds alternating idle / loaded (two busy processes, "
             "bench/load.py, started and stopped per round; common.alternating_rounds); \"rounds: idle / loaded "
             "ratio\" = median over rounds of the per-round gsdf/igl ratio, \"loaded/idle ratio\" = their quotient "
             "(target ≤ 1.25); \"loaded: gsdf s / igl s\" = medians of the loaded batch means. The "
             "idle columns before them are medians of 3 single calls.")


def queries_in_box(X, n, rng, pad=0.1):
    lo, hi = X.min(0), X.max(0)
    return rng.uniform(lo - pad * (hi - lo), hi + pad * (hi - lo), (n, 3))


def voxel_centres(X, res=100, pad=0.05):
    lo, hi = X.min(0), X.max(0)
    lo, hi = lo - pad * (hi - lo), hi + pad * (hi - lo)
    axes = [lo[d] + (np.arange(res) + 0.5) * (hi[d] - lo[d]) / res for d in range(3)]
    G = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([g.ravel() for g in G])


def bench_triangles(igl, root, n_queries, voxels, rng, load=False):
    rows = []
    for name in MESHES:
        if not os.path.exists(os.path.join(root, "meshes", name)):
            print(f"skipping {name}: not in {root}/meshes", flush=True)
            continue
        V, F = gsdf.read_mesh(os.path.join(root, "meshes", name))
        Q = queries_in_box(V, n_queries, rng)
        Qa = Q[:10000]
        # accuracy against exact (ours hierarchical; cross-check with libigl's exact)
        exact = gsdf.ExactWindingNumber(V, F)(Qa)
        exact_igl = igl.winding_number(V, F, Qa)
        fast = gsdf.FastWindingNumber(V, F)(Qa)
        fast_igl = igl.fast_winding_number(V, F, Qa)
        rms = np.sqrt(np.mean((fast - exact) ** 2))
        rms_igl = np.sqrt(np.mean((fast_igl - exact) ** 2))
        # speed, 10^6 queries (build + query; libigl's call includes its own precompute)
        igl.fast_winding_number(V, F, Q[:10])
        t_pre, fwn = median_time(lambda: gsdf.FastWindingNumber(V, F))
        t_q, _ = median_time(lambda: fwn(Q))
        t_igl, _ = median_time(lambda: igl.fast_winding_number(V, F, Q))
        up = uptime()
        ratio = (t_pre + t_q) / t_igl
        load_cols = []
        if load:  # build + query idle and with two busy processes: alternating rounds of batches ≥ 0.1 s
            t = alternating_rounds({"gsdf": lambda: gsdf.FastWindingNumber(V, F)(Q),
                                    "igl": lambda: igl.fast_winding_number(V, F, Q)}, LOAD_ROUNDS)
            r_i = np.median(np.array(t["idle", "gsdf"]) / np.array(t["idle", "igl"]))
            r_l = np.median(np.array(t["loaded", "gsdf"]) / np.array(t["loaded", "igl"]))
            load_cols = [f"{np.median(t['loaded', 'gsdf']):.3f}", f"{np.median(t['loaded', 'igl']):.3f}",
                         f"{r_i:.2f}", f"{r_l:.2f}", f"{r_l / r_i:.2f}"]
        # exact speed on 10^4 queries
        t_ex, _ = median_time(lambda: gsdf.ExactWindingNumber(V, F)(Qa))
        t_ex_igl, _ = median_time(lambda: igl.winding_number(V, F, Qa))
        mis = mis_igl = near = "—"
        if voxels:
            C = voxel_centres(V)
            w_ex = gsdf.ExactWindingNumber(V, F)(C)
            wrong = (fwn(C) > 0.5) != (w_ex > 0.5)
            mis = int(np.count_nonzero(wrong))
            mis_igl = int(np.count_nonzero((igl.fast_winding_number(V, F, C) > 0.5) != (w_ex > 0.5)))
            # how close to 1/2 the exact winding number is at the misclassified voxels (holes: w crosses 1/2
            # in open space, where any approximation error flips the voxel)
            near = f"{np.abs(w_ex[wrong] - 0.5).max():.1e}" if mis else "0"
        rows.append([name, len(F), f"{rms:.1e}", f"{rms_igl:.1e}", f"{np.abs(exact - exact_igl).max():.0e}",
                     f"{mis} (igl {mis_igl})", near,
                     f"{t_pre:.3f}", f"{t_q:.3f}", f"{t_igl:.3f}", f"{ratio:.2f}", *load_cols,
                     f"{t_ex:.3f}", f"{t_ex_igl:.3f}", f"{t_ex / t_ex_igl:.2f}", up])
        print(rows[-1], flush=True)
    header = ["mesh", "faces", "RMS fast (gsdf)", "RMS fast (igl)", "exact gsdf−igl max", "voxels wrong /100³",
              "max |w_exact − ½| there",
              "gsdf pre s", f"gsdf {n_queries:.0e} q s", "igl fast s", "ratio gsdf/igl",
              *(["loaded: gsdf s", "loaded: igl s", "rounds: idle ratio", "rounds: loaded ratio",
                 "loaded/idle ratio"] if load else []),
              "gsdf exact 1e4 s", "igl exact 1e4 s", "exact ratio", "uptime"]
    return table(header, rows)


def bench_points(igl, root, n_queries, rng):
    rows = []
    area_line = ""
    for name in CLOUDS:
        P, N = gsdf.read_points(os.path.join(root, "points_3", name))
        t_area, A = median_time(lambda: gsdf.point_areas(P, N), repeat=1)
        Q = queries_in_box(P, n_queries, rng)
        Qa = Q[:10000]
        exact = gsdf.winding_number_points(P, N, Qa, areas=A)
        Nu = N / np.linalg.norm(N, axis=1, keepdims=True)
        fast = gsdf.FastWindingNumberPoints(P, N, areas=A)(Qa)
        fast_igl = igl.fast_winding_number(P, Nu, A, Qa, 2, 2.3)
        rms = np.sqrt(np.mean((fast - exact) ** 2))
        rms_igl = np.sqrt(np.mean((fast_igl - exact) ** 2))
        t_pre, fwn = median_time(lambda: gsdf.FastWindingNumberPoints(P, N, areas=A))
        t_q, _ = median_time(lambda: fwn(Q))
        t_igl, _ = median_time(lambda: igl.fast_winding_number(P, Nu, A, Q, 2, 2.3))
        rows.append([name, len(P), f"{t_area:.3f}", f"{rms:.1e}", f"{rms_igl:.1e}", f"{t_pre:.3f}", f"{t_q:.3f}",
                     f"{t_igl:.3f}", f"{(t_pre + t_q) / t_igl:.2f}"])
        print(rows[-1], flush=True)
        if name.startswith("sphere_20k"):
            r = np.linalg.norm(P - P.mean(0), axis=1).mean()
            area_line = (f"Point areas on {name}: sum = {A.sum():.4f}, 4πr² = {4 * np.pi * r * r:.4f} "
                         f"(r = mean distance to centroid = {r:.4f}): ratio {A.sum() / (4 * np.pi * r * r):.4f}. "
                         f"The plain 3D k-NN rule (candidates=1) gives "
                         f"{gsdf.point_areas(P, N, candidates=1).sum() / (4 * np.pi * r * r):.4f} on this noisy shell.")
    header = ["cloud", "points", "areas s", "RMS fast (gsdf)", "RMS fast (igl, same areas)", "gsdf pre s",
              f"gsdf {n_queries:.0e} q s", "igl s", "ratio gsdf/igl"]
    return table(header, rows) + "\n\n" + area_line


def bench_growth(igl, n_queries, rng):
    import trimesh

    rows = []
    for sub in range(2, 9):
        m = trimesh.creation.icosphere(subdivisions=sub)
        V, F = np.asarray(m.vertices), np.asarray(m.faces, dtype=np.int64)
        Q = queries_in_box(V, n_queries, rng)
        igl.fast_winding_number(V, F, Q[:10])
        t_pre, fwn = median_time(lambda: gsdf.FastWindingNumber(V, F))
        t_q, _ = median_time(lambda: fwn(Q))
        t_igl, _ = median_time(lambda: igl.fast_winding_number(V, F, Q))
        P = V / np.linalg.norm(V, axis=1, keepdims=True)  # the vertices as a cloud: exact normals, areas
        A = np.full(len(P), 4 * np.pi / len(P))
        t_ppre, fwp = median_time(lambda: gsdf.FastWindingNumberPoints(P, P, areas=A))
        t_pq, _ = median_time(lambda: fwp(Q))
        rows.append([len(F), f"{t_pre:.3f}", f"{t_q / len(Q) * 1e6:.2f}", f"{t_igl / len(Q) * 1e6:.2f}",
                     len(P), f"{t_ppre:.3f}", f"{t_pq / len(Q) * 1e6:.2f}"])
        print(rows[-1], flush=True)
    header = ["triangles", "gsdf pre s", "gsdf µs/query", "igl µs/query (incl. pre)", "points", "gsdf pts pre s",
              "gsdf pts µs/query"]
    return table(header, rows)


PARTS = ("triangles", "points", "growth")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="10^5 queries, no 100^3 voxel check")
    ap.add_argument("--load", action="store_true",
                    help="also time the fast triangle winding numbers with two busy processes running")
    ap.add_argument("--queries", type=int, default=0,
                    help="queries per input for the speed tables (default 10^6, 10^5 with --quick)")
    ap.add_argument("--only", default="", help=f"comma list of parts: {','.join(PARTS)} (default all)")
    args = ap.parse_args(argv)
    parts = [p for p in args.only.split(",") if p] or list(PARTS)
    for p in parts:
        if p not in PARTS:
            ap.error(f"--only: unknown part {p!r}; known: {', '.join(PARTS)}")
    import igl

    root = data_dir()
    rng = np.random.default_rng(0)
    n_q = args.queries or (100_000 if args.quick else 1_000_000)
    if n_q < 10_000:
        raise SystemExit("--queries: need at least 10000 (the accuracy columns use the first 10^4)")
    print("machine:", machine(), uptime(), flush=True)
    # warm up numba (compile or load from cache) outside the timings
    V, F = gsdf.read_mesh(os.path.join(root, "meshes", "holes.off"))
    gsdf.FastWindingNumber(V, F)(V[:5000] + 1e-3)
    gsdf.ExactWindingNumber(V, F)(V[:5000] + 1e-3)
    gsdf.FastWindingNumberPoints(V, V, areas=np.ones(len(V)))(V[:5000])
    flags = (f"{' --quick' if args.quick else ''}{f' --queries {args.queries}' if args.queries else ''}"
             f"{' --load' if args.load and 'triangles' in parts else ''}")
    for part in parts:
        start, t0 = uptime(), time.time()
        if part == "triangles":
            body = bench_triangles(igl, root, n_q, not args.quick, rng, load=args.load)
            title = "Winding numbers of triangle meshes and soups against libigl"
            note = (f"β = 2, order 2; RMS against the exact winding number on 10⁴ random queries in the padded box; "
                    f"times are medians of 3 in one process, {n_q:,} queries. \"voxels wrong\" counts voxel centres "
                    "of a 100³ grid whose inside/outside (w > 1/2) differs from the exact winding number (libigl's "
                    "count in brackets); the next column is the largest |w_exact − 1/2| among them (on meshes with "
                    "holes the 1/2 level set crosses open space, where either method may flip a voxel). \"ratio\" is "
                    "(gsdf precompute + query) / libigl (which precomputes inside its call); < 1 is faster."
                    + (LOAD_NOTE if args.load else ""))
        elif part == "points":
            body = bench_points(igl, root, n_q, rng)
            title = "Winding numbers of oriented point clouds against libigl"
            note = (f"β = 2.3, order 2, gsdf's point areas given to both; {n_q:,} queries; times are medians of 3 "
                    "in one process.")
        else:
            body = bench_growth(igl, 100_000, rng)
            title = "Winding numbers: growth with element count"
            note = "Icosphere meshes and their vertices as a cloud, 10⁵ queries; medians of 3."
        cmd = command("bench_winding.py", [f"--only {part}{flags}"], python="/work/anchors/bin/python",
                      env="NUMBA_NUM_THREADS=2")
        text = (heading(title, cmd, start) + f"{note} Part took {time.time() - t0:.0f} s "
                f"(gsdf and libigl both use all {os.cpu_count()} cores).\n\n{body}\n")
        write_section(f"winding-{part}", text)
        print(text, flush=True)


if __name__ == "__main__":
    main()
