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
times the full LP (HiGHS dual simplex vs interior point) on the scaling case of bench_swn.py.

Usage::

    PYTHONPATH=src python3 bench/bench_swn_lp.py --quick           # 4 cases per mesh (48), small speed run
    PYTHONPATH=src python3 bench/bench_swn_lp.py                   # 42 per mesh (all 504), speed to 134k faces
    PYTHONPATH=src python3 bench/bench_swn_lp.py --only speed|cases [--breaking long|random]
    PYTHONPATH=src python3 bench/bench_swn_lp.py --only summary    # the table of a partial run's CSV

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

from gsdf.winding.surface import SurfaceWindingNumbers  # noqa: E402

NOTES = """\
What was checked and what was wrong (cases replayed by their bench_swn.py ids):

- **The LP itself matches** spec §1(b) step ④, thesis §6.1.2 and the authors' demo (`solveLinearProgram`): unknowns
  one shift per face, vInit from integrating γ in every face, jump Jv = d + x_A − x_B (a closed dual chain),
  objective Σ ℓ_e κ_e |Jv_e| with κ = ε = 1e-2 on input edges and 1 elsewhere, "no extra loops" 0 ≤ g·Jv ≤ g². The
  Hodge step (γ = ω − δβ for open curves; no boundary condition = harmonic forms tangent to the boundary =
  absolute cohomology, dual to the relative homology of §2.3.2: an arc between boundary circles is nonbounding, a
  loop around a hole bounds) agrees with a tree–cotree homology basis (`gsdf.dec.cycles`, b1 generators whose
  period matrix on the harmonic basis has full rank). The same truths with unbroken boundaries plus unbroken
  generators are solved exactly (torus, annulus, shark: 0.00 %, one ambiguous homologous choice 1.3 %).
- **Defect: the final jump solve (step ⑤).** w was solved with jumps g − Jv on *every* edge, i.e. also −Jv where
  the LP closed gaps off the input. A broken *bounding* curve has a nonzero harmonic part — the flux of the
  harmonic forms through its gaps (⟨Du_gap, h⟩ = ∫_gap ⋆h: for a gap running across an annulus, a large fraction
  of the radial class) — which the LP, with cheap input edges, places on a cycle along part of the curve and
  across the gap; imposing −Jv across the gap then cut the region's outside along that path (author-annulus:31 of
  the long-gap run: 40 % mislabeled vs 7 % naive; with the fix and the best offset both ≈ 2 %). The thesis solves
  "with jumps encoded by Γ ∖ Jv … the bounding components of Γ … taken as a subset of Γ": jumps g − Jv on the
  input's edges only, which is now the solver (test `tests/test_swn_lp.py::test_final_solve_jumps_only_across_the_input`).
- **Option `homology="integer"`** (not the default): the input is an integer chain, so its nonbounding part is an
  integer class; γ's periods on the tree–cotree basis are rounded first (class 0 → no LP: bounding curves with
  gaps are left alone, and the median time drops to the jump solve). Measured a tie with the real class below.
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
           ("lp, as before", dict(method="lp", _final="all")),
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
                        w = r.corner_values.mean(1) + r.offset
                        row[f"oracle {k}"] = min(B.mislabeled(np.round(w - s).astype(int), truth, A)
                                                 for s in np.linspace(-0.5, 0.5, 51))
                wr.writerow(row)
                fh.flush()
                rows.append(row)
            print(f"  done {name} ({len(rows)} cases so far)", flush=True)
    return rows


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


def speed(sizes, time_limit):
    """Full-LP time on the scaling case of bench_swn.py (torus grid, a broken meridian + a broken band): the face
    form (spec §1(b) ④, ``lp_form="faces"``, the only one before) and the cycle form (``lp_form="cycles"``,
    gsdf.dec.cycle_lp), HiGHS dual simplex and interior point each; objectives must agree."""
    rows = ["| faces | step ① jump solve | faces: dual simplex | faces: interior point | cycles: dual simplex | "
            "cycles: interior point | reduced LP (LP / total) | objectives agree |",
            "|---|---|---|---|---|---|---|---|"]
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
        r0 = s0.solve(g, method="none")
        line.append(f" {r0.timings['jump_solve']:.3f} s |")
        obj = []
        for form in ("faces", "cycles"):
            for alg in ("highs-ds", "highs-ipm"):
                try:
                    r = swn[form].solve(g, method="lp", time_limit=time_limit, lp_algorithm=alg)
                    line.append(f" {r.timings['lp']:.2f} s |")
                    obj.append(r.lp_objective)
                except ValueError as exc:
                    line.append(f" > {time_limit:.0f} s ({'limit' if 'limit' in str(exc) else str(exc)[:30]}) |")
        rr = s0.solve(g, method="reduced")
        line.append(f" {rr.timings['lp']:.3f} s / {rr.timings['total']:.2f} s |")
        agree = len(obj) > 1 and max(obj) - min(obj) < 1e-6 * max(1, abs(obj[0]))
        line.append(f" {'yes' if agree else '–'} ({len(obj)} solved) |")
        rows.append("".join(line))
        print(rows[-1], flush=True)
    return "\n".join(rows)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="4 cases per mesh and a small speed run")
    ap.add_argument("--per-mesh", type=int, default=None)
    ap.add_argument("--only", choices=["cases", "speed", "summary"], default=None,
                    help="summary: re-summarize the per-case CSV of an earlier (possibly partial) run")
    ap.add_argument("--breaking", choices=["random", "long"], default="random")
    ap.add_argument("--time-limit", type=float, default=300.0)
    ap.add_argument("--sizes", default=None, help="comma-separated torus grid sizes nu for the speed run "
                    "(faces = 2 nu max(8, nu//3); default 56,112,224,448: 2k to 134k faces)")
    a = ap.parse_args()
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    t0 = time.perf_counter()
    text = [f"Machine: {machine()}. Load at start: `{load}` (shared with other helpers; times are indicative).",
            f"Command: `PYTHONPATH=src python3 bench/bench_swn_lp.py{' --quick' if a.quick else ''}"
            f"{' --only ' + a.only if a.only else ''}{f' --per-mesh {a.per_mesh}' if a.per_mesh else ''} "
            f"--breaking {a.breaking}{f' --time-limit {a.time_limit:g}' if a.time_limit != 300 else ''}"
            f"{f' --sizes {a.sizes}' if a.sizes else ''}`", ""]
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
        sizes = [int(x) for x in a.sizes.split(",")] if a.sizes else ([48, 112] if a.quick else [56, 112, 224, 448])
        text += ["### Full LP time vs faces (torus grid, one broken meridian + a 30 %-broken band boundary)", "",
                 speed(sizes, a.time_limit), ""]
    text[1] += f" ({time.perf_counter() - t0:.0f} s)."
    name = "swn-lp" + ("-quick" if a.quick else "") + ("-speed" if a.only == "speed" else "") + \
        ("-long" if a.breaking == "long" and a.only != "speed" else "")
    write_section(name, "## Surface winding numbers, not simply connected: residual LP (issue 12)\n\n" +
                  "\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
