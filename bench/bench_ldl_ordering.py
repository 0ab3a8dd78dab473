"""LDL orderings: approximate minimum degree vs nested dissection on the surface signed heat systems (issue 17).

For the two systems a surface / polygon signed heat solve factorizes (the complex vector heat operator and the
real Dirichlet Poisson matrix) of each of the 16 + 6 meshes of ``bench_heat_surface.py --speed``: time of each
ordering, time of the LDLᴴ with it (symbolic + numeric), one solve, and the fill (entries of L below the
diagonal); SuperLU's multiple minimum degree (``splu(permc_spec="MMD_AT_PLUS_A")``, its ``perm_c`` through the
same symbolic factorization) as the reference fill. The rule of :func:`gsdf.linalg._ordering.fill_reducing_ordering`
comes from this table (RESULTS section "ldl-ordering").

Run: ``PYTHONPATH=src /work/anchors/bin/python bench/bench_ldl_ordering.py [--quick]`` (``--quick``: 6 + 3
meshes, no RESULTS.md update).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import machine, table, write_section  # noqa: E402

import bench_heat_surface as bhs  # noqa: E402
from gsdf.linalg._direct import LDL_MAX_UNKNOWNS, Factorization  # noqa: E402
from gsdf.linalg._ldl import LDLFactorization, fill_count  # noqa: E402
from gsdf.linalg._ordering import order_csr  # noqa: E402


RULE = ("`LDLFactorization(ordering=\"auto\")` (gsdf.linalg._ldl): AMD; on systems of at most AUTO_ND_MAX_N = "
        "10,000 unknowns whose AMD factor is flop-heavy (Σ_j c_j² ≥ 12 · nnz(A) · log2 n, c_j = column counts "
        "of L) nested dissection is computed too and kept when its flop count is below 0.9× AMD's. Measured "
        "reason: AMD's ordering + factorization wins on the triangle-mesh systems (fill 0.5–0.9× ND's, "
        "ordering 1.5–4× faster); ND wins only on regular quad grids, where the factor is flop-heavy; trying ND "
        "on large meshes (up to 160 ms of ordering on bunny00) costs more than it can save. The backend limit "
        "(gsdf.linalg._direct.LDL_MAX_UNKNOWNS) went from 64k to 300k real unknowns: with AMD the LDL beats "
        "SuperLU (its factorization column) on every system here, the largest included.")


def best(fn, repeat):
    ts = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return min(ts), out


def measure(names, repeat=3):
    rows, summary = [], []
    for name in names:
        A, P = bhs._solver_matrices(name)
        for lab, M in (("vector heat", A), ("Poisson", P)):
            M = sp.csr_matrix(M)
            real_unknowns = M.shape[0] * (2 if np.iscomplexobj(M.data) else 1)
            ip, ix, n = M.indptr.astype(np.int64), M.indices.astype(np.int64), M.shape[0]
            b = np.random.default_rng(0).normal(size=n).astype(M.dtype)
            res = {}
            for meth in ("amd", "nd"):
                t_ord, perm = best(lambda: order_csr(ip, ix, n, meth), repeat)
                t_fac, f = best(lambda: LDLFactorization(M, ordering=perm), repeat)
                t_sol, _ = best(lambda: f.solve(b), repeat)
                res[meth] = (t_ord, t_fac, t_sol, f.nnz)
            lu = spla.splu(sp.csc_matrix(M), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
            auto = "nd" if np.array_equal(LDLFactorization(M).perm, order_csr(ip, ix, n, "nd")) else "amd"
            t_slu, lu_g = best(lambda: Factorization(sp.csc_matrix(M), reorder=True), repeat)
            t_slu_s, _ = best(lambda: lu_g.solve(b), repeat)
            pmmd = np.empty(n, np.int64)
            pmmd[lu.perm_c] = np.arange(n)                # perm_c[j] = the position of column j
            mmd = fill_count(M, pmmd)
            a, d = res["amd"], res["nd"]
            tot_a, tot_d = a[0] + a[1], d[0] + d[1]
            win = "amd" if tot_a <= tot_d else "nd"
            summary.append((name, lab, real_unknowns, win, tot_a / tot_d, a[3] / d[3], a[3] / mmd, tot_a / t_slu,
                            a[2] / t_slu_s))
            rows.append([name.replace("shm:", "").replace("poly:", "polygon "), lab, n, real_unknowns <= LDL_MAX_UNKNOWNS,
                         f"{a[0] * 1e3:.1f} / {d[0] * 1e3:.1f}", f"{a[1] * 1e3:.1f} / {d[1] * 1e3:.1f}",
                         f"{tot_a * 1e3:.1f} / {tot_d * 1e3:.1f} ({tot_a / tot_d:.2f})",
                         f"{a[2] * 1e3:.2f} / {d[2] * 1e3:.2f}", f"{a[3]} / {d[3]} ({a[3] / d[3]:.2f})",
                         f"{mmd} ({a[3] / mmd:.3f})", win, auto, f"{t_slu * 1e3:.1f} ({tot_a / t_slu:.2f})",
                         f"{t_slu_s * 1e3:.2f} ({a[2] / t_slu_s:.2f})"])
            print(rows[-1], f"load {os.getloadavg()[0]:.1f}", flush=True)
    hdr = ["mesh", "system", "unknowns", "LDL used (≤ LDL_MAX_UNKNOWNS real)", "ordering ms AMD / ND", "factorize ms AMD / ND",
           "ordering + factorize ms AMD / ND (ratio)", "solve ms AMD / ND", "nnz(L) AMD / ND (ratio)",
           "nnz(L) SuperLU MMD (AMD / MMD)", "faster", "auto picks", "SuperLU factorize ms (LDL-AMD / SuperLU)",
           "SuperLU solve ms (LDL-AMD / SuperLU)"]
    return table(hdr, rows), summary


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="6 + 3 meshes, no RESULTS.md update")
    ap.add_argument("--only", help="comma-separated mesh names (as in bench_heat_surface.py; no RESULTS.md update)")
    args = ap.parse_args()
    names = bhs.SPEED_QUICK + bhs.POLY_QUICK if args.quick else bhs.SPEED_MESHES + bhs.POLY_SPEED
    if args.only:
        names = args.only.split(",")
    start = os.popen("uptime").read().strip()
    # compile first (not timed)
    LDLFactorization(sp.identity(3, format="csr"), ordering="amd")
    LDLFactorization(sp.identity(3, format="csr"), ordering="nd")
    tab, summary = measure(names)
    used = [s for s in summary if s[2] <= LDL_MAX_UNKNOWNS]
    amd_wins = sum(s[3] == "amd" for s in used)
    text = (f"Machine: {machine()}; uptime at start: {start}; at end: {os.popen('uptime').read().strip()} "
            "(shared machine: other helpers' jobs ran alongside; every ratio compares two runs of the same process).\n\n"
            "Command: `PYTHONPATH=src /work/anchors/bin/python bench/bench_ldl_ordering.py`. Times: best of 3, ms. "
            "AMD = gsdf.linalg._ordering.approximate_minimum_degree, ND = nested_dissection (BFS level-structure "
            "separators); the MMD column is SuperLU's multiple minimum degree (perm_c of "
            "`splu(..., permc_spec='MMD_AT_PLUS_A')`) counted by the same symbolic factorization.\n\n"
            f"**Rule:** AMD is faster (ordering + factorization) on {amd_wins} of {len(used)} systems the LDL "
            f"factorizes (≤ {LDL_MAX_UNKNOWNS} real unknowns); ordering + factorization AMD/ND ratio "
            f"{min(s[4] for s in used):.2f}–{max(s[4] for s in used):.2f}, fill AMD/ND "
            f"{min(s[5] for s in used):.2f}–{max(s[5] for s in used):.2f}, fill AMD/MMD "
            f"{min(s[6] for s in summary):.3f}–{max(s[6] for s in summary):.3f}.\n\n" + RULE + "\n\nLDL (AMD, ordering + factorization) / "
            f"SuperLU factorization on all systems: {min(s[7] for s in summary):.2f}–{max(s[7] for s in summary):.2f}"
            f" (above {LDL_MAX_UNKNOWNS} real unknowns: "
            + ", ".join(f"{s[0].replace('shm:', '')} {s[1]} {s[7]:.2f}" for s in summary if s[2] > LDL_MAX_UNKNOWNS)
            + f"); solves {min(s[8] for s in summary):.2f}–{max(s[8] for s in summary):.2f}.\n\n" + tab)
    print(text)
    if not (args.quick or args.only):
        write_section("ldl-ordering", "## LDL orderings: approximate minimum degree vs nested dissection "
                      "(16 + 6 meshes)\n\n" + text)


if __name__ == "__main__":
    main()
