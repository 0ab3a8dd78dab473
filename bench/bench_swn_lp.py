"""Surface winding numbers on surfaces that are not simply connected (issue 12): the residual LP variants on
the generated cases of bench/bench_swn.py, and the LP's speed vs faces.

Replays the not-simply-connected cases of the benchmark generator (same meshes, seeds and case ids as
bench/bench_swn.py, with its ``--breaking`` scheme) and scores, on the same cases:

- naive rounding of u (``method="none"``);
- "lp, as before": the full LP with the final jump solve across g − Jv on *every* edge (the solver before this
  section's fix: ``_final="all"``, diagnosis only);
- "lp": the full LP, final solve across the bounding part of the input only (thesis §6.1.2 "Γ ∖ Jv"; default);
- "lp, integer class": the same with γ's cohomology class rounded to the nearest integer class first
  (``homology="integer"``);
- "reduced" and "reduced, integer class": the reduced LP of §6.3.

For every method the error with the solver's rounding offset and, for naive and lp, with the best offset in
hindsight (an oracle that reads the truth: how much is the offset rule, how much the labels). The speed part
(``--only speed``, section "swn-lp-scaling") times the full LP per form (banded LP, network simplex, HiGHS on the
face and cycle forms) and the linear solves, 2k → 326k faces, on the scaling case of bench_swn.py.

Usage::

    PYTHONPATH=src python3 bench/bench_swn_lp.py --quick           # 4 cases per mesh (48), small speed run
    PYTHONPATH=src python3 bench/bench_swn_lp.py                   # 42 per mesh (all 504), speed to 134k faces
    PYTHONPATH=src python3 bench/bench_swn_lp.py --only speed [--quick] [--sizes 56,112] [--max-faces N]
    PYTHONPATH=src python3 bench/bench_swn_lp.py --only cases [--breaking long|random]
    PYTHONPATH=src python3 bench/bench_swn_lp.py --only summary    # the table of a partial run's CSV
    PYTHONPATH=src python3 bench/bench_swn_lp.py --only ns-diagnose [--quick]   # causes of the misses with
                                                                   # broken nonbounding loops (section swn-ns-diagnose)

Per-case rows: bench/swn_lp_cases[_quick].csv; summary: section "swn-lp" ("swn-lp-quick") of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import csv
import inspect
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import bench_swn as B  # noqa: E402
from common import machine, write_section  # noqa: E402

from gsdf.swn._solver import SurfaceWindingNumbers  # noqa: E402

NOTES = """\
What was checked and what was wrong (cases replayed by their bench_swn.py ids):

- **The LP itself matches** spec §1(b) step ④, thesis §6.1.2 and the authors' demo (`solveLinearProgram`): unknowns
  one shift per face, vInit from integrating γ in every face, jump Jv = d + x_A − x_B (a closed dual chain),
  objective Σ ℓ_e κ_e |Jv_e| with κ = ε = 1e-2 on input edges and 1 elsewhere, "no extra loops" 0 ≤ g·Jv ≤ g². The
  Hodge step (γ = ω − δβ for open curves; no boundary condition = harmonic forms tangent to the boundary =
  absolute cohomology, dual to the relative homology of §2.3.2: an arc between boundary circles is nonbounding, a
  loop around a hole bounds) agrees with a tree–cotree homology basis (`gsdf.dec._cycles`, b1 generators whose
  period matrix on the harmonic basis has full rank). The same truths with unbroken boundaries plus unbroken
  generators are solved exactly (torus, annulus, shark: 0.00 %, one ambiguous homologous choice 1.3 %).
- **Defect: the final jump solve (step ⑤).** w was solved with jumps g − Jv on *every* edge, i.e. also −Jv where
  the LP closed gaps off the input. A broken *bounding* curve has a nonzero harmonic part — the flux of the
  harmonic forms through its gaps (⟨Du_gap, h⟩ = ∫_gap ⋆h: for a gap running across an annulus, a large fraction
  of the radial class) — which the LP, with cheap input edges, places on a cycle along part of the curve and
  across the gap; imposing −Jv across the gap then cut the region's outside along that path (author-annulus:31 of
  the long-gap run: 40 % mislabeled vs 7 % naive; with the fix and the best offset both ≈ 2 %). The thesis solves
  "with jumps encoded by Γ ∖ Jv … the bounding components of Γ … taken as a subset of Γ": jumps g − Jv on the
  input's edges only, which is now the solver (test `tests/swn/test_lp.py::test_final_solve_jumps_only_across_the_input`).
- **Option `homology="integer"`** (not the default): the input is an integer chain, so its nonbounding part is an
  integer class; γ's periods on the tree–cotree basis are rounded first (class 0 → no LP: bounding curves with
  gaps are left alone, and the median time drops to the jump solve). Measured a tie with the real class below.
- **Step ⑤ reads "Γ ∖ Jv" as a subset of Γ** (branch swn-ns; `bounding="subset"`, the default now): with broken
  nonbounding loops the LP explains only a fraction of their jump (Jv ≈ 0.5–0.9 on the loop, thesis Fig. 6.6),
  and the former final solve across g − Jv left the rest (0.1–0.5) as a jump of w round the handle: a phantom
  ramp that the global rounding offset cannot undo. The thesis takes the bounding part "as a subset of Γ": an
  input edge is nonbounding when Jv explains at least half of its jump (g − round(Jv), the rule §6.4.1's
  filter `bounding_segments` already used), and a remainder that still has a harmonic part is decomposed again
  (at most 3 passes; a second pass is needed where the first left pieces of a loop below ½). "lp, fractional
  bounding" is the former reading. Tests: `tests/swn/test_lp.py::test_bounding_part_is_a_subset_of_the_input`.
  `--only ns-diagnose` sorts the remaining misses with broken nonbounding loops by cause.
- **What is left:** (a) the LP's choice between homologous loops (thesis Fig. 6.10: e.g. author-torus:2, same
  error with the best offset); (b) the rounding offset after a partial correction (author-double-torus:2:
  9.9 % with the solver's offset, 0.8 % with the best one; a threshold vote over the input edges was tried:
  better on simply connected cases — mean 0.49 % → 0.28 % on 60 — but worse here, 77 % → 69 % of 48 cases < 0.5 %;
  not adopted); (c) the reduced LP with broken nonbounding loops: nearest-endpoint completion links one curve's
  end to another curve, the completed chain stops separating (torus:3: one piece with 99.4 % of the area, χ = −9,
  in which the BFS integration of γ is path dependent); pairing endpoints by least total length instead was
  tried and was mixed (67.7 % vs 66.7 % < 0.5 % on 96 random-breaking cases, 41.7 % vs 43.8 % on long gaps).
"""

METHODS = [("naive", dict(method="none")),
           ("lp, as before", dict(method="lp", _final="all", bounding="fractional")),
           ("lp, fractional bounding", dict(method="lp", bounding="fractional")),
           ("lp", dict(method="lp")),
           ("lp, integer class", dict(method="lp", homology="integer")),
           ("reduced", dict(method="reduced")),
           ("reduced, integer class", dict(method="reduced", homology="integer"))]
ORACLE = ("naive", "lp")


def _cases(mc, n, breaking):
    if "breaking" in inspect.signature(B.generate_cases).parameters:
        return B.generate_cases(mc, n, breaking=breaking)
    if breaking != "long":
        raise SystemExit("this bench_swn.py has only the 'long' breaking scheme")
    return B.generate_cases(mc, n)


def run_cases(per_mesh, csv_path, breaking, time_limit):
    rows = []
    fields = ["case", "mesh", "faces", "b1", "boundary", "region", "broken", "nonbounding"]
    for k, _ in METHODS:
        fields += [f"err {k}", f"t {k}"]
    fields += [f"oracle {k}" for k in ORACLE]
    with open(csv_path, "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=fields)
        wr.writeheader()
        for mi, (name, load) in enumerate(B.mesh_list()):
            try:
                V, F = load()
                swn0 = SurfaceWindingNumbers(V, F)
                if swn0.betti_1 == 0:
                    continue
                mc = B.MeshCases(name, V, F, seed=1000 + mi)
            except Exception as exc:                       # a missing mesh: skip, say so
                print(f"skip {name}: {exc}", flush=True)
                continue
            for c, cid, kind, truth, g, gb, frac, nb in _cases(mc, per_mesh, breaking):
                if not np.any(gb):
                    continue
                A = mc.area
                row = {"case": cid, "mesh": name, "faces": mc.dec.n_faces, "b1": mc.swn.betti_1,
                       "boundary": int(not mc.closed), "region": kind, "broken": round(frac, 3), "nonbounding": nb}
                for k, kw in METHODS:
                    try:
                        r = mc.swn.solve(gb, time_limit=time_limit, **kw)
                    except ValueError as exc:
                        print(f"  {cid} {k}: {exc}", flush=True)
                        row[f"err {k}"], row[f"t {k}"] = np.nan, np.nan
                        continue
                    row[f"err {k}"] = B.mislabeled(r.face_labels, truth, A)
                    row[f"t {k}"] = r.timings["total"]
                    if k in ORACLE:
                        w = r.corner_values.mean(1) + r.label_shift + r.offset
                        row[f"oracle {k}"] = min(B.mislabeled(np.round(w - s).astype(int), truth, A)
                                                 for s in np.linspace(-0.5, 0.5, 51))
                wr.writerow(row)
                fh.flush()
                rows.append(row)
            print(f"  done {name} ({len(rows)} cases so far)", flush=True)
    return rows


def _lp_without(swn, forbid):
    """The full residual LP of ``swn`` with the jump forced to 0 on the edges ``forbid`` (diagnosis only)."""
    from gsdf.linalg._dual_l1 import dual_graph_l1

    def residual(gamma, g, eps, time_limit, algorithm="highs-ds", ends=None):
        dec, topo = swn.dec, swn.topology
        inter = np.flatnonzero(topo.edge_face_count == 2)
        d = swn._edge_offsets(swn._face_integrals(gamma), inter)
        gi = g[inter]
        on = gi != 0
        lo = np.where(on, np.minimum(0.0, gi), -np.inf)
        hi = np.where(on, np.maximum(0.0, gi), np.inf)
        lo[forbid[inter]] = 0.0
        hi[forbid[inter]] = 0.0
        r = dual_graph_l1(dec.n_faces, topo.edge_faces[inter], d, dec.edge_len[inter] * np.where(on, eps, 1.0),
                          bounds=np.column_stack([lo, hi]), time_limit=time_limit, algorithm=algorithm)
        Jv = np.zeros(dec.n_edges)
        Jv[inter] = r.jumps
        return Jv, r.objective, r.seconds
    return residual


def ns_diagnose(per_mesh, breaking, time_limit):
    """Closed surfaces with broken nonbounding loops: why the full LP misses 0.5 %. Per failing case: the LP's
    objective against the LP that may not put jumps on the region's own edges (an oracle that knows which input
    edges bound), the error of that oracle, of naive rounding of the region boundary alone (what the gaps cost
    without any nonbounding loop) and with the best rounding offset in hindsight."""
    rows = []
    for mi, (name, load) in enumerate(B.mesh_list()):
        if mi < B.N_SIMPLY:
            continue
        V, F = load()
        mc = B.MeshCases(name, V, F, seed=1000 + mi)
        if not mc.closed or not mc.gens:
            continue
        for c, cid, kind, truth, g, gb, frac, nb, parts in B.generate_cases_parts(mc, per_mesh, breaking):
            if nb == 0:
                continue
            sw, A = mc.swn, mc.area
            r = sw.solve(gb, method="lp", time_limit=time_limit)
            e = B.mislabeled(r.face_labels, truth, A)
            loops = sum(parts["loops"])
            forbid = (parts["region"] != 0) & (loops == 0)
            sw._residual_full = _lp_without(sw, forbid)
            try:
                ro = sw.solve(gb, method="lp", time_limit=time_limit, cycle_choice="lp")   # the oracle's own LP
            finally:
                del sw._residual_full
            w = r.corner_values.mean(1) + r.label_shift + r.offset
            best = min(B.mislabeled(np.round(w - s).astype(int), truth, A) for s in np.linspace(-0.5, 0.5, 51))
            row = dict(case=cid, err=e, oracle_err=B.mislabeled(ro.face_labels, truth, A),
                       obj=r.lp_objective, oracle_obj=ro.lp_objective, best_offset=best,
                       region_alone=B.mislabeled(sw.solve(parts["region"], method="none").face_labels, truth, A),
                       on_loops=float(np.abs(r.residual[loops != 0]).mean()), passes=r.passes)
            rows.append(row)
        print(f"  done {name} ({len(rows)} cases)", flush=True)
    fail = [r for r in rows if r["err"] >= 0.005]
    cat = {"the region alone (naive, no loops) is already ≥ 0.5 % (truth inside the gaps)": [],
           "the LP's nonbounding loop runs partly along the region boundary, cheaper than along the input loop "
           "(the oracle LP that may not use region edges has a higher objective and is < 0.5 %)": [],
           "the LP closes a shorter homologous loop off the input loop (Jv < 0.3 on the loop's edges)": [],
           "the rounding offset (< 0.5 % with the best offset)": [], "other": []}
    keys = list(cat)
    for r in fail:
        if r["region_alone"] >= 0.005:
            cat[keys[0]].append(r)
        elif r["oracle_obj"] > r["obj"] + 1e-6 and r["oracle_err"] < 0.005:
            cat[keys[1]].append(r)
        elif r["on_loops"] < 0.3:
            cat[keys[2]].append(r)
        elif r["best_offset"] < 0.005:
            cat[keys[3]].append(r)
        else:
            cat[keys[4]].append(r)
    out = [f"{len(rows)} cases (closed, with broken nonbounding loops; up to {per_mesh} per mesh), full LP < 0.5 %: "
           f"{100 * np.mean([r['err'] < 0.005 for r in rows]):.1f} %; with the oracle LP: "
           f"{100 * np.mean([r['oracle_err'] < 0.005 for r in rows]):.1f} %. The {len(fail)} misses, first cause "
           "that applies:", "", "| cause | cases | examples |", "|---|---|---|"]
    for k in keys:
        out.append(f"| {k} | {len(cat[k])} | {', '.join(r['case'] for r in cat[k][:6])} |")
    out += ["", "| case | error | oracle LP error | objective / oracle's | region alone | best offset | Jv on the loops "
            "(mean) | passes |", "|---|---|---|---|---|---|---|---|"]
    for r in fail:
        out.append(f"| {r['case']} | {100 * r['err']:.2f} % | {100 * r['oracle_err']:.2f} % | {r['obj']:.3f} / "
                   f"{r['oracle_obj']:.3f} | {100 * r['region_alone']:.2f} % | {100 * r['best_offset']:.2f} % | "
                   f"{r['on_loops']:.2f} | {r['passes']} |")
    return "\n".join(out)


def versus(old_csv, new_csv):
    """Old vs new per-case errors of bench_swn.py (its CSV rows, e.g. main's bench/swn_cases.csv against this
    worktree's), on the not simply connected cases present in both, by subgroup."""
    with open(old_csv) as fh:
        old = {r["case"]: r for r in csv.DictReader(fh)}
    with open(new_csv) as fh:
        new = {r["case"]: r for r in csv.DictReader(fh)}
    ids = [c for c in new if c in old and new[c]["b1"] != "0"]
    out = [f"{len(ids)} not simply connected cases in both ({old_csv} → {new_csv}); share < 0.5 % (mean error):", "",
           "| subgroup | cases | full LP, before | full LP, now | reduced, before | reduced, now | naive |",
           "|---|---|---|---|---|---|---|"]
    groups = (("all not simply connected", lambda r: True),
              ("closed, no nonbounding loops", lambda r: r["boundary"] == "0" and r["nonbounding"] == "0"),
              ("closed, with broken nonbounding loops", lambda r: r["boundary"] == "0" and r["nonbounding"] != "0"),
              ("with boundary", lambda r: r["boundary"] == "1"))
    for lab, sel in groups:
        cc = [c for c in ids if sel(new[c])]
        if not cc:
            continue
        cell = []
        for src, k in ((old, "err_lp"), (new, "err_lp"), (old, "err_reduced"), (new, "err_reduced"),
                       (new, "err_none")):
            e = np.array([float(src[c][k]) for c in cc])
            cell.append(f"{100 * np.nanmean(e < 0.005):.1f} % ({100 * np.nanmean(e):.2f} %)")
        out.append(f"| {lab} | {len(cc)} | " + " | ".join(cell) + " |")
    return "\n".join(out)


def summarize(rows):
    f = lambda r, k: float(r[k]) if r.get(k) not in (None, "", "nan") else np.nan  # noqa: E731
    out = [f"{len(rows)} cases on {len({r['mesh'] for r in rows})} meshes (genus 1–3 and/or several boundary "
           "components).", "",
           "| method | cases < 0.5 % | mean error | median error | error with the best offset in hindsight "
           "(mean / < 0.5 %) | worse than naive by > 0.1 % of the area | median time | max time |",
           "|---|---|---|---|---|---|---|---|"]
    en = np.array([f(r, "err naive") for r in rows])
    for k, _ in METHODS:
        e = np.array([f(r, f"err {k}") for r in rows])
        t = np.array([f(r, f"t {k}") for r in rows])
        if k in ORACLE:
            o = np.array([f(r, f"oracle {k}") for r in rows])
            orc = f"{100 * np.nanmean(o):.2f} % / {100 * np.nanmean(o < 0.005):.1f} %"
        else:
            orc = ""
        worse = "" if k == "naive" else f"{int(np.nansum(e > en + 1e-3))}"
        out.append(f"| {k} | {100 * np.nanmean(e < 0.005):.1f} % | {100 * np.nanmean(e):.2f} % | "
                   f"{100 * np.nanmedian(e):.3f} % | {orc} | {worse} | {np.nanmedian(t):.3f} s | {np.nanmax(t):.2f} s |")
    out += ["", "| subgroup | cases | " + " | ".join(f"{k} < 0.5 % (mean)" for k, _ in METHODS) + " |",
            "|---|---|" + "---|" * len(METHODS)]
    for lab, sel in (("closed, no nonbounding loops", lambda r: r["boundary"] == "0" and r["nonbounding"] == "0"),
                     ("closed, with broken nonbounding loops", lambda r: r["boundary"] == "0" and r["nonbounding"] != "0"),
                     ("with boundary", lambda r: r["boundary"] == "1"),
                     ("deleted 10–30 %", lambda r: float(r["broken"]) < 0.3),
                     ("deleted 30–50 %", lambda r: float(r["broken"]) >= 0.3)):
        rr = [r for r in rows if sel(r)]
        if not rr:
            continue
        cells = []
        for k, _ in METHODS:
            e = np.array([f(r, f"err {k}") for r in rr])
            cells.append(f"{100 * np.nanmean(e < 0.005):.0f} % ({100 * np.nanmean(e):.2f} %)")
        out.append(f"| {lab} | {len(rr)} | " + " | ".join(cells) + " |")
    return "\n".join(out)


FORMS = {  # column -> (lp_form, lp_algorithm, largest face count run by default)
    "band": ("faces", "band", 10**9),
    "faces: network simplex": ("faces", "network", 40_000),
    "faces: HiGHS dual simplex": ("faces", "highs-ds", 40_000),
    "faces: HiGHS interior point": ("faces", "highs-ipm", 40_000),
    "cycles: HiGHS dual simplex": ("cycles", "highs-ds", 10_000),
    "cycles: HiGHS interior point": ("cycles", "highs-ipm", 10_000),
}


def speed(sizes, time_limit, max_faces=None):
    """Full-LP time vs faces on the scaling case of bench_swn.py (torus grid, a broken meridian + a broken band),
    one decomposition (``bounding="fractional"``: every form solves the same LP): per form the LP time, and the
    linear solves (step ① jump solve + Hodge decomposition + step ⑤ final solve) once per size. Forms slower
    than a few minutes at 134k faces in earlier runs are skipped above their size cap (``--max-faces`` lifts it);
    objectives must agree to 1e-7 (relative)."""
    from gsdf.linalg._band_lp import banded_l1
    from gsdf.linalg._dual_l1 import dual_graph_l1

    dual_graph_l1(2, [[0, 1]], [0.5], [1.0], algorithm="network")        # load the numba kernels once
    banded_l1(3, [[0, 1], [1, 2], [2, 0]], [1.0, 0.0, 0.0], [2.0, 1.0, 5.0], seeds=[0])
    cols = list(FORMS)
    rows = ["| faces | linear solves (① + Hodge + ⑤) | " + " | ".join(f"LP: {c}" for c in cols) +
            " | reduced LP (LP / total) | objectives agree |",
            "|---|---|" + "---|" * len(cols) + "---|---|"]
    for nu in sizes:
        nv = max(8, nu // 3)
        V, F = B.torus_grid(nu, nv)
        swn = {f: SurfaceWindingNumbers(V, F, lp_form=f) for f in ("faces", "cycles")}
        s0 = swn["faces"]
        idx = np.arange(nu * nv).reshape(nu, nv)
        i0 = (F // nv).min(1)
        band = (i0 >= nu // 3) & (i0 < nu // 2)
        g = np.rint(s0.dec.d1.T @ band.astype(float))
        gap = (s0.dec.edges % nv < int(0.3 * nv)).all(axis=1)
        g[gap] = 0
        g = g + s0.chain([idx[nu // 7, : int(0.8 * nv)]])
        line = [f"| {len(F)} |"]
        obj, lin = [], None
        cells = []
        for c in cols:
            form, alg, cap = FORMS[c]
            if len(F) > (max_faces or cap):
                cells.append(" skipped |")
                continue
            try:
                r = swn[form].solve(g, method="lp", time_limit=time_limit, lp_algorithm=alg, bounding="fractional")
                cells.append(f" {r.timings['lp']:.2f} s |")
                obj.append(r.lp_objective)
                if lin is None:
                    T = r.timings
                    lin = T["jump_solve"] + T["hodge"] + T["final_solve"]
            except ValueError as exc:
                cells.append(f" > {time_limit:.0f} s ({'limit' if 'limit' in str(exc) else str(exc)[:30]}) |")
            print(len(F), c, cells[-1], flush=True)
        line.append(f" {lin:.2f} s |" if lin is not None else " – |")
        line += cells
        rr = s0.solve(g, method="reduced", bounding="fractional")
        line.append(f" {rr.timings['lp']:.3f} s / {rr.timings['total']:.2f} s |")
        agree = len(obj) > 1 and max(obj) - min(obj) <= 1e-7 * max(1, abs(obj[0]))
        line.append(f" {'yes' if agree else ('–' if len(obj) < 2 else 'NO')} ({len(obj)} solved) |")
        rows.append("".join(line))
        print(rows[-1], flush=True)
    return "\n".join(rows)


SPEED_NOTES = """One decomposition per solve (`bounding="fractional"`), so that every form solves the same LP; the
default `bounding="subset"` runs up to three (bench_swn.py `--only scaling` times those). "band" (the default from
12k faces on, `lp_algorithm="auto"`): gsdf.linalg._band_lp — the face-form LP on a band of faces around the curves and
their shortest-path completions, every outside piece one cell, then a proof of optimality on all faces (a maximum
flow: a circulation satisfying complementary slackness exists), growing the band over the certificate's minimum
cut until proven. "network simplex": the face-form LP's dual min-cost circulation on all faces (gsdf.linalg._netflow).
The objectives are compared to 1e-7 (relative)."""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="4 cases per mesh and a small speed run")
    ap.add_argument("--per-mesh", type=int, default=None)
    ap.add_argument("--only", choices=["cases", "speed", "summary", "ns-diagnose", "versus"], default=None,
                    help="summary: re-summarize the per-case CSV of an earlier (possibly partial) run")
    ap.add_argument("--breaking", choices=["random", "long"], default="random")
    ap.add_argument("--time-limit", type=float, default=300.0)
    ap.add_argument("--old", default="/work/main/bench/swn_cases.csv", help="--only versus: the old CSV")
    ap.add_argument("--new", default=os.path.join(HERE, "swn_cases.csv"), help="--only versus: the new CSV")
    ap.add_argument("--sizes", default=None, help="comma-separated torus grid sizes nu for the speed run "
                    "(faces = 2 nu max(8, nu//3); default 56,112,224,448,700: 2k to 326k faces; --quick 56,112,224)")
    ap.add_argument("--max-faces", type=int, default=None, help="speed run: run every form up to this many faces "
                    "(default: per-form caps, FORMS)")
    a = ap.parse_args()
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    t0 = time.perf_counter()
    text = [f"Machine: {machine()}. Load at start: `{load}` (shared with other helpers; times are indicative).",
            f"Command: `PYTHONPATH=src python3 bench/bench_swn_lp.py{' --quick' if a.quick else ''}"
            f"{' --only ' + a.only if a.only else ''}{f' --per-mesh {a.per_mesh}' if a.per_mesh else ''} "
            f"--breaking {a.breaking}{f' --time-limit {a.time_limit:g}' if a.time_limit != 300 else ''}"
            f"{f' --sizes {a.sizes}' if a.sizes else ''}`", ""]
    if a.only == "versus":
        text[1] = f"Command: `PYTHONPATH=src python3 bench/bench_swn_lp.py --only versus --old {a.old} --new {a.new}`"
        text += [versus(a.old, a.new), ""]
        write_section("swn-ns-versus", "## Surface winding numbers, not simply connected: before vs now on the same "
                      "cases (issue 12)\n\n" + "\n".join(text))
        print("\n".join(text))
        return
    if a.only == "ns-diagnose":
        per = a.per_mesh or (10 if a.quick else 42)
        text += ["### Closed surfaces with broken nonbounding loops: causes of the remaining misses", "",
                 ns_diagnose(per, a.breaking, a.time_limit), ""]
        text[1] += f" ({time.perf_counter() - t0:.0f} s)."
        write_section("swn-ns-diagnose" + ("-quick" if a.quick else ""),
                      "## Surface winding numbers, not simply connected: why the full LP misses (issue 12)\n\n" +
                      "\n".join(text))
        print("\n".join(text))
        return
    if a.only in (None, "cases", "summary"):
        text += [NOTES, ""]
        per = a.per_mesh or (4 if a.quick else 42)
        path = os.path.join(HERE, f"swn_lp_cases{'_quick' if a.quick else ''}_{a.breaking}.csv")
        if a.only != "summary":
            run_cases(per, path, a.breaking, a.time_limit)
        with open(path) as fh:
            rows = list(csv.DictReader(fh))
        text += [f"### Not simply connected cases, {a.breaking} breaking (up to {per} per mesh; rows in "
                 f"bench/{os.path.basename(path)})", "", summarize(rows), ""]
    if a.only in (None, "speed"):
        sizes = [int(x) for x in a.sizes.split(",")] if a.sizes else \
            ([56, 112, 224] if a.quick else [56, 112, 224, 448, 700])
        text += ["### Full LP time vs faces (torus grid, one broken meridian + a 30 %-broken band boundary)", "",
                 SPEED_NOTES, "", speed(sizes, a.time_limit, a.max_faces), ""]
    text[1] += f" ({time.perf_counter() - t0:.0f} s)."
    if a.only == "speed":
        text[1] += f"{f' --max-faces {a.max_faces}' if a.max_faces else ''}"
        write_section("swn-lp-scaling" + ("-quick" if a.quick else ""),
                      "## Surface winding numbers: full residual LP time vs faces, by form (issue 12)\n\n" +
                      "\n".join(text))
        print("\n".join(text))
        return
    name = "swn-lp" + ("-quick" if a.quick else "") + ("-speed" if a.only == "speed" else "") + \
        ("-long" if a.breaking == "long" and a.only != "speed" else "")
    write_section(name, "## Surface winding numbers, not simply connected: residual LP (issue 12)\n\n" +
                  "\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
