"""Fast winding numbers under load, per mesh, with interleaved rounds (issue 17 goal 5).

bench_winding.py --load times medians of 3 single calls idle, then 3 under load: a ~0.1 s call is either not
preempted or loses a whole time slice, so its loaded/idle ratio swings (e.g. couplingdown.off 0.84 in one run,
1.75 in the next). Here each sample is gsdf (build + 10^5 queries) and libigl on the same queries, timed back to
back, and rounds alternate idle / loaded (bench/load.py BusyLoad(2)); the ratio per round is gsdf / libigl.

    NUMBA_NUM_THREADS=2 PYTHONPATH=src /work/anchors/bin/python bench/bench_winding_load.py --meshes couplingdown.off,man.off
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from common import alternating_rounds, data_dir, machine, table, write_section  # noqa: E402
from load import uptime  # noqa: E402

import gsdf  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="couplingdown.off,man.off,holes.off,elephant-with-holes.off,bunny00.off")
    ap.add_argument("--queries", type=int, default=100_000)
    ap.add_argument("--rounds", type=int, default=7)
    a = ap.parse_args(argv)
    import igl
    root = data_dir()
    rng = np.random.default_rng(0)
    rows, start = [], uptime()
    for name in a.meshes.split(","):
        V, F = gsdf.read_mesh(os.path.join(root, "meshes", name))
        lo, hi = V.min(0), V.max(0)
        pad = 0.1 * (hi - lo)
        Q = rng.uniform(lo - pad, hi + pad, (a.queries, 3))
        g = lambda: gsdf.FastWindingNumber(V, F)(Q)         # noqa: E731
        i = lambda: igl.fast_winding_number(V, F, Q)         # noqa: E731
        g(), i()
        t = alternating_rounds({"gsdf": g, "igl": i}, a.rounds)
        ratios = {m: np.array(t[m, "gsdf"]) / np.array(t[m, "igl"]) for m in ("idle", "loaded")}
        mi, ml = float(np.median(ratios["idle"])), float(np.median(ratios["loaded"]))
        q = lambda x: f"{np.percentile(x, 25):.2f}–{np.percentile(x, 75):.2f}"  # noqa: E731
        rows.append((name, len(F), f"{mi:.2f}", q(ratios["idle"]), f"{ml:.2f}", q(ratios["loaded"]),
                     f"**{ml / mi:.2f}**"))
        print(rows[-1], flush=True)
    cmd = ("NUMBA_NUM_THREADS=2 PYTHONPATH=src /work/anchors/bin/python bench/bench_winding_load.py "
           f"--meshes {a.meshes} --queries {a.queries} --rounds {a.rounds}")
    text = (f"## Fast winding numbers under load, interleaved rounds (issue 17 goal 5)\n\n{machine()} Load at start: "
            f"{start}; at end: {uptime()}. Command: `{cmd}`.\n\nPer round: gsdf (tree build + {a.queries:,} "
            "queries) over libigl's `fast_winding_number` on the same queries, each timed as a batch of calls "
            "≥ 0.1 s; rounds alternate idle and loaded (two busy processes, bench/load.py). Medians and "
            "interquartile ranges of the per-round ratios.\n\n"
            + table(["mesh", "faces", "idle ratio", "idle IQR", "loaded ratio", "loaded IQR", "loaded / idle"], rows))
    write_section("winding-load-rounds", text)


if __name__ == "__main__":
    main()
