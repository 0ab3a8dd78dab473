"""The volumetric signed heat method (grid and tet domains) against signedheat3d (the authors' C++).

Run in the anchors' venv, which has both packages:

    PYTHONPATH=src /work/anchors/bin/python bench/bench_heat_volume.py [--quick] [--only PART,...] [--load]

Parts (``--only``, default all), each writing its own section of bench/RESULTS.md:

* ``accuracy`` ("heat-volume"): grid and tet domains against signedheat3d at 32³ (the anchor's direct Yukawa
  sums are slow; the tet fields of both are evaluated at the grid nodes) on a broken bunny, meshes with holes
  and clouds: mean |φ − φ_ref| per constraint mode and t_scale; timings at 64³ / 128³, step I growth, offsets;
* ``speed`` ("heat-volume-speed"): grid domain at 32³, defaults, 10 inputs (5 with ``--quick``): time (every case
  in a process of its own), error, peak RSS, gsdf's stages (cProfile); with ``--load`` also under two busy
  processes;
* ``scaling`` ("heat-volume-scaling"): growth with input size at fixed 32³ / 64³ grids (gsdf only);
* ``choices`` ("heat-volume-choices"): the measured choices behind the grid defaults on the speed inputs: Step
  III's CG tolerance, Step I by tree sum or screened grid solve, point areas on one thread or the threads, the
  soft-penalty matrix;
* ``solvers`` ("solver-choices"): complex SuperLU vs CHOLMOD on vector heat operators, tet step III CG vs a
  factorization, ``t_scale`` "grid" vs "input" on corrupted clouds.

Same input, bounding box and node counts for both solvers; errors are mean |φ − φ_ref| over all grid nodes, with
φ_ref the exact signed distance (gsdf.signed_distance: exact unsigned distance, winding-number sign) of the
*intact* mesh for damaged meshes, of the input itself for the meshes with holes, and of the points
(gsdf.signed_distance_points) for clouds; the anchor's sign is flipped when it is anti-correlated with the
reference (its convention).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import subprocess
import sys
import time
import zlib

import numpy as np
import scipy.sparse as sp

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import command, data_dir, heading, table, write_section  # noqa: E402
from load import BusyLoad, uptime  # noqa: E402

import gsdf  # noqa: E402
from gsdf.grid import grid_points  # noqa: E402
from gsdf.heat._yukawa import YukawaTree, grid_nearest_distance  # noqa: E402
from gsdf.heat.grid import _poisson as G  # noqa: E402
from gsdf.heat.grid._domain import GridPoisson  # noqa: E402
from gsdf.heat.volume import VolumeHeatOptions as VO  # noqa: E402
from gsdf.heat.volume import input_spacing, signed_heat_volume, volume_grid_box  # noqa: E402
from gsdf.heat.volume import _sources as S  # noqa: E402
from gsdf.heat.volume._sources import mesh_sources  # noqa: E402
from gsdf.linalg import HermitianFactorization  # noqa: E402
from gsdf.linalg import _iterative as iterative  # noqa: E402
from gsdf.spatial import _knn as knn  # noqa: E402
from gsdf.winding import _point_areas as pa  # noqa: E402


# ---------------------------------------------------------------------------------------------- accuracy
def broken_bunny(frac=0.3, seed=0):
    """bunny00.off with ``frac`` of its faces deleted in round patches around random faces."""
    from scipy.spatial import cKDTree

    V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "bunny00.off"))
    C = V[F].mean(axis=1)
    rng = np.random.default_rng(seed)
    centres = C[rng.choice(len(C), 40, replace=False)]
    d = cKDTree(centres).query(C)[0]
    r = np.quantile(d, frac)  # the radius that removes exactly frac of the faces
    Fb = F[d > r]
    used = np.unique(Fb)  # drop unreferenced vertices (signedheat3d refuses them)
    remap = np.full(len(V), -1)
    remap[used] = np.arange(len(used))
    return V, F, V[used], remap[Fb]


def anchor_grid(V, F, lo, hi, shape, P=None, N=None):
    import signedheat3d as shm

    s = shm.SignedHeatGridSolver(verbose=False)
    opts = {"bbox_min": np.asarray(lo, float), "bbox_max": np.asarray(hi, float),
            "resolution": np.asarray(shape, dtype=np.int64)}
    t = time.perf_counter()
    if P is None:
        phi = s.compute_distance_to_mesh(V, F, opts)
    else:
        phi = s.compute_distance_to_point_cloud(P, N, options=opts)
    el = time.perf_counter() - t
    return s.to_grid_array(np.asarray(phi)), el


def anchor_tet(kw, lo, hi, shape, Q):
    """signedheat3d's tet solver (TetGen mesh, ZeroSet), its field evaluated at ``Q``; (values, s, vertices)."""
    import signedheat3d as shm

    from gsdf.field import TetField

    s = shm.SignedHeatTetSolver(verbose=False)
    opts = {"bbox_min": np.asarray(lo, float), "bbox_max": np.asarray(hi, float),
            "resolution": np.asarray(shape, dtype=np.int64)}
    t = time.perf_counter()
    if "mesh" in kw:
        phi = s.compute_distance_to_mesh(kw["mesh"][0], kw["mesh"][1], opts)
    else:
        phi = s.compute_distance_to_point_cloud(kw["points"][0], kw["points"][1], options=opts)
    el = time.perf_counter() - t
    P, T = np.asarray(s.get_vertices()), np.asarray(s.get_tets())
    return TetField(P, T, np.asarray(phi)).__call__(Q), el, len(P)


def unsigned_error(phi, phi_ref) -> float:
    """Mean ||φ| − |φ_ref||: the distance error with the sign left out."""
    return float(np.abs(np.abs(phi) - np.abs(phi_ref)).mean())


def closed_manifold(F):
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, c = np.unique(E, axis=0, return_counts=True)
    return bool(len(F) > 0 and np.all(c == 2))


def inputs():
    dd = data_dir()
    V, Fi, Vb, Fb = broken_bunny()
    yield "bunny00 −30 % faces", dict(mesh=(Vb, Fb)), (V, Fi)
    for name in ("holes.off", "elephant-with-holes.off", "mech-holes-shark.off"):
        V, F = gsdf.read_mesh(os.path.join(dd, "meshes", name))
        yield name, dict(mesh=(V, F)), (V, F)
    for name in ("kitten.xyz", "oni.pwn"):
        P, N = gsdf.read_points(os.path.join(dd, "points_3", name))
        if N is None:
            N = gsdf.estimate_normals(P)
        yield name, dict(points=(P, N)), (P, N)


def reference(ref, Q, is_mesh):
    return gsdf.signed_distance(*ref, Q) if is_mesh else gsdf.signed_distance_points(*ref, Q)


def run_accuracy(quick, write):
    """The "heat-volume" section: grid and tet domains against signedheat3d at 32³, timings, step I growth,
    offsets (``quick``: no 64³ anchor run, no 128³ timing, no growth / offsets)."""
    lines = []
    V0, Fi, V, Fb = broken_bunny()
    signed_heat_volume(mesh=(V, Fb[:10]), resolution=8)  # JIT warm-up
    signed_heat_volume(mesh=(V, Fb[:10]), resolution=8, domain="tet")

    # 1. accuracy and time against the anchor at 32³ (and 64³ for gsdf), grid and tet domains
    rows, trows = [], []
    for name, kw, ref in inputs():
        is_mesh = "mesh" in kw
        X = kw["mesh"][0] if is_mesh else kw["points"][0]
        for res in (32, 64):
            lo, hi, shape = volume_grid_box(X, res)
            box = dict(resolution=shape, bbox_min=lo, bbox_max=hi)
            Q = grid_points(lo, hi, shape)
            phi_ref = reference(ref, Q, is_mesh)
            diag = np.linalg.norm(X.max(0) - X.min(0))
            f = signed_heat_volume(options=VO(level_set_constraint="none"), **box, **kw)
            eg = np.abs(f.values.ravel() - phi_ref).mean()
            t = time.perf_counter()
            fz = signed_heat_volume(options=VO(level_set_constraint="zero", soft_weight=10.0), **box, **kw)
            tz = time.perf_counter() - t
            ez = np.abs(fz.values.ravel() - phi_ref).mean()
            uz = unsigned_error(fz.values.ravel(), phi_ref)
            # t from the input's own spacing, as signedheat3d sets it (meanEdgeLength²)
            fi = signed_heat_volume(options=VO(level_set_constraint="zero", soft_weight=10.0, t_scale="input"), **box,
                                    **kw)
            ei = np.abs(fi.values.ravel() - phi_ref).mean()
            ui = unsigned_error(fi.values.ravel(), phi_ref)
            ex = "—"
            if res == 32:
                fx = signed_heat_volume(options=VO(level_set_constraint="zero", soft_weight=None), **box, **kw)  # hard (exact rows)
                ex = f"{np.abs(fx.values.ravel() - phi_ref).mean():.5f}"
            ea = ta = ua = "—"
            if res == 32:
                if is_mesh:
                    pa, ta = anchor_grid(kw["mesh"][0], kw["mesh"][1], lo, hi, shape)
                else:
                    pa, ta = anchor_grid(None, None, lo, hi, shape, *kw["points"])
                # the anchor's sign convention: flip if anti-correlated with the reference
                if np.mean(np.sign(pa.ravel()) == np.sign(phi_ref)) < 0.5:
                    pa = -pa
                ea = f"{np.abs(pa.ravel() - phi_ref).mean():.5f}"
                ua = f"{unsigned_error(pa.ravel(), phi_ref):.5f}"
                ta = f"{ta:.2f}"
            rows.append([name, f"{shape}", f"{diag:.3g}", f"{eg:.5f}", f"{ez:.5f}", ex, f"{ei:.5f}", ea, f"{uz:.5f}",
                         f"{ui:.5f}", ua,
                         f"{tz:.2f}", ta])
            print(rows[-1], flush=True)
            if res != 32:
                continue
            # tet domain: both solvers evaluated (piecewise linearly) at the same grid nodes
            t = time.perf_counter()
            ft = signed_heat_volume(domain="tet", options=VO(level_set_constraint="zero"), **box, **kw)
            tt = time.perf_counter() - t
            et = np.abs(ft(Q) - phi_ref).mean()
            ut = unsigned_error(ft(Q), phi_ref)
            ftm = signed_heat_volume(domain="tet", options=VO(level_set_constraint="multiple"), **box, **kw)
            em = np.abs(ftm(Q) - phi_ref).mean()
            fti = signed_heat_volume(domain="tet", options=VO(level_set_constraint="zero", t_scale="input"), **box, **kw)
            eti, uti = np.abs(fti(Q) - phi_ref).mean(), unsigned_error(fti(Q), phi_ref)
            try:
                va, ta2, nva = anchor_tet(kw, lo, hi, shape, Q)
                if np.mean(np.sign(va) == np.sign(phi_ref)) < 0.5:
                    va = -va
                eat, ta2, nva = f"{np.abs(va - phi_ref).mean():.5f}", f"{ta2:.2f}", f"{nva:,}"
                uat = f"{unsigned_error(va, phi_ref):.5f}"
            except Exception as exc:  # noqa: BLE001 - report and go on
                eat, ta2, nva, uat = f"failed ({type(exc).__name__})", "—", "—", "—"
            trows.append([name, f"{shape}", f"{et:.5f}", f"{em:.5f}", f"{eti:.5f}", eat, f"{ut:.5f}", f"{uti:.5f}", uat,
                          f"{ft.meta['n_vertices']:,}", nva,
                          f"{tt:.2f}", ta2])
            print(trows[-1], flush=True)
    lines += ["### Grid domain: mean |SDF error| over the grid nodes and time, gsdf vs signedheat3d (same box and "
              "nodes)", "",
              "gsdf columns: level_set_constraint \"none\" (shift only), \"zero\" with soft_weight=10 (the penalty "
              "at the sources; gsdf heat's default), \"zero\" exact (soft_weight=None: "
              "per-cell trilinear rows, augmented Lagrangian; the library default soft_weight=\"auto\" is the "
              "penalty on grids); "
              "\"input t\": t_scale=\"input\", i.e. t = (mean input edge length or point spacing)², the time "
              "signedheat3d uses (gsdf's default t is the grid spacing², more robust to corrupted normals, "
              "the Points as Tori landscapes); "
              "gsdf s is the soft \"zero\" solve. \"unsigned err\" = mean ||φ| − |φ_ref||: on open inputs "
              "(holes.off: the winding number of the input stays in [−0.36, 0.78], its sign agrees with both "
              "solvers on only ~72 % of the nodes) the reference's sign is itself a guess, and this column "
              "separates distance accuracy from that sign.", "",
              table(["input", "nodes", "bbox diag", "gsdf err (none)", "gsdf err (zero)", "gsdf err (zero, exact)",
                     "gsdf err (zero, input t)", "signedheat3d err", "gsdf unsigned err (zero)",
                     "gsdf unsigned err (zero, input t)", "signedheat3d unsigned err", "gsdf s",
                     "signedheat3d s"], rows), ""]
    lines += ["### Tet domain (32³ grid spacing): mean |SDF error| at the same grid nodes, gsdf vs signedheat3d "
              "(SignedHeatTetSolver, its default ZeroSet constraint, same box and resolution)", "",
              "Both tet fields are evaluated piecewise linearly at the grid nodes (signedheat3d's TetGen mesh by "
              "gsdf.field.locate_in_tets).", "",
              table(["input", "grid nodes", "gsdf tet err (zero)", "gsdf tet err (multiple)",
                     "gsdf tet err (zero, input t)", "signedheat3d tet err", "gsdf tet unsigned err",
                     "gsdf tet unsigned err (input t)", "signedheat3d tet unsigned err", "gsdf vertices", "signedheat3d vertices", "gsdf s", "signedheat3d s"], trows), ""]

    if not quick:  # partial results first (the rest takes minutes more)
        write("\n".join(lines) + "\n(partial: timing, step I growth and offsets still running)\n")

    # 2. timing at 64³ / 128³ on the broken bunny
    rows = []
    small = quick
    for res in ((64, 128) if not small else (64,)):
        lo, hi, shape = volume_grid_box(V, res)
        t = time.perf_counter()
        f = signed_heat_volume(mesh=(V, Fb), resolution=shape, bbox_min=lo, bbox_max=hi, options=VO(soft_weight=10.0))
        el = time.perf_counter() - t
        tm = f.meta["timings"]  # level_set_constraint "zero" with the soft penalty (gsdf heat's default)
        rows.append([f"{shape}", f"{el:.2f}", f"{tm['step1']:.2f}", f"{tm['step3']:.2f}"])
        print(rows[-1], flush=True)
    if not quick:
        lo, hi, shape = volume_grid_box(V, 64)
        _, ta = anchor_grid(V, Fb, lo, hi, shape)
        rows.append([f"signedheat3d {shape}", f"{ta:.1f}", "", ""])
        print(rows[-1], flush=True)
    lines += ["### Broken bunny: total / step I / step III seconds", "",
              table(["grid", "total s", "step I s", "step III s"], rows), ""]

    if small:
        return "\n".join(lines)

    # 3. step I growth with resolution and face count
    rows = []
    Vs, Fs = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "bunny00.off"))
    for nf in (len(Fs) // 16, len(Fs) // 4, len(Fs)):
        src = mesh_sources(Vs, Fs[:: max(1, len(Fs) // nf)])
        for res in (32, 64, 96):
            lo, hi, shape = volume_grid_box(Vs, res)
            sp = (hi - lo) / (np.array(shape) - 1)
            tree = YukawaTree(src.B, src.W, float(sp.max()) ** 2, theta=1.5)
            d, sl = grid_nearest_distance(src.B, lo, sp, shape)
            Q = grid_points(lo, hi, shape)
            t = time.perf_counter()
            tree(Q, d, sl)
            el = time.perf_counter() - t
            rows.append([len(src.B), f"{shape}", len(Q), f"{el:.2f}", f"{1e6 * el / len(Q):.2f}"])
            print(rows[-1], flush=True)
    lines += ["### Step I (tree Yukawa sum) growth", "",
              table(["faces", "grid", "nodes", "step I s", "µs / node"], rows), ""]

    # 4. offsets ±1 % and ±3 % of the bbox diagonal
    rows = []
    lo, hi, shape = volume_grid_box(V, 96)
    f = signed_heat_volume(mesh=(V, Fb), resolution=shape, bbox_min=lo, bbox_max=hi, options=VO(soft_weight=10.0))
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    for frac in (-0.03, -0.01, 0.0, 0.01, 0.03):
        Vc, Fc = f.isosurface(frac * diag)
        Vk, Fk = f.isosurface(frac * diag, close=True)
        rows.append([f"{frac:+.0%}", len(Fc), "yes" if closed_manifold(Fc) else "NO (reaches the box)",
                     "yes" if closed_manifold(Fk) else "NO"])
    lines += ["### Offsets of the broken bunny (96³ grid)", "",
              table(["offset / diag", "triangles", "closed, edge-manifold (raw)", "closed (close=True, capped)"],
                    rows), ""]
    return "\n".join(lines)



# ---------------------------------------------------------------------------------------------- speed, scaling
ALL = ["holes.off", "elephant-with-holes.off", "mech-holes-shark.off", "fandisk.off", "cow soup −25 % faces",
       "kitten.xyz", "oni.pwn", "hippo1.ply", "bunny00 −30 % faces", "couplingdown.off"]  # slowest anchors last
SLOW_ANCHOR = 60.0  # s: an anchor run longer than this is not repeated (its speed-up is > 100× either way)
QUICK = ["holes.off", "elephant-with-holes.off", "fandisk.off", "cow soup −25 % faces", "oni.pwn"]
KIND = {"bunny00 −30 % faces": "scan, holes cut", "holes.off": "mesh with holes",
        "elephant-with-holes.off": "mesh with holes", "mech-holes-shark.off": "CAD-like, holes",
        "fandisk.off": "CAD, closed", "couplingdown.off": "CAD, closed",
        "cow soup −25 % faces": "soup: unshared, 10 % flipped, holes", "kitten.xyz": "cloud",
        "oni.pwn": "cloud", "hippo1.ply": "cloud (scan)"}


def rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


# ---------------------------------------------------------------- inputs
def load_input(name):
    """(kw for signed_heat_volume, reference geometry, is_mesh)."""
    import gsdf

    dd = data_dir()
    if name.startswith("bunny00"):

        V, F, Vb, Fb = broken_bunny()
        return dict(mesh=(Vb, Fb)), (V, F), True
    if name.startswith("cow soup"):
        V, F = gsdf.read_mesh(os.path.join(dd, "meshes", "cow.off"))
        rng = np.random.default_rng(1)
        keep = np.sort(rng.choice(len(F), int(0.75 * len(F)), replace=False))
        Fk = F[keep].copy()
        flip = rng.random(len(Fk)) < 0.1
        Fk[flip] = Fk[flip][:, ::-1]
        Vs = V[Fk].reshape(-1, 3)  # every triangle its own three vertices: a soup
        return dict(mesh=(Vs, np.arange(len(Vs)).reshape(-1, 3))), (V, F), True
    if name.endswith(".off"):
        V, F = gsdf.read_mesh(os.path.join(dd, "meshes", name))
        return dict(mesh=(V, F)), (V, F), True
    P, N = gsdf.read_points(os.path.join(dd, "points_3", name))
    if N is None:
        N = gsdf.estimate_normals(P)
    return dict(points=(P, N)), (P, N), False


def scaled_input(kind, k):
    """Inputs of growing size for the scaling table: every k-th face of bunny00 / point of sphere_20k."""
    import gsdf

    if kind == "bunny00 faces":
        V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "bunny00.off"))
        Fk = F[::k]
        used = np.unique(Fk)
        remap = np.full(len(V), -1)
        remap[used] = np.arange(len(used))
        return dict(mesh=(V[used], remap[Fk])), len(Fk)
    P, N = gsdf.read_points(os.path.join(data_dir(), "points_3", "sphere_20k_normal.xyz"))
    return dict(points=(P[::k], N[::k])), len(P[::k])


def box_of(kw, res):
    from gsdf.heat.volume import volume_grid_box

    X = kw["mesh"][0] if "mesh" in kw else kw["points"][0]
    return volume_grid_box(X, res)


# ---------------------------------------------------------------- workers (one process per case)
STAGES = [  # (label, file suffix, function name): disjoint stages of the grid path
    ("sources", "heat/volume/_sources.py", "mesh_sources"),
    ("sources", "heat/volume/_sources.py", "point_sources"),
    ("step I tree build", "heat/_yukawa.py", "__init__"),
    ("step I nearest", "heat/_yukawa.py", "grid_nearest_distance"),
    ("step I sum", "heat/_yukawa.py", "__call__"),
    ("step I sum", "heat/grid/_screened.py", "screened_heat"),  # the grid solve of Step I (chosen per input)
    ("step II normalize", "heat/_core.py", "unit_field"),
    ("divergence", "heat/grid/_domain.py", "divergence"),
    ("factorization (coarse)", "linalg/_direct.py", "__init__"),
    ("CG solve", "linalg/_iterative.py", "pcg"),
    ("CG solve", "linalg/_iterative.py", "cg_loop"),       # the grid's soft-penalty solve (numba operators)
    ("shift", "heat/_core.py", "shift"),
]


def profile_stages(fn):
    import cProfile
    import pstats

    pr = cProfile.Profile()
    t = time.perf_counter()
    pr.enable()
    fn()
    pr.disable()
    total = time.perf_counter() - t
    st = pstats.Stats(pr).stats
    out = {}
    for label, suffix, func in STAGES:
        for (file, _line, name), (_cc, _nc, _tt, ct, _callers) in st.items():
            if name == func and file.replace(os.sep, "/").endswith(suffix):
                out[label] = out.get(label, 0.0) + ct
    out["other"] = total - sum(out.values())
    out["total (profiled)"] = total
    return out


def anchor_call(kw, lo, hi, shape):
    """signedheat3d's grid solver on ``kw``; (φ on the grid, whether its AMGCL solve fell back to the direct one).

    Step 3 of signedheat3d's grid solver is an AMGCL BiCGStab solve (tol 1e-2, at most 1000 iterations) whose
    start vector is left uninitialised; when it does not converge the solver falls back to a sparse direct LU of
    the saddle-point system. Which path a call takes depends on leftover heap memory, so the time of one call
    varies several-fold (couplingdown: 2.7 s converged, 7-37 s with the 1000 iterations and the fallback). The
    solver's own verbose log (file descriptor 2, captured here) says which path was taken.
    """
    import tempfile

    import signedheat3d as shm

    s = shm.SignedHeatGridSolver(verbose=True)
    opts = {"bbox_min": np.asarray(lo, float), "bbox_max": np.asarray(hi, float),
            "resolution": np.asarray(shape, dtype=np.int64)}
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+") as log:
        os.dup2(log.fileno(), 2)
        try:
            if "mesh" in kw:
                phi = s.compute_distance_to_mesh(kw["mesh"][0], kw["mesh"][1], opts)
            else:
                phi = s.compute_distance_to_point_cloud(kw["points"][0], kw["points"][1], options=opts)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        log.seek(0)
        fell_back = "use direct solver" in log.read()
    return s.to_grid_array(np.asarray(phi)).ravel(), fell_back


def worker(args):
    who, name, res, repeat = args[0], args[1], int(args[2]), int(args[3])
    t_first = None
    if who == "gsdf":
        from gsdf.heat.volume import signed_heat_volume

        t = time.perf_counter()
        C = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1, -1], [0.5, -1, 0.2]])
        signed_heat_volume(points=(C, C), resolution=6)  # numba kernels: load (or compile)
        signed_heat_volume(mesh=(C, np.array([[0, 1, 2], [0, 2, 3], [1, 3, 4]])), resolution=6)
        t_first = time.perf_counter() - t
    else:
        import signedheat3d  # noqa: F401
    if name.startswith("scale:"):
        _, kind, k = name.split(":")
        kw, size = scaled_input(kind, int(k))
        ref = None
    else:
        kw, ref, is_mesh = load_input(name)
        size = len(kw["mesh"][1]) if "mesh" in kw else len(kw["points"][0])
    lo, hi, shape = box_of(kw, res)
    base = rss_mb()
    times, phi, fallbacks = [], None, []
    for _ in range(repeat):
        if who == "gsdf":  # every run builds its grid operators, as the anchor's new solver object does
            from gsdf.heat.grid import _poisson as _grid

            _grid._dct_matrix.cache_clear()  # (the Step III operators are built per solve)
        t = time.perf_counter()
        if who == "gsdf":
            from gsdf.heat.volume import signed_heat_volume

            f = signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, **kw)
            phi = f.values.ravel()
        else:
            phi, fell_back = anchor_call(kw, lo, hi, shape)
            fallbacks.append(fell_back)
        times.append(time.perf_counter() - t)
        if who == "anchor" and times[-1] > SLOW_ANCHOR:
            break
    peak = rss_mb()
    out = {"who": who, "name": name, "size": size, "shape": list(shape), "times": times,
           "median": float(np.median(times)), "rss_mb": peak, "base_rss_mb": base, "first_call": t_first,
           "fallbacks": int(sum(fallbacks))}
    if who == "gsdf":  # the solve's own array memory: numpy / scipy buffers seen by tracemalloc (not timed)
        import tracemalloc

        from gsdf.heat.volume import signed_heat_volume

        tracemalloc.start()
        signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, **kw)
        out["traced_mb"] = tracemalloc.get_traced_memory()[1] / 2 ** 20
        tracemalloc.stop()
    if who == "gsdf" and ref is not None:
        from gsdf.heat.volume import signed_heat_volume

        out["stages"] = profile_stages(lambda: signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, **kw))
        fi = signed_heat_volume(resolution=shape, bbox_min=lo, bbox_max=hi, options=VO(t_scale="input"), **kw)
    if ref is not None:
        import gsdf
        from gsdf.grid import grid_points

        Q = grid_points(lo, hi, shape)
        phi_ref = gsdf.signed_distance(*ref, Q) if is_mesh else gsdf.signed_distance_points(*ref, Q)
        if who == "anchor" and np.mean(np.sign(phi) == np.sign(phi_ref)) < 0.5:
            phi = -phi
        out["err"] = float(np.abs(phi - phi_ref).mean())
        if who == "gsdf":
            out["err_input_t"] = float(np.abs(fi.values.ravel() - phi_ref).mean())
    print("RESULT " + json.dumps(out), flush=True)


def run_case(who, name, res, repeat):
    env = dict(os.environ)
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", who, name, str(res), str(repeat)]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=3600)
    for line in p.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    sys.stderr.write(p.stdout[-2000:] + p.stderr[-4000:])
    return {"who": who, "name": name, "failed": (p.stderr.strip().splitlines() or ["?"])[-1][:120]}


# ---------------------------------------------------------------- main
def speed_table(names, repeat_gsdf, repeat_anchor, label, partial=None):
    rows, srows, cases = [], [], []
    for name in names:
        if partial is not None and rows:
            partial(rows, srows)
        g = run_case("gsdf", name, 32, repeat_gsdf)
        a = run_case("anchor", name, 32, repeat_anchor)
        cases.append((g, a))
        print(f"[{label}] {name}: gsdf {g.get('median', 'failed')} anchor {a.get('median', 'failed')} "
              f"({uptime()})", flush=True)
        if "failed" in g or "failed" in a:
            rows.append([name, KIND[name], "—", "—", "—", "—", "—", "—", "—", "—", "—", "—", "—",
                         f"failed: {g.get('failed', '')} {a.get('failed', '')}"])
            continue
        ratio, ratio_min = a["median"] / g["median"], min(a["times"]) / g["median"]
        nrep = (f" ({len(a['times'])} runs: stopped after one > {SLOW_ANCHOR:.0f} s)"
                if len(a["times"]) < repeat_anchor else "")
        spread = f"{min(a['times']):.2f} / **{a['median']:.2f}** / {max(a['times']):.2f}{nrep}"

        def fmt(r):
            return f"**{r:.0f}×**" if r >= 20 else f"{r:.1f}×"

        rows.append([name, KIND[name], f"{g['size']:,}", str(tuple(g["shape"])),
                     f"{min(g['times']):.3f} / **{g['median']:.3f}** / {max(g['times']):.3f}",
                     spread, f"{a.get('fallbacks', 0)}/{len(a['times'])}", fmt(ratio), fmt(ratio_min),
                     f"{g['err']:.5f}", f"{g['err_input_t']:.5f}", f"{a['err']:.5f}",
                     f"{g['rss_mb']:.0f} ({g['base_rss_mb']:.0f}) / {a['rss_mb']:.0f} ({a['base_rss_mb']:.0f})",
                     f"{g.get('traced_mb', float('nan')):.1f}"])
        s = g["stages"]
        srows.append([name] + [f"{s.get(k, 0.0) * 1e3:.0f}" for k in
                               ("sources", "step I tree build", "step I nearest", "step I sum", "step II normalize",
                                "divergence", "factorization (coarse)", "CG solve", "shift", "other",
                                "total (profiled)")] + [f"{g['first_call']:.1f}"])
    return rows, srows, cases


def scaling_table(quick):
    rows = []
    ks = {"bunny00 faces": (16, 4, 1), "sphere_20k points": (16, 4, 1)}
    for kind, kk in ks.items():
        for res in ((32,) if quick else (32, 64)):
            prev = None
            for k in kk:
                r = run_case("gsdf", f"scale:{kind}:{k}", res, 3 if res == 32 else 1)
                if "failed" in r:
                    rows.append([kind, "?", res, "failed", "", "", "", r["failed"]])
                    continue
                grow = ""
                if prev is not None:
                    mem = (f"{r['traced_mb'] / prev['traced_mb']:.2f}" if "traced_mb" in r and "traced_mb" in prev
                           else "—")
                    grow = f"{(r['median'] / prev['median']):.2f} / {mem} (input ×{r['size'] / prev['size']:.1f})"
                rows.append([kind, f"{r['size']:,}", str(tuple(r["shape"])), f"{r['median']:.3f}",
                             f"{r['rss_mb']:.0f}", f"{r['rss_mb'] - r['base_rss_mb']:.0f}",
                             f"{r['traced_mb']:.1f}" if "traced_mb" in r else "—", grow])
                print(rows[-1], flush=True)
                prev = r
    return rows


def run_speed(quick, load, scaling_only, write):
    """The "heat-volume-speed" section (``scaling_only``: the "heat-volume-scaling" one)."""
    names = QUICK if quick else ALL
    rep_g = rep_a = 3 if quick else 5  # the same number of warm runs for both
    head = [f"gsdf: median of {rep_g}; signedheat3d: median of {rep_a} (no further run after one over {SLOW_ANCHOR:.0f} s), "
            "both in a process of their own, every run timed (gsdf's numba kernels loaded before the first; its "
            "DCT-matrix cache cleared before each run and its Step III operators built in every run, as signedheat3d gets a new solver object per run). "
            "signedheat3d's time varies between runs because its Step 3 (AMGCL BiCGStab, tol 1e-2) starts from an "
            "uninitialised vector: when it fails to converge in 1000 iterations the solver falls back to a sparse "
            "direct LU (\"AMGCL fell back\": runs that did, from its own log); its Steps 1-2 (direct sums over all "
            "nodes × sources) take the same time every run. Both speed-ups are listed: medians, and against the "
            "anchor's fastest run. Grid 32³ along the longest side "
            "(cubic cells), the box padded by 10 % of the diagonal, the same box and node counts for both. gsdf "
            "defaults (\"zero\", soft penalty); \"gsdf err input t\" is t_scale=\"input\" (signedheat3d's t). "
            "RSS: peak of the case's own process, MB (its baseline after imports in parentheses).", ""]
    t0 = time.perf_counter()

    def tables(rows, srows):
        return ["### 32³ grid: time, accuracy, peak RSS, gsdf vs signedheat3d", "",
                table(["input", "kind", "faces / points", "nodes", "gsdf s min / median / max",
                       "signedheat3d s min / median / max", "AMGCL fell back", "speed-up (medians)",
                       "speed-up vs anchor's fastest run", "gsdf err", "gsdf err input t", "signedheat3d err",
                       "peak RSS MB gsdf / signedheat3d", "gsdf arrays MB"], rows), "",
                "### gsdf stages at 32³ (ms, one cProfile'd run; first call = numba load/compile of the process, s)",
                "", table(["input", "sources", "tree build", "nearest", "step I sum", "normalize", "divergence",
                           "coarse LU", "CG", "shift", "other", "total", "first call s"], srows), ""]

    def partial(rows, srows):
        write("\n".join(head + tables(rows, srows)) + f"\n(partial: {len(rows)} of {len(names)} inputs so far; {uptime()})\n")

    if scaling_only:  # just the growth table, in its own section
        names = []
        text = []
    else:
        rows, srows, _ = speed_table(names, rep_g, rep_a, "idle", partial)
        text = head + tables(rows, srows)
    if load and names:
        with BusyLoad(2):
            lrows, _, _ = speed_table(names, rep_g, rep_a, "load")
        text += ["### Same, with two busy processes (bench/load.py)", "",
                 table(["input", "kind", "faces / points", "nodes", "gsdf s", "signedheat3d s",
                        "AMGCL fell back", "speed-up (medians)", "speed-up vs fastest", "gsdf err", "gsdf err input t", "signedheat3d err", "peak RSS MB", "gsdf arrays MB"], lrows), ""]
    if scaling_only:
        srows2 = scaling_table(quick)
        text += ["### Scaling with input size at a fixed grid (gsdf, peak RSS per case)", "",
                 "Peak RSS is the case's own process (interpreter, numba and SciPy included: ~185–210 MB before "
                 "any work); \"RSS above baseline\" its growth during the solves (0: below the peak of the "
                 "imports and kernel loading); \"arrays MB\" the peak of numpy / SciPy buffers during one solve "
                 "(tracemalloc; SuperLU's and numba's own allocations are not seen). Growth = time ratio / arrays "
                 "ratio to the previous row; linear in the input would be ≤ the input ratio.", "",
                 table(["input", "faces / points", "nodes", "s (median)", "peak RSS MB", "RSS above baseline MB",
                        "arrays MB", "growth time / memory"], srows2), ""]
    text += [f"Total {time.perf_counter() - t0:.0f} s."]
    return "\n".join(text)



# ---------------------------------------------------------------------------------------------- choices
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


@contextlib.contextmanager
def forced_step1(step1):
    """Step I by ``step1`` ("yukawa": the tree sum, "heat": the screened grid solve) instead of the library's
    choice per input, inside the block (the grid domain's ``step1`` is not a public option)."""
    from gsdf.heat.grid._domain import GridDomain

    init = GridDomain.__init__

    def forced(self, *args, **kwargs):
        init(self, *args, **{**kwargs, "step1": step1})

    GridDomain.__init__ = forced
    try:
        yield
    finally:
        GridDomain.__init__ = init


def part_step1():
    rows = []
    for res, names in ((32, ALL), (64, MESHES_64)):
        for name in names:
            kw, box, ref = case(name, res)
            row = [name, res]
            errs = []
            for s1 in ("yukawa", "heat"):
                with forced_step1(s1):
                    t, f = timed(kw, box, repeat=3 if res == 64 else 5)
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



# ---------------------------------------------------------------------------------------------- solvers
def _grab(module, name):
    """Run with ``module.name`` (a solver class) wrapped so the matrix it is built from is kept."""
    got = {}
    cls = getattr(module, name)

    class Grab(cls):
        def __init__(self, A, **kw):
            got.setdefault("A", A)
            super().__init__(A, **kw)

    setattr(module, name, Grab)
    return got, lambda: setattr(module, name, cls)


def _median(f, n=3):
    ts = []
    for _ in range(n):
        t = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), out


def hermitian():
    import gsdf.heat._core as CORE
    import gsdf.heat.polygon._solver as PM
    import gsdf.heat.triangle._solver as SM
    from bench_heat_surface import _cube_sphere

    mats = []
    got, undo = _grab(CORE, "HermitianFactorization")  # the signed heat core factorizes for every domain
    V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "bunny00.off"))
    SM.SurfaceSignedHeatSolver(V, F).vector_heat_factorization
    undo()
    mats.append(("bunny00.off, CR edges", got["A"]))
    got, undo = _grab(CORE, "HermitianFactorization")
    V, Q = _cube_sphere(64)
    PM.PolygonMeshSignedHeatSolver(V, list(Q)).core.vector_heat_factorization
    undo()
    mats.append((f"cube sphere, {len(Q)} quads, vertices", got["A"]))
    rows = []
    rng = np.random.default_rng(0)
    for name, A in mats:
        b = rng.standard_normal(A.shape[0]) + 1j * rng.standard_normal(A.shape[0])
        res = {}
        for be in ("superlu", "cholmod"):
            tf, H = _median(lambda: HermitianFactorization(A, backend=be))
            ts, x = _median(lambda: H.solve(b), 5)
            res[be] = (tf, ts, float(np.abs(A @ x - b).max()))
        rows.append([name, f"{A.shape[0]:,}", f"{res['superlu'][0]:.3f}", f"{res['cholmod'][0]:.3f}",
                     f"{res['superlu'][1]:.4f}", f"{res['cholmod'][1]:.4f}",
                     f"{max(res['superlu'][2], res['cholmod'][2]):.1e}"])
        print(rows[-1], flush=True)
    return ("### Hermitian vector-heat factorization\n\n"
            + table(["operator", "unknowns", "SuperLU factorize s", "CHOLMOD (2n real) factorize s", "SuperLU solve s",
                     "CHOLMOD solve s", "max residual"], rows) + "\n")


def tet_step3():
    import gsdf.heat.tet._domain as T

    got, undo = _grab(T, "SPDSolver")  # the tet domain's Poisson solves (through gsdf.heat._core)
    V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "mech-holes-shark.off"))
    signed_heat_volume(mesh=(V, F), resolution=32, domain="tet")
    undo()
    A = sp.csr_matrix(got["A"])
    b = np.random.default_rng(1).standard_normal(A.shape[0])
    from scipy.sparse.linalg import splu

    rows = []
    tcg, x = _median(lambda: T.SPDSolver(A).solve(b))
    rows.append(["SPDSolver default (Jacobi or pyamg CG, rtol 1e-10)", f"{tcg:.3f}", f"{np.abs(A @ x - b).max():.1e}"])
    tch, x = _median(lambda: T.SPDSolver(A, direct_max=10**9).solve(b), 1)
    rows.append(["SPDSolver factorized (CHOLMOD via cholespy)", f"{tch:.3f}", f"{np.abs(A @ x - b).max():.1e}"])
    tlu, x = _median(lambda: splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.1).solve(b), 1)
    rows.append(["SuperLU (MMD_AT_PLUS_A), the fallback before this change", f"{tlu:.3f}",
                 f"{np.abs(A @ x - b).max():.1e}"])
    for r in rows:
        print(r, flush=True)
    return (f"### Tet step III on mech-holes-shark.off at 32³ ({A.shape[0]:,} unknowns, {A.nnz:,} nonzeros), "
            "setup + one solve\n\n" + table(["solver", "s", "max residual"], rows) + "\n")


def t_scale_study(res=48):
    from gsdf.data import _shapes as S

    X = S.grid(res)
    rows, tot = [], {"grid": [], "input": []}
    for shape in ("cylinder", "sphere"):
        sample = S.sample_cylinder if shape == "cylinder" else S.sample_sphere
        truth = S.cylinder_sdf if shape == "cylinder" else S.sphere_sdf
        for r in ([0.1, 0.3] if shape == "cylinder" else [0.2, 0.6]):
            tr = truth(X, r)
            for kind, lv in [("clean", 0), ("density", 256), ("noise", 0.02), ("outliers", 0.02), ("flips", 0.1),
                             ("flips", 0.3)]:
                rng = np.random.default_rng(zlib.crc32(repr((shape, r, kind, lv)).encode()))
                P, N = sample(int(lv if kind == "density" else 2048), r, rng)
                P, N = S.corrupt(P, N, rng, noise=lv if kind == "noise" else 0.0,
                                 outliers=lv if kind == "outliers" else 0.0, flips=lv if kind == "flips" else 0.0)
                errs = {}
                for ts in ("grid", "input"):
                    try:
                        v = signed_heat_volume(points=(P, N), resolution=(res,) * 3, bbox_min=[-1] * 3,
                                               bbox_max=[1] * 3, options=VO(t_scale=ts))(X)
                    except ValueError:  # e.g. an outlier outside the box: φ = 0
                        v = np.zeros(len(X))
                    errs[ts] = float(np.abs(v - tr).mean())
                    tot[ts].append(errs[ts])
                rows.append([shape, r, kind, lv, f"{input_spacing(P) / (2 / (res - 1)):.2f}",
                             f"{errs['grid']:.4f}", f"{errs['input']:.4f}"])
                print(rows[-1], flush=True)
    summary = (f"Mean over the {len(rows)} cases: t_scale=\"grid\" {np.mean(tot['grid']):.4f}, "
               f"t_scale=\"input\" {np.mean(tot['input']):.4f}.")
    return (f"### Volume SHM diffusion time on corrupted clouds ({res}³ over [-1,1]³, mean |φ − φ_true|)\n\n"
            + table(["shape", "radius", "corruption", "level", "input spacing / grid spacing", "t_scale grid",
                     "t_scale input"], rows) + "\n\n" + summary + "\n")



# ---------------------------------------------------------------------------------------------- main
PARTS = ("accuracy", "speed", "scaling", "choices", "solvers")
SECTIONS = {"accuracy": "heat-volume", "speed": "heat-volume-speed", "scaling": "heat-volume-scaling",
            "choices": "heat-volume-choices", "solvers": "solver-choices"}
TITLES = {"accuracy": "Signed heat method in volumes against signedheat3d: accuracy",
          "speed": "Volume signed heat: speed and memory against signedheat3d",
          "scaling": "Volume signed heat: growth with input size at a fixed grid",
          "choices": "Volume signed heat: the measured choices behind its grid defaults",
          "solvers": "Solver choices: complex factorization, tet step III, volume t_scale"}


def run_choices(rounds):
    C = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1, -1], [0.5, -1, 0.2]])
    signed_heat_volume(points=(C, C), resolution=6)        # numba kernels loaded before any timing
    signed_heat_volume(mesh=(C, np.array([[0, 1, 2], [0, 2, 3], [1, 3, 4]])), resolution=6)
    text = []
    for block in (part_tol(), part_step1(), part_threads(rounds), part_penalty()):
        print("\n".join(block), flush=True)
        text += block
    return "\n".join(text)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="reduced sizes and fewer inputs in accuracy, speed, scaling")
    ap.add_argument("--only", default="", help=f"comma list of parts: {','.join(PARTS)} (default all)")
    ap.add_argument("--load", action="store_true", help="speed: also under two busy processes")
    ap.add_argument("--rounds", type=int, default=10, help="choices: idle / loaded rounds of the threads table")
    args = ap.parse_args(argv)
    parts = [p for p in args.only.split(",") if p] or list(PARTS)
    for p in parts:
        if p not in PARTS:
            ap.error(f"--only: unknown part {p!r}; known: {', '.join(PARTS)}")
    for part in parts:
        start = uptime()
        flags = [f"--only {part}"] + (["--quick"] if args.quick and part in ("accuracy", "speed", "scaling") else []) \
            + (["--load"] if args.load and part == "speed" else [])
        cmd = command("bench_heat_volume.py", flags, python="/work/anchors/bin/python")

        def write(body, part=part, cmd=cmd, start=start):
            text = heading(TITLES[part], cmd, start) + body.strip() + "\n"
            write_section(SECTIONS[part], text)
            return text

        if part == "accuracy":
            body = run_accuracy(args.quick, write)
        elif part in ("speed", "scaling"):
            body = run_speed(args.quick, args.load, part == "scaling", write)
        elif part == "choices":
            body = run_choices(args.rounds)
        else:
            body = "\n".join([hermitian(), tet_step3(), t_scale_study()])
        print(write(body), flush=True)


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2:])
    else:
        main()
