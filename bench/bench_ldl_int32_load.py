"""Repeated surface signed heat solves with int32 vs int64 indices of L, idle and under two busy processes
(issue 17, goal 5).

One warmed-up gsdf solver and one potpourri3d solver per mesh. "i64" runs the same factors with int64 copies of
L's column pointers and row indices (the layout before int32; the arithmetic is identical, checked bit for bit),
"i32" the library's own. Rounds alternate idle / loaded (bench/load.py BusyLoad(2)), order flipped every round;
each figure is the median over rounds of common.batch_mean (≥ 0.1 s batches). Printed per mesh: ms per call,
loaded/idle of each, and the gsdf/pp3d ratio loaded over idle (goal 5: ≤ 1.25).

Run: ``PYTHONPATH=src /work/anchors/bin/python bench/bench_ldl_int32_load.py [--meshes a,shm:b] [--rounds 7]
[--write]`` (writes RESULTS section "heat-ldl-int32-load" with --write).
"""

from __future__ import annotations

import argparse
import gc
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import batch_mean, data_dir, machine, table, write_section  # noqa: E402
from load import BusyLoad  # noqa: E402

import bench_heat_surface as bhs  # noqa: E402

DEFAULT = ["ChineseDragon-10kv.off", "turbine.off", "shm:fish-unsigned.obj", "shm:hemisphere.obj",
           "mech-holes-shark.off", "cow.off", "fandisk.off"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default=",".join(DEFAULT))
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    import potpourri3d as pp3d

    from gsdf.heat import SurfaceSignedHeatSolver
    from gsdf.linalg._ldl import LDLFactorization

    start = os.popen("uptime").read().strip()
    rows = []
    for name in args.meshes.split(","):
        path = os.path.join(bhs.SHM_DATA, name[4:]) if name.startswith("shm:") else \
            os.path.join(data_dir(), "meshes", name)
        V, F, loops = bhs._speed_case(path)
        g = SurfaceSignedHeatSolver(V, F)
        ref = g.compute_distance(loops)
        facs = [o for o in gc.get_objects() if isinstance(o, LDLFactorization)]
        nfac = len(facs)
        own = [(f._lp, f._li) for f in facs]
        wide = [(lp.astype(np.int64), li.astype(np.int64)) for lp, li in own]

        def use(layout):
            for f, (lp, li) in zip(facs, layout):
                f._lp, f._li = lp, li
        p = pp3d.MeshSignedHeatSolver(V, F)
        ppl = [[(int(v), []) for v in c] for c in loops]
        p.compute_distance(ppl)
        use(wide)
        same = np.array_equal(g.compute_distance(loops), ref)
        use(own)
        res = {}
        for rnd in range(args.rounds):
            conds = (("idle", 0), ("loaded", 2)) if rnd % 2 == 0 else (("loaded", 2), ("idle", 0))
            for lab, nb in conds:
                with BusyLoad(nb):
                    for var, lay in (("i64", wide), ("i32", own)) if rnd % 2 == 0 else (("i32", own), ("i64", wide)):
                        use(lay)
                        res.setdefault((var, lab), []).append(batch_mean(lambda: g.compute_distance(loops)))
                    res.setdefault(("pp3d", lab), []).append(batch_mean(lambda: p.compute_distance(ppl)))
        use(own)
        del facs, own, wide, g, p
        gc.collect()
        m = {k: float(np.median(v)) * 1e3 for k, v in res.items()}
        lr = {v: m[(v, "loaded")] / m[(v, "idle")] for v in ("i64", "i32", "pp3d")}
        rr = {v: lr[v] / lr["pp3d"] for v in ("i64", "i32")}
        row = [name.replace("shm:", ""), nfac, "yes" if same else "NO",
               *(f"{m[(v, 'idle')]:.2f} / {m[(v, 'loaded')]:.2f}" for v in ("i64", "i32", "pp3d")),
               f"{lr['i64']:.2f} / {lr['i32']:.2f} / {lr['pp3d']:.2f}", f"{rr['i64']:.2f}", f"{rr['i32']:.2f}"]
        print(" | ".join(map(str, row)), flush=True)
        rows.append(row)
    end = os.popen("uptime").read().strip()
    text = (f"## Surface signed heat repeat solves: int32 vs int64 indices of L under two busy processes "
            f"(issue 17, goal 5)\n\n{machine()}; shared with other helpers (at start: {start}; at end: {end}). "
            f"Command: `PYTHONPATH=src /work/anchors/bin/python bench/bench_ldl_int32_load.py --rounds "
            f"{args.rounds} --write`. Same process, same factors; i64 = int64 copies of L's indices (the old "
            f"layout). Medians over {args.rounds} alternating idle/loaded rounds of ≥ 0.1 s batch means.\n\n"
            + table(["mesh", "LDL factors", "i64 result bit-identical", "gsdf i64 ms idle / loaded",
                     "gsdf i32 ms idle / loaded", "pp3d ms idle / loaded", "loaded/idle i64 / i32 / pp3d",
                     "(gsdf/pp3d) loaded over idle, i64", "same, i32"], rows))
    print(text)
    if args.write:
        write_section("heat-ldl-int32-load", text)


if __name__ == "__main__":
    main()
