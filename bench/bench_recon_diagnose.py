"""Where does the Chamfer gap of ours to screened Poisson come from?  (issue 13, the worst Table-2 cases)

For a few Table-2 clouds of the full run of ``bench_recon.py`` (same rng stream, hence the same clouds), this
splits CD×100 = ½(mean truth→recon + mean recon→truth) into its two one-sided terms, for ours (default
options), ours without the fitting steps (``relocate=False, remesh=False, subdivide=0, fit=False``: the tet region's
boundary with projected Steiner vertices) and SPSR given the true normals, and finds the large per-sample
contributions:

* the share of each term carried by its worst 1 % / 5 % of samples, and the gap ours − SPSR that is left when
  both methods drop their worst 1 % / 5 % of each term (trimmed CD);
* truth samples farther than 1 % of the diagonal from the recon ("missed"): count, area, the signed side
  (recon inside the truth = a part cut off or shrunk; outside = filled), the local thickness of the truth there
  (ray cast along the inward normal) against the median thickness, and the largest clusters of them;
* recon samples farther than 1 % from the truth ("spurious"): count, area, side, and how many of them are
  nearer to an input outlier than to any inlier (outliers kept as bumps).

Run: ``PYTHONPATH=src /work/anchors/bin/python bench/bench_recon_diagnose.py [--png]`` (section recon-diagnose;
``--png`` also writes bench/recon_diag_<case>.png: ours / SPSR seen from +x, vertices coloured by the largest tilt of their faces against the truth normal, white 0 → red ≥ 0.5).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import data_dir, machine, table, write_section  # noqa: E402
from bench_recon import INLIERS, MESHES, OUTLIERS, _uptime, face_normals, make_case, normalise, run_spsr, \
    sample_surface  # noqa: E402

import gsdf  # noqa: E402

CASES = [("camel.off", 8000, 200), ("camel.off", 4000, 400), ("bull.off", 4000, 400), ("bunny00.off", 2000, 200),
         ("homer.off", 4000, 400)]
FAR = 0.01  # 1 % of the bounding-box diagonal


def full_run_clouds(wanted):
    """The clouds (P, N, n_out) and truth samples of the full run of bench_recon.py for the cases in ``wanted``:
    the same rng stream, the draws of the metric samples of every method skipped (as its before_after_table)."""
    rng = np.random.default_rng(0)
    out = {}
    for mname in MESHES:
        V0, F0 = gsdf.read_mesh(os.path.join(data_dir(), "meshes", mname))
        V0 = normalise(V0)
        GT, gf = sample_surface(V0, F0, 100_000, rng)
        cases = ([(a, b) for a in INLIERS for b in OUTLIERS] if mname == "bunny00.off"
                 else [(8000, 200), (4000, 400), (2000, 400), (1000, 800)])
        for n_in, n_out in cases:
            P, N = make_case(V0, F0, n_in, n_out, rng)
            n_metric = 2 + (mname == "bunny00.off" or (n_in, n_out) == (2000, 400)) \
                + ((n_in, n_out) == (2000, 400)) + (mname == "bunny00.off" and (n_in, n_out) == (2000, 400))
            for _ in range(n_metric):
                rng.random(3 * 100_000)
            if (mname, n_in, n_out) in wanted:
                out[(mname, n_in, n_out)] = (V0, F0, GT, face_normals(V0, F0)[gf], P, N)
        if all(k in out for k in wanted):
            break
    return out


def thickness(V0, F0, G, NG):
    """Distance from each truth sample to the truth surface along its inward normal (ray cast)."""
    import open3d as o3d
    sc = o3d.t.geometry.RaycastingScene()
    sc.add_triangles(o3d.core.Tensor(V0.astype(np.float32)), o3d.core.Tensor(F0.astype(np.uint32)))
    rays = np.concatenate([G - 1e-5 * NG, -NG], 1).astype(np.float32)
    t = sc.cast_rays(o3d.core.Tensor(rays))["t_hit"].numpy()
    return np.where(np.isfinite(t), t, np.nan)


def clusters(X, r):
    """Single-linkage clusters of the points X at radius r: labels, sizes (descending order of label size)."""
    if len(X) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    pr = cKDTree(X).query_pairs(r, output_type="ndarray")
    A = coo_matrix((np.ones(len(pr)), (pr[:, 0], pr[:, 1])), shape=(len(X), len(X)))
    _, lab = connected_components(A, directed=False)
    return lab, np.bincount(lab)


def analyse(V, F, V0, F0, G, NG, thick, P, n_out, rng):
    """One-sided terms and their tails for the mesh (V, F) against the truth samples G (normals NG)."""
    A, af = sample_surface(V, F, len(G), rng)
    tA = cKDTree(A)
    dG, iG = tA.query(G)          # truth → recon
    dA, iA = cKDTree(G).query(A)  # recon → truth
    n = len(G)
    area = 0.5 * np.linalg.norm(np.cross(V0[F0[:, 1]] - V0[F0[:, 0]], V0[F0[:, 2]] - V0[F0[:, 0]]), axis=1).sum()
    r = {"t2r": 50 * dG.mean(), "r2t": 50 * dA.mean()}
    r["cd"] = r["t2r"] + r["r2t"]
    for q in (1, 5):
        k = n * q // 100
        r[f"tail{q}"] = 50 * (np.sort(dG)[-k:].sum() + np.sort(dA)[-k:].sum()) / n
        r[f"trim{q}"] = 50 * (np.sort(dG)[:-k].mean() + np.sort(dA)[:-k].mean())
    # missed truth: which side is the recon?  < 0: inside the truth (a part cut off / shrunk)
    far = dG > FAR
    side = np.einsum("ij,ij->i", A[iG] - G, NG)
    r["miss_n"] = int(far.sum())
    r["miss_area"] = far.mean() * area
    r["miss_share"] = 50 * dG[far].sum() / n / r["cd"]  # share of CD carried by missed truth samples
    r["miss_inside"] = float((side[far] < 0).mean()) if far.any() else float("nan")
    r["miss_thick"] = float(np.nanmedian(thick[far])) if far.any() else float("nan")
    r["thick_all"] = float(np.nanmedian(thick))
    lab, sz = clusters(G[far], 2 * FAR)
    top = []
    for c in np.argsort(-sz)[:3]:
        m = lab == c
        Gi = G[far][m]
        top.append(f"{sz[c]} at ({', '.join(f'{x:+.2f}' for x in Gi.mean(0))}) thick {np.nanmedian(thick[far][m]):.3f}"
                   f" max {dG[far][m].max():.3f} {'in' if np.median(side[far][m]) < 0 else 'out'}")
    r["miss_top"] = "; ".join(top)
    # spurious recon: outside the truth (> 0) = filled / bumps; near an input outlier?
    farA = dA > FAR
    sideA = np.einsum("ij,ij->i", A - G[iA], NG[iA])
    r["spur_n"] = int(farA.sum())
    rec_area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()
    r["spur_area"] = farA.mean() * rec_area
    r["spur_share"] = 50 * dA[farA].sum() / n / r["cd"]
    r["spur_out"] = float((sideA[farA] > 0).mean()) if farA.any() else float("nan")
    din = cKDTree(P[:-n_out]).query(A[farA])[0] if n_out else np.full(farA.sum(), np.inf)
    dout = cKDTree(P[-n_out:]).query(A[farA])[0] if n_out else np.full(farA.sum(), np.inf)
    r["spur_outlier"] = float((dout < din).mean()) if farA.any() else float("nan")
    # bulk shape of the recon: area ratio, medians, and recon samples whose face normal deviates from the truth's
    r["area_ratio"] = rec_area / area
    r["med"] = (100 * np.median(dG), 100 * np.median(dA))
    sgn = np.einsum("ij,ij->i", face_normals(V, F)[af], NG[iA])
    r["inverted"] = ((sgn < 0).mean(), 50 * dA[sgn < 0].sum() / n / r["cd"])
    cosang = np.abs(sgn)
    for deg in (30, 60):
        m = cosang < np.cos(np.radians(deg))
        r[f"tilt{deg}"] = (m.mean(), 50 * dA[m].sum() / n / r["cd"])
    return r, dG, A, dA


def steiner_split(V, F, P, G, NG, rng):
    """On a mesh before the subdivision: its vertices that are not input points (Steiner points, relocated
    points), their distance to the truth, and its faces by how many such vertices they have — share of area,
    tilted (> 60°) share, and share of the recon→truth term (½ mean over 100k samples, ×100)."""
    st = cKDTree(P).query(V)[0] > 1e-12
    dv = cKDTree(G).query(V)[0]
    A, af = sample_surface(V, F, len(G), rng)
    dA, iA = cKDTree(G).query(A)
    cos = np.abs(np.einsum("ij,ij->i", face_normals(V, F)[af], NG[iA]))
    k = st[F].sum(1)[af]
    cols = [f"{st.sum()} / {len(V)}", f"{1000 * np.median(dv[st]):.2f} / {1000 * np.median(dv[~st]):.2f}"]
    for j in range(4):
        m = k == j
        cols.append(f"{100 * m.mean():.0f} / {100 * (m & (cos < 0.5)).sum() / max(m.sum(), 1):.0f} / "
                    f"{50 * dA[m].sum() / len(G):.3f}")
    return cols


def main(png: bool):
    up, t0 = _uptime(), time.perf_counter()
    print(machine(), up, flush=True)
    clouds = full_run_clouds(CASES)
    rows, rows2, rows3, rows4, rows5 = [], [], [], [], []
    # the metric's own floor: two independent 100k samples of the truth
    floor = {}
    for mname, n_in, n_out in CASES:
        V0, F0, G, NG, P, N = clouds[(mname, n_in, n_out)]
        thick = thickness(V0, F0, G, NG)
        G2, _ = sample_surface(V0, F0, len(G), np.random.default_rng(1))
        floor = 100 * 0.5 * (cKDTree(G2).query(G)[0].mean() + cKDTree(G).query(G2)[0].mean())
        name = f"{mname.replace('.off', '')} {n_in // 1000}K+{n_out}"
        res = {}
        Vo, Fo, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
        Vf, Ff = gsdf.reconstruct_simply_connected(P, relocate=False, remesh=False, subdivide=0, fit=False)
        Vs, Fs, _ = run_spsr(P, N)
        V0s, F0s = gsdf.reconstruct_simply_connected(P, subdivide=0)
        rows5.append([name, "ours subdivide=0"] + steiner_split(V0s, F0s, P, G, NG, np.random.default_rng(1)))
        rows5.append([name, "ours unfitted"] + steiner_split(Vf, Ff, P, G, NG, np.random.default_rng(1)))
        print(rows5[-2:], flush=True)
        for key, (V, F) in (("ours", (Vo, Fo)), ("ours unfitted", (Vf, Ff)), ("SPSR", (Vs, Fs))):
            res[key] = analyse(V, F, V0, F0, G, NG, thick, P, n_out, np.random.default_rng(1))
        kept = int((~rep["outliers"][-n_out:]).sum())
        kept_far = int(((~rep["outliers"][-n_out:]) & (np.abs(cKDTree(G).query(P[-n_out:])[0]) > FAR)).sum())
        s = res["SPSR"][0]
        for key in ("ours", "ours unfitted", "SPSR"):
            r = res[key][0]
            gap = r["cd"] - s["cd"]
            rows.append([name, key, f"{r['cd']:.3f}", f"{r['t2r']:.3f}", f"{r['r2t']:.3f}",
                         f"{100 * r['tail1'] / r['cd']:.0f} / {100 * r['tail5'] / r['cd']:.0f}",
                         f"{r['trim1']:.3f} / {r['trim5']:.3f}",
                         "" if key == "SPSR" else f"{gap:+.3f}",
                         "" if key == "SPSR" else f"{r['trim1'] - s['trim1']:+.3f} / {r['trim5'] - s['trim5']:+.3f}"])
            rows2.append([name, key, f"{r['miss_n']}", f"{r['miss_area']:.4f}", f"{100 * r['miss_share']:.0f}",
                          f"{100 * r['miss_inside']:.0f}", f"{r['miss_thick']:.3f} / {r['thick_all']:.3f}",
                          r["miss_top"]])
            rows3.append([name, key, f"{r['spur_n']}", f"{r['spur_area']:.4f}", f"{100 * r['spur_share']:.0f}",
                          f"{100 * r['spur_out']:.0f}", f"{100 * r['spur_outlier']:.0f}",
                          f"{kept} / {kept_far}" if key == "ours" else ""])
            rows4.append([name, key, f"{r['area_ratio']:.3f}", f"{r['med'][0]:.3f} / {r['med'][1]:.3f}",
                          f"{100 * r['tilt30'][0]:.1f} / {100 * r['tilt30'][1]:.0f}",
                          f"{100 * r['tilt60'][0]:.1f} / {100 * r['tilt60'][1]:.0f}",
                          f"{100 * r['inverted'][0]:.1f} / {100 * r['inverted'][1]:.0f}",
                          f"{floor:.3f}" if key == "SPSR" else ""])
            print(rows[-1], rows2[-1], rows3[-1], rows4[-1], flush=True)
        if png:
            from gsdf.render._raster import render_function_png
            tag = name.replace(" ", "_").replace("+", "p")
            for key, lab in (("ours", "ours"), ("SPSR", "spsr")):
                V, F = (Vo, Fo) if key == "ours" else (Vs, Fs)
                # recon vertices coloured by the largest tilt (1 − |cos|) of their faces against the truth normal
                tilt = 1 - np.abs(np.einsum("ij,ij->i", face_normals(V, F), NG[cKDTree(G).query(V[F].mean(1))[1]]))
                vt = np.zeros(len(V))
                np.maximum.at(vt, F.ravel(), np.repeat(tilt, 3))
                vt[0] = 0.5  # pin the colour scale (the renderer scales by the 99th percentile)
                render_function_png(os.path.join(os.path.dirname(__file__), f"recon_diag_{tag}_{lab}.png"), V, F,
                                    np.minimum(vt, 0.5), size=600, view=(1.0, 0.0, 0.0), n_isolines=2)
    text = [
        "## recon-diagnose: where the Chamfer gap of ours to screened Poisson comes from (issue 13)", "",
        f"Machine: {machine()}. Load at start: `{up}`; at the end: `{_uptime()}`. Command: `PYTHONPATH=src "
        f"/work/anchors/bin/python bench/bench_recon_diagnose.py` ({time.perf_counter() - t0:.0f} s).  The clouds "
        "of the full run (section recon: same rng stream); 100k area-uniform samples each side (metric rng 1 "
        "for every method, so CD can differ from section recon in the third decimal).  \"ours unfitted\" = "
        "`relocate=False, remesh=False, subdivide=0, fit=False` (the grown tet region's boundary, Steiner "
        "vertices projected): the surface chosen before the fitting steps.", "",
        "### CD×100 split into its one-sided terms (each ½ × mean), tails and trimmed CD", "",
        "\"worst 1 / 5 %\" = share of CD carried by the worst 1 % / 5 % of samples of each term; \"trimmed\" = CD "
        "with those samples dropped from each term; gap = ours − SPSR.", "",
        table(["case", "method", "CD×100", "truth→recon", "recon→truth", "worst 1 / 5 % (% of CD)",
               "trimmed 1 / 5 %", "gap", "trimmed gap 1 / 5 %"], rows), "",
        f"### Truth samples farther than {FAR} (1 % of the diagonal) from the recon (missed)", "",
        "\"in\" = share whose nearest recon sample lies inside the truth (along the truth normal); thickness = "
        "distance along the inward normal to the other side of the truth; clusters = single linkage at "
        f"{2 * FAR}: size, centroid, median thickness, largest distance, side.", "",
        table(["case", "method", "missed", "area", "% of CD", "% in", "thickness there / median",
               "largest clusters"], rows2), "",
        f"### Recon samples farther than {FAR} from the truth (spurious)", "",
        "\"out\" = share outside the truth; \"near outlier\" = share nearer to an input outlier than to every "
        "inlier; kept outliers (ours) = outliers of the cloud not flagged by ours / of those, farther than "
        f"{FAR} from the truth.", "",
        table(["case", "method", "spurious", "area", "% of CD", "% out", "% near outlier",
               "kept outliers / far"], rows3), "",
        "### Bulk shape: area, medians, tilted faces", "",
        "area = recon area / truth area; medians of the two one-sided distances (×100); tilted = share of recon "
        "samples whose face normal is more than 30° / 60° off the nearest truth sample's normal, and the share of "
        "CD their recon→truth distances carry; inverted = the same for faces facing against the truth normal "
        "(pleats: the surface folds back over itself); floor = CD×100 of two independent 100k samples of the truth.", "",
        table(["case", "method", "area", "median truth→recon / recon→truth", "tilted > 30°: % area / % CD",
               "tilted > 60°: % area / % CD", "inverted: % area / % CD", "metric floor"], rows4), "",
        "### Faces by their number of Steiner vertices (before the subdivision)", "",
        "Steiner = a vertex that is not an input point at its exact coordinates (octree Steiner points; with "
        "relocation also moved input points); distance to the truth in units of 10⁻³ (diagonal 1), Steiner / "
        "input vertices; for faces with 0 / 1 / 2 / 3 Steiner vertices: % of recon samples / % of those on "
        "faces tilted > 60° / their part of the recon→truth term (CD×100 units; the four parts sum to it).", "",
        table(["case", "mesh", "Steiner / all vertices", "dist Steiner / input (10⁻³)", "0 Steiner",
               "1 Steiner", "2 Steiner", "3 Steiner"], rows5), ""]
    write_section("recon-diagnose", "\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--png", action="store_true", help="also write bench/recon_diag_<case>_<method>.png")
    main(ap.parse_args().png)
