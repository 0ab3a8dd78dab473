"""Benchmark of `gsdf batch`: dataset throughput and sign accuracy against mesh-to-sdf and mesh2sdf.

1. Throughput (meshes / minute) on a folder of CGAL meshes (broken ones included), 1 vs 2 workers, local
   processes vs a Dask LocalCluster, for sdf-samples (250k samples / mesh) and sdf-grid 128^3.
2. One run against mesh-to-sdf (sample_sdf_near_surface, 250k samples, its default scan + normal sign) and
   mesh2sdf (compute, 128^3, fix=True as its docs say for non-watertight input) on the broken meshes of the set:
   time per mesh and sign agreement with the exact generalized winding number (gsdf.winding_number > 1/2) at
   20k of each tool's own query points; failures are reported with their exception.

Run (anchors venv; mesh-to-sdf renders depth maps: EGL headless):
    PYOPENGL_PLATFORM=egl PYTHONPATH=src /work/anchors/bin/python bench/bench_batch.py \
        [--meshes 40] [--grid-meshes 20] [--anchor-meshes 8]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import traceback

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import command, data_dir, heading, write_section  # noqa: E402

MESH_EXT = (".off", ".obj", ".ply", ".stl")
CHECK = 20_000  # query points per mesh checked against the exact winding number


def pick_meshes(n: int) -> list[str]:
    """``n`` CGAL meshes of 2-400 KB (sorted by name), plus the smallest broken ones (holes, single faces)."""
    root = os.path.join(data_dir(), "meshes")
    files = sorted(os.path.join(root, f) for f in os.listdir(root) if f.lower().endswith(MESH_EXT))
    mid = [f for f in files if 2_000 <= os.path.getsize(f) <= 400_000]
    tiny = [f for f in files if os.path.basename(f) in (
        "elephant-with-holes.off", "holes.off", "mech-holes-shark.off", "cube-ouvert.off", "hedra_open.off",
        "corner_with_hole.off", "open_cube.off", "triangle.off", "triangular_hole.off", "degtri_sliding.off")]
    step = max(1, len(mid) // max(1, n - len(tiny)))
    chosen = [f for f in mid[::step] if f not in tiny][: n - len(tiny)] + tiny
    return sorted(chosen)


def broken(path) -> str:
    """'closed' for a closed edge-manifold mesh, else what is broken (boundary / non-manifold edges)."""
    import gsdf

    try:
        V, F = gsdf.read_mesh(path)
    except ValueError as exc:
        return f"unreadable ({exc})"
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, count = np.unique(E, axis=0, return_counts=True)
    b, nm = int((count == 1).sum()), int((count > 2).sum())
    return "closed" if b == 0 and nm == 0 else f"{b} boundary / {nm} non-manifold edges"


def throughput(lists, task, options, configs, work) -> list[tuple]:
    from gsdf.batch import DaskExecutor, LocalExecutor, run_batch

    rows = []
    for name, kind, n in configs:
        ex = LocalExecutor(n) if kind == "local" else DaskExecutor.local(n)
        try:
            # warm the workers (imports, numba cache loads) outside the timing
            run_batch(lists[:1], task, os.path.join(work, f"warm-{task}-{name}"), {**options, **_small(task)},
                      executor=ex)
            t = time.perf_counter()
            r = run_batch(lists, task, os.path.join(work, f"{task}-{name}"), options, executor=ex)
            wall = time.perf_counter() - t
        finally:
            ex.close()
        c = r.counts
        rows.append((task, name, len(lists), c["done"], c["failed"], wall, 60.0 * len(lists) / wall))
        print(rows[-1], flush=True)
    return rows


def _small(task):
    return {"n_samples": 1000} if task == "sdf-samples" else {"resolution": 8}


def sign_agreement(V, F, Q, sdf) -> float:
    import gsdf

    inside = gsdf.winding_number(V, F, Q) > 0.5
    return float(np.mean((np.asarray(sdf) < 0) == inside))


def anchors(paths, rng) -> list[dict]:
    import gsdf
    from gsdf.batch import Geometry, sdf_grid, sdf_samples

    rows = []
    for p in paths:
        V, F = gsdf.read_mesh(p)
        c = 0.5 * (V.min(0) + V.max(0))
        row = {"mesh": os.path.basename(p), "faces": len(F), "state": broken(p)}
        # gsdf sdf-samples in the unit-sphere frame (the frame mesh-to-sdf uses)
        t = time.perf_counter()
        out = sdf_samples(Geometry(V, F=F), n_samples=250_000, normalize="sphere")
        row["gsdf_samples_s"] = time.perf_counter() - t
        s = float(out["scale"])
        Vn = (V - c) / s
        k = rng.choice(len(out["sdf"]), CHECK, replace=False)
        row["gsdf_samples_sign"] = sign_agreement(Vn, F, out["points"][k].astype(float), out["sdf"][k])
        # mesh-to-sdf: its own near-surface sampler, same count
        try:
            import mesh_to_sdf
            import trimesh

            t = time.perf_counter()
            P, S = mesh_to_sdf.sample_sdf_near_surface(trimesh.Trimesh(V, F, process=False), number_of_points=250_000)
            row["m2s_s"] = time.perf_counter() - t
            k = rng.choice(len(S), min(CHECK, len(S)), replace=False)
            row["m2s_sign"] = sign_agreement(Vn, F, P[k].astype(float), S[k])
        except Exception as exc:  # how the tool breaks is part of the result
            row["m2s_error"] = f"{type(exc).__name__}: {str(exc)[:120]}"
        # gsdf sdf-grid 128^3 vs mesh2sdf 128^3, both in [-1, 1]^3 (mesh2sdf's required frame)
        half = 0.5 * float((V.max(0) - V.min(0)).max())
        Vc = (V - c) / half * 0.9  # mesh2sdf wants vertices inside [-1, 1]
        t = time.perf_counter()
        g = sdf_grid(Geometry(Vc, F=F), resolution=128, normalize="none", pad=1 / 0.9 - 1)
        row["gsdf_grid_s"] = time.perf_counter() - t
        X = np.stack(np.meshgrid(*[np.linspace(g["bbox_min"][i], g["bbox_max"][i], 128) for i in range(3)],
                                 indexing="ij"), -1).reshape(-1, 3)
        k = rng.choice(len(X), CHECK, replace=False)
        row["gsdf_grid_sign"] = sign_agreement(Vc, F, X[k], g["sdf"].reshape(-1)[k])
        try:
            import mesh2sdf

            t = time.perf_counter()
            G = mesh2sdf.compute(Vc, F, 128, fix=True, level=2 / 128)
            row["m2sdf_s"] = time.perf_counter() - t
            x = -1 + 2 * np.arange(128) / 128  # node i at -1 + 2i/size (its marching-cubes rescale)
            Xm = np.stack(np.meshgrid(x, x, x, indexing="ij"), -1).reshape(-1, 3)
            k = rng.choice(len(Xm), CHECK, replace=False)
            row["m2sdf_sign"] = sign_agreement(Vc, F, Xm[k], G.reshape(-1)[k])
            d = gsdf.TriangleDistance(Vc, F).query(Xm[k])[0]
            row["m2sdf_abs_err"] = float(np.median(np.abs(np.abs(G.reshape(-1)[k]) - d)))
        except Exception as exc:
            row["m2sdf_error"] = f"{type(exc).__name__}: {str(exc)[:120]}"
        print(row, flush=True)
        rows.append(row)
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", type=int, default=40)
    ap.add_argument("--grid-meshes", type=int, default=20)
    ap.add_argument("--anchor-meshes", type=int, default=8)
    ap.add_argument("--skip-samples", action="store_true", help="no sdf-samples throughput")
    ap.add_argument("--skip-grid", action="store_true", help="no sdf-grid throughput")
    ap.add_argument("--skip-anchors", action="store_true", help="no anchor comparison")
    ap.add_argument("--rows-from", nargs="*", default=None,
                    help="measure nothing: write the section from the printed rows of earlier runs' logs")
    args = ap.parse_args()
    load0 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    paths = pick_meshes(args.meshes)
    states = {p: broken(p) for p in paths}
    n_broken = sum(s != "closed" for s in states.values())
    print(f"{len(paths)} meshes, {n_broken} not closed manifold", flush=True)
    configs = [("local-1", "local", 1), ("local-2", "local", 2), ("dask-1", "dask", 1), ("dask-2", "dask", 2)]
    rows, arows, loads = [], [], []
    if args.rows_from is not None:  # compose: rows printed by earlier (possibly concurrent) phase runs
        import ast

        for log in args.rows_from:
            for line in open(log):
                if line.startswith("('sdf-"):
                    rows.append(ast.literal_eval(line.strip()))
                elif line.startswith("{'mesh'"):
                    arows.append(ast.literal_eval(line.strip()))
                elif line.startswith("load: "):
                    loads.append(line[6:].strip())
    else:
        print("load: " + load0, flush=True)
        with tempfile.TemporaryDirectory() as work:
            if not args.skip_samples:
                rows += throughput(paths, "sdf-samples", {"n_samples": 250_000}, configs, work)
            if not args.skip_grid:
                grid_paths = paths[:: max(1, len(paths) // args.grid_meshes)][: args.grid_meshes]
                rows += throughput(grid_paths, "sdf-grid", {"resolution": 128}, configs, work)
        if not args.skip_anchors:
            bad = [p for p in paths if states[p] != "closed" and not states[p].startswith("unreadable")]
            big = sorted(bad, key=os.path.getsize)[-args.anchor_meshes:]
            arows = anchors(big, np.random.default_rng(0))
    load1 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()

    if loads:
        load0 = "; ".join(loads)
    print("load: " + load1, flush=True)
    cmd = command("bench_batch.py", [f"--meshes {args.meshes} --grid-meshes {args.grid_meshes} "
                                     f"--anchor-meshes {args.anchor_meshes}"],
                  python="/work/anchors/bin/python", env="PYOPENGL_PLATFORM=egl")
    lines = [heading("Batch jobs (`gsdf batch`): throughput and sign accuracy against mesh-to-sdf and mesh2sdf",
                     cmd).rstrip(), "",
             f"Load before: `{load0}`; after: `{load1}`. Absolute times are inflated on a shared machine; the ratios "
             "measured in the same run are what count. The phases can run separately (`--skip-grid --skip-anchors`, "
             "`--skip-samples --skip-anchors`, `--skip-samples --skip-grid`, then `--rows-from LOGS` writes the "
             "section).", "",
             f"Mesh set: {len(paths)} CGAL meshes (`pick_meshes`: 2-400 KB files evenly over the sorted list, plus "
             f"ten named broken ones), {n_broken} of them not closed manifold (holes, borders, non-manifold edges); "
             "unreadable or degenerate files are recorded as failed and count in the throughput.", ""]
    if rows:
        lines += ["Throughput (warm workers; wall time of the whole run including reading, hashing and writing):", "",
                  "| task | executor | meshes | done | failed | wall s | meshes/min |", "|---|---|---|---|---|---|---|"]
        lines += [f"| {t} | {e} | {n} | {d} | {f} | {w:.1f} | {m:.1f} |" for t, e, n, d, f, w, m in rows]
        lines += ["", "sdf-samples: 250k samples/mesh on every mesh; sdf-grid: 128^3 on "
                  f"{args.grid_meshes} of them (evenly spaced in the sorted set: the full set at 128^3 x 4 executors did "
                  "not fit the time left on this loaded machine).", ""]
    lines += [f"Against the anchors, one run on the {len(arows)} largest broken meshes of the set: seconds per mesh, "
              f"and sign agreement with the exact winding number at {CHECK // 1000}k of each tool's own query "
              "points (its samples / its grid nodes).", "",
              "| mesh | faces | state | gsdf samples s | sign | mesh-to-sdf s | sign | gsdf grid s | sign | "
              "mesh2sdf s | sign | mesh2sdf median abs err |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]

    def f(row, k, fmt):
        return fmt.format(row[k]) if k in row else "error"

    for r in arows:
        lines.append(f"| {r['mesh']} | {r['faces']} | {r['state']} | {f(r, 'gsdf_samples_s', '{:.1f}')} | "
                     f"{f(r, 'gsdf_samples_sign', '{:.4f}')} | {f(r, 'm2s_s', '{:.1f}')} | {f(r, 'm2s_sign', '{:.4f}')} | "
                     f"{f(r, 'gsdf_grid_s', '{:.1f}')} | {f(r, 'gsdf_grid_sign', '{:.4f}')} | "
                     f"{f(r, 'm2sdf_s', '{:.1f}')} | {f(r, 'm2sdf_sign', '{:.4f}')} | {f(r, 'm2sdf_abs_err', '{:.4f}')} |")
    errs = [(r["mesh"], k, r[k]) for r in arows for k in ("m2s_error", "m2sdf_error") if k in r]
    if errs:
        lines += [""] + [f"- {m}: {'mesh-to-sdf' if k == 'm2s_error' else 'mesh2sdf'} raised {e}" for m, k, e in errs]
    text = "\n".join(lines)
    print(text)
    if args.rows_from is None and (args.skip_samples or args.skip_grid or args.skip_anchors):
        return  # a partial phase: its rows are in the log for --rows-from
    write_section("batch", text)


if __name__ == "__main__":
    try:
        main()
    except Exception:
        traceback.print_exc()
        sys.exit(1)
