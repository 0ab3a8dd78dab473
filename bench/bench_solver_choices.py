"""Measurements behind three defaults of gsdf (prints them and writes bench/RESULTS.md "solver-choices").

1. ``HermitianFactorization``: complex SuperLU (default) vs CHOLMOD on the 2n real embedding, on the vector heat
   operators of bunny00.off (CR edges) and of a 24576-quad sphere (polygon solver).
2. Tet step III: ``SPDSolver`` preconditioned CG (default above 5000 unknowns) vs a factorization, on the
   mech-holes-shark tet system at 32³.
3. Volume SHM ``t_scale``: "grid" (default) vs "input" on corrupted point clouds (cylinders and spheres, the
   Points-as-Tori corruptions) at 48³; mean |φ − φ_true|.

    python3 bench/bench_solver_choices.py
"""

from __future__ import annotations

import os
import sys
import time
import zlib

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import data_dir, machine, table, write_section  # noqa: E402

import gsdf  # noqa: E402
from gsdf.heat.volume import input_spacing, signed_heat_volume  # noqa: E402
from gsdf.linalg import HermitianFactorization  # noqa: E402


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
                                               bbox_max=[1] * 3, t_scale=ts)(X)
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


def main():
    parts = [f"## Solver choices (defaults of gsdf.linalg, tet step III, volume t_scale)\n\nMachine: {machine()}\n\n"
             "Command: `python3 bench/bench_solver_choices.py`\n"]
    parts += [hermitian(), tet_step3(), t_scale_study()]
    text = "\n".join(parts)
    print(text)
    write_section("solver-choices", text)


if __name__ == "__main__":
    main()
