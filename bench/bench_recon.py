"""Guaranteed simply connected reconstruction (seed 003) against screened Poisson and gsdf's level sets.

Protocol (seed 003 §6.2, Table 2): each closed genus-0 CGAL mesh is normalised to a bounding-box
diagonal of 1; 8K / 4K / 2K / 1K area-uniform surface samples plus 200 / 400 / 800 outliers (surface samples
moved along the normal by U[−b, b], b = 0.25); CD×100 = ½(mean A→B + mean B→A) and HD×100 = the larger directed
maximum, over 100k area-uniform samples of each surface; CC = connected components; genus per component; "man"
= closed, edge- and vertex-manifold.  Methods, in one run:

* ours: ``gsdf.reconstruct_simply_connected`` on the UNORIENTED cloud;
* SPSR: Open3D screened Poisson (depth 8) given the TRUE normals of the samples (outliers keep their source
  face's normal) — an advantage to it; no density trimming;
* gsdf winding ½ level set / signed heat zero set / Points-as-Tori zero set, with the same propagated PCA
  normals as ours (bunny and one case per other mesh in the full run; PAT only in the full run).

Also: thin tubes (branching vessels sampled on aligned / random cross-section planes), a torus cloud (genus-1
truth: ours must still be one sphere), and time / peak memory vs point count 1K → 100K.

Parts (``--only``, default both), each writing its own section of bench/RESULTS.md:

* ``table2`` ("recon"): the Table 2 protocol, thin tubes and the torus cloud; ``--quick`` runs a subset. Every
  case of ours is checked against the topology promise (CC = 1, genus 0, closed manifold): the script exits
  non-zero when one breaks it;
* ``sizes`` ("recon-time"): time and peak memory against point count (bunny samples, one process per size).

    PYTHONPATH=src /work/anchors/bin/python bench/bench_recon.py [--quick] [--only table2,sizes]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import command, data_dir, heading, table, write_section
from load import uptime  # noqa: E402  # noqa: E402

import gsdf  # noqa: E402
from gsdf.recon._compare import reconstruct_heat, reconstruct_pat, reconstruct_winding  # noqa: E402
from gsdf.mesh._topology import mesh_topology  # noqa: E402

MESHES = ["bunny00.off", "armadillo.off", "bull.off", "camel.off", "fandisk.off", "homer.off"]
INLIERS = [8000, 4000, 2000, 1000]
OUTLIERS = [200, 400, 800]
# the seed's own Table 2 figures for its bunny ("Ours"), CD×100 then HD×100, rows 8K..1K, columns 200/400/800
T2_HEADER = ["mesh", "case", "method", "CD×100", "HD×100", "CC", "genus", "manifold", "time (s)",
             "paper CD / HD (bunny, ours)"]
PAPER_CD = {8000: (.18, .26, .33), 4000: (.28, .31, .36), 2000: (.24, .26, .42), 1000: (.81, .93, 1.1)}
PAPER_HD = {8000: (12.1, 9.6, 2.8), 4000: (3.2, 4.3, 3.8), 2000: (3.1, 3.5, 8.9), 1000: (7.6, 12.6, 13.2)}


# ------------------------------------------------------------------------------------------- geometry helpers
def normalise(V):
    lo, hi = V.min(0), V.max(0)
    return (V - 0.5 * (lo + hi)) / np.linalg.norm(hi - lo)


def sample_surface(V, F, n, rng):
    """n area-uniform samples of a triangle mesh, with their face ids."""
    A = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    f = rng.choice(len(F), size=n, p=A / A.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    b = np.stack([1 - s, s * (1 - r2), s * r2], 1)
    return np.einsum("nk,nkx->nx", b, V[F[f]]), f


def face_normals(V, F):
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]


def cd_hd(V, F, GT, rng, n=100_000):
    """CD×100, HD×100 between (V, F) and the ground-truth sample GT (n, 3)."""
    if len(F) == 0:
        return float("nan"), float("nan")
    A, _ = sample_surface(V, F, n, rng)
    a = cKDTree(GT).query(A)[0]
    b = cKDTree(A).query(GT)[0]
    return 100 * 0.5 * (a.mean() + b.mean()), 100 * max(a.max(), b.max())


def topo(V, F):
    t = mesh_topology(V, F)
    man = bool(t["closed"] and t["edge_manifold"] and t["vertex_manifold"])
    g = t["genus"]
    gs = "—" if g is None else (str(g[0]) if len(set(g)) == 1 and len(g) == 1 else f"{sum(g)}Σ")
    return t["components"], gs, man, t


def make_case(V, F, n_in, n_out, rng):
    Nf = face_normals(V, F)
    S, fs = sample_surface(V, F, n_in, rng)
    O, fo = sample_surface(V, F, n_out, rng)
    O = O + Nf[fo] * rng.uniform(-0.25, 0.25, (n_out, 1))
    return np.concatenate([S, O]), np.concatenate([Nf[fs], Nf[fo]])


# ------------------------------------------------------------------------------------------- methods
def run_ours(P, N=None, **kw):
    t = time.perf_counter()
    V, F = gsdf.reconstruct_simply_connected(P, **kw)
    return V, F, time.perf_counter() - t


def run_spsr(P, N, depth=8):
    import open3d as o3d
    t = time.perf_counter()
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(P))
    pcd.normals = o3d.utility.Vector3dVector(N)
    mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=depth)
    el = time.perf_counter() - t
    return np.asarray(mesh.vertices), np.asarray(mesh.triangles, dtype=np.int64), el


def run_level(fn, P, res):
    t = time.perf_counter()
    try:
        V, F = fn(P, None, resolution=res)
    except ValueError:
        V, F = np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    return V, F, time.perf_counter() - t


# ------------------------------------------------------------------------------------------- tubes
def _capsules():
    """A branching vessel: a trunk with two branches and a side twig (segments a→b, radius)."""
    return [((0, 0, -0.45), (0, 0, 0.0), 0.05), ((0, 0, 0.0), (0.25, 0, 0.35), 0.04),
            ((0, 0, 0.0), (-0.2, 0.1, 0.4), 0.035), ((0, 0, -0.2), (0.0, 0.3, -0.05), 0.025)]


def vessel_sdf(Q):
    d = np.full(len(Q), np.inf)
    for a, b, r in _capsules():
        a, b = np.array(a), np.array(b)
        ab = b - a
        t = np.clip(((Q - a) @ ab) / (ab @ ab), 0, 1)
        d = np.minimum(d, np.linalg.norm(Q - a - t[:, None] * ab, axis=1) - r)
    return d


def vessel_mesh():
    V, F = gsdf.extract_isosurface(vessel_sdf, [-0.4, -0.2, -0.55], [0.4, 0.45, 0.5], resolution=160, level=0.0,
                                   inside="below")
    return V, F


def plane_samples(V, F, rng, aligned, n_planes=40, n=6000, eps=0.004):
    """Points of the surface near a family of planes: parallel z-planes (aligned) or random planes."""
    S, f = sample_surface(V, F, 40 * n, rng)
    if aligned:
        z = np.linspace(S[:, 2].min(), S[:, 2].max(), n_planes)
        d = np.abs(S[:, 2][:, None] - z[None]).min(axis=1)
    else:
        nrm = rng.normal(size=(n_planes, 3))
        nrm /= np.linalg.norm(nrm, axis=1)[:, None]
        off = np.einsum("pk,pk->p", nrm, S[rng.integers(0, len(S), n_planes)])
        d = np.abs(S @ nrm.T - off[None]).min(axis=1)
    keep = np.flatnonzero(d < eps)
    keep = keep[rng.permutation(len(keep))[:n]]
    return S[keep], face_normals(V, F)[f[keep]]


# ------------------------------------------------------------------------------------------- time vs size
def _size_worker(n):
    rng = np.random.default_rng(n)
    V, F = gsdf.read_mesh(os.path.join(data_dir(), "meshes", "bunny00.off"))
    V = normalise(V)
    P, _ = sample_surface(V, F, n, rng)
    t = time.perf_counter()
    V2, F2, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
    el = time.perf_counter() - t
    c, g, man, _ = topo(V2, F2)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps({"n": n, "time": el, "rss_mb": rss, "tets": rep["n_tets"], "cc": c, "genus": g, "man": man,
                      "timings": rep["timings"]}))


def time_vs_size(sizes):
    rows = []
    for n in sizes:
        out = subprocess.run([sys.executable, __file__, "--size-worker", str(n)], capture_output=True, text=True,
                             env=dict(os.environ))
        if out.returncode != 0:
            rows.append([n, "failed", out.stderr.strip().splitlines()[-1][:60], "", "", "", ""])
            continue
        r = json.loads(out.stdout.strip().splitlines()[-1])
        tm = r["timings"]
        rows.append([n, f"{r['time']:.1f}", f"{r['rss_mb']:.0f}", r["tets"],
                     f"{tm['tetrahedralisation']:.1f} / {tm['core']:.1f} / {tm['grow']:.2f} / {tm['alternation']:.1f}",
                     f"{tm.get('fit', 0.0):.1f} ({100 * tm.get('fit', 0.0) / r['time']:.0f} %)",
                     f"{r['cc']} / {r['genus']} / {'yes' if r['man'] else 'NO'}"])
        print("size", rows[-1], flush=True)
    return table(["points", "time (s)", "peak RSS (MB)", "tets", "tet / core / grow / alternation (s)",
                  "fit (s, % of time)", "CC / genus / manifold"], rows)


def table2(quick: bool):
    """The "recon" section: Table 2, thin tubes, torus cloud; raises SystemExit when ours breaks the promise."""
    rng = np.random.default_rng(0)
    failures = []
    start = uptime()
    cmd = command("bench_recon.py", ["--only table2"] + (["--quick"] if quick else []), python="/work/anchors/bin/python")
    lines = ["Absolute times on a shared machine are inflated; compare methods within a row.", ""]

    def flush(extra):
        """Write what is measured so far (a loaded machine may not finish the whole run)."""
        write_section("recon", heading("Guaranteed simply connected reconstruction: Table 2 protocol, thin tubes, "
                                       "torus", cmd, start) + "\n".join(lines + extra))

    def check(name, V, F):
        c, g, man, t = topo(V, F)
        ok = c == 1 and t["genus"] == [0] and man and t["oriented"]
        if not ok:
            failures.append(name)
        return c, g, man

    # ---------------- Table 2
    meshes = ["bunny00.off", "armadillo.off"] if quick else MESHES
    rows = []
    for mname in meshes:
        V0, F0 = gsdf.read_mesh(os.path.join(data_dir(), "meshes", mname))
        V0 = normalise(V0)
        GT, _ = sample_surface(V0, F0, 100_000, rng)
        if quick:
            cases = [(2000, 400), (1000, 800)] if mname == "bunny00.off" else [(2000, 200)]
        elif mname == "bunny00.off":
            cases = [(a, b) for a in INLIERS for b in OUTLIERS]
        else:  # the diagonal of Table 2 plus its worst case (time budget of a loaded 2-core machine)
            cases = [(8000, 200), (4000, 400), (2000, 400), (1000, 800)]
        for n_in, n_out in cases:
            P, N = make_case(V0, F0, n_in, n_out, rng)
            res = {}
            V, F, el = run_ours(P)
            c, g, man = check(f"{mname} {n_in}+{n_out}", V, F)
            res["ours"] = (*cd_hd(V, F, GT, rng), c, g, man, el)
            V, F, el = run_spsr(P, N)
            c, g, man, _ = topo(V, F)
            res["SPSR"] = (*cd_hd(V, F, GT, rng), c, g, man, el)
            levels = mname == "bunny00.off" or (n_in, n_out) == (2000, 400) or quick
            if levels:
                for key, fn, r in (("winding", reconstruct_winding, 128), ("heat", reconstruct_heat, 96),
                                   ("PAT", reconstruct_pat, 64)):
                    # PAT (k = 64 fits, 64³ evaluations) is the slowest: one case per mesh, full run only
                    if key == "PAT" and (quick or (n_in, n_out) != (2000, 400) or mname != "bunny00.off"):
                        continue
                    if key == "heat" and (n_in, n_out) != (2000, 400):
                        continue
                    V, F, el = run_level(fn, P, r)
                    c, g, man, _ = topo(V, F)
                    res[key] = (*cd_hd(V, F, GT, rng), c, g, man, el)
            for key, (cd, hd, c, g, man, el) in res.items():
                paper = ""
                if mname == "bunny00.off" and key == "ours" and n_out in OUTLIERS:
                    j = OUTLIERS.index(n_out)
                    paper = f"{PAPER_CD[n_in][j]} / {PAPER_HD[n_in][j]}"
                rows.append([mname.replace(".off", ""), f"{n_in // 1000}K+{n_out}", key, f"{cd:.2f}", f"{hd:.1f}", c,
                             g, "yes" if man else "no", f"{el:.1f}", paper])
                print(rows[-1], flush=True)
            flush(["### Table 2 protocol (partial: run in progress or interrupted)", "",
                   table(T2_HEADER, rows)])
    lines += ["### Table 2 protocol (CGAL meshes, bbox diagonal 1)", "",
              table(T2_HEADER, rows), ""]
    flush([])

    # ---------------- thin tubes
    Vt, Ft = vessel_mesh()
    GTt, _ = sample_surface(Vt, Ft, 100_000, rng)
    rows = []
    for aligned in (True, False):
        P, N = plane_samples(Vt, Ft, rng, aligned)
        for key in ("ours", "ours+clusters", "SPSR"):
            if key == "SPSR":
                V, F, el = run_spsr(P, N)
            else:
                V, F, el = run_ours(P, clusters=(key == "ours+clusters"))
                if key == "ours":
                    check(f"tube aligned={aligned}", V, F)
            c, g, man, _ = topo(V, F)
            cd, hd = cd_hd(V, F, GTt, rng)
            rows.append(["aligned" if aligned else "non-aligned", len(P), key, f"{cd:.2f}", f"{hd:.1f}", c, g,
                         "yes" if man else "no", f"{el:.1f}"])
            print(rows[-1], flush=True)
    lines += ["### Thin tubes (branching vessel, samples near 40 cross-section planes)", "",
              table(["planes", "points", "method", "CD×100", "HD×100", "CC", "genus", "manifold", "time (s)"], rows),
              ""]
    flush([])

    # ---------------- torus cloud (genus-1 truth)
    th = np.linspace(0, 2 * np.pi, 97)[:-1]
    u, v = np.meshgrid(th, th, indexing="ij")
    Vtor = np.stack([(1 + 0.35 * np.cos(v)) * np.cos(u), (1 + 0.35 * np.cos(v)) * np.sin(u), 0.35 * np.sin(v)],
                    -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(96), np.arange(96), indexing="ij")
    a, b, cc_, d = i * 96 + j, ((i + 1) % 96) * 96 + j, ((i + 1) % 96) * 96 + (j + 1) % 96, i * 96 + (j + 1) % 96
    Ftor = np.concatenate([np.stack([a, b, cc_], -1).reshape(-1, 3), np.stack([a, cc_, d], -1).reshape(-1, 3)])
    Vtor = normalise(Vtor)
    GTtor, _ = sample_surface(Vtor, Ftor, 100_000, rng)
    rows = []
    P, N = make_case(Vtor, Ftor, 4000, 0, rng)
    for key in ("ours", "SPSR"):
        V, F, el = run_ours(P) if key == "ours" else run_spsr(P, N)
        if key == "ours":
            check("torus", V, F)
        c, g, man, _ = topo(V, F)
        cd, hd = cd_hd(V, F, GTtor, rng)
        rows.append([key, f"{cd:.2f}", f"{hd:.1f}", c, g, "yes" if man else "no", f"{el:.1f}"])
        print(rows[-1], flush=True)
    lines += ["### Torus cloud (4K samples, genus-1 truth): ours cuts the handle to stay a sphere", "",
              table(["method", "CD×100", "HD×100", "CC", "genus", "manifold", "time (s)"], rows), ""]
    flush([])

    lines += [f"Topology promise (CC = 1, genus 0, closed, oriented, edge- and vertex-manifold) on every case of "
              f"ours: {'HELD' if not failures else 'FAILED on ' + ', '.join(failures)}."]
    flush([])
    if failures:
        raise SystemExit(f"topology promise broken on: {failures}")
    print("topology promise held on every case")


def sizes_part(quick: bool):
    """The "recon-time" section: time and peak memory against point count."""
    sizes = [1000, 4000, 16000] if quick else [1000, 4000, 16000, 50000, 100000]
    start, t0 = uptime(), time.perf_counter()
    tab = time_vs_size(sizes)
    text = (heading("Guaranteed simply connected reconstruction: time and peak memory against point count",
                    command("bench_recon.py", ["--only sizes"] + (["--quick"] if quick else []),
                            python="/work/anchors/bin/python"), start)
            + f"Took {time.perf_counter() - t0:.0f} s. bunny00 surface samples, no outliers, one process per size, "
            "default options.\n\n" + tab + "\n")
    write_section("recon-time", text)
    print(text)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a subset of the cases and sizes")
    ap.add_argument("--only", default="", help="comma list of parts: table2,sizes (default both)")
    ap.add_argument("--size-worker", type=int, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    parts = [p for p in a.only.split(",") if p] or ["table2", "sizes"]
    if a.size_worker is not None:
        _size_worker(a.size_worker)
    else:
        for p in parts:
            if p not in ("table2", "sizes"):
                ap.error(f"--only: unknown part {p!r}; known: table2, sizes")
        if "table2" in parts:
            table2(a.quick)
        if "sizes" in parts:
            sizes_part(a.quick)
