"""Fuzz report: the public library entry points on malformed, degenerate and extreme inputs, each case in
its own process with a timeout; counts of cases by outcome, written to bench/RESULTS.md section "fuzz".

Outcomes: ``ok`` (returned finite values), ``ValueError`` (refused with a message; FileNotFoundError for a
missing file counts here too), ``NaN`` (returned NaN/inf for finite input: silent failure), ``leaked``
(any other exception type), ``crash`` (the process died: segfault, abort), ``hang`` (timeout),
``overwritten`` (an input file changed). Target: 0 of the last five.

Run:  PYTHONPATH=src python3 bench/fuzz_report.py [--timeout 60] [--only SUBSTRING] [--no-write]

Cases run in forked children of one parent that has imported gsdf (fast start, and a crash or hang only
takes its child down). Inputs are deterministic (seeded), so reruns give the same table.
"""

from __future__ import annotations

import argparse
import collections
import hashlib
import multiprocessing as mp
import os
import sys
import tempfile
import time
import traceback

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src"))

import gsdf  # noqa: E402
import gsdf.contour  # noqa: E402,F401
import gsdf.distance  # noqa: E402,F401
import gsdf.ops  # noqa: E402,F401
import gsdf.ops._morphology  # noqa: E402,F401
import gsdf.tori  # noqa: E402,F401
from gsdf.winding._point_areas import estimate_normals, point_areas  # noqa: E402

TMP = tempfile.mkdtemp(prefix="gsdf-fuzz-")

# --------------------------------------------------------------------------------------------------------
# inputs
# --------------------------------------------------------------------------------------------------------


def tet():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return V, F


def sphere(n=400):
    i = np.arange(n) + 0.5
    ph, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    return np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])


def icosa():
    from scipy.spatial import ConvexHull

    P = sphere(80)
    h = ConvexHull(P)
    F = h.simplices.astype(np.int64)
    flip = np.einsum("ij,ij->i", np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]), P[F[:, 0]]) < 0
    F[flip] = F[flip][:, ::-1]
    return P, F


Q0 = np.array([[0.1, 0.1, 0.1], [2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.3, -0.2, 0.1]])


def mesh_variants():
    """(name, V, F, Q) — corruptions of a closed mesh and its queries."""
    V, F = icosa()
    rng = np.random.default_rng(1)
    out = [("clean", V, F, Q0)]
    for s in (1e-300, 1e-150, 1e-120, 1e50, 1e150, 1e300):
        out.append((f"scale{s:g}", V * s, F, Q0 * s))
    out.append(("offset1e8", V + 1e8, F, Q0 + 1e8))
    out.append(("offset1e15", V + 1e15, F, Q0 + 1e15))
    out.append(("tiny-far-query", V * 1e-300, F, np.array([[1e300, 0, 0]])))
    out.append(("far-query", V, F, np.array([[1e300, -1e300, 1e308]])))
    out.append(("float32", V.astype(np.float32), F.astype(np.int32), Q0.astype(np.float32)))
    out.append(("int-coords", (V * 10).astype(np.int64), F, (Q0 * 10).astype(np.int64)))
    out.append(("bool-coords", V > 0, F, Q0))
    out.append(("bool-faces", V, F > 3, Q0))
    out.append(("float-faces", V, F.astype(float), Q0))
    out.append(("fractional-faces", V, F + 0.5, Q0))
    out.append(("nan-V", np.where(np.arange(V.size).reshape(V.shape) == 5, np.nan, V), F, Q0))
    out.append(("inf-Q", V, F, np.array([[np.inf, 0, 0]])))
    out.append(("nan-Q", V, F, np.array([[np.nan, 0, 0]])))
    out.append(("empty-F", V, np.zeros((0, 3), int), Q0))
    out.append(("empty-V", np.zeros((0, 3)), F, Q0))
    out.append(("empty-Q", V, F, np.zeros((0, 3))))
    out.append(("oob-F", V, F + len(V), Q0))
    out.append(("negative-F", V, F - 1000, Q0))
    out.append(("huge-index", V, np.full(F.shape, 2 ** 62, dtype=np.int64), Q0))
    out.append(("F-2col", V, F[:, :2], Q0))
    out.append(("V-2col", V[:, :2], F, Q0))
    out.append(("Q-2col", V, F, Q0[:, :2]))
    out.append(("Q-1d", V, F, Q0[0]))
    out.append(("Q-3d", V, F, Q0[None]))
    out.append(("string-V", np.array([["a", "b", "c"]] * len(V)), F, Q0))
    out.append(("complex-Q", V, F, Q0 + 1j))
    out.append(("object-Q", V, F, np.array([[None, 1, 2]], dtype=object)))
    out.append(("all-same-V", np.zeros_like(V), F, Q0))
    out.append(("collinear", np.column_stack([np.linspace(0, 1, len(V)), np.zeros(len(V)), np.zeros(len(V))]), F, Q0))
    out.append(("degenerate-faces", V, np.column_stack([F[:, 0], F[:, 0], F[:, 1]]), Q0))
    out.append(("soup-flipped", V, np.where(rng.random(len(F))[:, None] < 0.5, F, F[:, ::-1]), Q0))
    out.append(("query-on-vertex", V, F, V[:5]))
    out.append(("list-input", V.tolist(), F.tolist(), Q0.tolist()))
    return out


def cloud_variants():
    """(name, P, N, Q)."""
    P = sphere(400)
    out = [("clean", P, P, Q0)]
    for s in (1e-300, 1e-150, 1e150, 1e300):
        out.append((f"scale{s:g}", P * s, P, Q0 * s))
    out.append(("offset1e8", P + 1e8, P, Q0 + 1e8))
    out.append(("tiny-normals", P, P * 1e-300, Q0))
    out.append(("huge-normals", P, P * 1e300, Q0))
    out.append(("zero-normals", P, np.zeros_like(P), Q0))
    out.append(("some-zero-normals", P, np.where(np.arange(len(P))[:, None] % 2 == 0, 0.0, P), Q0))
    out.append(("N-short", P, P[:-3], Q0))
    out.append(("nan-N", P, np.where(np.arange(P.size).reshape(P.shape) == 7, np.nan, P), Q0))
    out.append(("duplicates", np.repeat(P[:100], 4, axis=0), np.repeat(P[:100], 4, axis=0), Q0))
    out.append(("all-identical", np.zeros((100, 3)), np.tile([0, 0, 1.0], (100, 1)), Q0))
    out.append(("collinear", np.column_stack([np.linspace(0, 1, 100), np.zeros(100), np.zeros(100)]),
                np.tile([0, 0, 1.0], (100, 1)), Q0))
    out.append(("planar", np.column_stack([np.random.default_rng(0).random((200, 2)), np.zeros(200)]),
                np.tile([0, 0, 1.0], (200, 1)), Q0))
    out.append(("two-points", P[:2], P[:2], Q0))
    out.append(("one-point", P[:1], P[:1], Q0))
    out.append(("empty", np.zeros((0, 3)), np.zeros((0, 3)), Q0))
    out.append(("float32", P.astype(np.float32), P.astype(np.float32), Q0.astype(np.float32)))
    out.append(("far-query", P, P, np.array([[1e300, 0, 0]])))
    out.append(("inf-Q", P, P, np.array([[0, np.inf, 0]])))
    out.append(("bool-P", P > 0, P, Q0))
    return out


# --------------------------------------------------------------------------------------------------------
# entry points (each returns something whose finiteness is checked)
# --------------------------------------------------------------------------------------------------------

def _mesh_calls():
    from gsdf.distance import brute_force_distance, closest_point_triangle
    from gsdf.mesh._geometry import face_normals
    from gsdf.mesh._pseudonormals import pseudonormals

    return {
        "winding_number[direct]": lambda V, F, Q: gsdf.winding_number(V, F, Q, method="direct"),
        "winding_number[hier]": lambda V, F, Q: gsdf.winding_number(V, F, Q, method="hierarchical"),
        "ExactWindingNumber": lambda V, F, Q: gsdf.ExactWindingNumber(V, F)(Q),
        "fast_winding_number": lambda V, F, Q: gsdf.fast_winding_number(V, F, Q),
        "signed_distance[winding]": lambda V, F, Q: gsdf.signed_distance(V, F, Q),
        "signed_distance[pseudonormal]": lambda V, F, Q: gsdf.signed_distance(V, F, Q, sign="pseudonormal"),
        "unsigned_distance": lambda V, F, Q: gsdf.unsigned_distance(V, F, Q, return_closest=True),
        "brute_force_distance": lambda V, F, Q: brute_force_distance(V, F, Q),
        "closest_point_triangle": lambda V, F, Q: closest_point_triangle(
            Q, *[np.asarray(V)[k: k + len(np.atleast_2d(Q))] for k in range(3)]),
        "face_normals": lambda V, F, Q: face_normals(np.asarray(V, float), np.asarray(F)),
        "pseudonormals": lambda V, F, Q: pseudonormals(V, F),
        "voxelize[mesh]": lambda V, F, Q: gsdf.ops.voxelize(mesh=(V, F), resolution=12)[0],
        "mesh_boolean": lambda V, F, Q: gsdf.ops.mesh_boolean(V, F, np.asarray(V) + 0.3 * np.ptp(np.asarray(V, float), 0),
                                                              F, "union"),
    }


def _cloud_calls():
    return {
        "winding_number_points": lambda P, N, Q: gsdf.winding_number_points(P, N, Q),
        "fast_winding_number_points": lambda P, N, Q: gsdf.fast_winding_number_points(P, N, Q),
        "signed_distance_points": lambda P, N, Q: gsdf.signed_distance_points(P, N, Q),
        "point_cloud_distance": lambda P, N, Q: gsdf.distance.point_cloud_distance(P, Q),
        "point_areas": lambda P, N, Q: point_areas(P, N),
        "estimate_normals": lambda P, N, Q: estimate_normals(P, orient_towards=[0, 0, 0]),
        "PointsAsTori": lambda P, N, Q: gsdf.PointsAsTori(P, N, k=16).signed_distance(Q),
        "PointsAsTori.gradient": lambda P, N, Q: gsdf.PointsAsTori(P, N, k=16).gradient(Q),
        "voxelize[points]": lambda P, N, Q: gsdf.ops.voxelize(points=(P, N), resolution=10)[0],
    }


def _option_cases():
    """(name, thunk) for option values: bad ones must be ValueError, good ones ok."""
    V, F = icosa()
    P = sphere(400)
    bad = [-1, 0, -0.5, np.nan, np.inf, 1e300, "x", None, True, [1, 2], np.array([1.0, 2.0]), 2 ** 70, 1j]
    cases = []
    opt = {
        "fast_winding_number beta": lambda x: gsdf.fast_winding_number(V, F, Q0, beta=x),
        "fast_winding_number order": lambda x: gsdf.fast_winding_number(V, F, Q0, order=x),
        "FastWindingNumber leaf_size": lambda x: gsdf.FastWindingNumber(V, F, leaf_size=x)(Q0),
        "ExactWindingNumber leaf_size": lambda x: gsdf.ExactWindingNumber(V, F, leaf_size=x)(Q0),
        "winding_number method": lambda x: gsdf.winding_number(V, F, Q0, method=x),
        "fast_winding_number_points beta": lambda x: gsdf.fast_winding_number_points(P, P, Q0, beta=x),
        "fast_winding_number_points order": lambda x: gsdf.fast_winding_number_points(P, P, Q0, order=x),
        "winding_number_points areas": lambda x: gsdf.winding_number_points(
            P, P, Q0, areas=np.full(len(P), x) if isinstance(x, (int, float)) and not isinstance(x, bool) else x),
        "signed_distance sign": lambda x: gsdf.signed_distance(V, F, Q0, sign=x),
        "signed_distance beta": lambda x: gsdf.signed_distance(V, F, Q0, beta=x),
        "TriangleDistance leaf_size": lambda x: gsdf.distance.TriangleDistance(V, F, leaf_size=x).query(Q0)[0],
        "point_areas k": lambda x: point_areas(P, P, k=x),
        "point_areas candidates": lambda x: point_areas(P, P, candidates=x),
        "point_areas boundary": lambda x: point_areas(P, P, boundary=x),
        "estimate_normals k": lambda x: estimate_normals(P, k=x),
        "estimate_normals chunk": lambda x: estimate_normals(P, chunk=x),
        "estimate_normals orient_towards": lambda x: estimate_normals(P, orient_towards=x),
        "PAT k": lambda x: gsdf.PointsAsTori(P, P, k=x)(Q0),
        "PAT C": lambda x: gsdf.PointsAsTori(P, P, k=16, C=x)(Q0),
        "PAT r_eval": lambda x: gsdf.PointsAsTori(P, P, k=16, r_eval=x)(Q0),
        "PAT k_eval": lambda x: gsdf.PointsAsTori(P, P, k=16, k_eval=x)(Q0),
        "PAT k_fallback": lambda x: gsdf.PointsAsTori(P, P, k=16, k_fallback=x)(Q0),
        "PAT normal_weight": lambda x: gsdf.PointsAsTori(P, P, k=16, normal_weight=x)(Q0),
        "PAT ridge": lambda x: gsdf.PointsAsTori(P, P, k=16, ridge=x)(Q0),
        "PAT curvature_cap": lambda x: gsdf.PointsAsTori(P, P, k=16, curvature_cap=x)(Q0),
        "PAT kd_eps": lambda x: gsdf.PointsAsTori(P, P, k=16, kd_eps=x)(np.random.default_rng(0).uniform(-3, 3, (5000, 3))),
        "PAT estimator": lambda x: gsdf.PointsAsTori(P, P, k=16, estimator=x)(Q0),
        "voxelize resolution": lambda x: gsdf.ops.voxelize(mesh=(V, F), resolution=x)[0],
        "voxelize pad": lambda x: gsdf.ops.voxelize(mesh=(V, F), resolution=8, pad=x)[0],
        "voxelize beta": lambda x: gsdf.ops.voxelize(mesh=(V, F), resolution=8, beta=x)[0],
        "voxelize chunk": lambda x: gsdf.ops.voxelize(mesh=(V, F), resolution=8, chunk=x)[0],
        "voxelize bbox_min": lambda x: gsdf.ops.voxelize(mesh=(V, F), resolution=8, bbox_min=x)[0],
        "extract_isosurface resolution": lambda x: gsdf.contour.extract_isosurface(
            lambda q: np.linalg.norm(q, axis=1), [-1] * 3, [1] * 3, resolution=x, level=0.5)[0],
        "extract_isosurface level": lambda x: gsdf.contour.extract_isosurface(
            lambda q: np.linalg.norm(q, axis=1), [-1] * 3, [1] * 3, resolution=16, level=x)[0],
        "extract_isosurface bisection_steps": lambda x: gsdf.contour.extract_isosurface(
            lambda q: np.linalg.norm(q, axis=1), [-1] * 3, [1] * 3, resolution=16, level=0.5, bisection_steps=x)[0],
        "extract_isosurface inside": lambda x: gsdf.contour.extract_isosurface(
            lambda q: np.linalg.norm(q, axis=1), [-1] * 3, [1] * 3, resolution=16, level=0.5, inside=x)[0],
        "extract_isosurface func": lambda x: gsdf.contour.extract_isosurface(
            lambda q: np.full(len(q), x), [-1] * 3, [1] * 3, resolution=8, level=0.5)[0],
        "slice_contours resolution": lambda x: gsdf.contour.slice_contours(
            lambda q: np.linalg.norm(q, axis=1) - 0.5, 0.0, [-1] * 3, [1] * 3, resolution=x, level=0.0),
        "tori.offset r": lambda x: gsdf.tori.offset(lambda q: np.linalg.norm(q, axis=1) - 0.5, x)(Q0),
        "render_png width": lambda x: gsdf.tori.render_png(lambda q: np.linalg.norm(q, axis=1) - 0.5,
                                                           os.path.join(TMP, "r.png"), width=x, height=16,
                                                           bbox_min=[-1] * 3, bbox_max=[1] * 3),
        "render_png level": lambda x: gsdf.tori.render_png(lambda q: np.linalg.norm(q, axis=1) - 0.5,
                                                           os.path.join(TMP, "r.png"), width=16, height=16, level=x,
                                                           bbox_min=[-1] * 3, bbox_max=[1] * 3),
        "render_png bbox": lambda x: gsdf.tori.render_png(lambda q: np.linalg.norm(q, axis=1) - 0.5,
                                                          os.path.join(TMP, "r.png"), width=16, height=16,
                                                          bbox_min=[0, 0, 0], bbox_max=[x, x, x]),
        "mesh_boolean op": lambda x: gsdf.ops.mesh_boolean(V, F, V + 0.3, F, x),
        "mesh_boolean beta": lambda x: gsdf.ops.mesh_boolean(V, F, V + 0.3, F, "union", beta=x),
        "mesh_boolean bisection_steps": lambda x: gsdf.ops.mesh_boolean(V, F, V + 0.3, F, "union", bisection_steps=x),
        "offset_surface distance": lambda x: gsdf.ops._morphology.offset_surface(_grid_field(), x),
        "dilate_erode radius": lambda x: gsdf.ops._morphology.dilate_erode(_grid_field(), x),
        "GridField.isosurface level": lambda x: _grid_field().isosurface(x),
        "GridField.isosurface close": lambda x: _grid_field().isosurface(0.0, close=x),
    }
    for name, f in opt.items():
        for i, x in enumerate(bad):
            cases.append((f"option {name}={x!r}"[:90], (lambda f=f, x=x: f(x))))
    return cases


def _grid_field():
    from gsdf.field import GridField
    from gsdf.grid import grid_points

    shape = (12, 12, 12)
    lo, hi = np.full(3, -1.0), np.full(3, 1.0)
    return GridField((np.linalg.norm(grid_points(lo, hi, shape), axis=1) - 0.5).reshape(shape), lo, hi)


def _save_good_pat(path):
    P = sphere(300)
    gsdf.PointsAsTori(P, P, k=16).save(path)


def _file_cases():
    """PointsAsTori.load and load_voxels on corrupted files."""
    good = os.path.join(TMP, "pat.npz")
    # fitted in a child: the parent must not start OpenMP threads (a fork after that aborts the child)
    ctx = mp.get_context("fork")
    p = ctx.Process(target=_save_good_pat, args=(good,))
    p.start()
    p.join()
    z = dict(np.load(good))
    cases = []

    def variant(name, **changes):
        d = dict(z)
        for k, v in changes.items():
            if v is None:
                d.pop(k)
            else:
                d[k] = v
        p = os.path.join(TMP, f"pat-{name}.npz")
        np.savez(p, **d)
        cases.append((f"PAT.load {name}", lambda p=p: gsdf.PointsAsTori.load(p)(Q0), p))

    variant("good")
    variant("short-tori", tori=z["tori"][:10])
    variant("long-tori", tori=np.concatenate([z["tori"], z["tori"]]))
    variant("short-N", N=z["N"][:10])
    variant("nan-tori", tori=np.where(np.arange(z["tori"].size).reshape(z["tori"].shape) == 3, np.nan, z["tori"]))
    variant("wide-coefficients", coefficients=np.zeros((len(z["P"]), 9)))
    variant("no-P", P=None)
    variant("k-array", k=np.array([1, 2]))
    variant("C-negative", C=np.float64(-1))
    variant("r_eval-nan", r_eval=np.float64(np.nan))
    variant("k_eval-zero", k_eval=np.int64(0))
    variant("estimator-bogus", estimator=np.str_("bogus"))
    variant("format-9", format=np.int64(9))
    junk = os.path.join(TMP, "junk.npz")
    with open(junk, "wb") as f:
        f.write(os.urandom(512))
    cases.append(("PAT.load junk bytes", lambda: gsdf.PointsAsTori.load(junk), junk))
    cases.append(("PAT.load missing", lambda: gsdf.PointsAsTori.load(os.path.join(TMP, "nope.npz")), None))
    cases.append(("PAT.load directory", lambda: gsdf.PointsAsTori.load(TMP), None))
    cases.append(("load_voxels junk", lambda: gsdf.ops.load_voxels(junk), junk))
    return cases


def all_cases():
    cases = []
    calls = _mesh_calls()
    for vname, V, F, Q in mesh_variants():
        for cname, f in calls.items():
            cases.append((f"{cname} | mesh {vname}", (lambda f=f, V=V, F=F, Q=Q: f(V, F, Q)), None))
    calls = _cloud_calls()
    for vname, P, N, Q in cloud_variants():
        for cname, f in calls.items():
            cases.append((f"{cname} | cloud {vname}", (lambda f=f, P=P, N=N, Q=Q: f(P, N, Q)), None))
    V2 = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]) - 0.5
    E = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    for s in (1e-300, 1e-150, 1, 1e150, 1e300):
        cases.append((f"winding_number_2d | scale{s:g}", lambda s=s: gsdf.winding_number_2d(V2 * s, E, [[0.1 * s, 0]]), None))
    for name, bad in (("oob", E + 9), ("1col", E[:, :1]), ("nan", np.where(V2 > 0, np.nan, V2))):
        cases.append((f"winding_number_2d | {name}", lambda bad=bad, name=name:
                      gsdf.winding_number_2d(bad if name == "nan" else V2, E if name == "nan" else bad, [[0, 0]]), None))
    cases += [(n, f, None) for n, f in _option_cases()]
    cases += _file_cases()
    return cases


# --------------------------------------------------------------------------------------------------------
# runner
# --------------------------------------------------------------------------------------------------------


def _finite(x) -> bool:
    if isinstance(x, (tuple, list)):
        return all(_finite(y) for y in x)
    if hasattr(x, "_fields"):
        return all(_finite(getattr(x, f)) for f in x._fields)
    if x is None or isinstance(x, (str, bytes)):
        return True
    a = np.asarray(x)
    if a.dtype.kind in "fc":
        return bool(np.isfinite(a).all())
    return True


def _child(fn, conn):
    try:
        r = fn()
        conn.send(("ok" if _finite(r) else "NaN", ""))
    except (ValueError, FileNotFoundError) as exc:
        conn.send(("ValueError", f"{type(exc).__name__}: {exc}"[:200]))
    except BaseException as exc:  # noqa: BLE001 - this is what the report counts
        tb = traceback.extract_tb(exc.__traceback__)
        where = f"{os.path.basename(tb[-1].filename)}:{tb[-1].lineno}" if tb else ""
        conn.send(("leaked", f"{type(exc).__name__} at {where}: {exc}"[:200]))
    conn.close()


def _digest(path):
    if path is None or not os.path.isfile(path):
        return None
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def run_case(fn, path, timeout):
    before = _digest(path)
    ctx = mp.get_context("fork")
    a, b = ctx.Pipe(duplex=False)
    p = ctx.Process(target=_child, args=(fn, b))
    p.start()
    b.close()
    outcome, msg = None, ""
    if a.poll(timeout):
        try:
            outcome, msg = a.recv()
        except EOFError:
            pass
    p.join(5 if outcome is not None else 0.1)
    if p.is_alive():
        p.kill()
        p.join()
        if outcome is None:
            outcome, msg = "hang", f"no answer in {timeout} s"
    if outcome is None:
        outcome, msg = "crash", f"exit code {p.exitcode}"
    if before is not None and _digest(path) != before:
        outcome, msg = "overwritten", path
    return outcome, msg


ORDER = ["ok", "ValueError", "NaN", "leaked", "crash", "hang", "overwritten"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--only", default="")
    ap.add_argument("--no-write", action="store_true")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args()
    cases = [c for c in all_cases() if args.only in c[0]]
    counts = collections.Counter()
    bad = []
    t0 = time.time()
    for name, fn, path in cases:
        outcome, msg = run_case(fn, path, args.timeout)
        counts[outcome] += 1
        if outcome not in ("ok", "ValueError"):
            bad.append((outcome, name, msg))
            print(f"{outcome:11s} {name}  -- {msg}", flush=True)
        elif args.verbose:
            print(f"{outcome:11s} {name}  -- {msg}", flush=True)
    dt = time.time() - t0
    table = "| outcome | cases |\n|---|---|\n" + "".join(f"| {k} | {counts.get(k, 0)} |\n" for k in ORDER)
    print(table)
    print(f"{len(cases)} cases in {dt:.0f} s")
    if not args.no_write and not args.only:
        from common import machine, write_section  # noqa: E402

        load = os.popen("uptime").read().strip()
        text = (f"`PYTHONPATH=src python3 bench/fuzz_report.py` — {len(cases)} cases (library entry points on "
                f"malformed, degenerate, extreme-scale inputs and bad options; each in its own forked process, "
                f"timeout {args.timeout:g} s), {dt:.0f} s. Machine: {machine()}; load: {load} (shared with other "
                f"sessions).\n\n" + table)
        if bad:
            text += "\nNot ok:\n\n" + "".join(f"- {o}: {n} — {m}\n" for o, n, m in bad)
        write_section("fuzz", text)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    sys.exit(main())
