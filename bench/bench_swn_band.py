"""The banded residual LP against HiGHS on the benchmark's own cases (issue 12): same mislabeled area?

``lp_algorithm="auto"`` uses the band (gsdf.linalg._band_lp) from 12k faces on. This replays the bench_swn.py cases
(same generator, ids and seeds) of the not simply connected meshes near that size, solves each with
``lp_algorithm="band"`` and ``"highs-ipm"`` (the previous rule there) and writes their errors and LP times to
section swn-band of RESULTS.md.

Usage: ``PYTHONPATH=src python3 bench/bench_swn_band.py [--meshes torus-fine,triple-torus-mc] [--per-mesh 10]``
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import bench_swn as B  # noqa: E402
from common import machine, table, write_section  # noqa: E402


def main(names, n):
    up = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    rows, same, t0 = [], 0, time.perf_counter()
    for mi, (name, load) in enumerate(B.mesh_list()):
        if name not in names:
            continue
        V, F = load()
        mc = B.MeshCases(name, V, F, seed=1000 + mi)
        for c, cid, kind, truth, g, gb, frac, nb in B.generate_cases(mc, n, "random"):
            if not np.any(gb):
                continue
            res = {}
            for alg in ("highs-ipm", "band"):
                try:
                    r = mc.swn.solve(gb, method="lp", time_limit=120, lp_algorithm=alg)
                    res[alg] = (B.mislabeled(r.face_labels, truth, mc.area), r.timings.get("lp", 0.0))
                except ValueError as exc:
                    res[alg] = (float("nan"), float("nan"))
                    print(cid, alg, "failed:", exc, flush=True)
            (eh, th), (eb, tb) = res["highs-ipm"], res["band"]
            same += int(abs(eh - eb) < 1e-12)
            rows.append([cid, mc.dec.n_faces, nb, f"{100 * eh:.3f} %", f"{100 * eb:.3f} %", f"{th:.2f}", f"{tb:.2f}",
                         f"{th / tb:.1f}" if tb > 0 else "–"])
            print(rows[-1], flush=True)
    text = ["## Surface winding numbers: banded LP vs HiGHS on the benchmark cases (issue 12)", "",
            f"Machine: {machine()}. Load at start: `{up}`. Command: `PYTHONPATH=src python3 bench/bench_swn_band.py "
            f"--meshes {','.join(names)} --per-mesh {n}` ({time.perf_counter() - t0:.0f} s). Full LP, default "
            "bounding=\"subset\"; mislabeled area as in bench_swn.py.", "",
            f"Same mislabeled area on {same} of {len(rows)} cases.", "",
            table(["case", "faces", "broken loops", "error, HiGHS interior point", "error, band", "LP s HiGHS",
                   "LP s band", "HiGHS / band"], rows)]
    write_section("swn-band", "\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", default="torus-fine,triple-torus-mc")
    ap.add_argument("--per-mesh", type=int, default=10)
    a = ap.parse_args()
    main(a.meshes.split(","), a.per_mesh)
