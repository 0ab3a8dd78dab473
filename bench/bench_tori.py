"""Points as Tori benchmark: §7.2 corruption landscapes, real clouds, speed (thesis ch. 5 and 7).

    python bench/bench_tori.py                 # reduced sweep on a 48³ grid (~10 min on 2 busy cores)
    python bench/bench_tori.py --grid 64 --full  # the §7.2 grid resolution and a finer sweep
    python bench/bench_tori.py --quick         # the speed-under-load part only, one cloud size
    python bench/bench_tori.py --only real --output-dir /tmp/tori   # ... with the renders

Parts (``--only``, default all), each writing its own section of bench/RESULTS.md: ``speed-load``
("tori-speed-load": queries/s against ``cKDTree.query(k=64)``, idle and under two busy processes), ``speed``
("tori-speed": growth with cloud size), ``real`` ("tori-real": CGAL clouds, fit / zero set / render times,
accuracy on the noisy sphere), ``landscape`` ("tori-landscape": §7.2 corruption landscapes, mean error per
method). With ``--output-dir``: tori_landscape.csv, tori_landscape_<shape>.png (heatmaps: rows = methods,
columns = corruption types, each panel radius × level) and tori_real_<name>.png (sphere-traced renders) go
there. Methods: PAT (learned / jet estimator), smoothed signed planar distance, signed Hopf–Cole,
the winding-number pipeline, and the volumetric signed heat method on the evaluation grid (gsdf.heat.volume,
default options: Yukawa step I by tree, soft zero-set constraint).
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import command, data_dir, heading, median_time, output_dir, table, write_section  # noqa: E402
from load import BusyLoad, uptime  # noqa: E402

from gsdf.data import _shapes as S  # noqa: E402
from gsdf.tori._baselines import SignedHopfCole, SmoothedSignedPlanarDistance, WindingNumberPipeline, _conv_kernel
from gsdf.heat.volume import signed_heat_volume  # noqa: E402
from gsdf.tori import PointsAsToriOptions  # noqa: E402
from gsdf.tori._pat import PointsAsTori, _pat_kernel  # noqa: E402

METHODS = ["PAT (learned)", "PAT (jet)", "SSPD", "SHC", "WN pipeline", "SHM (grid)"]


def evaluate_all(P, N, X, resolution):
    """Errors of every method on one cloud; the k-d tree neighbour query is shared by the three kernels."""
    out, times = {}, {}
    t = time.perf_counter()
    pat = PointsAsTori(P, N)
    patl = PointsAsTori(P, N, estimator="learned")  # same cleaned cloud, hence the same neighbour queries
    b = pat._blend
    phi, phil = np.empty(len(X)), np.empty(len(X))
    for s in range(0, len(X), 1 << 16):
        q = X[s: s + (1 << 16)]
        d, i = b.neighbours(q)
        o = np.empty(len(q))
        _pat_kernel(q, d, i, pat.tori, pat.P, b.hull, pat.C, b.r_eval, b.k_fallback, False, o, np.empty((1, 3)))
        phi[s: s + len(q)] = o
        _pat_kernel(q, d, i, patl.tori, pat.P, b.hull, pat.C, b.r_eval, b.k_fallback, False, o, np.empty((1, 3)))
        phil[s: s + len(q)] = o
        for name, cls in (("SSPD", SmoothedSignedPlanarDistance), ("SHC", SignedHopfCole)):
            if name not in out:
                out[name] = (cls(pat.P, pat.N, areas=None), np.empty(len(X)))
            m, arr = out[name]
            o2 = np.empty(len(q))
            _conv_kernel(q, d, i, m.P, m.N, m.areas, b.hull, m.C, 0.0, b.r_eval, b.k_fallback, m._mode, o2)
            arr[s: s + len(q)] = o2
    res = {"PAT (learned)": phil, "PAT (jet)": phi, "SSPD": out["SSPD"][1], "SHC": out["SHC"][1]}
    times["kernels"] = time.perf_counter() - t
    t = time.perf_counter()
    try:
        res["WN pipeline"] = WindingNumberPipeline(P, N, [-1, -1, -1], [1, 1, 1], resolution)(X)
    except ValueError:
        res["WN pipeline"] = np.zeros(len(X))  # no surface: counts as φ = 0
    times["wn"] = time.perf_counter() - t
    # the volumetric signed heat method on the evaluation grid itself, default options
    t = time.perf_counter()
    try:
        res["SHM (grid)"] = signed_heat_volume(points=(P, N), resolution=(resolution,) * 3, bbox_min=[-1, -1, -1],
                                               bbox_max=[1, 1, 1])(X)
    except ValueError as exc:  # e.g. a corrupted point outside the box: counts as φ = 0, like the WN pipeline
        print("SHM (grid) failed:", exc)
        res["SHM (grid)"] = np.zeros(len(X))
    times["shm"] = time.perf_counter() - t
    return res, times


def landscapes(args):
    X = S.grid(args.grid)
    if args.full:
        radii = {"cylinder": [0.05, 0.1, 0.2, 0.3, 0.45], "sphere": [0.1, 0.2, 0.4, 0.6, 0.8]}
        levels = {"density": [256, 512, 1024, 4096], "noise": [0.005, 0.01, 0.02, 0.04],
                  "outliers": [0.005, 0.01, 0.02, 0.05], "flips": [0.05, 0.1, 0.2, 0.3]}
    else:
        radii = {"cylinder": [0.1, 0.2, 0.3, 0.45], "sphere": [0.2, 0.4, 0.6, 0.8]}
        levels = {"density": [512, 1024], "noise": [0.01, 0.03], "outliers": [0.01, 0.05], "flips": [0.1, 0.3]}
    rows = []
    for shape in ("cylinder", "sphere"):
        sample = S.sample_cylinder if shape == "cylinder" else S.sample_sphere
        truth = S.cylinder_sdf if shape == "cylinder" else S.sphere_sdf
        for r in radii[shape]:
            tr = truth(X, r)
            configs = [("clean", 0)] + [(kind, lv) for kind in levels for lv in levels[kind]]
            for kind, lv in configs:
                rng = np.random.default_rng(zlib.crc32(repr((shape, r, kind, lv)).encode()))  # str hash() is salted per process
                n = lv if kind == "density" else 2048
                P, N = sample(int(n), r, rng)
                P, N = S.corrupt(P, N, rng, noise=lv if kind == "noise" else 0.0,
                                 outliers=lv if kind == "outliers" else 0.0, flips=lv if kind == "flips" else 0.0)
                res, tm = evaluate_all(P, N, X, args.grid)
                for m in METHODS:
                    rows.append(dict(shape=shape, radius=r, corruption=kind, level=lv, n_points=len(P), method=m,
                                     error=float(np.abs(res[m] - tr).mean())))
                print(shape, r, kind, lv, {m: round(rows[-len(METHODS) + j]["error"], 4) for j, m in enumerate(METHODS)},
                      {k: round(v, 1) for k, v in tm.items()}, flush=True)
    if args.output_dir:
        with open(os.path.join(args.output_dir, "tori_landscape.csv"), "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        for shape in ("cylinder", "sphere"):
            heatmap(rows, shape, radii[shape], levels, os.path.join(args.output_dir, f"tori_landscape_{shape}.png"))
    return rows, radii, levels


# ---------------------------------------------------------------------------------------------- heatmaps


def _colour(v, lo, hi):
    """Viridis-like ramp on log10 error."""
    t = np.clip((np.log10(v) - lo) / (hi - lo), 0, 1)
    stops = np.array([[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], float)
    x = t * (len(stops) - 1)
    i = np.minimum(x.astype(int), len(stops) - 2)
    f = (x - i)[..., None]
    return (stops[i] * (1 - f) + stops[i + 1] * f).astype(np.uint8)


def heatmap(rows, shape, radii, levels, path):
    from PIL import Image, ImageDraw

    kinds = list(levels)
    cell, pad, left, top = 44, 24, 110, 40
    cols = {k: [0] + levels[k] if k != "density" else levels[k] + [2048] for k in kinds}
    err = {(r["method"], r["radius"], r["corruption"], r["level"]): r["error"] for r in rows if r["shape"] == shape}
    vals = np.array(list(err.values()))
    lo, hi = np.log10(max(vals.min(), 1e-4)), np.log10(vals.max())
    pw = {k: cell * len(cols[k]) for k in kinds}
    W = left + sum(pw.values()) + pad * len(kinds) + 90
    H = top + len(METHODS) * (cell * len(radii) + pad) + 40
    img = Image.new("RGB", (W, H), "white")
    dr = ImageDraw.Draw(img)
    dr.text((5, 5), f"{shape}: mean |phi - phi_true| over the grid (log colour); rows: radius "
                    f"{radii[0]} (top) .. {radii[-1]}", fill="black")
    for mi, m in enumerate(METHODS):
        y0 = top + mi * (cell * len(radii) + pad)
        dr.text((5, y0 + cell), m, fill="black")
        x0 = left
        for k in kinds:
            if mi == 0:
                dr.text((x0, top - 14), k, fill="black")
            for ci, lv in enumerate(cols[k]):
                for ri, r in enumerate(radii):
                    key = (m, r, "clean", 0) if (lv == 0 or (k == "density" and lv == 2048)) else (m, r, k, lv)
                    v = err.get(key)
                    if v is None:
                        continue
                    c = tuple(int(a) for a in _colour(v, lo, hi))
                    xa, ya = x0 + ci * cell, y0 + ri * cell
                    dr.rectangle([xa, ya, xa + cell - 1, ya + cell - 1], fill=c)
                    dr.text((xa + 3, ya + cell // 2 - 5), f"{v:.3f}", fill="white" if sum(c) < 350 else "black")
                if mi == len(METHODS) - 1:
                    dr.text((x0 + ci * cell + 3, y0 + cell * len(radii) + 2), str(lv), fill="black")
            x0 += pw[k] + pad
    # colour bar
    for j in range(200):
        v = 10 ** (lo + (hi - lo) * (1 - j / 199))
        dr.line([(W - 60, top + j), (W - 45, top + j)], fill=tuple(int(a) for a in _colour(v, lo, hi)))
    dr.text((W - 42, top), f"{10 ** hi:.2f}", fill="black")
    dr.text((W - 42, top + 190), f"{10 ** lo:.4f}", fill="black")
    img.save(path)


def summarize(rows, radii):
    lines = []
    for shape in ("cylinder", "sphere"):
        out = []
        for kind in ("clean", "density", "noise", "outliers", "flips"):
            sel = [r for r in rows if r["shape"] == shape and r["corruption"] == kind]
            out.append([kind] + [f"{np.mean([r['error'] for r in sel if r['method'] == m]):.4f}" for m in METHODS])
        lines.append(f"**{shape}** (mean error over radii {radii[shape]} and levels)\n\n" + table(["inputs"] + METHODS, out))
    clean = [r for r in rows if r["corruption"] == "clean"]
    avg = {m: np.mean([r["error"] for r in clean if r["method"] == m]) for m in METHODS}
    lines.append("Uncorrupted 2048-point inputs, averaged over both radius sweeps: " +
                 ", ".join(f"{m} {v:.4f}" for m, v in avg.items()) +
                 f". Targets: PAT (learned) / SSPD = {avg['PAT (learned)'] / avg['SSPD']:.2f} (target <= 0.5; "
                 f"PAT (jet) {avg['PAT (jet)'] / avg['SSPD']:.2f}); "
                 f"PAT (learned) / WN pipeline = {avg['PAT (learned)'] / avg['WN pipeline']:.2f} (target < 1; "
                 f"PAT (jet) {avg['PAT (jet)'] / avg['WN pipeline']:.2f}); "
                 f"PAT (learned) / PAT (jet) = {avg['PAT (learned)'] / avg['PAT (jet)']:.3f} (target < 1).")
    try:
        z = np.load(os.path.join(os.path.dirname(S.__file__), "pat_weights.npz"))
        m_blend = f" --m-blend {int(z['m_blend'])}" if "m_blend" in z.files else ""
        lines.append(f"Learned estimator: weights from `python scripts/train_pat.py --minutes {float(z['minutes']):.0f}"
                     f" --seed {int(z['seed'])}{m_blend}` ({int(z['steps'])} steps on {int(z['train_clouds'])} "
                     f"procedural clouds); validation loss (Eq. 5.5) {float(z['val_loss']):.5f} vs jet "
                     f"{float(z['val_loss_jet']):.5f}, distance term {float(z['val_dist']):.5f} vs jet "
                     f"{float(z['val_dist_jet']):.5f}.")
    except Exception as exc:  # pragma: no cover
        lines.append(f"(learned-weights metadata unavailable: {exc})")
    return "\n\n".join(lines)


# ---------------------------------------------------------------------------------------------- real clouds


def _closed(V, F, lo, hi):
    """(closed?, open edges inside the box, open edges on the box faces where the surface is cut)."""
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    u, c = np.unique(E, axis=0, return_counts=True)
    bad = u[c != 2]
    gap = np.minimum(np.abs(V[bad] - lo), np.abs(V[bad] - hi)).min(axis=2)  # (e, 2)
    on_box = (gap < 1e-9 * np.linalg.norm(hi - lo)).all(axis=1)
    return len(bad) == 0, int((~on_box).sum()), int(on_box.sum())


def real_clouds(args):
    import gsdf
    from gsdf.render._trace import render_png

    root = os.path.join(data_dir(), "points_3")
    rows = []
    for name, est in [(n, e) for n in ("kitten.xyz", "oni.pwn", "sphere_20k_normal.xyz") for e in ("jet", "learned")]:
        P, N = gsdf.read_points(os.path.join(root, name))
        t = time.perf_counter()
        pat = PointsAsTori(P, N, estimator=est)
        tfit = time.perf_counter() - t
        t = time.perf_counter()
        V, F = pat.isosurface(0.0, resolution=args.grid)
        tiso = time.perf_counter() - t
        lo, hi = pat.P.min(0), pat.P.max(0)
        m = 0.1 * np.linalg.norm(hi - lo)
        closed, bad, cut = _closed(V, F, lo - m, hi + m)
        extra = ""
        if name.startswith("sphere"):
            # least-squares sphere through the points: |p|² = 2 c·p + (ρ² − |c|²)
            A = np.column_stack([2 * P, np.ones(len(P))])
            sol = np.linalg.lstsq(A, (P ** 2).sum(1), rcond=None)[0]
            c, rho = sol[:3], np.sqrt(sol[3] + sol[:3] @ sol[:3])
            lo, hi = P.min(0), P.max(0)
            m = 0.1 * np.linalg.norm(hi - lo)
            X = S.grid(args.grid, 0, 1) * (hi - lo + 2 * m) + lo - m
            e = np.abs(pat(X) - (np.linalg.norm(X - c, axis=1) - rho))
            near = np.abs(np.linalg.norm(X - c, axis=1) - rho) < 0.1 * rho
            extra = f"mean error vs exact sphere (ρ={rho:.4f}) {e.mean():.5f}, within 0.1ρ of the surface {e[near].mean():.5f}"
            for mname, cls in (("SSPD", SmoothedSignedPlanarDistance), ("SHC", SignedHopfCole)):
                if est == "learned":
                    break
                ee = np.abs(cls(P, N)(X) - (np.linalg.norm(X - c, axis=1) - rho))
                extra += f"; {mname} {ee.mean():.5f}"
        trend = float("nan")
        if args.output_dir:
            png = os.path.join(args.output_dir, f"tori_real_{os.path.splitext(name)[0]}_{est}.png")
            t = time.perf_counter()
            render_png(pat, png, width=240, height=240)
            trend = time.perf_counter() - t
        rows.append([name, est, len(P), f"{tfit:.2f}", f"{tiso:.1f}", len(F), "yes" if closed else f"no: {bad} open edges inside the box, {cut} where it leaves the box",
                     f"{trend:.1f}", extra])
        print(rows[-1], flush=True)
    return table(["cloud", "estimator", "points", "fit s", f"zero set {args.grid}³ s", "triangles", "closed", "render s", "accuracy"], rows)


# ---------------------------------------------------------------------------------------------- speed


def _elephant_cloud(n, rng):
    import gsdf

    V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "elephant.off"))
    A = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    area = np.linalg.norm(A, axis=1)
    f = rng.choice(len(F), size=n, p=area / area.sum())
    u, v = rng.uniform(size=(2, n))
    s = u + v > 1
    u[s], v[s] = 1 - u[s], 1 - v[s]
    P = V[F[f, 0]] + u[:, None] * (V[F[f, 1]] - V[F[f, 0]]) + v[:, None] * (V[F[f, 2]] - V[F[f, 0]])
    return P, A[f] / area[f, None]


def speed(args):
    rng = np.random.default_rng(0)
    rows = []
    sizes = [12500, 25000, 50000, 100000] if not args.full else [12500, 25000, 50000, 100000, 200000]
    nq = 100000
    P, N = _elephant_cloud(2000, np.random.default_rng(1))  # warm-up: numba compilation/cache load is not timed
    for est in ("jet", "learned"):
        w = PointsAsTori(P, N, estimator=est)
        w.signed_distance(P[:100] + 0.01)
        w.gradient(P[:100] + 0.01)
    for n in sizes:
        P, N = _elephant_cloud(n, rng)
        lo, hi = P.min(0), P.max(0)
        # queries: half uniform in the padded box, half within 2 % of the diagonal of the surface
        diag = np.linalg.norm(hi - lo)
        Qu = rng.uniform(lo - 0.1 * diag, hi + 0.1 * diag, size=(nq // 2, 3))
        Qn = P[rng.choice(n, nq // 2)] + rng.normal(scale=0.02 * diag, size=(nq // 2, 3))
        Q = np.vstack([Qu, Qn])
        tfit, pat = median_time(lambda: PointsAsTori(P, N), repeat=1)
        tfitl, _ = median_time(lambda: PointsAsTori(P, N, estimator="learned"), repeat=1)
        tq, _ = median_time(lambda: pat.signed_distance(Q), repeat=2)
        cpu = []
        for _ in range(2):  # process CPU seconds: on a shared machine, q/s on 2 idle cores ≈ 2 nq / CPU seconds
            c0 = time.process_time()
            pat.signed_distance(Q)
            cpu.append(time.process_time() - c0)
        tcpu = float(np.median(cpu))
        pat2 = PointsAsTori(P, N, options=PointsAsToriOptions(kd_eps=0.5))
        tq2, _ = median_time(lambda: pat2.signed_distance(Q), repeat=2)
        tg, _ = median_time(lambda: pat.gradient(Q), repeat=1)
        rows.append([n, f"{tfit:.2f}", f"{tfitl:.2f}", f"{nq / tq:.3g}", f"{2 * nq / tcpu:.3g}", f"{nq / tq2:.3g}",
                     f"{nq / tg:.3g}"])
        print(rows[-1], flush=True)
    return table(["points (meshes/elephant.off resampled)", "fit s (jet)", "fit s (learned)", "queries/s (wall)",
                  "queries/s (2 × nq / CPU s)", "queries/s (kd_eps=0.5, wall)",
                  "gradient queries/s"], rows) + \
        f"\n\n{nq} queries: half uniform in the box padded by 10 % of the diagonal, half within ~2 % of the surface. " \
        f"Wall-clock rates depend on the load of the shared machine (load average at the end of this part: " \
        f"{os.getloadavg()[0]:.1f}); the CPU-time column estimates the rate on 2 idle cores (2 × queries / process " \
        f"CPU seconds of the numba-parallel call), which load inflates much less."


def speed_load(args):
    """PAT queries/s against the k-nearest-neighbour query it replaces, idle and under two busy processes.

    Issue 17, goal 5: on the same points and queries, PAT's ``signed_distance`` (fit excluded) vs
    ``scipy.spatial.cKDTree(P).query(Q, k=64, workers=-1)`` (tree build excluded), medians of ``args.repeat``;
    the same again inside ``BusyLoad(2)`` (bench/load.py: two spinning processes the benchmark starts and
    stops). The ratio under load should stay within 1.25× of the idle ratio."""
    import resource

    from scipy.spatial import cKDTree

    rng = np.random.default_rng(0)
    sizes = [50000] if args.quick else [12500, 50000, 200000]
    nq = 30000 if args.quick else 100000
    P, N = _elephant_cloud(2000, np.random.default_rng(1))
    PointsAsTori(P, N).signed_distance(P[:100] + 0.01)  # numba load / compile, not timed
    rows, ratios = [], []
    for n in sizes:
        P, N = _elephant_cloud(n, rng)
        lo, hi = P.min(0), P.max(0)
        diag = np.linalg.norm(hi - lo)
        Q = np.vstack([rng.uniform(lo - 0.1 * diag, hi + 0.1 * diag, size=(nq // 2, 3)),
                       P[rng.choice(n, nq // 2)] + rng.normal(scale=0.02 * diag, size=(nq // 2, 3))])
        pat, kd = PointsAsTori(P, N), cKDTree(P)
        for label in ("no added load", "2 busy processes"):
            def measure():
                tp, _ = median_time(lambda: pat.signed_distance(Q), repeat=args.repeat)
                tk, _ = median_time(lambda: kd.query(Q, k=64, workers=-1), repeat=args.repeat)
                return tp, tk, uptime()

            if label == "no added load":
                tp, tk, up = measure()
            else:
                with BusyLoad(2):
                    tp, tk, up = measure()
            ratios.append((n, label, tk / tp))
            rows.append([n, label, f"{nq / tp:.3g}", f"{nq / tk:.3g}", f"{tk / tp:.2f}", up])
            print(rows[-1], flush=True)
    summary = []
    for n in sizes:
        r = {lab: v for m, lab, v in ratios if m == n}
        r0, r2 = r["no added load"], r["2 busy processes"]
        summary.append(f"{n} points: ratio without added load {r0:.2f}, with 2 busy processes {r2:.2f} (the first "
                       f"over the second = {r0 / r2:.2f}; target ≤ 1.25: PAT must not collapse where the kNN does not)")
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return (table(["points (elephant.off resampled)", "machine", "PAT queries/s", "cKDTree k=64 queries/s",
                   "PAT / kNN (speed ratio)", "load average during"], rows)
            + f"\n\n{nq} queries (half uniform in the padded box, half near the surface), medians of {args.repeat}; "
            "PAT = `PointsAsTori(P, N).signed_distance(Q)` (jet estimator, fit not timed); kNN = "
            "`cKDTree(P).query(Q, k=64, workers=-1)` (build not timed). \"no added load\" is the machine as it is "
            "(on a shared machine: other jobs running, see the load column; on a quiet one, idle); \"2 busy "
            "processes\" adds bench/load.py's "
            f"BusyLoad(2). Peak RSS of this benchmark process: {rss:.0f} MB.\n\n" + "\n".join("* " + s for s in summary))


PARTS = ("speed-load", "speed", "real", "landscape")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="only the speed-under-load part, one cloud size")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--grid", type=int, default=48)
    ap.add_argument("--full", action="store_true")
    ap.add_argument("--only", default="", help=f"comma list of parts: {','.join(PARTS)} (default all)")
    ap.add_argument("--output-dir", default=None, help="folder for the landscape CSV, heatmaps and renders")
    args = ap.parse_args()
    output_dir(args.output_dir)
    parts = ["speed-load"] if args.quick else ([p for p in args.only.split(",") if p] or list(PARTS))
    for p in parts:
        if p not in PARTS:
            ap.error(f"--only: unknown part {p!r}; known: {', '.join(PARTS)}")
    flags = ("--quick" if args.quick else f"--grid {args.grid}") + (" --full" if args.full else "")
    for part in parts:
        start = uptime()
        cmd = command("bench_tori.py", [flags] + ([] if args.quick else [f"--only {part}"]),
                      python="/work/anchors/bin/python")
        if part == "speed-load":
            title, body = "Points as Tori: speed against the k-nearest-neighbour query, idle and under load", speed_load(args)
        elif part == "speed":
            title, body = "Points as Tori: speed against cloud size (Fig. 5.15 analogue)", speed(args)
        elif part == "real":
            title, body = "Points as Tori on real clouds", real_clouds(args)
        else:
            rows, radii, levels = landscapes(args)
            title = f"Points as Tori: corruption landscapes (§7.2), grid {args.grid}³ over [-1,1]³"
            body = f"Levels: {levels}; clean = 2048 points.\n\n" + summarize(rows, radii)
        text = heading(title, cmd, start) + body + "\n"
        print(text, flush=True)
        write_section(f"tori-{part}", text)


if __name__ == "__main__":
    main()
