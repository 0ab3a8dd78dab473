"""Where the time of the global fit (gsdf.recon._globalfit.fit_to_samples) goes, per stage, on the fit inputs of
real reconstructions (bunny00 surface samples, as in bench_recon.py --only-sizes).

``--capture N,N,...`` runs ``reconstruct_simply_connected`` on N bunny samples (same draw as bench_recon's size
worker) and stores the arguments of both fit calls (before the flips, on the subdivided mesh) under --dir;
``--profile`` (default) runs the fit on every stored case ``--repeat`` times and prints the per-stage wall and
CPU seconds of the fit's report (``report["seconds"]``, ``report["cpu_seconds"]``), medians over the repeats.
``--before REV`` also runs the fit of git revision REV (its globalfit.py and relocate.py, loaded from git, with
the same stage clock put in: setup, attach = closest mesh points, surface = local_surface, assemble, solve),
alternating with the current one in the same process, and prints both and the largest difference of the
results (in spacings).

Run: ``PYTHONPATH=src /work/anchors/bin/python bench/profile_fit.py --capture 4000,16000,100000`` once, then
``PYTHONPATH=src /work/anchors/bin/python bench/profile_fit.py [--before cdd70d2]``.
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
    import gsdf.recon._globalfit as gf
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


_CLOCK = '''
_STAGES = ("setup", "attach", "surface", "assemble", "solve")


class _Clock:
    def __init__(self, report):
        import time
        self._pc, self._cpu, self._r = time.perf_counter, time.process_time, report
        self._t, self._c = self._pc(), self._cpu()

    def __call__(self, stage):
        t, c = self._pc(), self._cpu()
        self._r["seconds"][stage] += t - self._t
        self._r["cpu_seconds"][stage] += c - self._c
        self._t, self._c = t, c


def fit_to_samples('''


def old_fit(rev):
    """fit_to_samples of git revision ``rev`` (with the stage clock put in where it has none)."""
    import importlib.util
    import subprocess
    import tempfile

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    show = lambda f: subprocess.run(["git", "show", f"{rev}:src/gsdf/recon/{f}"], cwd=root, check=True,
                                    capture_output=True, text=True).stdout
    d = tempfile.mkdtemp(prefix="oldfit")
    rel = show("relocate.py").replace("from .._checks", "from gsdf._checks").replace("from ..threads", "from gsdf.threads")
    g = show("globalfit.py")
    for a, b in (("from .._checks", "from gsdf._checks"), ("from ..distance", "from gsdf.distance"),
                 ("from ..linalg", "from gsdf.linalg"), ("from ..spatial", "from gsdf.spatial"),
                 ("from ..threads", "from gsdf.threads"), ("from .relocate import", "from oldfit_relocate import")):
        g = g.replace(a, b)
    if '"seconds"' not in g:
        g = g.replace("def fit_to_samples(", _CLOCK, 1)
        g = g.replace('''"mean_shift": 0.0, "max_shift": 0.0}''', '''"mean_shift": 0.0, "max_shift": 0.0,
              "seconds": dict.fromkeys(_STAGES, 0.0), "cpu_seconds": dict.fromkeys(_STAGES, 0.0)}
    clock = _Clock(report)''', 1)
        for a, b in (("        d, face, _, bary = TriangleDistance(X, F).query_barycentric(S)\n",
                      "        clock(\"setup\")\n        d, face, _, bary = TriangleDistance(X, F).query_barycentric(S)\n"
                      "        clock(\"attach\")\n"),
                     ("        foot, nrm, _, rms = local_surface(X, S, h, k=k, tree=tree, return_fit=True)\n",
                      "        clock(\"assemble\")\n        foot, nrm, _, rms = local_surface(X, S, h, k=k, tree=tree, "
                      "return_fit=True)\n        clock(\"surface\")\n"),
                     ("        x, _ = pcg(", "        clock(\"assemble\")\n        x, _ = pcg("),
                     ("        X = x.reshape(n, 3)\n", "        clock(\"solve\")\n        X = x.reshape(n, 3)\n")):
            assert a in g, a
            g = g.replace(a, b, 1)
    mods = {}
    for name, text in (("oldfit_relocate", rel), ("oldfit_globalfit", g)):
        path = os.path.join(d, name + ".py")
        with open(path, "w") as f:
            f.write(text)
        spec = importlib.util.spec_from_file_location(name, path)
        mods[name] = importlib.util.module_from_spec(spec)
        sys.modules[name] = mods[name]
        spec.loader.exec_module(mods[name])
    return mods["oldfit_globalfit"].fit_to_samples


def _uptime():
    import subprocess
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def _line(label, tw, tc, wall, cpu, its):
    keys = list(wall[0])
    med = {s: np.median([w[s] for w in wall]) for s in keys}
    medc = {s: np.median([w[s] for w in cpu]) for s in keys}
    return (f"  {label:7s} total {np.median(tw):6.2f} s wall / {np.median(tc):6.2f} s cpu;  "
            + "  ".join(f"{s} {med[s]:.2f}/{medc[s]:.2f}" for s in keys) + f"  cg {its}")


def compare(d, repeat, rev, only=None, write=False):
    from gsdf.recon._globalfit import fit_to_samples

    out = []

    def say(line):
        print(line, flush=True)
        out.append(line)

    up0, t0 = _uptime(), time.perf_counter()

    fits = {"before": old_fit(rev), "after": fit_to_samples}
    files = sorted(glob.glob(os.path.join(d, "*.npz")), key=lambda f: (int(f.split("bunny")[1].split("_")[0]), f))
    if only:
        files = [f for f in files if any(f"bunny{o}_" in f for o in only)]
    say(f"per stage: median wall / cpu seconds over {repeat} alternating runs; before = {rev}")
    for f in files:
        z = np.load(f)
        V, F, S, h, k = z["V"], z["F"], z["S"], float(z["spacing"]), int(z["k"])
        for fit in fits.values():
            fit(V, F[:200], S[:500], h, k=k, iterations=1)
        res = {lab: ([], [], [], [], None, None) for lab in fits}
        for _ in range(repeat):
            for lab, fit in fits.items():
                tw, tc, wall, cpu, _, _ = res[lab]
                t, c = time.perf_counter(), time.process_time()
                X, rep = fit(V, F, S, h, k=k, return_report=True)
                tw.append(time.perf_counter() - t)
                tc.append(time.process_time() - c)
                wall.append(rep["seconds"])
                cpu.append(rep["cpu_seconds"])
                res[lab] = (tw, tc, wall, cpu, rep["cg_iterations"], X)
        dx = np.linalg.norm(res["before"][5] - res["after"][5], axis=1).max() / h
        say(f"{os.path.basename(f)[:-4]}: {len(V)} vertices, {len(S)} samples; max |x_after - x_before| = "
            f"{dx:.1e} spacings; whole fit after / before: wall "
            f"{np.median(res['after'][0]) / np.median(res['before'][0]):.3f}, cpu "
            f"{np.median(res['after'][1]) / np.median(res['before'][1]):.3f}")
        for lab in fits:
            say(_line(lab, *res[lab][:5]))
    if write:
        from common import machine, write_section
        cmd = (f"PYTHONPATH=src /work/anchors/bin/python bench/profile_fit.py --before {rev} --repeat {repeat} --write")
        write_section("recon-fit-stages", "## recon-fit-stages: where the time of the global fit goes, per stage, "
                      "before / after (issue 13)\n\n"
                      f"Machine: {machine()}. Load at start: `{up0}`; at the end: `{_uptime()}`. Command: `{cmd}` "
                      f"({time.perf_counter() - t0:.0f} s), after `PYTHONPATH=src /work/anchors/bin/python "
                      "bench/profile_fit.py --capture 4000,16000,100000` (the arguments of both fit calls of "
                      "`reconstruct_simply_connected` on N bunny00 samples, as in section recon-time: `_0` before the "
                      "flips, `_1` on the subdivided mesh).  Stages: setup (k-d tree, edge pattern, relabelling), "
                      "attach (closest mesh point of every sample), surface (MLS foot of every vertex, "
                      "`relocate.local_surface`), assemble (normal equations), solve (block-Jacobi CG); 4 rounds.  "
                      "Before = the fit of the given revision loaded from git, after = the working tree, alternating "
                      "in one process.\n\n```\n" + "\n".join(out) + "\n```")


def profile(d, repeat, only=None):
    from gsdf.recon._globalfit import fit_to_samples

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
    ap.add_argument("--before", default=None, metavar="REV")
    ap.add_argument("--write", action="store_true", help="with --before: write section recon-fit-stages")
    a = ap.parse_args()
    os.makedirs(a.dir, exist_ok=True)
    if a.capture:
        capture([int(x) for x in a.capture.split(",")], a.dir)
    elif a.before:
        compare(a.dir, a.repeat, a.before, a.only.split(",") if a.only else None, a.write)
    else:
        profile(a.dir, a.repeat, a.only.split(",") if a.only else None)
