"""Speed, accuracy and peak memory of the volumetric signed heat method (grid domain) against signedheat3d.

Issue 17, goals 6 and 7. Run in the anchors' venv (it has signedheat3d):

    PYTHONPATH=src /work/anchors/bin/python bench/bench_heat_volume_speed.py            # 10 inputs, medians of 3
    PYTHONPATH=src /work/anchors/bin/python bench/bench_heat_volume_speed.py --quick    # 5 inputs, anchor once
    ... --only=oni.pwn,holes.off   --no-scaling   --only-scaling   --load (also under two busy processes, bench/load.py)

Every case (one input, one solver) runs in its own process, so its peak RSS (``ru_maxrss``) is its own; the
baseline RSS of that process after imports (and, for gsdf, after the numba kernels are loaded) is listed too.
Both solvers get the same input, bounding box and node counts (``volume_grid_box(X, 32)``); gsdf runs with its
defaults (level_set_constraint "zero", soft penalty). Errors are mean |φ − φ_ref| over the grid nodes, φ_ref the
exact signed distance (exact unsigned distance, winding-number sign) of the intact mesh for the damaged ones, of
the input for the meshes with holes, of the points for clouds; the anchor's sign is flipped when it is
anti-correlated with the reference (its convention). The stage table is one cProfile'd gsdf run per input
(cumulative seconds of the stage functions; "other" = the rest: assembly, Python); the first-call column is the
one-time numba load/compile of the process (excluded from the medians). The scaling table varies the input size
at fixed 32³ and 64³ grids (gsdf only).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import data_dir, machine, table, write_section  # noqa: E402
from load import BusyLoad, uptime  # noqa: E402

ALL = ["holes.off", "elephant-with-holes.off", "mech-holes-shark.off", "fandisk.off", "cow soup −25 % faces",
       "kitten.xyz", "oni.pwn", "hippo1.ply", "bunny00 −30 % faces", "couplingdown.off"]  # slowest anchors last
SLOW_ANCHOR = 60.0  # s: an anchor run longer than this is not repeated (its speed-up is > 100× either way)
QUICK = ["holes.off", "elephant-with-holes.off", "fandisk.off", "cow soup −25 % faces", "oni.pwn"]
KIND = {"bunny00 −30 % faces": "scan, holes cut", "holes.off": "mesh with holes",
        "elephant-with-holes.off": "mesh with holes", "mech-holes-shark.off": "CAD-like, holes",
        "fandisk.off": "CAD, closed", "couplingdown.off": "CAD, closed",
        "cow soup −25 % faces": "soup: unshared, 10 % flipped, holes", "kitten.xyz": "cloud",
        "oni.pwn": "cloud", "hippo1.ply": "cloud (scan)"}


def rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


# ---------------------------------------------------------------- inputs
def load_input(name):
    """(kw for signed_heat_volume, reference geometry, is_mesh)."""
    import gsdf

    dd = data_dir()
    if name.startswith("bunny00"):
        from bench_heat_volume import broken_bunny

        V, F, Vb, Fb = broken_bunny()
        return dict(mesh=(Vb, Fb)), (V, F), True
    if name.startswith("cow soup"):
        V, F = gsdf.read_mesh(os.path.join(dd, "meshes", "cow.off"))
        rng = np.random.default_rng(1)
        keep = np.sort(rng.choice(len(F), int(0.75 * len(F)), replace=False))
        Fk = F[keep].copy()
        flip = rng.random(len(Fk)) < 0.1
        Fk[flip] = Fk[flip][:, ::-1]
        Vs = V[Fk].reshape(-1, 3)  # every triangle its own three vertices: a soup
        return dict(mesh=(Vs, np.arange(len(Vs)).reshape(-1, 3))), (V, F), True
    if name.endswith(".off"):
        V, F = gsdf.read_mesh(os.path.join(dd, "meshes", name))
        return dict(mesh=(V, F)), (V, F), True
    P, N = gsdf.read_points(os.path.join(dd, "points_3", name))
    if N is None:
        N = gsdf.estimate_normals(P)
    return dict(points=(P, N)), (P, N), False


def scaled_input(kind, k):
    """Inputs of growing size for the scaling table: every k-th face of bunny00 / point of sphere_20k."""
    import gsdf

    if kind == "bunny00 faces":
        V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "bunny00.off"))
        Fk = F[::k]
        used = np.unique(Fk)
        remap = np.full(len(V), -1)
        remap[used] = np.arange(len(used))
        return dict(mesh=(V[used], remap[Fk])), len(Fk)
    P, N = gsdf.read_points(os.path.join(data_dir(), "points_3", "sphere_20k_normal.xyz"))
    return dict(points=(P[::k], N[::k])), len(P[::k])


def box_of(kw, res):
    from gsdf.heat.volume import volume_grid_box

    X = kw["mesh"][0] if "mesh" in kw else kw["points"][0]
    return volume_grid_box(X, res)


# ---------------------------------------------------------------- workers (one process per case)
STAGES = [  # (label, file suffix, function name): disjoint stages of the grid path
    ("sources", "volume/sources.py", "mesh_sources"),
    ("sources", "volume/sources.py", "point_sources"),
    ("step I tree build", "volume/yukawa.py", "__init__"),
    ("step I nearest", "volume/yukawa.py", "grid_nearest_distance"),
    ("step I sum", "volume/yukawa.py", "__call__"),
    ("step I sum", "volume/screened.py", "screened_heat"),  # the grid solve of clouds (step1="auto")
    ("step II normalize", "heat/core.py", "unit_field"),
    ("divergence", "domains/grid.py", "divergence"),
    ("factorization (coarse)", "linalg/direct.py", "__init__"),
    ("CG solve", "linalg/iterative.py", "pcg"),
    ("CG solve", "linalg/iterative.py", "cg_loop"),       # the grid's soft-penalty solve (numba operators)
    ("shift", "heat/core.py", "shift"),
]


def profile_stages(fn):
    import cProfile
    import pstats

    pr = cProfile.Profile()
    t = time.perf_counter()
    pr.enable()
    fn()
    pr.disable()
    total = time.perf_counter() - t
    st = pstats.Stats(pr).stats
    out = {}
    for label, suffix, func in STAGES:
        for (file, _line, name), (_cc, _nc, _tt, ct, _callers) in st.items():
            if name == func and file.replace(os.sep, "/").endswith(suffix):
                out[label] = out.get(label, 0.0) + ct
    out["other"] = total - sum(out.values())
    out["total (profiled)"] = total
    return out


def anchor_call(kw, lo, hi, shape):
    """signedheat3d's grid solver on ``kw``; (φ on the grid, whether its AMGCL solve fell back to the direct one).

    Step 3 of signedheat3d's grid solver is an AMGCL BiCGStab solve (tol 1e-2, at most 1000 iterations) whose
    start vector is left uninitialised; when it does not converge the solver falls back to a sparse direct LU of
    the saddle-point system. Which path a call takes depends on leftover heap memory, so the time of one call
    varies several-fold (couplingdown: 2.7 s converged, 7-37 s with the 1000 iterations and the fallback). The
    solver's own verbose log (file descriptor 2, captured here) says which path was taken.
    """
    import tempfile

    import signedheat3d as shm

    s = shm.SignedHeatGridSolver(verbose=True)
    opts = {"bbox_min": np.asarray(lo, float), "bbox_max": np.asarray(hi, float),
            "resolution": np.asarray(shape, dtype=np.int64)}
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+") as log:
        os.dup2(log.fileno(), 2)
        try:
            if "mesh" in kw:
                phi = s.compute_distance_to_mesh(kw["mesh"][0], kw["mesh"][1], opts)
            else:
                phi = s.compute_distance_to_point_cloud(kw["points"][0], kw["points"][1], options=opts)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        log.seek(0)
        fell_back = "use direct solver" in log.read()
    return s.to_grid_array(np.asarray(phi)).ravel(), fell_back


def worker(args):
    who, name, res, repeat = args[0], args[1], int(args[2]), int(args[3])
    t_first = None
    if who == "gsdf":
        from gsdf.heat.volume import signed_heat_volume

        t = time.perf_counter()
        C = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1, -1], [0.5, -1, 0.2]])
        signed_heat_volume(points=(C, C), resolution=6)  # numba kernels: load (or compile)
        signed_heat_volume(mesh=(C, np.array([[0, 1, 2], [0, 2, 3], [1, 3, 4]])), resolution=6)
        t_first = time.perf_counter() - t
    else:
        import signedheat3d  # noqa: F401
    if name.startswith("scale:"):
        _, kind, k = name.split(":")
        kw, size = scaled_input(kind, int(k))
        ref = None
    else:
        kw, ref, is_mesh = load_input(name)
        size = len(kw["mesh"][1]) if "mesh" in kw else len(kw["points"][0])
    lo, hi, shape = box_of(kw, res)
    base = rss_mb()
    times, phi, fallbacks = [], None, []
    for _ in range(repeat):
        if who == "gsdf":  # every run builds its grid operators, as the anchor's new solver object does
            from gsdf.heat.grid import _poisson as _grid

            _grid._dct_matrix.cache_clear()  # (the Step III operators are built per solve)
        t = time.perf_counter()
        if who == "gsdf":
            from gsdf.heat.volume import signed_heat_volume

            f = signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, **kw)
            phi = f.values.ravel()
        else:
            phi, fell_back = anchor_call(kw, lo, hi, shape)
            fallbacks.append(fell_back)
        times.append(time.perf_counter() - t)
        if who == "anchor" and times[-1] > SLOW_ANCHOR:
            break
    peak = rss_mb()
    out = {"who": who, "name": name, "size": size, "shape": list(shape), "times": times,
           "median": float(np.median(times)), "rss_mb": peak, "base_rss_mb": base, "first_call": t_first,
           "fallbacks": int(sum(fallbacks))}
    if who == "gsdf":  # the solve's own array memory: numpy / scipy buffers seen by tracemalloc (not timed)
        import tracemalloc

        from gsdf.heat.volume import signed_heat_volume

        tracemalloc.start()
        signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, **kw)
        out["traced_mb"] = tracemalloc.get_traced_memory()[1] / 2 ** 20
        tracemalloc.stop()
    if who == "gsdf" and ref is not None:
        from gsdf.heat.volume import signed_heat_volume

        out["stages"] = profile_stages(lambda: signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, **kw))
        fi = signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, t_scale="input", **kw)
    if ref is not None:
        import gsdf
        from gsdf.grid import grid_points

        Q = grid_points(lo, hi, shape)
        phi_ref = gsdf.signed_distance(*ref, Q) if is_mesh else gsdf.signed_distance_points(*ref, Q)
        if who == "anchor" and np.mean(np.sign(phi) == np.sign(phi_ref)) < 0.5:
            phi = -phi
        out["err"] = float(np.abs(phi - phi_ref).mean())
        if who == "gsdf":
            out["err_input_t"] = float(np.abs(fi.values.ravel() - phi_ref).mean())
    print("RESULT " + json.dumps(out), flush=True)


def run_case(who, name, res, repeat):
    env = dict(os.environ)
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", who, name, str(res), str(repeat)]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=3600)
    for line in p.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    sys.stderr.write(p.stdout[-2000:] + p.stderr[-4000:])
    return {"who": who, "name": name, "failed": (p.stderr.strip().splitlines() or ["?"])[-1][:120]}


# ---------------------------------------------------------------- main
def speed_table(names, repeat_gsdf, repeat_anchor, label, partial=None):
    rows, srows, cases = [], [], []
    for name in names:
        if partial is not None and rows:
            partial(rows, srows)
        g = run_case("gsdf", name, 32, repeat_gsdf)
        a = run_case("anchor", name, 32, repeat_anchor)
        cases.append((g, a))
        print(f"[{label}] {name}: gsdf {g.get('median', 'failed')} anchor {a.get('median', 'failed')} "
              f"({uptime()})", flush=True)
        if "failed" in g or "failed" in a:
            rows.append([name, KIND[name], "—", "—", "—", "—", "—", "—", "—", "—", "—", "—", "—",
                         f"failed: {g.get('failed', '')} {a.get('failed', '')}"])
            continue
        ratio, ratio_min = a["median"] / g["median"], min(a["times"]) / g["median"]
        nrep = (f" ({len(a['times'])} runs: stopped after one > {SLOW_ANCHOR:.0f} s)"
                if len(a["times"]) < repeat_anchor else "")
        spread = f"{min(a['times']):.2f} / **{a['median']:.2f}** / {max(a['times']):.2f}{nrep}"

        def fmt(r):
            return f"**{r:.0f}×**" if r >= 20 else f"{r:.1f}×"

        rows.append([name, KIND[name], f"{g['size']:,}", str(tuple(g["shape"])),
                     f"{min(g['times']):.3f} / **{g['median']:.3f}** / {max(g['times']):.3f}",
                     spread, f"{a.get('fallbacks', 0)}/{len(a['times'])}", fmt(ratio), fmt(ratio_min),
                     f"{g['err']:.5f}", f"{g['err_input_t']:.5f}", f"{a['err']:.5f}",
                     f"{g['rss_mb']:.0f} ({g['base_rss_mb']:.0f}) / {a['rss_mb']:.0f} ({a['base_rss_mb']:.0f})",
                     f"{g.get('traced_mb', float('nan')):.1f}"])
        s = g["stages"]
        srows.append([name] + [f"{s.get(k, 0.0) * 1e3:.0f}" for k in
                               ("sources", "step I tree build", "step I nearest", "step I sum", "step II normalize",
                                "divergence", "factorization (coarse)", "CG solve", "shift", "other",
                                "total (profiled)")] + [f"{g['first_call']:.1f}"])
    return rows, srows, cases


def scaling_table(quick):
    rows = []
    ks = {"bunny00 faces": (16, 4, 1), "sphere_20k points": (16, 4, 1)}
    for kind, kk in ks.items():
        for res in ((32,) if quick else (32, 64)):
            prev = None
            for k in kk:
                r = run_case("gsdf", f"scale:{kind}:{k}", res, 3 if res == 32 else 1)
                if "failed" in r:
                    rows.append([kind, "?", res, "failed", "", "", "", r["failed"]])
                    continue
                grow = ""
                if prev is not None:
                    mem = (f"{r['traced_mb'] / prev['traced_mb']:.2f}" if "traced_mb" in r and "traced_mb" in prev
                           else "—")
                    grow = f"{(r['median'] / prev['median']):.2f} / {mem} (input ×{r['size'] / prev['size']:.1f})"
                rows.append([kind, f"{r['size']:,}", str(tuple(r["shape"])), f"{r['median']:.3f}",
                             f"{r['rss_mb']:.0f}", f"{r['rss_mb'] - r['base_rss_mb']:.0f}",
                             f"{r['traced_mb']:.1f}" if "traced_mb" in r else "—", grow])
                print(rows[-1], flush=True)
                prev = r
    return rows


def main(argv):
    if "--help" in argv or "-h" in argv:
        print(__doc__)
        return
    quick = "--quick" in argv
    only = [a.split("=", 1)[1] for a in argv if a.startswith("--only=")]
    names = [n for n in ALL if n in only[0].split(",")] if only else (QUICK if quick else ALL)
    rep_g = rep_a = 3 if quick else 5  # the same number of warm runs for both
    head = [f"Machine: {machine()}. Load at start: {uptime()} (shared machine: other helpers' jobs running; "
            "ratios are same-run).", "",
            f"Command: `PYTHONPATH=src /work/anchors/bin/python bench/bench_heat_volume_speed.py {' '.join(argv)}`",
            "", f"gsdf: median of {rep_g}; signedheat3d: median of {rep_a} (no further run after one over {SLOW_ANCHOR:.0f} s), "
            "both in a process of their own, every run timed (gsdf's numba kernels loaded before the first; its "
            "DCT-matrix cache cleared before each run and its Step III operators built in every run, as signedheat3d gets a new solver object per run). "
            "signedheat3d's time varies between runs because its Step 3 (AMGCL BiCGStab, tol 1e-2) starts from an "
            "uninitialised vector: when it fails to converge in 1000 iterations the solver falls back to a sparse "
            "direct LU (\"AMGCL fell back\": runs that did, from its own log); its Steps 1-2 (direct sums over all "
            "nodes × sources) take the same time every run. Both speed-ups are listed: medians, and against the "
            "anchor's fastest run. Grid 32³ along the longest side "
            "(cubic cells), the box padded by 10 % of the diagonal, the same box and node counts for both. gsdf "
            "defaults (\"zero\", soft penalty); \"gsdf err input t\" is t_scale=\"input\" (signedheat3d's t). "
            "RSS: peak of the case's own process, MB (its baseline after imports in parentheses).", ""]
    t0 = time.perf_counter()
    section = "heat-volume-speed" + ("-quick" if quick else "")
    title = "## Volume signed heat speed and memory vs signedheat3d (issue 17, goals 6–7)\n\n"

    def tables(rows, srows):
        return ["### 32³ grid: time, accuracy, peak RSS, gsdf vs signedheat3d", "",
                table(["input", "kind", "faces / points", "nodes", "gsdf s min / median / max",
                       "signedheat3d s min / median / max", "AMGCL fell back", "speed-up (medians)",
                       "speed-up vs anchor's fastest run", "gsdf err", "gsdf err input t", "signedheat3d err",
                       "peak RSS MB gsdf / signedheat3d", "gsdf arrays MB"], rows), "",
                "### gsdf stages at 32³ (ms, one cProfile'd run; first call = numba load/compile of the process, s)",
                "", table(["input", "sources", "tree build", "nearest", "step I sum", "normalize", "divergence",
                           "coarse LU", "CG", "shift", "other", "total", "first call s"], srows), ""]

    def partial(rows, srows):
        write_section(section, title + "\n".join(head + tables(rows, srows))
                      + f"\n(partial: {len(rows)} of {len(names)} inputs so far; {uptime()})\n")

    if "--only-scaling" in argv:  # just the growth table, in its own section
        section, names = "heat-volume-scaling" + ("-quick" if quick else ""), []
        title = "## Volume signed heat: growth with input size at a fixed grid (issue 17, goal 7)\n\n"
        text = list(head)
    else:
        rows, srows, _ = speed_table(names, rep_g, rep_a, "idle", partial)
        text = head + tables(rows, srows)
    if "--load" in argv and names:
        with BusyLoad(2):
            lrows, _, _ = speed_table(names, rep_g, rep_a, "load")
        text += ["### Same, with two busy processes (bench/load.py)", "",
                 table(["input", "kind", "faces / points", "nodes", "gsdf s", "signedheat3d s",
                        "AMGCL fell back", "speed-up (medians)", "speed-up vs fastest", "gsdf err", "gsdf err input t", "signedheat3d err", "peak RSS MB", "gsdf arrays MB"], lrows), ""]
    if "--no-scaling" not in argv:
        srows2 = scaling_table(quick)
        text += ["### Scaling with input size at a fixed grid (gsdf, peak RSS per case)", "",
                 "Peak RSS is the case's own process (interpreter, numba and SciPy included: ~185–210 MB before "
                 "any work); \"RSS above baseline\" its growth during the solves (0: below the peak of the "
                 "imports and kernel loading); \"arrays MB\" the peak of numpy / SciPy buffers during one solve "
                 "(tracemalloc; SuperLU's and numba's own allocations are not seen). Growth = time ratio / arrays "
                 "ratio to the previous row; linear in the input would be ≤ the input ratio.", "",
                 table(["input", "faces / points", "nodes", "s (median)", "peak RSS MB", "RSS above baseline MB",
                        "arrays MB", "growth time / memory"], srows2), ""]
    text += [f"Total {time.perf_counter() - t0:.0f} s; load at end: {uptime()}."]
    out = title + "\n".join(text)
    print(out)
    write_section(section, out)


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2:])
    else:
        main(sys.argv[1:])
