"""Signed distance and occupancy: gsdf against Open3D, Warp (CPU), fcpw, pysdf, mesh2sdf, mesh-to-sdf, libigl and
point-cloud-utils, every tool in one process run on the same inputs.

    PYOPENGL_PLATFORM=egl PYTHONPATH=src /work/anchors/bin/python bench/bench_sdf_peers.py            # full
    PYOPENGL_PLATFORM=egl PYTHONPATH=src /work/anchors/bin/python bench/bench_sdf_peers.py --quick    # minutes
    PYTHONPATH=src /work/anchors/bin/python bench/bench_sdf_peers.py --scaling                        # slopes

Workloads (each timed as build + query, the acceleration structure built afresh in every call):

* ``build``   the acceleration structure alone (gsdf: what ``gsdf.signed_distance`` builds);
* ``sd1e5`` / ``sd1e6``   signed distance at 1e5 / 1e6 uniform random points in the padded box
  (:func:`gsdf.grid.padded_box`: the bounding box grown by 0.1 of its diagonal);
* ``grid``    signed distance on the nodes of a 128^3 grid over the padded box made cubic (64^3 with --quick);
* ``occ1e5`` / ``occ1e6``   inside / outside at 1e5 / 1e6 random points.

Every (mesh, workload) runs every tool ``--reps`` times, the tools' order rotating between repetitions
(interleaved), and keeps the median; a call slower than ``--slow`` seconds is not repeated, and a tool whose
previous workload predicts more than ``--cap`` seconds is skipped ("skip"). Input format conversions (float32
copies, fcpw's point lists) are prepared before the clock starts. ``--load both`` (default) runs each mesh's
block idle and then with two busy processes (bench/load.py BusyLoad(2)).

Accuracy, on up to 2e5 of the points of a workload: "wrong sign" = % of points whose inside/outside differs from
the reference — the exact generalized winding number (gsdf's hierarchical exact evaluation) rounded, for a soup
that of the intact mesh it was made from; "dist err" = max | |s| - d | / bounding-box diagonal with d the exact
double-precision distance (libigl's point_mesh_squared_distance, cross-checked against gsdf's brute force).

Writes the sections ``sdf-peers`` (``sdf-peers-quick``) and ``sdf-peers-scaling`` of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
if "GSDF_CGAL_DATA" not in os.environ and os.path.isdir("/work/cgal/data/meshes"):
    os.environ["GSDF_CGAL_DATA"] = "/work/cgal/data"
from common import command, data_dir, machine, table, write_section  # noqa: E402
from load import BusyLoad, uptime  # noqa: E402

import gsdf  # noqa: E402
from gsdf.grid import Grid, padded_box  # noqa: E402

# (label, CGAL file or recipe, kind)
MESHES = [
    ("rotor", "rotor.off", "CAD"),
    ("fandisk", "fandisk.off", "CAD"),
    ("mech-holes-shark", "mech-holes-shark.off", "CAD, open"),
    ("elephant-with-holes", "elephant-with-holes.off", "open"),
    ("holes", "holes.off", "open"),
    ("camel", "camel.off", "scan"),
    ("armadillo", "armadillo.off", "scan"),
    ("bunny00", "bunny00.off", "scan, watertight"),
    ("bunny00-soup", "soup:bunny00.off", "soup"),
    ("refined_elephant", "refined_elephant.off", "scan"),
    ("bunny00-loop2", "loop2:bunny00.off", "scan, 1.2M"),
]
QUICK_MESHES = ["bunny00", "bunny00-soup", "elephant-with-holes"]
WORKLOADS = ["build", "sd1e5", "sd1e6", "grid", "occ1e5", "occ1e6"]
QUICK_WORKLOADS = ["build", "sd1e5", "grid", "occ1e5"]
TOOLS = ["gsdf", "open3d", "warp", "warp-wn", "fcpw", "pysdf", "mesh2sdf", "mesh2sdf-fix", "mesh-to-sdf", "igl", "pcu"]
QUICK_TOOLS = ["gsdf", "open3d", "warp-wn", "fcpw", "pysdf", "mesh2sdf", "igl", "pcu"]
#: points on which accuracy is measured (a fixed random subset of each workload's points)
CHECK = 200_000


# ----------------------------------------------------------------------------------------------------------
# inputs
# ----------------------------------------------------------------------------------------------------------


def soup_of(V, F, seed=0):
    """The issue's soup: 10 % of the faces deleted, 5 % duplicated, 10 % flipped (seeded)."""
    rng = np.random.default_rng(seed)
    F = F[rng.random(len(F)) >= 0.10]
    F = np.vstack([F, F[rng.random(len(F)) < 0.05]])
    flip = rng.random(len(F)) < 0.10
    F[flip] = F[flip][:, ::-1]
    return V, np.ascontiguousarray(F)


def load_mesh(recipe):
    """(V, F, V_ref, F_ref): the mesh and the intact mesh whose inside is the reference."""
    root = os.path.join(data_dir(), "meshes")
    if recipe.startswith("soup:"):
        V, F = gsdf.read_mesh(os.path.join(root, recipe[5:]))
        Vs, Fs = soup_of(V, F)
        return Vs, Fs, V, F
    if recipe.startswith("loop"):
        import igl

        k, name = recipe[4:].split(":")
        V, F = gsdf.read_mesh(os.path.join(root, name))
        V, F = igl.loop(V, F.astype(np.int64), int(k))
        V, F = np.ascontiguousarray(V), np.ascontiguousarray(F)
        return V, F, V, F
    V, F = gsdf.read_mesh(os.path.join(root, recipe))
    return V, F, V, F


def cube_grid(V, n):
    """The n^3 grid over the padded box made cubic (the box mesh2sdf needs)."""
    lo, hi = padded_box(V)
    c, h = 0.5 * (lo + hi), 0.5 * float((hi - lo).max())
    return Grid((c - h, c + h), (n, n, n))


# ----------------------------------------------------------------------------------------------------------
# tools: prepare(V, F, Q) -> state (untimed); run(state) -> result (timed)
# ----------------------------------------------------------------------------------------------------------


def _gsdf_structures(V, F):
    """What gsdf.signed_distance builds: one shared structure if the library has it, else its two trees."""
    from gsdf.distance import TriangleDistance
    from gsdf.winding import FastWindingNumber

    try:  # the merged layout: one shared triangle tree (gsdf.spatial._triangle_tree), as signed_distance builds it
        from gsdf._checks import as_mesh
        from gsdf.spatial._triangle_tree import triangle_tree
    except ImportError:
        return TriangleDistance(V, F), FastWindingNumber(V, F)
    V, F = as_mesh(V, F)
    tt = triangle_tree(V, F)
    return TriangleDistance._of_tree(V, F, tt), FastWindingNumber._of_tree(tt, beta=2.0, order=2)


def gsdf_tool(work, V, F, X):
    if work == "build":
        return lambda: _gsdf_structures(V, F)
    if work.startswith("sd"):
        return lambda: gsdf.signed_distance(V, F, X)
    if work.startswith("occ"):
        if hasattr(gsdf, "inside"):  # the occupancy entry point (closed meshes: grid cells and crossing counts)
            return lambda: gsdf.inside(V, F, X)
        return lambda: gsdf.FastWindingNumber(V, F)(X) > 0.5
    if work == "grid":
        return lambda: gsdf.signed_distance_grid(V, F, resolution=X).values.ravel()


def open3d_tool(work, V, F, X):
    import open3d as o3d

    V32, F32 = o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(F.astype(np.uint32))
    P = None if work == "build" else o3d.core.Tensor(_points(X).astype(np.float32))

    def scene():
        s = o3d.t.geometry.RaycastingScene()
        s.add_triangles(V32, F32)
        return s

    if work == "build":  # Embree commits the scene at the first query
        one = o3d.core.Tensor(V[:1].astype(np.float32))
        return lambda: scene().compute_closest_points(one)
    if work.startswith("occ"):
        return lambda: scene().compute_occupancy(P).numpy() > 0.5
    return lambda: scene().compute_signed_distance(P).numpy()


_WARP = {}


def _warp_kernels():
    if _WARP:
        return _WARP
    import warp as wp

    wp.config.quiet = True
    wp.init()

    @wp.kernel
    def sd_normal(mesh: wp.uint64, pts: wp.array(dtype=wp.vec3), out: wp.array(dtype=float)):
        i = wp.tid()
        p = pts[i]
        q = wp.mesh_query_point_sign_normal(mesh, p, 1.0e30)
        if q.result:
            out[i] = q.sign * wp.length(p - wp.mesh_eval_position(mesh, q.face, q.u, q.v))

    @wp.kernel
    def sd_winding(mesh: wp.uint64, pts: wp.array(dtype=wp.vec3), out: wp.array(dtype=float)):
        i = wp.tid()
        p = pts[i]
        q = wp.mesh_query_point_sign_winding_number(mesh, p, 1.0e30, 2.0, 0.5)
        if q.result:
            out[i] = q.sign * wp.length(p - wp.mesh_eval_position(mesh, q.face, q.u, q.v))

    _WARP.update(wp=wp, normal=sd_normal, winding=sd_winding)
    return _WARP


def warp_tool(work, V, F, X, sign="normal"):
    k = _warp_kernels()
    wp = k["wp"]
    pv = V.astype(np.float32)
    fi = F.astype(np.int32).ravel()

    def mesh():
        return wp.Mesh(points=wp.array(pv, dtype=wp.vec3, device="cpu"), indices=wp.array(fi, dtype=int, device="cpu"))

    if work == "build":
        return mesh
    P = _points(X).astype(np.float32)
    kern = k[sign]

    def run():
        m = mesh()
        pts = wp.array(P, dtype=wp.vec3, device="cpu")
        out = wp.zeros(len(P), dtype=float, device="cpu")
        wp.launch(kern, dim=len(P), inputs=[m.id, pts, out], device="cpu")
        wp.synchronize()
        o = out.numpy()
        return o < 0 if work.startswith("occ") else o

    return run


def fcpw_tool(work, V, F, X):
    import fcpw

    Vf, Ff = np.asfortranarray(V.astype(np.float32)), np.asfortranarray(F.astype(np.int32))

    def scene():
        s = fcpw.scene_3D()
        s.set_object_count(1)
        s.set_object_vertices(Vf, 0)
        s.set_object_triangles(Ff, 0)
        s.build(fcpw.aggregate_type.bvh_surface_area, True)
        return s

    if work == "build":
        return scene
    P = _points(X).astype(np.float32)
    Pf = np.asfortranarray(P)
    # fcpw's contains() on a numpy array leaves its result untouched (0.20): the list overload works
    plist = fcpw.float_3D_list(list(P))
    r2 = np.full(len(P), np.inf, np.float32)

    def run():
        s = scene()
        inside = fcpw.uint32_list()
        s.contains(plist, inside)
        if work.startswith("occ"):
            return inside
        inter = fcpw.interaction_3D_list()
        s.find_closest_points(Pf, r2, inter)
        return inter, inside

    def result(r):  # untimed: reading fcpw's result objects
        if work.startswith("occ"):
            return np.array(r, dtype=bool)
        inter, inside = r
        d = np.fromiter((i.d for i in inter), np.float64, len(P))
        return np.where(np.array(inside, dtype=bool), -d, d)

    run.result = result
    return run


def pysdf_tool(work, V, F, X):
    import pysdf

    V32, F32 = np.ascontiguousarray(V, np.float32), np.ascontiguousarray(F, np.uint32)
    if work == "build":
        return lambda: pysdf.SDF(V32, F32)
    P = np.ascontiguousarray(_points(X), np.float32)
    if work.startswith("occ"):
        return lambda: pysdf.SDF(V32, F32).contains(P).ravel()
    return lambda: -pysdf.SDF(V32, F32)(P).ravel()  # pysdf: positive inside


def mesh2sdf_tool(work, V, F, X, fix=False):
    if work != "grid":
        return None
    import mesh2sdf

    n = X.shape[0]
    lo, _ = X.box
    h = float(X.spacing[0])
    # node i of mesh2sdf's n^3 grid is at -1 + 2 i / n: map the mesh so that it lands on the grid's node i
    Vm = -1.0 + (V - lo) / (h * n / 2.0)
    scale = h * n / 2.0
    return lambda: mesh2sdf.compute(Vm, F, n, fix=fix, level=2.0 / n).ravel() * scale


def mesh_to_sdf_tool(work, V, F, X):
    if work != "sd1e5":
        return None
    import mesh_to_sdf
    import trimesh

    P = _points(X)
    return lambda: mesh_to_sdf.mesh_to_sdf(trimesh.Trimesh(V, F, process=False), P)


def igl_tool(work, V, F, X):
    import igl

    F64 = F.astype(np.int64)
    if work == "build":
        def build():
            t = igl.AABB()
            t.init(V, F64)
            return t
        return build
    P = _points(X)
    if work.startswith("occ"):
        return lambda: igl.fast_winding_number(V, F64, P) > 0.5
    return lambda: igl.signed_distance(P, V, F64, igl.SignedDistanceType.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER)[0]


def pcu_tool(work, V, F, X):
    import point_cloud_utils as pcu

    if work == "build":
        return None
    P = _points(X)
    if work.startswith("occ"):
        return lambda: np.asarray(pcu.triangle_soup_fast_winding_number(V, F, P)) > 0.5
    return lambda: np.asarray(pcu.signed_distance_to_mesh(P, V, F)[0])


FACTORY = {"gsdf": gsdf_tool, "open3d": open3d_tool, "warp": warp_tool,
           "warp-wn": lambda w, V, F, X: warp_tool(w, V, F, X, "winding"), "fcpw": fcpw_tool, "pysdf": pysdf_tool,
           "mesh2sdf": mesh2sdf_tool, "mesh2sdf-fix": lambda w, V, F, X: mesh2sdf_tool(w, V, F, X, True),
           "mesh-to-sdf": mesh_to_sdf_tool, "igl": igl_tool, "pcu": pcu_tool}


def _points(X):
    return X.points() if isinstance(X, Grid) else X


def available(names):
    ok, why = [], {}
    mods = {"open3d": "open3d", "warp": "warp", "warp-wn": "warp", "fcpw": "fcpw", "pysdf": "pysdf",
            "mesh2sdf": "mesh2sdf", "mesh2sdf-fix": "mesh2sdf", "mesh-to-sdf": "mesh_to_sdf", "igl": "igl",
            "pcu": "point_cloud_utils"}
    for n in names:
        try:
            if n in mods:
                __import__(mods[n])
            ok.append(n)
        except Exception as exc:  # a missing peer is reported, not fatal
            why[n] = f"{type(exc).__name__}: {exc}"
    return ok, why


# ----------------------------------------------------------------------------------------------------------
# references and accuracy
# ----------------------------------------------------------------------------------------------------------


class Reference:
    """Exact inside/outside and exact distance at a fixed subset of a workload's points."""

    def __init__(self, V, F, Vr, Fr, P, rng):
        import igl

        self.idx = np.sort(rng.choice(len(P), min(CHECK, len(P)), replace=False)) if len(P) > CHECK else None
        S = P if self.idx is None else P[self.idx]
        self.inside = gsdf.ExactWindingNumber(Vr, Fr)(S) > 0.5
        self.d = np.sqrt(igl.point_mesh_squared_distance(S, V, F.astype(np.int64))[0])
        k = slice(0, min(300, len(S)))
        db = gsdf.distance.brute_force_distance(V, F, S[k])[0]
        self.cross = float(np.max(np.abs(db - self.d[k]))) if len(db) else 0.0
        lo, hi = V.min(0), V.max(0)
        self.diag = float(np.linalg.norm(hi - lo))

    def check(self, out, work):
        out = np.asarray(out).ravel()
        if self.idx is not None:
            out = out[self.idx]
        if work.startswith("occ"):
            return float(np.mean(out.astype(bool) != self.inside) * 100), None
        out = out.astype(np.float64)
        wrong = float(np.mean((out < 0) != self.inside) * 100)
        return wrong, float(np.max(np.abs(np.abs(out) - self.d)) / self.diag)


# ----------------------------------------------------------------------------------------------------------
# the run
# ----------------------------------------------------------------------------------------------------------


def inputs_for(work, V, n_grid, rng):
    if work == "build":
        return None
    if work == "grid":
        return cube_grid(V, n_grid)
    n = int(float(work[-3:]))
    lo, hi = padded_box(V)
    return rng.uniform(lo, hi, (n, 3))


_WARM = set()


def warm_up(V, F, works, tools, n_grid):
    """Each tool once per workload on this mesh, untimed: imports, JIT caches, kernel builds. On 20000 points
    (a 28^3 grid) and on the mesh itself: numba's serial and parallel kernels are different functions (gsdf's
    queries go parallel from 4096 / 16384 points, its tree build from 20000 faces), each loaded at its first call."""
    rng = np.random.default_rng(5)
    for work in works:
        X = inputs_for(work, V, 28, rng) if work in ("build", "grid") else inputs_for("sd1e5", V, 8, rng)[:20000]
        for t in tools:
            _WARM.add((t, work))
            try:
                fn = FACTORY[t](work, V, F, X)
                if fn is not None and t != "mesh-to-sdf":
                    fn()
            except Exception:
                pass


def run_block(label, V, F, Vr, Fr, works, tools, args, cond, results, est):
    rng = np.random.default_rng(1)
    warm_up(V, F, works, tools, args.grid)
    for work in works:
        X = inputs_for(work, V, args.grid, rng)
        ref = None if work == "build" else Reference(V, F, Vr, Fr, _points(X), np.random.default_rng(2))
        runs = {}
        for t in tools:
            key = (t, work)
            if key in est and est[key] > args.cap and not (t == "mesh-to-sdf" and work != "sd1e5") \
                    and not (t.startswith("mesh2sdf") and work != "grid"):
                results[(cond, label, work, t)] = {"skip": f"est. {est[key]:.0f} s"}
                continue
            try:
                fn = FACTORY[t](work, V, F, X)
            except Exception as exc:
                results[(cond, label, work, t)] = {"error": f"{type(exc).__name__}: {str(exc)[:100]}"}
                continue
            if fn is not None:
                runs[t] = fn
        times = {t: [] for t in runs}
        outs = {}
        for rep in range(args.reps):
            order = list(runs)
            order = order[rep % len(order):] + order[: rep % len(order)] if order else order
            for t in order:
                if rep > 0 and (not times[t] or times[t][0] > args.slow):
                    continue  # failed, or too slow to repeat
                gc.collect()
                try:
                    t0 = time.perf_counter()
                    out = runs[t]()
                    times[t].append(time.perf_counter() - t0)
                    if rep == 0:
                        outs[t] = runs[t].result(out) if hasattr(runs[t], "result") else out
                except Exception as exc:
                    results[(cond, label, work, t)] = {"error": f"{type(exc).__name__}: {str(exc)[:100]}"}
                    times[t] = []
                out = None
        for t in runs:
            if not times[t]:
                continue
            r = {"time": float(np.median(times[t])), "n": len(times[t])}
            if ref is not None and t in outs:
                r["wrong"], r["err"] = ref.check(outs[t], work)
            results[(cond, label, work, t)] = r
            # the next (larger) workload of this tool, predicted from this one
            nxt = {"sd1e5": ("sd1e6", 10.0), "occ1e5": ("occ1e6", 10.0), "sd1e6": ("grid", 2.1)}.get(work)
            if nxt and (nxt[0] != "grid" or args.grid == 128):  # sd1e6 -> grid holds for 128^3 nodes only
                est[(t, nxt[0])] = r["time"] * nxt[1]
            if work == "sd1e5":
                est.setdefault((t, "grid"), r["time"] * 21.0 * (args.grid / 128) ** 3)
        line = "  ".join(f"{t} {results[(cond, label, work, t)].get('time', float('nan')):.3g}"
                         for t in tools if (cond, label, work, t) in results)
        print(f"[{cond}] {label} {work}: {line}", flush=True)
        if ref is not None and ref.cross > 1e-12 * ref.diag:
            print(f"  warning: reference distance vs brute force differs by {ref.cross:.2e}", flush=True)


def fmt_t(r):
    if r is None:
        return "—"
    if "skip" in r:
        return "skip"
    if "error" in r:
        return "error"
    t = r["time"]
    return f"{t:.3f}" if t < 10 else f"{t:.1f}"


def report(results, labels, kinds, faces, works, tools, cond, args, errors):
    """Markdown tables of one load condition."""
    out = []
    # summary: gsdf / fastest peer per workload
    rows = []
    for w in works:
        ratios, peers = [], []
        for lab in labels:
            g = results.get((cond, lab, w, "gsdf"), {})
            if "time" not in g:
                continue
            best = min(((results[(cond, lab, w, t)]["time"], t) for t in tools if t != "gsdf"
                        and "time" in results.get((cond, lab, w, t), {})), default=None)
            if best:
                ratios.append(g["time"] / best[0])
                peers.append(best[1])
        if not ratios:
            continue
        ratios = np.array(ratios)
        common = max(set(peers), key=peers.count)
        rows.append([w, f"{np.min(ratios):.2f}", f"{np.median(ratios):.2f}", f"{np.max(ratios):.2f}",
                     f"{np.sum(ratios <= 0.7)}/{len(ratios)}", f"{np.sum(ratios <= 1.0)}/{len(ratios)}", common])
    out.append("gsdf time ÷ the fastest peer's time on the same mesh (build + query), over the meshes:\n")
    out.append(table(["workload", "min", "median", "max", "meshes ≤ 0.7", "meshes ≤ 1", "fastest peer (most often)"],
                     rows))
    # per workload: time and ratio
    for w in works:
        ts = [t for t in tools if any((cond, lab, w, t) in results for lab in labels)]
        if not ts:
            continue
        rows = []
        for lab in labels:
            g = results.get((cond, lab, w, "gsdf"), {}).get("time")
            row = [lab, faces[lab]]
            for t in ts:
                r = results.get((cond, lab, w, t))
                s = fmt_t(r)
                if t != "gsdf" and g and r and "time" in r:
                    s += f" ({r['time'] / g:.2g}×)"
                row.append(s)
            rows.append(row)
        out.append(f"\n**{w}** — seconds, (peer ÷ gsdf):\n")
        out.append(table(["mesh", "faces"] + ts, rows))
    # accuracy
    acc = []
    for t in tools:
        row = [t]
        for w in [w for w in works if w != "build"]:
            wr = [(results[(cond, lab, w, t)].get("wrong"), kinds[lab]) for lab in labels
                  if "wrong" in results.get((cond, lab, w, t), {})]
            er = [results[(cond, lab, w, t)].get("err") for lab in labels
                  if results.get((cond, lab, w, t), {}).get("err") is not None]
            if not wr:
                row.append("—")
                continue
            closed = [x for x, k in wr if "watertight" in k or k in ("scan", "CAD", "scan, 1.2M")]
            broken = [x for x, k in wr if not ("watertight" in k or k in ("scan", "CAD", "scan, 1.2M"))]
            s = (f"{max(closed):.3g} / " if closed else "— / ") + (f"{max(broken):.3g}" if broken else "—")
            if er:
                s += f"; {max(er):.1e}"
            row.append(s)
        acc.append(row)
    out.append("\nAccuracy per tool: max wrong sign % over the closed / the broken (open, soup) meshes; max distance "
               "error ÷ diagonal:\n")
    out.append(table(["tool"] + [w for w in works if w != "build"], acc))
    # wrong sign per mesh: the issue asks for each tool's wrong-sign % on the soup
    checked = [w for w in works if w != "build"]
    rows = []
    for lab in labels:
        row = [f"{lab} ({kinds[lab]})"]
        for t in tools:
            cells = [results.get((cond, lab, w, t), {}).get("wrong") for w in checked]
            row.append(" / ".join("—" if c is None else f"{c:.3g}" for c in cells))
        rows.append(row)
    out.append(f"\nWrong sign % per mesh and tool ({' / '.join(checked)}):\n")
    out.append(table(["mesh"] + tools, rows))
    if errors:
        out.append("\n" + "\n".join(f"- {k}: {v}" for k, v in sorted(errors.items())))
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="3 meshes, 1e5 points, 64^3 grid, fewer tools")
    ap.add_argument("--meshes", help="comma-separated labels (default: all, or the quick ones)")
    ap.add_argument("--tools", help="comma-separated tools")
    ap.add_argument("--work", help="comma-separated workloads")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--grid", type=int, default=None)
    ap.add_argument("--slow", type=float, default=20.0, help="calls slower than this are not repeated")
    ap.add_argument("--cap", type=float, default=300.0, help="skip a tool whose predicted call exceeds this")
    ap.add_argument("--load", choices=["idle", "busy", "both"], default="both")
    ap.add_argument("--scaling", action="store_true", help="only the scaling section")
    ap.add_argument("--json", help="also dump the raw results here")
    ap.add_argument("--resume", help="results of an earlier run (its --json): its complete meshes are not rerun")
    ap.add_argument("--check", type=int, default=CHECK, help="points per workload on which accuracy is measured")
    ap.add_argument("--no-write", action="store_true", help="print only, do not touch RESULTS.md")
    args = ap.parse_args(argv)
    globals()["CHECK"] = args.check
    if args.scaling:
        return scaling(args)
    labels = args.meshes.split(",") if args.meshes else (QUICK_MESHES if args.quick else [m[0] for m in MESHES])
    works = args.work.split(",") if args.work else (QUICK_WORKLOADS if args.quick else WORKLOADS)
    tools, errors = available(args.tools.split(",") if args.tools else (QUICK_TOOLS if args.quick else TOOLS))
    args.grid = args.grid or (64 if args.quick else 128)
    conds = ["idle", "busy"] if args.load == "both" else [args.load]
    info = machine()
    print("machine:", info, "|", uptime(), flush=True)
    t_start = time.time()
    recipes = {m[0]: m for m in MESHES}
    results, kinds, faces, loads = {}, {}, {}, {c: [] for c in conds}
    cmd = "`" + command("bench_sdf_peers.py", python="/work/anchors/bin/python", env="PYOPENGL_PLATFORM=egl") + "`"
    start_load = uptime()

    def finish(done, final):
        """The section of the meshes done so far: printed, and written after every mesh (a run stopped part way
        keeps what it measured; the heading says how many meshes of how many)."""
        head = (f"## sdf-peers{' (quick)' if args.quick else ''}: signed distance and occupancy against Open3D, "
                f"Warp, fcpw, pysdf, mesh2sdf, mesh-to-sdf, libigl, pcu\n\n"
                f"Command: {cmd}. Machine: {info}; {start_load} at start, {uptime()} at "
                f"{'end' if final else 'the last write'} (shared machine). {time.strftime('%Y-%m-%d %H:%M')}; "
                f"{'run took' if final else 'partial: ' + str(len(done)) + ' of ' + str(len(labels)) + ' meshes after'} "
                f"{(time.time() - t_start) / 60:.0f} min. Median of {args.reps} interleaved calls (one call when "
                f"slower than {args.slow:g} s; a tool predicted slower than {args.cap:g} s is skipped); every time "
                f"is build + query; grid = {args.grid}^3 nodes over the padded box made cubic; points uniform in the "
                "padded box (bounding box + 0.1 × diagonal). Wrong sign against the exact winding number rounded (a "
                "soup: of the intact mesh); distance error against libigl's exact double-precision distance. Warp "
                "runs its CPU kernels on one thread; the others use both cores.\n")
        body = [head]
        for cond in conds:
            lv = loads[cond]
            if not lv:
                continue
            body.append(f"\n### {cond}{' (two busy processes, bench/load.py BusyLoad(2))' if cond == 'busy' else ''}"
                        f" — 1-min load average at the start of each mesh's block: {min(lv):.1f}–{max(lv):.1f}\n")
            body.append(report(results, done, kinds, faces, works, tools, cond, args, errors))
        text = "\n".join(body)
        if args.json:
            with open(args.json, "w") as f:
                json.dump({"|".join(k): v for k, v in results.items()} | {"loads": loads}, f, indent=1)
        if not args.no_write:
            write_section("sdf-peers-quick" if args.quick else "sdf-peers", text)
        return text

    done = []
    if args.resume:
        with open(args.resume) as f:
            old = json.load(f)
        for k, v in old.items():
            if k == "loads":
                for c, lv in v.items():
                    loads.setdefault(c, []).extend(lv)
                continue
            results[tuple(k.split("|"))] = v
    for lab in labels:
        _, recipe, kind = recipes[lab]
        V, F, Vr, Fr = load_mesh(recipe)
        kinds[lab], faces[lab] = kind, len(F)
        if all(any((c, lab, w, t) in results for t in tools) for c in conds for w in works):
            print(f"== {lab}: from {args.resume}", flush=True)
            done.append(lab)
            continue
        print(f"== {lab}: {len(F)} faces ({kind}) | {uptime()}", flush=True)
        est = {}
        for cond in conds:
            with BusyLoad(2 if cond == "busy" else 0):
                loads[cond].append(os.getloadavg()[0])
                run_block(lab, V, F, Vr, Fr, works, tools, args, cond, results, est)
        done.append(lab)
        gc.collect()
        if lab != labels[-1]:
            finish(done, False)
    print(finish(done, True))


# ----------------------------------------------------------------------------------------------------------
# scaling
# ----------------------------------------------------------------------------------------------------------


def _slope(x, y):
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def scaling(args):
    """Build and query time of gsdf (and Open3D) against faces (1k -> 1M) and against queries (1e4 -> 1e7)."""
    import igl

    info = machine()
    print("machine:", info, "|", uptime(), flush=True)
    root = os.path.join(data_dir(), "meshes")
    V0, F0 = gsdf.read_mesh(os.path.join(root, "bunny00.off"))
    Vd, Fd = igl.decimate(np.asfortranarray(V0), np.asfortranarray(F0.astype(np.int32)), 1200)[:2]
    Vd, Fd = np.ascontiguousarray(Vd), np.ascontiguousarray(Fd)
    levels = [0, 1, 2, 3, 4, 5] if not args.quick else [0, 1, 2, 3]
    nq = 100_000
    rng = np.random.default_rng(0)
    tools = [t for t in (args.tools.split(",") if args.tools else ["gsdf", "open3d"])]
    rows_f, data_f = [], {t: {"build": [], "sd": [], "occ": []} for t in tools}
    nfaces = []
    for lev in levels:
        V, F = (Vd, Fd) if lev == 0 else igl.loop(Vd, Fd.astype(np.int64), lev)
        V, F = np.ascontiguousarray(V), np.ascontiguousarray(F)
        nfaces.append(len(F))
        lo, hi = padded_box(V)
        Q = rng.uniform(lo, hi, (nq, 3))
        row = [len(F)]
        for t in tools:
            for w, key in (("build", "build"), ("sd1e5", "sd"), ("occ1e5", "occ")):
                fn = FACTORY[t](w, V, F, None if w == "build" else Q)
                ts = []
                for _ in range(args.reps):
                    t0 = time.perf_counter()
                    fn()
                    ts.append(time.perf_counter() - t0)
                data_f[t][key].append(float(np.median(ts)))
                row.append(f"{np.median(ts):.3f}")
        rows_f.append(row)
        print(row, flush=True)
    # queries
    V, F = V0, F0
    lo, hi = padded_box(V)
    counts = [10_000, 100_000, 1_000_000, 10_000_000] if not args.quick else [10_000, 100_000, 1_000_000]
    rows_q, data_q = [], {t: {"sd": [], "occ": []} for t in tools}
    for n in counts:
        Q = rng.uniform(lo, hi, (n, 3))
        row = [f"{n:.0e}"]
        for t in tools:
            for w, key in (("sd", "sd"), ("occ", "occ")):
                fn = FACTORY[t](w + "1e5", V, F, Q)
                ts = []
                for _ in range(args.reps if n <= 1_000_000 else 1):
                    t0 = time.perf_counter()
                    fn()
                    ts.append(time.perf_counter() - t0)
                data_q[t][key].append(float(np.median(ts)))
                row.append(f"{np.median(ts):.3f}")
        rows_q.append(row)
        print(row, flush=True)
        Q = None
    head_f = ["faces"] + [f"{t} {k} s" for t in tools for k in ("build", "sd 1e5", "occ 1e5")]
    slope_f = ["log-log slope"] + [f"{_slope(nfaces, data_f[t][k]):.2f}" for t in tools for k in ("build", "sd", "occ")]
    head_q = ["queries"] + [f"{t} {k} s" for t in tools for k in ("sd", "occ")]
    slope_q = ["log-log slope"] + [f"{_slope(counts, data_q[t][k]):.2f}" for t in tools for k in ("sd", "occ")]
    text = (f"## sdf-peers-scaling: build and query against faces and queries\n\n"
            f"Command: `{command('bench_sdf_peers.py', python='/work/anchors/bin/python')}`. Machine: {info}. "
            f"{uptime()} at the end. Faces: bunny00 decimated to 1.2k faces (igl.decimate) and Loop-subdivided "
            f"0–{levels[-1]} times, 1e5 points in the padded box; queries: bunny00 (75k faces). Times include the "
            f"build; median of {args.reps}.\n\n"
            + table(head_f, rows_f + [slope_f]) + "\n\n" + table(head_q, rows_q + [slope_q]) + "\n")
    print(text)
    if not args.no_write:
        write_section("sdf-peers-scaling", text)


if __name__ == "__main__":
    main()
