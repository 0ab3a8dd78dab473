"""Where the time of the global fit (gsdf.recon.globalfit.fit_to_samples) goes, per stage, on the fit inputs of
real reconstructions (bunny00 surface samples, as in bench_recon.py --only-sizes).

``--capture N,N,...`` runs ``reconstruct_simply_connected`` on N bunny samples (same draw as bench_recon's size
worker) and stores the arguments of both fit calls (before the flips, on the subdivided mesh) under --dir;
``--profile`` (default) runs the fit on every stored case ``--repeat`` times and prints the per-stage wall and
CPU seconds of the fit's report (``report["seconds"]``, ``report["cpu_seconds"]``), medians over the repeats.

Run: ``PYTHONPATH=src /work/anchors/bin/python bench/profile_fit.py --capture 4000,16000,100000`` once, then
``PYTHONPATH=src /work/anchors/bin/python bench/profile_fit.py``.
"""
from __future__ import annotations

import argparse
import glob
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def capture(sizes, out):
    import gsdf
    import gsdf.recon.globalfit as gf
    from bench_recon import normalise, sample_surface
    from common import data_dir

    orig = gf.fit_to_samples
    for n in sizes:
        calls = []

        def spy(V, F, S, spacing, **kw):
            calls.append((np.array(V), np.array(F), np.array(S), spacing, kw.get("k", 8)))
            t = time.perf_counter()
            r = orig(V, F, S, spacing, **kw)
            print(f"  fit call {len(calls)}: {len(V)} vertices, {len(S)} samples, {time.perf_counter() - t:.2f} s",
                  flush=True)
            return r

        gf.fit_to_samples = spy
        rng = np.random.default_rng(n)
        V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "bunny00.off"))
        P, _ = sample_surface(normalise(V), F, n, rng)
        t = time.perf_counter()
        _, _, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
        print(n, f"whole call {time.perf_counter() - t:.1f} s", {k: round(v, 2) for k, v in rep["timings"].items()},
              flush=True)
        for i, (V, F, S, h, k) in enumerate(calls):
            np.savez(os.path.join(out, f"bunny{n}_{i}.npz"), V=V, F=F, S=S, spacing=h, k=k)
    gf.fit_to_samples = orig


def profile(d, repeat, only=None):
    from gsdf.recon.globalfit import fit_to_samples

    files = sorted(glob.glob(os.path.join(d, "*.npz")), key=lambda f: (int(f.split("bunny")[1].split("_")[0]), f))
    if only:
        files = [f for f in files if any(f"bunny{o}_" in f for o in only)]
    tot = {}
    for f in files:
        z = np.load(f)
        V, F, S, h, k = z["V"], z["F"], z["S"], float(z["spacing"]), int(z["k"])
        fit_to_samples(V, F[:200], S[:500], h, k=k, iterations=1)           # compile outside the timing
        wall, cpu, tw, tc, its = [], [], [], [], None
        for _ in range(repeat):
            t, c = time.perf_counter(), time.process_time()
            X, rep = fit_to_samples(V, F, S, h, k=k, return_report=True)
            tw.append(time.perf_counter() - t)
            tc.append(time.process_time() - c)
            wall.append(rep["seconds"])
            cpu.append(rep["cpu_seconds"])
            its = rep["cg_iterations"]
        name = os.path.basename(f)[:-4]
        keys = list(wall[0])
        med = {s: np.median([w[s] for w in wall]) for s in keys}
        medc = {s: np.median([w[s] for w in cpu]) for s in keys}
        print(f"{name:16s} v={len(V):7d} s={len(S):7d} total {np.median(tw):6.2f} s wall / {np.median(tc):6.2f} s cpu;  "
              + "  ".join(f"{s} {med[s]:.2f}/{medc[s]:.2f}" for s in keys) + f"  cg {its}", flush=True)
        tot[name] = (np.median(tw), X)
    return tot


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--capture", default=None)
    ap.add_argument("--dir", default="/tmp/fitcases")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", default=None)
    a = ap.parse_args()
    os.makedirs(a.dir, exist_ok=True)
    if a.capture:
        capture([int(x) for x in a.capture.split(",")], a.dir)
    else:
        profile(a.dir, a.repeat, a.only.split(",") if a.only else None)
