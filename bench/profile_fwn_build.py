"""Stage profile of the fast triangle winding number build (FastWindingNumber.__init__), wall and CPU.

    NUMBA_NUM_THREADS=2 PYTHONPATH=src python3 bench/profile_fwn_build.py [--repeat 7] [mesh.off ...]

Times each stage of the build with time.perf_counter (wall) and time.process_time (CPU of all threads):
validation + frame, the element rows, the tree (root bounds, top levels, subtree tasks, splice), the moments,
the wide lanes. Medians over ``--repeat`` builds after one warm-up build; "total" is a plain
FastWindingNumber(V, F) timed the same way (its stages are not the sum of parts exactly: the profiled run
repeats the calls with timers between them; the third column counts minor page faults (first touches of
fresh memory, ~1 µs each on the 2-core VM); "threads in f" is the wall / CPU of f's run_tasks calls, the
thread-parallel parts). Prints one table per mesh.
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time
from collections import defaultdict

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import data_dir  # noqa: E402

import gsdf  # noqa: E402
from gsdf.spatial import _binned as binned, _bvh as bvh  # noqa: E402
from gsdf.winding import _fast as fast  # noqa: E402

MESHES = ["refined_elephant.off", "armadillo.off", "man.off", "bunny00.off"]

_acc = defaultdict(list)
_cur = {}


class stage:
    def __init__(self, name):
        self.name = name

    def __enter__(self):
        self.t = time.perf_counter(), time.process_time(), resource.getrusage(resource.RUSAGE_SELF).ru_minflt

    def __exit__(self, *exc):
        w, c = time.perf_counter() - self.t[0], time.process_time() - self.t[1]
        f = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - self.t[2]
        a = _cur.setdefault(self.name, [0.0, 0.0, 0.0])
        a[0] += w
        a[1] += c
        a[2] += f * 1e-3


def _wrap(mod, name, label):
    fn = getattr(mod, name)

    def wrapped(*a, **k):
        with stage(label):
            return fn(*a, **k)

    wrapped.__wrapped__ = fn
    setattr(mod, name, wrapped)


def install():
    """Timers around the build's stages (module attributes looked up at call time)."""
    _wrap(fast, "as_mesh", "validate")
    _wrap(fast.Frame, "of_mesh", "frame")
    _wrap(fast, "_triangle_elements_root", "elements")
    _wrap(binned, "_root_bounds", "tree: root bounds")
    _wrap(binned, "_parallel_grow", "tree: top + subtrees")
    _wrap(binned, "_splice", "tree: splice")
    _wrap(binned, "_skips", "tree: skips")
    _wrap(fast, "build_volume_bvh", "tree (all)")
    _wrap(fast, "_tree_moments", "moments")
    _wrap(fast, "widen", "lanes: widen")
    _wrap(fast, "_pack_wide", "lanes (all)")
    _wrap(fast, "_node_moments_list", "moments: nodes above")
    from gsdf import threads

    def labelled(fn):
        def wrapped(*a, **k):
            caller = sys._getframe(1).f_code.co_name
            if caller == "run_ranges":  # name the function that asked for the ranges
                caller = sys._getframe(2).f_code.co_name
            with stage("threads in " + caller):
                return fn(*a, **k)

        wrapped.__wrapped__ = fn
        return wrapped

    for mod in (threads, fast):
        mod.run_tasks = labelled(mod.run_tasks)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("meshes", nargs="*", default=MESHES)
    args = ap.parse_args(argv)
    import numba

    root = data_dir()
    print(f"threads {numba.get_num_threads()}, medians of {args.repeat} builds (ms wall, ms CPU, minor page faults)")
    for name in args.meshes:
        V, F = gsdf.read_mesh(os.path.join(root, "meshes", name))
        gsdf.FastWindingNumber(V, F)
        tot = []
        for _ in range(args.repeat):
            t = time.perf_counter(), time.process_time()
            gsdf.FastWindingNumber(V, F)
            tot.append((time.perf_counter() - t[0], time.process_time() - t[1]))
        install()
        runs = []
        for _ in range(args.repeat):
            _cur.clear()
            with stage("build (profiled)"):
                gsdf.FastWindingNumber(V, F)
            runs.append(dict(_cur))
        uninstall()
        print(f"\n{name} ({len(F)} faces)")
        w, c = np.median(np.array(tot), axis=0) * 1e3
        print(f"  {'total (unprofiled)':28s} {w:7.2f} {c:7.2f}")
        for key in runs[0]:
            a = np.median(np.array([r.get(key, [0, 0, 0]) for r in runs]), axis=0) * 1e3
            print(f"  {key:28s} {a[0]:7.2f} {a[1]:7.2f} {a[2]:7.0f}")


def uninstall():
    for mod in (fast, fast.Frame, binned, bvh, sys.modules["gsdf.threads"]):
        for name, val in list(vars(mod).items()):
            if hasattr(val, "__wrapped__") and callable(val) and getattr(val, "__name__", "") == "wrapped":
                setattr(mod, name, val.__wrapped__)


if __name__ == "__main__":
    main()
