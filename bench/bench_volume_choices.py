"""The measured choices behind the grid signed heat method's defaults (issue 17, goal 6), on the 10 inputs of
bench_heat_volume_speed.py:

* ``tol``      Step III's CG tolerance (GridPoisson.penalty_tol): iterations, time, mean error at 1e-4 / 1e-3 / 3e-3;
* ``step1``    Step I by the Yukawa tree sum or by the screened grid solve: time and mean error at 32³ (10
               inputs) and 64³ (5 meshes);
* ``threads``  point areas on one thread or on the threads (point_areas.SERIAL_POINTS, knn.PARALLEL_POINTS):
               whole volume solve at 32³, rounds alternating idle / two busy processes (bench/load.py);
* ``penalty``  the soft-penalty matrix (penalty_matrix, one trilinear row per source) against SciPy's product.

Errors are mean |φ − φ_ref| over the grid nodes against the exact signed distance, as in
bench_heat_volume_speed.py. Times are medians of repeated calls in this process (numba kernels loaded first).

    PYTHONPATH=src python3 bench/bench_volume_choices.py [--only tol,step1,threads,penalty] [--rounds 10]

Writes RESULTS section "volume-choices" (only when every part ran).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from bench_heat_volume_speed import ALL, box_of, load_input  # noqa: E402
from common import machine, table, write_section  # noqa: E402
from load import BusyLoad, uptime  # noqa: E402

import gsdf  # noqa: E402
from gsdf.grid import grid_points  # noqa: E402
from gsdf.heat.grid._domain import GridPoisson  # noqa: E402
from gsdf.heat.grid import _poisson as G  # noqa: E402
from gsdf.heat.volume import signed_heat_volume  # noqa: E402
from gsdf.heat.volume import _sources as S  # noqa: E402
from gsdf.linalg import _iterative as iterative  # noqa: E402
from gsdf.spatial import _knn as knn  # noqa: E402
from gsdf.winding import _point_areas as pa  # noqa: E402

MESHES_64 = ["holes.off", "elephant-with-holes.off", "fandisk.off", "couplingdown.off", "bunny00 −30 % faces"]
CLOUDS = ["hippo1.ply", "kitten.xyz", "oni.pwn"]


def case(name, res):
    kw, ref, is_mesh = load_input(name)
    lo, hi, shape = box_of(kw, res)
    Q = grid_points(lo, hi, shape)
    phi_ref = gsdf.signed_distance(*ref, Q) if is_mesh else gsdf.signed_distance_points(*ref, Q)
    return kw, (lo, hi, shape), phi_ref


def solve(kw, box, **opt):
    lo, hi, shape = box
    G._dct_matrix.cache_clear()
    return signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, **kw, **opt)


def timed(kw, box, repeat=5, **opt):
    ts, f = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        f = solve(kw, box, **opt)
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), f


def part_tol():
    iters = []
    real = iterative.cg_loop

    def counting(matvec, psolve, b, x0, **kw):
        n = [0]

        def ps(r):
            n[0] += 1
            return psolve(r)
        out = real(matvec, ps, b, x0, **kw)
        iters.append(n[0])
        return out

    rows, default = [], GridPoisson.penalty_tol
    iterative.cg_loop = counting
    try:
        for name in ALL:
            kw, box, ref = case(name, 32)
            row = [name]
            for tol in (1e-4, 1e-3, 3e-3):
                GridPoisson.penalty_tol = tol
                iters.clear()
                t, f = timed(kw, box)
                row.append(f"{iters[-1]} / {1e3 * t:.1f} / {np.abs(f.values.ravel() - ref).mean():.6f}")
            rows.append(row)
    finally:
        iterative.cg_loop = real
        GridPoisson.penalty_tol = default
    return ["### Step III CG tolerance at 32³: iterations / ms / mean error", "",
            f"Default: {default:g}.", "",
            table(["input", "1e-4", "1e-3", "3e-3"], rows), ""]


def part_step1():
    rows = []
    for res, names in ((32, ALL), (64, MESHES_64)):
        for name in names:
            kw, box, ref = case(name, res)
            row = [name, res]
            errs = []
            for s1 in ("yukawa", "heat"):
                t, f = timed(kw, box, repeat=3 if res == 64 else 5, step1=s1)
                errs.append(np.abs(f.values.ravel() - ref).mean())
                row += [f"{1e3 * t:.1f}", f"{errs[-1]:.6f}"]
            auto = solve(kw, box).meta["step1"]
            rows.append(row + [f"{100 * (errs[1] / errs[0] - 1):+.2f} %", auto])
    return ["### Step I: Yukawa tree sum against the screened grid solve", "",
            table(["input", "grid", "tree ms", "tree err", "grid-solve ms", "grid-solve err", "err change",
                   "default (auto)"], rows), ""]


def part_threads(rounds):
    cases = {name: case(name, 32)[:2] for name in CLOUDS}
    serial = (pa.SERIAL_POINTS, knn.PARALLEL_POINTS)
    res = {}
    try:
        for r in range(rounds):
            for load in ((0, 2) if r % 2 == 0 else (2, 0)):
                with BusyLoad(load):
                    for mode in ("one thread", "threads"):
                        pa.SERIAL_POINTS, knn.PARALLEL_POINTS = (10 ** 9, 10 ** 9) if mode == "one thread" else serial
                        for name, (kw, box) in cases.items():
                            res.setdefault((name, load, mode), []).append(timed(kw, box, repeat=7)[0])
    finally:
        pa.SERIAL_POINTS, knn.PARALLEL_POINTS = serial
    rows = []
    for name in cases:
        row = [name]
        for load in (0, 2):
            a, b = (np.median(res[(name, load, m)]) for m in ("one thread", "threads"))
            row += [f"{1e3 * a:.1f} → {1e3 * b:.1f}", f"{b / a:.2f}"]
        rows.append(row)
    return [f"### Point areas on one thread → on the threads: whole volume solve at 32³, ms (median of {rounds} "
            "rounds, each the median of 7 calls)", "",
            f"Defaults: point_areas.SERIAL_POINTS = {serial[0]}, knn.PARALLEL_POINTS = {serial[1]}.", "",
            table(["cloud", "idle", "ratio", "two busy processes", "ratio"], rows), ""]


def part_penalty():
    import scipy.sparse as sp

    rows = []
    for name in ("hippo1.ply", "oni.pwn", "fandisk.off", "bunny00 −30 % faces"):
        kw, box, _ = case(name, 32)
        lo, hi, shape = box
        src = S.point_sources(*kw["points"]) if "points" in kw else S.mesh_sources(*kw["mesh"])
        T = G.trilinear_matrix(src.B, lo, (np.asarray(hi) - lo) / (np.array(shape) - 1), shape)
        P = G.penalty_matrix(T, src.a, shape)
        R = (T.T @ sp.diags(src.a) @ T).tocsr()
        ts = {}
        for lab, fn in (("gsdf", lambda: G.penalty_matrix(T, src.a, shape)),
                        ("scipy", lambda: (T.T @ sp.diags(src.a) @ T).tocsr())):
            v = []
            for _ in range(30):
                t = time.perf_counter()
                fn()
                v.append(time.perf_counter() - t)
            ts[lab] = float(np.median(v))
        rows.append([name, T.shape[0], f"{1e3 * ts['gsdf']:.2f}", f"{1e3 * ts['scipy']:.2f}",
                     f"{abs(P - R).max() / abs(R).max():.1e}"])
    return ["### Soft-penalty matrix Tᵀ diag(a) T at 32³ (one trilinear row per source)", "",
            table(["input", "rows", "penalty_matrix ms", "SciPy product ms", "max rel. difference"], rows), ""]


def main(argv):
    only = next((a.split("=", 1)[1].split(",") for a in argv if a.startswith("--only=")), None)
    rounds = int(next((a.split("=", 1)[1] for a in argv if a.startswith("--rounds=")), 10))
    parts = only or ["tol", "step1", "threads", "penalty"]
    C = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1, -1], [0.5, -1, 0.2]])
    signed_heat_volume(points=(C, C), resolution=6)        # numba kernels loaded before any timing
    signed_heat_volume(mesh=(C, np.array([[0, 1, 2], [0, 2, 3], [1, 3, 4]])), resolution=6)
    t0, start = time.perf_counter(), uptime()
    text = ["## Volume signed heat: the measured choices behind its defaults (issue 17, goal 6)", "",
            f"Machine: {machine()}. Command: `PYTHONPATH=src python3 bench/bench_volume_choices.py "
            f"{' '.join(argv)}`.".replace(" `.", "`."), ""]
    fns = {"tol": part_tol, "step1": part_step1, "threads": lambda: part_threads(rounds), "penalty": part_penalty}
    for p in parts:
        if p not in fns:
            raise SystemExit(f"--only: unknown part {p!r}; expected some of {sorted(fns)}")
        block = fns[p]()
        print("\n".join(block), flush=True)
        text += block
    text.append(f"Took {time.perf_counter() - t0:.0f} s; {start} at start, {uptime()} at end.")
    if only is None:
        write_section("volume-choices", "\n".join(text))


if __name__ == "__main__":
    main(sys.argv[1:])
