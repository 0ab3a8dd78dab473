"""Unsigned and signed distance: gsdf against libigl on the CGAL meshes, in one process run.

    VENV/bin/python bench/bench_distance.py [--queries N]

For each mesh: time of gsdf's TriangleDistance (build + query) against igl.point_mesh_squared_distance for N
random queries in the padded bounding box (medians of 3), the largest distance difference, and the
agreement of winding-number signing with igl.signed_distance (winding-number sign) on the same queries.
Writes the table to bench/RESULTS.md (section "distance").
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import command, data_dir, heading, machine, median_time, table, write_section  # noqa: E402

import gsdf  # noqa: E402

MESHES = ["bunny00.off", "refined_elephant.off", "holes.off", "elephant-with-holes.off", "mech-holes-shark.off"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=200_000)
    args = ap.parse_args()
    import igl

    root = data_dir()
    rng = np.random.default_rng(0)
    from load import uptime

    start = uptime()
    print("machine:", machine(), start, flush=True)
    t0 = time.time()
    rows = []
    for name in MESHES:
        V, F = gsdf.read_mesh(os.path.join(root, "meshes", name))
        lo, hi = V.min(0), V.max(0)
        Q = rng.uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), (args.queries, 3))
        gsdf.TriangleDistance(V, F).query(Q[:100])
        igl.point_mesh_squared_distance(Q[:100], V, F)
        t_g, (d, _, _) = median_time(lambda: gsdf.TriangleDistance(V, F).query(Q))
        t_i, (d2, _, _) = median_time(lambda: igl.point_mesh_squared_distance(Q, V, F))
        s = gsdf.signed_distance(V, F, Q[:20000], sign="winding")
        si = igl.signed_distance(Q[:20000], V, F, igl.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER)[0]
        agree = np.mean(np.sign(s) == np.sign(si)) * 100
        rows.append([name, len(F), f"{t_g:.3f}", f"{t_i:.3f}", f"{t_g / t_i:.2f}",
                     f"{np.abs(d - np.sqrt(d2)).max():.1e}", f"{agree:.3f} %"])
        print(rows[-1], flush=True)
    header = ["mesh", "faces", f"gsdf {args.queries:.0e} q s (build+query)", "igl s", "ratio", "max |Δd|",
              "sign agrees with igl (winding)"]
    cmd = command("bench_distance.py", [f"--queries {args.queries}"], python="/work/anchors/bin/python")
    text = (heading("Distance to triangle meshes against libigl", cmd, start)
            + f"Run took {time.time() - t0:.0f} s. Medians of 3 runs in one process.\n\n{table(header, rows)}\n")
    write_section("distance", text)
    print(text)


if __name__ == "__main__":
    main()
