"""Surface winding numbers, not simply connected (issue 12): which homologous cycle carries the class of γ.

Replays the not-simply-connected cases of bench/bench_swn.py (same meshes, seeds and case ids, random breaking)
and scores the full LP with ``cycle_choice="lp"`` (the LP's optimum: least ε-weighted length, thesis §6.1.2)
against ``cycle_choice="complete"`` (the LP again with the first cycle's input edges forbidden, the cycle with
the larger share of its jump mass on the input kept; see SurfaceWindingNumbers.solve). When "complete" keeps the
first cycle in every pass its result is the "lp" result (same LPs), so "lp" is only solved again on the cases
where the second cycle was chosen at least once.

Usage::

    PYTHONPATH=src python3 bench/bench_swn_choice.py --quick          # 4 cases per mesh
    PYTHONPATH=src python3 bench/bench_swn_choice.py                  # 42 per mesh: all 504 cases

Per-case rows: bench/swn_choice_cases[_quick].csv; section "swn-ns-5" ("swn-ns-5-quick") of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import csv
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
Why (section swn-ns-diagnose-quick): on closed surfaces with broken nonbounding loops the LP's cycle often
runs along a side of the broken region instead of along the broken loop — a side of a band round a handle is
homologous to the loop. The LP minimises ε·(length on the input) + (length across gaps), so between two whole
homologous candidates it takes the one with less *gap length*; a long loop with few gaps loses to a shorter,
more broken region side (author-torus:2: loop 2.58 long, 26 % deleted, gaps 0.66; band side ≈ 1.57 long,
≈ 40 % deleted, gaps ≈ 0.63 — LP objective 0.57 vs 0.60 for the loop, 36.9 % mislabeled). The criterion here
compares whole candidate cycles by the share of their jump mass Σ ℓ|Jv| that lies on the input (0.60 for the
band side, 0.74 for the loop): the share of a broken curve that survives does not grow with its length.
Candidates: the LP's cycle and the LP's best cycle that may not use the first one's input edges
(|Jv| > 0.1; with 1e-3 the loop's own faint traces, |Jv| ≈ 0.002, were forbidden too and the second cycle ran
off the input: no case changed). One extra LP per decomposition pass that has a harmonic part.

Also measured and dropped (41 closed cases with broken loops, cases 0–9 per mesh, scratch runs): ε = 1e-3
instead of 1e-2 — no case crosses the 0.5 % line (38 of 41 replayed: 19 < 0.5 % either way); ε = 0.1 — 17
instead of 19 (torus:8 0.03 → 0.54 %, author-torus:6 0.19 → 0.81 %; author-double-torus:2 9.9 → 2.0 %).
Forbidding pieces of the chosen cycle one at a time as well (pieces = its input edges split at crossings of
the curves, the 6 lightest, each kept when the share grows): 26 of the 41 cases replayed before it was stopped,
none crossed the 0.5 % line (author-torus:8 stays 35.6 %), 1–18 LPs per case — dropped.
Cost of the kept rule: the second LP about doubles the LP time of every case that needs an LP (also when it
is not chosen); ``cycle_choice="lp"`` is the thesis' single LP.
Simply connected surfaces never reach the LP (the solve stops after the jump solve): their results (sections
swn, swn-floor) are unchanged.
The misses left are cycles that follow the loop for most of their length and the region for a stretch
(knot1:9, author-torus:8: the loops and the region cross, so the second LP, which may not use the loop's edges
either, is worse) and the other causes of swn-ns-diagnose-quick (truth inside the gaps, offsets).
"""

FIELDS = ["case", "mesh", "group", "switched", "err lp", "err complete", "t lp", "t complete", "err complete global"]


def run(per_mesh, csv_path, time_limit):
    rows = []
    with open(csv_path, "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=FIELDS)
        wr.writeheader()
        for mi, (name, load) in enumerate(B.mesh_list()):
            if mi < B.N_SIMPLY:
                continue
            V, F = load()
            mc = B.MeshCases(name, V, F, seed=1000 + mi)
            sw = mc.swn
            assert isinstance(sw, SurfaceWindingNumbers) and sw.betti_1 > 0
            switched = []
            real = sw._complete_cycle

            def spy(gamma, g, eps, tl, alg, extra, Jv, obj, lp_s):
                out = real(gamma, g, eps, tl, alg, extra, Jv, obj, lp_s)
                switched.append(out[0] is not Jv)
                return out
            sw._complete_cycle = spy
            for c, cid, kind, truth, g, gb, frac, nb in B.generate_cases(mc, per_mesh, "random"):
                if not np.any(gb):
                    continue
                group = "with boundary" if not mc.closed else \
                    ("closed, with broken nonbounding loops" if nb else "closed, no nonbounding loops")
                switched.clear()
                r = sw.solve(gb, method="lp", time_limit=time_limit)
                row = {"case": cid, "mesh": name, "group": group, "switched": int(any(switched)),
                       "err complete": B.mislabeled(r.face_labels, truth, mc.area),
                       # labels="global" (one rounding level, before) from the same solve
                       "err complete global": B.mislabeled(
                           np.round(r.corner_values.mean(axis=1) + r.label_shift).astype(np.int64), truth, mc.area),
                       "t complete": r.timings["total"]}
                if any(switched):
                    r0 = sw.solve(gb, method="lp", time_limit=time_limit, cycle_choice="lp")
                    row["err lp"], row["t lp"] = B.mislabeled(r0.face_labels, truth, mc.area), r0.timings["total"]
                else:
                    row["err lp"], row["t lp"] = row["err complete"], float("nan")
                wr.writerow(row)
                fh.flush()
                rows.append(row)
                if any(switched):
                    print(f"  {cid}: switched, {100 * row['err lp']:.2f} % -> {100 * row['err complete']:.2f} %",
                          flush=True)
            del sw._complete_cycle
            print(f"  done {name} ({len(rows)} cases)", flush=True)
    return rows


def summarize(rows):
    groups = ["all not simply connected", "closed, no nonbounding loops", "closed, with broken nonbounding loops",
              "with boundary"]
    out = ["| subgroup | cases | cycle_choice=\"lp\" < 0.5 % (mean) | \"complete\" < 0.5 % (mean) | second cycle "
           "chosen | fixed / broken (0.5 % line) |", "|---|---|---|---|---|---|"]
    for gname in groups:
        R = [r for r in rows if gname.startswith("all") or r["group"] == gname]
        if not R:
            continue
        a = np.array([float(r["err lp"]) for r in R])
        b = np.array([float(r["err complete"]) for r in R])
        sw = sum(int(r["switched"]) for r in R)
        fixed = int(np.sum((a >= 0.005) & (b < 0.005)))
        broke = int(np.sum((a < 0.005) & (b >= 0.005)))
        out.append(f"| {gname} | {len(R)} | {100 * np.mean(a < 0.005):.1f} % ({100 * a.mean():.2f} %) | "
                   f"{100 * np.mean(b < 0.005):.1f} % ({100 * b.mean():.2f} %) | {sw} | {fixed} / {broke} |")
    if rows and rows[0].get("err complete global") not in (None, ""):
        out += ["", "Face labels of the same solves (cycle_choice=\"complete\"): one global rounding level "
                "(labels=\"global\", before) vs the level across each gap (labels=\"gaps\", "
                "SurfaceWindingNumbers.gap_shift):", "",
                "| subgroup | cases | labels=\"global\" < 0.5 % (mean) | labels=\"gaps\" < 0.5 % (mean) | "
                "fixed / broken (0.5 % line) |", "|---|---|---|---|---|"]
        for gname in groups:
            R = [r for r in rows if gname.startswith("all") or r["group"] == gname]
            if not R:
                continue
            a = np.array([float(r["err complete global"]) for r in R])
            b = np.array([float(r["err complete"]) for r in R])
            out.append(f"| {gname} | {len(R)} | {100 * np.mean(a < 0.005):.1f} % ({100 * a.mean():.2f} %) | "
                       f"{100 * np.mean(b < 0.005):.1f} % ({100 * b.mean():.2f} %) | "
                       f"{int(np.sum((a >= 0.005) & (b < 0.005)))} / {int(np.sum((a < 0.005) & (b >= 0.005)))} |")
    ch = [r for r in rows if int(r["switched"])]
    if ch:
        out += ["", "Cases where the second cycle was chosen (mislabeled area, lp → complete; total time):", "",
                "| case | group | lp | complete | time lp / complete |", "|---|---|---|---|---|"]
        for r in ch:
            out.append(f"| {r['case']} | {r['group']} | {100 * float(r['err lp']):.2f} % | "
                       f"{100 * float(r['err complete']):.2f} % | {float(r['t lp']):.2f} / "
                       f"{float(r['t complete']):.2f} s |")
    t = np.array([float(r["t complete"]) for r in rows])
    tl = np.array([float(r["t lp"]) for r in ch]) if ch else np.array([])
    tc = np.array([float(r["t complete"]) for r in ch]) if ch else np.array([])
    out += ["", f"Time, \"complete\" (total per case): median {np.median(t):.2f} s, max {t.max():.1f} s"
            + (f"; on the switched cases lp / complete median {np.median(tl):.2f} / {np.median(tc):.2f} s" if ch
               else "") + "."]
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="4 cases per mesh")
    ap.add_argument("--per-mesh", type=int, default=None)
    ap.add_argument("--time-limit", type=float, default=120.0)
    ap.add_argument("--summary", action="store_true", help="rewrite the section from the per-case CSV of a run")
    ap.add_argument("--run-note", default=None, help="with --summary: the run's machine/load/time line, when the "
                    "CSV was made by another process calling run() (replaces the old section's run lines)")
    a = ap.parse_args()
    per = a.per_mesh or (4 if a.quick else 42)
    csv_path = os.path.join(HERE, f"swn_choice_cases{'_quick' if a.quick else ''}.csv")
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    t0 = time.perf_counter()
    if a.summary:
        with open(csv_path) as fh:
            rows = list(csv.DictReader(fh))
    else:
        rows = run(per, csv_path, a.time_limit)
    load2 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    flags = "".join(" " + t for t in sys.argv[1:] if t != "--summary")
    name = "swn-ns-5" + ("-quick" if a.quick else "")
    head = [f"Machine: {machine()}. Load at start: `{load}`; at end: `{load2}` (shared with other helpers; "
            "times are indicative, errors are not affected).",
            f"Command: `PYTHONPATH=src python3 bench/bench_swn_choice.py{flags}` ({time.perf_counter() - t0:.0f} s); "
            f"cases 0–{per - 1} of every not simply connected mesh of bench_swn.py, random breaking, full LP "
            f"(lp_algorithm=\"auto\"); rows in bench/{os.path.basename(csv_path)}."]
    if a.summary:                # keep the run's machine, load and command lines
        old = open(os.path.join(HERE, "RESULTS.md")).read().split(f"<!-- {name}:start -->")[-1]
        old = old.split(f"<!-- {name}:end -->")[0].splitlines()
        head = [ln for ln in old if ln.startswith(("Machine:", "Command:"))] or head
        if a.run_note:
            head = [f"Machine: {machine()}. {a.run_note}",
                    f"Command: `PYTHONPATH=src python3 bench/bench_swn_choice.py` (rewrites the CSV and this section; "
                    f"`--summary` rewrites the section from the CSV); cases 0–{per - 1} of every not simply connected "
                    f"mesh of bench_swn.py, random breaking, full LP (lp_algorithm=\"auto\"); rows in "
                    f"bench/{os.path.basename(csv_path)}."]
    text = ["## Surface winding numbers, not simply connected: which homologous cycle carries the class (issue 12)",
            ""] + head + ["", NOTES, summarize(rows)]
    write_section(name, "\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
