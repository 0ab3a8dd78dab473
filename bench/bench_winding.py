"""Winding numbers: gsdf against libigl on the CGAL meshes and clouds, in one process run.

Run in a Python that has gsdf and the anchors (``../shared/tools/install-anchors VENV``):

    VENV/bin/python bench/bench_winding.py            # full run (~15 min on 2 cores)
    VENV/bin/python bench/bench_winding.py --quick    # fewer queries, no 100^3 voxel check

Prints every table and writes them to bench/RESULTS.md (section "winding"; a run with --only gets
"winding-PARTS", and one with --only and --queries other than 10^6 "winding-PARTS-qN", e.g.
``--quick --queries 100000 --load --only triangles`` writes "winding-triangles-q100000").
Speed is a ratio of medians of 3 runs in this process (with --load: alternating idle / loaded rounds of batches ≥ 0.1 s, see LOAD_NOTE); accuracy is against exact winding numbers
(gsdf's hierarchical exact evaluation, cross-checked against igl.winding_number).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import alternating_rounds, data_dir, machine, median_time, table, write_section  # noqa: E402
from load import uptime  # noqa: E402

import gsdf  # noqa: E402

# >= 10 triangle inputs of different kinds (issue 17): scans, CAD parts, soups / meshes with holes
MESHES = ["bunny00.off", "refined_elephant.off", "armadillo.off", "man.off", "ChineseDragon-10kv.off",   # scans
          "fandisk.off", "blade.off", "couplingdown.off", "cheese.off", "rotor.off",                     # CAD
          "holes.off", "elephant-with-holes.off", "mech-holes-shark.off"]                               # holes
CLOUDS = ["kitten.xyz", "oni.pwn", "sphere_20k_normal.xyz"]


#: Rounds of the loaded protocol (common.alternating_rounds, as bench_winding_load.py).
LOAD_ROUNDS = 7

LOAD_NOTE = ("\n\"loaded\" columns (issue 17 goal 5): build + query of gsdf and libigl, each timed as the mean of a "
             f"batch of calls lasting ≥ 0.1 s, in {LOAD_ROUNDS} rounds alternating idle / loaded (two busy processes, "
             "bench/load.py, started and stopped per round; common.alternating_rounds); \"rounds: idle / loaded "
             "ratio\" = median over rounds of the per-round gsdf/igl ratio, \"loaded/idle ratio\" = their quotient "
             "(issue 17 asks for ≤ 1.25); \"loaded: gsdf s / igl s\" = medians of the loaded batch means. The "
             "idle columns before them are medians of 3 single calls.")


READING = """

Triangle walk (src/gsdf/winding/fast.py): the binary tree (volume splits, leaves of 4 triangles) is walked
4 children at a time: per node the 4 children's far-field tests and order-2 expansions are evaluated
together in one unrolled loop that LLVM turns into 4-lane SIMD (AVX2 doubles), the near children are
descended. The query points of a chunk are grouped by a counting sort on coarse Morton cells, and small
builds / query sets run on the calling thread (a parallel launch waits for workers under load).
Build (src/gsdf/spatial/binned.py, winding/fast.py): the tree moves element rows instead of indexing them,
bins the two longest axes of each node's centroid box in one pass and sweeps every split position along
them in nodes of ≤ 24 triangles; the node moments are summed bottom-up (children shifted to the parent's
centre), O(m + k) instead of O(m log m), and folded straight into the 4-wide lanes; from 20k faces the element rows, the two halves below the root
and the lower subtrees (pipelined), the leaf moments (with the wide view beside them) and the lanes use the
threads of one persistent pool (gsdf.threads.run_tasks). "gsdf pre s" is this whole build
(bench/profile_fwn_build.py prints it stage by stage)."""


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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="10^5 queries, no 100^3 voxel check")
    ap.add_argument("--load", action="store_true",
                    help="also time the fast triangle winding numbers with two busy processes running")
    ap.add_argument("--queries", type=int, default=0,
                    help="queries per input for the speed tables (default 10^6, 10^5 with --quick)")
    ap.add_argument("--only", default="", help="comma list of parts: triangles,points,growth (default all)")
    args = ap.parse_args(argv)
    parts = set(args.only.split(",")) if args.only else {"triangles", "points", "growth"}
    import igl

    root = data_dir()
    rng = np.random.default_rng(0)
    n_q = args.queries or (100_000 if args.quick else 1_000_000)
    if n_q < 10_000:
        raise SystemExit("--queries: need at least 10000 (the accuracy columns use the first 10^4)")
    info = machine()
    print("machine:", info, flush=True)
    t0 = time.time()
    # warm up numba (compile or load from cache) outside the timings
    V, F = gsdf.read_mesh(os.path.join(root, "meshes", "holes.off"))
    gsdf.FastWindingNumber(V, F)(V[:5000] + 1e-3)
    gsdf.ExactWindingNumber(V, F)(V[:5000] + 1e-3)
    gsdf.FastWindingNumberPoints(V, V, areas=np.ones(len(V)))(V[:5000])
    skipped = "(not run: --only)"
    tri = bench_triangles(igl, root, n_q, not args.quick, rng, load=args.load) if "triangles" in parts else skipped
    pts = bench_points(igl, root, n_q, rng) if "points" in parts else skipped
    growth = bench_growth(igl, 100_000, rng) if "growth" in parts else skipped
    flags = (f"{' --quick' if args.quick else ''}{f' --queries {args.queries}' if args.queries else ''}"
             f"{' --load' if args.load else ''}{f' --only {args.only}' if args.only else ''}")
    text = f"""## Winding numbers (bench/bench_winding.py{flags})

Machine: {info}. Run took {time.time() - t0:.0f} s. Times are medians of 3 runs in one process.
The machine is shared with other work: the `uptime` column is the load average when each row was measured;
ratios against libigl measured in the same run are what count.{LOAD_NOTE if args.load else ""}
Command: `NUMBA_NUM_THREADS=2 PYTHONPATH=src /work/anchors/bin/python bench/bench_winding.py{flags}`
(gsdf and libigl both use all cores of this machine: {os.cpu_count()}).{{reading}}

### Triangle meshes and soups, β = 2, order 2 (RMS against exact on 10⁴ random queries in the padded box)

{tri}

"voxels wrong" counts voxel centres of a 100³ grid whose inside/outside (w > 1/2) differs from the exact
winding number (libigl's count on the same grid in brackets); the next column is the largest |w_exact − 1/2|
among them: on meshes with holes the 1/2 level set crosses open space, where w is within the approximation
error of 1/2 and either method may flip a voxel. "ratio" is (gsdf precompute + query) / libigl (which precomputes inside its call); < 1 is faster.

### Oriented point clouds, β = 2.3, order 2, gsdf point areas given to both

{pts}

### Growth with element count (icosphere meshes / their vertices as a cloud, 10⁵ queries)

{growth}
"""
    text = text.replace("{reading}", READING if "triangles" in parts else "")
    # a partial run (--only) gets its own section, so the full tables of the last full run stay
    # (a query count other than the default 10^6 of a partial run gets its own section too: --queries 100000)
    name = "winding" if not args.only else "winding-" + "-".join(sorted(parts))
    if args.only and args.queries and args.queries != 1_000_000:
        name += f"-q{args.queries}"
    write_section(name, text)
    print(text)


if __name__ == "__main__":
    main()
