"""Signed heat method on digital surfaces (Feng & Crane 2024 §8.5): convergence and timings.

* Digital sphere R = N/2 − 2 at N = 16 … 128, curve = boundary of {quads with centre z < zc + ¼},
  zc = c + round(0.3 R), reference
  φ⁰ = R(θ − θ0) at the radial projection; §9.1 error ε, sign correct (fraction of area, against the digital
  region; curve vertices excluded); corrected normals (integral invariants, r = 3 voxels, and r = ½ N^{2/3}
  voxels, i.e. r ∝ h^{1/3} in world units), trivial normals, and the broken curve (50 % of segments deleted).
* Slanted digital planes (normal (1,1,1) and (1,2,0)) with a straight curve through the centre; reference the
  in-plane signed distance on the plane's vertices within 0.3 N of the centre; normals: II r = 3, trivial, and
  exact (the analytic normal on the plane's quads).
* Option A vs Option B connection Laplacian, timings (surface, normals, operators, first solve with the
  factorizations, repeated solve).

Run: ``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python3 bench/bench_heat_voxel.py``
(writes the "heat-voxel" section of RESULTS.md).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import machine, write_section  # noqa: E402

from gsdf.contour import region_boundary_curves  # noqa: E402
from gsdf.heat.voxel._digital import digital_surface, integral_invariant_normals  # noqa: E402
from gsdf.heat.voxel._domain import VoxelSurfaceSignedHeatSolver  # noqa: E402

SIZES = [int(s) for s in os.environ.get("VOXEL_SIZES", "16,32,64,128").split(",")]


def eps(phi, ref, A):
    return float(np.sqrt((A * (phi - ref) ** 2).sum() / A.sum()) / (ref.max() - ref.min()))


def ball(N, R):
    x = np.indices((N,) * 3) - (N - 1) / 2
    return (x ** 2).sum(0) <= R ** 2


def sphere(N, radius=3.0, broken=False, connection="A", timings=None, t_coef=1.0):
    R = N / 2 - 2
    occ = ball(N, R)
    t0 = time.perf_counter()
    s = VoxelSurfaceSignedHeatSolver(occ, normal_radius=radius, connection=connection, t_coef=t_coef)
    t_build = time.perf_counter() - t0
    c = N / 2
    # the curve at the grid plane z = zc nearest to c + 0.3 R (quads with centres below zc + ¼: the region's
    # boundary edges then lie on that plane, not up to half a voxel off it)
    zc = c + np.round(0.3 * R)
    region = s.face_centres[:, 2] < zc + 0.25
    curves = region_boundary_curves(s.faces, region)
    if broken:
        curves = [p for g in curves for p in (g[a:a + 5] for a in range(0, len(g) - 1, 8)) if len(p) >= 2]
    t0 = time.perf_counter()
    phi = s.compute_distance(curves)
    t_first = time.perf_counter() - t0
    t0 = time.perf_counter()
    s.compute_distance(curves)
    t_again = time.perf_counter() - t0
    P = s.vertices - c
    ref = R * (np.arccos(np.clip(-P[:, 2] / np.linalg.norm(P, axis=1), -1, 1)) - np.arccos(-(zc - c) / R))
    A = s.domain.mass()
    nin = np.bincount(s.faces.ravel(), weights=np.repeat(region, 4).astype(float), minlength=len(P))
    nall = np.bincount(s.faces.ravel(), minlength=len(P))
    inside, outside = nin == nall, nin == 0
    ok = (inside & (phi < 0)) | (outside & (phi > 0))
    if timings is not None:
        timings.update(build=t_build, first=t_first, again=t_again, n=len(s.vertices), m=len(s.faces))
    return eps(phi, ref, A), float(A[ok].sum() / A[inside | outside].sum())


def plane(N, nrm, mdir, radius=3.0, exact=False, t_coef=1.0):
    nrm = np.asarray(nrm, float) / np.linalg.norm(nrm)
    m = np.asarray(mdir, float) / np.linalg.norm(mdir)
    x = np.indices((N,) * 3).transpose(1, 2, 3, 0) + 0.5
    occ = ((x - N / 2) @ nrm) < 0
    normals = None
    if exact:
        S = digital_surface(occ, np.ones(3))
        on = ((S.trivial_normals @ nrm) > 0) & (np.abs((S.centres - N / 2) @ nrm) < 1.0)
        normals = np.where(on[:, None], nrm, S.trivial_normals)
    s = VoxelSurfaceSignedHeatSolver(occ, normal_radius=radius, normals=normals, t_coef=t_coef)
    ctr = np.full(3, N / 2)
    phi = s.compute_distance(region_boundary_curves(s.faces, (s.face_centres - ctr) @ m < 0))
    P = s.vertices - ctr
    sel = (np.linalg.norm(P - np.outer(P @ nrm, nrm), axis=1) < 0.3 * N) & (np.abs(P @ nrm) < 1.0)
    return eps(phi[sel], (P @ m)[sel], s.domain.mass()[sel])


def icosphere(subdivisions, R=1.0, z_rel=0.3):
    """Baseline: the triangle-mesh (Crouzeix–Raviart) signed heat method on an icosphere, curve z = z_rel·R."""
    from gsdf.heat import SurfaceSignedHeatSolver
    from gsdf.contour._surface_curves import level_set_curves
    from gsdf.data._shapes import sphere_mesh

    V, F = sphere_mesh(subdivisions, R)
    s = SurfaceSignedHeatSolver(V, F)
    t0 = time.perf_counter()
    phi = s.compute_distance(level_set_curves(V, F, V[:, 2] - z_rel * R))
    dt = time.perf_counter() - t0
    ref = R * (np.arccos(np.clip(-V[:, 2] / R, -1, 1)) - np.arccos(-z_rel))
    return eps(phi, ref, s.ops.vertex_mass()), len(V), dt


def order(errs):
    return [float("nan")] + [float(np.log2(a / b)) for a, b in zip(errs[:-1], errs[1:])]


def main():
    load0 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    lines = ["## heat-voxel — signed heat method on digital surfaces (§8.5)", "",
             f"Machine: {machine()}.", f"Load at start: `{load0}` (the machine is shared with other helpers: "
             "timings are indicative).", "",
             "Command: `OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python3 bench/bench_heat_voxel.py` "
             "(single-threaded BLAS: on the shared, oversubscribed machine threaded BLAS made the factorizations "
             "10-70x slower).", "",
             "ε is the §9.1 error (mass-weighted L2 / range of φ⁰ / √area); 'order' = log2(ε_N/2 / ε_N).", ""]
    # ---------------------------------------------------------------- sphere
    lines += ["### Digital sphere R = N/2 − 2, curve on the grid plane z = c + round(0.3R), φ⁰ = R(θ − θ0)", "",
              "| N | vertices | ε II r=3 | order | sign | ε II r=½N^⅔ | order | ε trivial | order | "
              "ε broken (50 %) | sign broken | build s | 1st solve s | again s |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    rows = []
    for N in SIZES:
        tm = {}
        e3, s3 = sphere(N, 3.0, timings=tm)
        es, _ = sphere(N, 0.5 * N ** (2 / 3))
        et, _ = sphere(N, 0.0)
        eb, sb = sphere(N, 3.0, broken=True)
        rows.append((N, tm, e3, s3, es, et, eb, sb))
        print(f"sphere N={N}: {e3:.5f} {s3:.4f} {es:.5f} {et:.5f} {eb:.5f} {sb:.4f} {tm}", flush=True)
    o3 = order([r[2] for r in rows])
    osc = order([r[4] for r in rows])
    ot = order([r[5] for r in rows])
    for k, (N, tm, e3, s3, es, et, eb, sb) in enumerate(rows):
        lines.append(f"| {N} | {tm['n']} | {e3:.5f} | {o3[k]:.2f} | {100 * s3:.2f} % | {es:.5f} | {osc[k]:.2f} | "
                     f"{et:.5f} | {ot[k]:.2f} | {eb:.5f} | {100 * sb:.2f} % | {tm['build']:.2f} | "
                     f"{tm['first']:.2f} | {tm['again']:.3f} |")
    # ---------------------------------------------------------------- planes
    lines += ["", "### Slanted digital planes, straight curve, φ⁰ = in-plane signed distance", "",
              "| plane | N | ε II r=3 | order | ε trivial | order | ε exact normals | order |",
              "|---|---|---|---|---|---|---|---|"]
    for nrm, m in (((1, 1, 1), (1, -1, 0)), ((1, 2, 0), (2, -1, 0))):
        ii = [plane(N, nrm, m) for N in SIZES]
        tr = [plane(N, nrm, m, radius=0.0) for N in SIZES]
        ex = [plane(N, nrm, m, exact=True) for N in SIZES]
        print(f"plane {nrm}: {ii} {tr} {ex}", flush=True)
        oi, ot_, oe = order(ii), order(tr), order(ex)
        for k, N in enumerate(SIZES):
            lines.append(f"| {nrm} | {N} | {ii[k]:.5f} | {oi[k]:.2f} | {tr[k]:.5f} | {ot_[k]:.2f} | {ex[k]:.5f} | "
                         f"{oe[k]:.2f} |")
    # ---------------------------------------------------------------- diffusion time
    lines += ["", "Diffusion time t = t_coef·h² (default t_coef = 1, the notes' t = h²): ε at the two finest N.", "",
              "| case | N | t_coef = 1 | 2 | 4 | 16 |", "|---|---|---|---|---|---|"]
    for N in SIZES[-2:]:
        row = [sphere(N, 0.5 * N ** (2 / 3), t_coef=tc)[0] for tc in (1, 2, 4, 16)]
        lines.append(f"| sphere, II r=½N^⅔ | {N} | " + " | ".join(f"{e:.5f}" for e in row) + " |")
        row = [plane(N, (1, 2, 0), (2, -1, 0), exact=True, t_coef=tc) for tc in (1, 2, 4, 16)]
        lines.append(f"| plane (1,2,0), exact normals | {N} | " + " | ".join(f"{e:.5f}" for e in row) + " |")
        print("t_coef", N, lines[-2:], flush=True)
    # ---------------------------------------------------------------- smooth baseline
    lines += ["", "Baseline, the same method on a smooth triangle mesh (Crouzeix–Raviart SHM, "
              "`SurfaceSignedHeatSolver`) on icospheres of similar vertex counts, curve z = 0.3R:", "",
              "| subdivisions | vertices | ε | order | 1st solve s |", "|---|---|---|---|---|"]
    base = [icosphere(k) for k in (3, 4, 5)]            # 6 (41k vertices): minutes in the complex SuperLU
    ob = order([b[0] for b in base])
    for k, (e, nv, dt) in enumerate(base):
        lines.append(f"| {k + 3} | {nv} | {e:.5f} | {ob[k]:.2f} | {dt:.2f} |")
    print("icosphere", base, flush=True)
    # ---------------------------------------------------------------- option A vs B, component timings
    N = SIZES[-2] if len(SIZES) > 1 else SIZES[0]
    eA, _ = sphere(N)
    eB, _ = sphere(N, connection="B")
    occ = ball(SIZES[-1], SIZES[-1] / 2 - 2)
    t0 = time.perf_counter()
    S = digital_surface(occ, np.ones(3))
    t_surf = time.perf_counter() - t0
    integral_invariant_normals(occ, np.ones(3), S, 3.0)               # compile (cached) and warm
    t0 = time.perf_counter()
    integral_invariant_normals(occ, np.ones(3), S, 3.0)
    t_norm = time.perf_counter() - t0
    load1 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    lines += ["", f"Option A (de Goes/DGtal connection Laplacian) vs Option B (rotated scalar off-diagonals), sphere "
              f"N = {N}: ε = {eA:.5f} vs {eB:.5f}.", "",
              f"Components at N = {SIZES[-1]} ({len(S.faces)} quads): surface extraction + manifold split "
              f"{t_surf:.2f} s, integral-invariant normals (r = 3, numba parallel) {t_norm:.2f} s; 'build' above "
              "= extraction + normals + operators, '1st solve' includes the two factorizations (vector heat, "
              "Dirichlet Poisson), 'again' reuses them.", "", f"Load at end: `{load1}`."]
    text = "\n".join(lines)
    print(text)
    write_section("heat-voxel", text)


if __name__ == "__main__":
    main()
