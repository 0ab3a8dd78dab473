"""Build of the shared triangle tree (what gsdf.signed_distance builds: tree, wide view, distance packets, fast
winding moments) before / after a change and against the peers' builds (Warp CPU, fcpw, Open3D/Embree).

    PYTHONPATH=src /work/anchors/bin/python bench/bench_build.py --peers warp,fcpw,open3d
    PYTHONPATH=src python3 bench/bench_build.py --before /path/to/old/src --what bvh   # the binned tree alone

"before" and "after" run in two worker processes (PYTHONPATH = --before / this checkout's src), asked in turn
for one build at a time, the peers in the calling process: interleaved, median of --reps, wall and CPU seconds
(CPU of the whole worker process: both threads). Prints load, the ratios and the log-log slope of build time
against faces. Meshes from the CGAL data (``loopK:name`` = K Loop subdivisions, ``soup:name`` = the soup of
bench_sdf_peers.py).
"""

import argparse
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.environ.get("GSDF_CGAL_DATA", "/work/cgal/data") + "/meshes/"


def worker():
    """Read 'mesh what' lines, reply 'wall cpu faces' of one build."""
    import numba

    from gsdf._checks import as_mesh
    from gsdf._normalize import Frame
    from gsdf.distance import TriangleDistance
    from gsdf.spatial import _triangle_tree as T
    from gsdf.spatial._bvh import build_volume_bvh
    from gsdf.spatial._triangle_tree import triangle_tree
    from gsdf.winding import FastWindingNumber

    def full(V, F):
        V1, F1 = as_mesh(V, F)
        tt = triangle_tree(V1, F1)
        return TriangleDistance._of_tree(V1, F1, tt), FastWindingNumber._of_tree(tt, beta=2.0, order=2)

    def bvh(V, F):
        V1, F1 = as_mesh(V, F)
        fr = Frame.of_mesh(V1, F1)
        E, rt = T.triangle_elements_root(np.ascontiguousarray(fr.geometry(V1)), F1)
        numba.set_num_threads(1)
        try:
            a, c = time.perf_counter(), time.process_time()
            build_volume_bvh(E, 4, rt)
            return time.perf_counter() - a, time.process_time() - c
        finally:
            numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)

    print("ready", flush=True)
    for line in sys.stdin:
        name, what = line.split()
        V, F = mesh(name)
        if what == "bvh":
            w, c = bvh(V, F)
        else:
            a, cc = time.perf_counter(), time.process_time()
            full(V, F)
            w, c = time.perf_counter() - a, time.process_time() - cc
        print(f"{w} {c} {len(F)}", flush=True)


_CACHE = {}


def mesh(name):
    import gsdf

    if name not in _CACHE:
        if name.startswith("loop"):
            import igl

            k, nm = name[4:].split(":")
            V, F = gsdf.read_mesh(ROOT + nm)
            V, F = igl.loop(V, F.astype(np.int64), int(k))
            _CACHE[name] = (np.ascontiguousarray(V), np.ascontiguousarray(F))
        elif name.startswith("soup:"):
            sys.path.insert(0, HERE)
            from bench_sdf_peers import soup_of

            _CACHE[name] = soup_of(*gsdf.read_mesh(ROOT + name[5:]))
        else:
            _CACHE[name] = gsdf.read_mesh(ROOT + name)
    return _CACHE[name]


MESHES = ("rotor.off,elephant-with-holes.off,holes.off,fandisk.off,camel.off,fandisk_large.off,armadillo.off,"
          "soup:bunny00.off,bunny00.off,refined_elephant.off,loop2:bunny00.off")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", default=MESHES)
    ap.add_argument("--what", default="full", choices=["full", "bvh"])
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--peers", default="", help="comma-separated: warp, fcpw, open3d")
    ap.add_argument("--before", default="/work/main/src", help="the old code's src folder")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        return worker()
    after_src = os.path.join(os.path.dirname(HERE), "src")

    def spawn(src, cache=None):
        env = dict(os.environ, PYTHONPATH=src)
        if cache:
            env["NUMBA_CACHE_DIR"] = cache  # the old code's kernels compile here, not into its tree
        p = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker"], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True, env=env)
        assert p.stdout.readline().startswith("ready")
        return p

    W = {"before": spawn(a.before, "/tmp/gsdf_bench_build_before"), "after": spawn(after_src)}

    def ask(p, m, w):
        p.stdin.write(f"{m} {w}\n")
        p.stdin.flush()
        wall, cpu, nf = p.stdout.readline().split()
        return float(wall), float(cpu), int(nf)

    if a.peers:
        sys.path.insert(0, HERE)
        import bench_sdf_peers as B
    print(os.popen("uptime").read().strip())
    rows = []
    for m in a.meshes.split(","):
        for p in W.values():
            ask(p, m, a.what)
            ask(p, m, a.what)  # warm: pages, caches
        res = {k: [] for k in W}
        pt = {}
        if a.peers:
            V, F = mesh(m)
            for tname in a.peers.split(","):
                fn = {"warp": B.warp_tool, "fcpw": B.fcpw_tool, "open3d": B.open3d_tool}[tname]("build", V, F, None)
                fn()
                pt[tname] = fn
                res[tname] = []
        nf = 0
        for r in range(a.reps):
            order = list(W) + list(pt)
            order = order[r % len(order):] + order[:r % len(order)]
            for k in order:
                if k in W:
                    wall, cpu, nf = ask(W[k], m, a.what)
                else:
                    t0 = time.perf_counter()
                    pt[k]()
                    wall, cpu = time.perf_counter() - t0, float("nan")
                res[k].append((wall, cpu))
        med = {k: np.median(np.array(v), axis=0) for k, v in res.items()}
        fastest = min((med[k][0] for k in pt), default=float("nan"))
        print(f"{m:24s} {nf:8d} " + " ".join(f"{k}={v[0]*1e3:.1f}ms(cpu {v[1]*1e3:.1f})" for k, v in med.items())
              + f"  after/before={med['after'][0]/med['before'][0]:.2f}"
              + (f" after/fastest_peer={med['after'][0]/fastest:.2f}" if pt else "")
              + "  load" + os.popen("uptime").read().strip().split("load")[1], flush=True)
        rows.append((nf, {k: v[0] for k, v in med.items()}))
    if len(rows) > 2:
        x = np.log([r[0] for r in rows])
        for k in rows[0][1]:
            print(f"log-log slope of build wall time vs faces, {k}: "
                  f"{np.polyfit(x, np.log([r[1][k] for r in rows]), 1)[0]:.2f}")


if __name__ == "__main__":
    main()
