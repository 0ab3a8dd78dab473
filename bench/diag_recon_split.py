"""Diagnosis of the recon CD gap (issue 13): split the Chamfer distance into its one-sided terms and map the large
per-sample contributions, for ours and for screened Poisson (true normals), on Table-2 clouds of the full run.

Run: ``PYTHONPATH=src /work/anchors/bin/python bench/diag_recon_split.py camel:4000:400 bull:4000:400 ...``
(mesh:inliers:outliers; the clouds are those of ``bench_recon.py``'s full run, same rng stream).  Prints, per
method: CD, recon→truth and truth→recon means, each split at 2 median spacings into a "far" share and a "bulk"
share (all ×100, summing to the term); for ours also the output vertices by kind (input inlier / input outlier at
its exact coordinates / other = Steiner, relocated or subdivision vertex) and how much of the far recon→truth
share lies on faces touching a vertex farther than 2 spacings from the truth.  Prints only; writes no section.
"""
import os
import sys

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_recon import INLIERS, MESHES, OUTLIERS, make_case, normalise, run_spsr, sample_surface  # noqa: E402
from common import data_dir  # noqa: E402

import gsdf  # noqa: E402


def clouds(want):
    rng = np.random.default_rng(0)
    for mname in MESHES:
        V0, F0 = gsdf.read_mesh(os.path.join(data_dir(), "meshes", mname))
        V0 = normalise(V0)
        GT, _ = sample_surface(V0, F0, 100_000, rng)
        cases = ([(a, b) for a in INLIERS for b in OUTLIERS] if mname == "bunny00.off"
                 else [(8000, 200), (4000, 400), (2000, 400), (1000, 800)])
        for n_in, n_out in cases:
            P, N = make_case(V0, F0, n_in, n_out, rng)
            n_metric = 2 + (mname == "bunny00.off" or (n_in, n_out) == (2000, 400)) \
                + ((n_in, n_out) == (2000, 400)) + (mname == "bunny00.off" and (n_in, n_out) == (2000, 400))
            for _ in range(n_metric):
                rng.random(3 * 100_000)
            key = f"{mname[:-4]}:{n_in}:{n_out}"
            if key in want:
                yield key, P, N, GT, n_in


def split(V, F, GT, sp):
    A, fa = sample_surface(V, F, 100_000, np.random.default_rng(1))
    a = cKDTree(GT).query(A)[0]          # recon -> truth
    b = cKDTree(A).query(GT)[0]          # truth -> recon
    r = {"CD": 50 * (a.mean() + b.mean()), "r2t": 100 * a.mean(), "t2r": 100 * b.mean()}
    for nm, d in (("r2t", a), ("t2r", b)):
        r[nm + " far"] = 100 * d[d > 2 * sp].sum() / len(d)
        r[nm + " bulk"] = 100 * d[d <= 2 * sp].sum() / len(d)
    return r, a, fa


def main(keys):
    for key, P, N, GT, n_in in clouds(set(keys)):
        sp = float(np.median(cKDTree(P[:n_in]).query(P[:n_in], k=2)[0][:, 1]))
        V, F, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
        Vs, Fs, _ = run_spsr(P, N)
        print(key, f"spacing {sp:.4f}; outliers judged {int(rep['outliers'][n_in:].sum())} / {len(P) - n_in}, "
              f"inliers judged outliers {int(rep['outliers'][:n_in].sum())}")
        for nm, (VV, FF) in (("ours", (V, F)), ("SPSR", (Vs, Fs))):
            r, a, fa = split(VV, FF, GT, sp)
            print(f"  {nm:5s}", "  ".join(f"{k} {v:.4f}" for k, v in r.items()))
        d, i = cKDTree(P).query(V)
        kind = np.where(d < 1e-12, np.where(i < n_in, 0, 1), 2)
        dv = cKDTree(GT).query(V)[0]
        r, a, fa = split(V, F, GT, sp)
        far = a > 2 * sp
        touch = (dv[F[fa[far]]] > 2 * sp).any(axis=1)
        print(f"  ours vertices: inlier {(kind == 0).sum()}, exact outlier {(kind == 1).sum()}, other {(kind == 2).sum()}; "
              f">2 sp from truth: inlier {((kind == 0) & (dv > 2 * sp)).sum()}, exact outlier "
              f"{((kind == 1) & (dv > 2 * sp)).sum()}, other {((kind == 2) & (dv > 2 * sp)).sum()}; far r2t share "
              f"{100 * a[far].sum() / len(a):.4f} of which on faces touching such a vertex {100 * a[far][touch].sum() / len(a):.4f}")


if __name__ == "__main__":
    main(sys.argv[1:] or ["camel:4000:400"])
