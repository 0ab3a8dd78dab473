"""Surface winding numbers, not simply connected (issue 12): which homologous cycle carries the class of γ.

Replays the not-simply-connected cases of bench/bench_swn.py (same meshes, seeds and case ids, random breaking)
and scores the full LP with ``cycle_choice="lp"`` (the LP's optimum: least ε-weighted length, thesis §6.1.2)
against ``cycle_choice="complete"`` (the LP again with the first cycle's input edges forbidden, the cycle with
the larger share of its jump mass on the input kept; see SurfaceWindingNumbers.solve). When "complete" keeps the
first cycle in every pass its result is the "lp" result (same LPs), so "lp" is only solved again on the cases
where the second cycle was chosen at least once.

Every case is also solved with the reduced LP (method="reduced") and by naive rounding of u (method="none"),
library defaults otherwise (columns "err reduced", "err none"; absent from CSVs written before).

``--loops disjoint`` draws the nonbounding loops of the closed surfaces so that they share no edge with the region
boundary nor with each other (bench_swn.py's module docstring, MeshCases.disjoint_loops; same regions, breaking and
loop counts as the default generator, except where a region had to be drawn again). Its rows go to
bench/swn_choice_cases_disjoint[_quick].csv and its section "swn-ns-disjoint" compares them with the default
generator's CSV (bench/swn_choice_cases[_quick].csv) subgroup by subgroup.

Usage::

    PYTHONPATH=src python3 bench/bench_swn_choice.py --quick          # 4 cases per mesh
    PYTHONPATH=src python3 bench/bench_swn_choice.py                  # 42 per mesh: all 504 cases
    PYTHONPATH=src python3 bench/bench_swn_choice.py --loops disjoint # the same 504 with edge-disjoint loops
    PYTHONPATH=src python3 bench/bench_swn_choice.py --loops disjoint --summary   # section from the two CSVs

Per-case rows: bench/swn_choice_cases[_disjoint][_quick].csv; sections "swn-ns-5" ("swn-ns-5-quick") and
"swn-ns-disjoint" ("swn-ns-disjoint-quick") of bench/RESULTS.md.
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

from gsdf.swn._solver import SurfaceWindingNumbers  # noqa: E402

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

FIELDS = ["case", "mesh", "group", "switched", "err lp", "err complete", "t lp", "t complete", "err complete global",
          "err reduced", "err none", "t reduced", "loops", "resamples", "regions", "loop edges", "shared edges",
          "shared vertices", "doubled edges", "cancelled edges"]


def overlap(mc, g, gb, parts):
    """How the generator's parts meet: unbroken loops' lengths (edges, summed), edges shared by two unbroken parts
    (region boundary g, loops), vertices shared by two parts (summed over pairs), input edges with |gb| > 1
    (parts running the same way) and edges of a broken part where gb cancels to 0 (parts running opposite)."""
    E = mc.dec.edges
    full = [g] + parts["loops_full"]
    cnt = np.sum([f != 0 for f in full], axis=0)
    vs = [set(E[f != 0].ravel().tolist()) for f in full]
    anyp = np.any([parts["region"] != 0] + [x != 0 for x in parts["loops"]], axis=0)
    return {"loop edges": int(sum(np.sum(f != 0) for f in parts["loops_full"])),
            "shared edges": int(np.sum(cnt > 1)),
            "shared vertices": sum(len(vs[i] & vs[j]) for i in range(len(vs)) for j in range(i + 1, len(vs))),
            "doubled edges": int(np.sum(np.abs(gb) > 1)), "cancelled edges": int(np.sum(anyp & (gb == 0)))}


def run(per_mesh, csv_path, time_limit, loops="tree-cotree"):
    rows = []
    with open(csv_path, "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=FIELDS)
        wr.writeheader()
        for mi, (name, load) in enumerate(B.mesh_list()):
            if mi < B.N_SIMPLY:
                continue
            V, F = load()
            mc = B.MeshCases(name, V, F, seed=1000 + mi, loops=loops)
            sw = mc.swn
            assert isinstance(sw, SurfaceWindingNumbers) and sw.betti_1 > 0
            switched = []
            real = sw._complete_cycle

            def spy(gamma, g, eps, tl, alg, extra, Jv, obj, lp_s):
                out = real(gamma, g, eps, tl, alg, extra, Jv, obj, lp_s)
                switched.append(out[0] is not Jv)
                return out
            sw._complete_cycle = spy
            for c, cid, kind, truth, g, gb, frac, nb, parts in B.generate_cases_parts(mc, per_mesh, "random"):
                if not np.any(gb):
                    continue
                group = "with boundary" if not mc.closed else \
                    ("closed, with broken nonbounding loops" if nb else "closed, no nonbounding loops")
                switched.clear()
                r = sw.solve(gb, method="lp", time_limit=time_limit)
                chose = any(switched)
                row = {"case": cid, "mesh": name, "group": group, "switched": int(chose), "loops": nb,
                       "resamples": parts["resamples"], "regions": parts["regions"], **overlap(mc, g, gb, parts),
                       "err complete": B.mislabeled(r.face_labels, truth, mc.area),
                       # labels="global" (one rounding level, before) from the same solve
                       "err complete global": B.mislabeled(
                           np.round(r.corner_values.mean(axis=1) + r.label_shift).astype(np.int64), truth, mc.area),
                       "t complete": r.timings["total"]}
                if chose:
                    r0 = sw.solve(gb, method="lp", time_limit=time_limit, cycle_choice="lp")
                    row["err lp"], row["t lp"] = B.mislabeled(r0.face_labels, truth, mc.area), r0.timings["total"]
                else:
                    row["err lp"], row["t lp"] = row["err complete"], float("nan")
                try:
                    rr = sw.solve(gb, method="reduced", time_limit=time_limit)
                    row["err reduced"], row["t reduced"] = B.mislabeled(rr.face_labels, truth, mc.area), \
                        rr.timings["total"]
                except ValueError as exc:
                    print(f"  {cid}: reduced failed: {exc}", flush=True)
                    row["err reduced"], row["t reduced"] = float("nan"), float("nan")
                row["err none"] = B.mislabeled(sw.solve(gb, method="none").face_labels, truth, mc.area)
                wr.writerow(row)
                fh.flush()
                rows.append(row)
                if chose:
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


GROUPS = ["all not simply connected", "closed, no nonbounding loops", "closed, with broken nonbounding loops",
          "with boundary"]


def _err(r, k):
    v = r.get(k)
    return float(v) if v not in (None, "", "nan") else float("nan")


def _cell(e):
    e = np.asarray(e, float)
    if e.size == 0 or not np.isfinite(e).all():
        return "–"
    return f"{100 * np.mean(e < 0.005):.1f} % ({100 * e.mean():.2f} %)"


def _old_overlap(old):
    """Case id -> input edges where the default generator's parts double or cancel, from the old CSV's columns or
    else from bench/swn_runs_cases.csv (bench_swn_runs.py, same cases)."""
    out = {}
    if old and old[0].get("doubled edges") not in (None, ""):
        return {r["case"]: int(r["doubled edges"]) + int(r["cancelled edges"]) for r in old}
    path = os.path.join(HERE, "swn_runs_cases.csv")
    if os.path.exists(path):
        with open(path) as fh:
            for r in csv.DictReader(fh):
                out[r["case"]] = int(float(r["doubled edges"])) + int(float(r["cancelled edges"]))
    return out


def summarize_generators(old, new):
    """Default generator (old CSV) against edge-disjoint loops (new CSV), per subgroup and method."""
    O = {r["case"]: r for r in old}
    methods = [("full LP (library default)", "err complete"), ("reduced LP", "err reduced"),
               ("naive rounding of u", "err none")]
    out = ["Share of cases under 0.5 % mislabeled area (mean mislabeled area); fixed / broken = cases crossing the "
           "0.5 % line from the default generator to the disjoint one, on the same case ids (with broken loops: "
           "only the cases whose region was not drawn again):", "",
           "| subgroup | cases | method | default generator (loops may share edges) | disjoint loops | "
           "fixed / broken |", "|---|---|---|---|---|---|"]
    for gname in GROUPS:
        R = [r for r in new if gname.startswith("all") or r["group"] == gname]
        if not R:
            continue
        for mname, key in methods:
            a = [_err(O[r["case"]], key) if r["case"] in O else float("nan") for r in R]
            b = [_err(r, key) for r in R]
            P = [(x, y) for x, y, r in zip(a, b, R) if np.isfinite(x) and np.isfinite(y) and
                 int(r.get("regions") or 0) == 0]
            fb = (f"{sum(x >= 0.005 > y for x, y in P)} / {sum(y >= 0.005 > x for x, y in P)}" if P else "–")
            out.append(f"| {gname} | {len(R)} | {mname} | {_cell(a)} | {_cell(b)} | {fb} |")
    # the broken-loop cases by overlap of the default generator's parts
    L = [r for r in new if r["group"] == "closed, with broken nonbounding loops"]
    ov = _old_overlap(old)
    if L and ov:
        sh = [r for r in L if ov.get(r["case"], 0) > 0]
        ns = [r for r in L if r["case"] in ov and ov[r["case"]] == 0]
        out += ["", "Closed, with broken nonbounding loops, split by whether the *default* generator's parts share "
                "input edges there (|g| = 2 or cancelled to 0; as in section swn-ns-runs). Full LP (library "
                "default):", "",
                "| cases (by the default generator's overlap) | n | default generator | disjoint loops |",
                "|---|---|---|---|"]
        for nm, S in (("default's parts share edges", sh), ("default's parts share no edge", ns)):
            out.append(f"| {nm} | {len(S)} | {_cell([_err(O[r['case']], 'err complete') for r in S])} | "
                       f"{_cell([_err(r, 'err complete') for r in S])} |")
    if L:
        res = [r for r in L if int(r["resamples"]) > 0]
        reg = [r for r in L if int(r["regions"]) > 0]
        se = sum(int(r["shared edges"]) > 0 for r in L)
        dc = sum(int(r["doubled edges"]) + int(r["cancelled edges"]) > 0 for r in L)
        sv = np.array([int(r["shared vertices"]) for r in L])
        le = np.array([int(r["loop edges"]) / max(int(r["loops"]), 1) for r in L])
        line = (f"Disjoint loops, {len(L)} broken-loop cases: {len(res)} needed a resample of the loop set "
                f"({', '.join(r['case'] for r in res) or 'none'}; {sum(int(r['resamples']) for r in res)} sets "
                f"drawn again in all), {len(reg)} of them a new region ({', '.join(r['case'] for r in reg) or 'none'}"
                f"; these are different cases from the default's); unbroken parts sharing an edge: {se} cases "
                f"(input edges doubled or cancelled: {dc}); vertices shared by two parts: median {np.median(sv):.0f}"
                f" (max {sv.max()}); loop length median {np.median(le):.0f} edges")
        if old and old[0].get("shared vertices") not in (None, ""):
            OL = [O[r["case"]] for r in L if r["case"] in O]
            osv = np.array([int(x["shared vertices"]) for x in OL])
            ole = np.array([int(x["loop edges"]) / max(int(x["loops"]), 1) for x in OL])
            line += (f"; default generator: {sum(int(x['shared edges']) > 0 for x in OL)} cases with shared edges "
                     f"(doubled or cancelled in the input: "
                     f"{sum(int(x['doubled edges']) + int(x['cancelled edges']) > 0 for x in OL)}), shared vertices "
                     f"median {np.median(osv):.0f} (max {osv.max()}), loop length median {np.median(ole):.0f} edges")
        out += ["", line + "."]
    same = [r for r in new if r["group"] != "closed, with broken nonbounding loops" and r["case"] in O]
    if same:
        eq = sum(_err(r, "err complete") == _err(O[r["case"]], "err complete") for r in same)
        out += ["", f"Cases without loops are the same cases in both runs (the loops are drawn after them from a "
                f"per-case stream): full-LP error identical on {eq} of {len(same)}."]
    return "\n".join(out)


DISJOINT_NOTES = """\
Why (section swn-ns-runs): with the default generator, in 94 of the 157 broken-loop cases of the 504-case run a
tree–cotree loop shares edges with the region boundary or the other loop; running the same way the input carries
2 there, running opposite ways the chain cancels to 0 and that stretch of both curves is missing from the input,
so no method can tell which curve went where. The thesis' figures (Fig. 6.7) show loops crossing the regions.
Generator ``loops="disjoint"`` (bench/bench_swn.py docstring, MeshCases.disjoint_loops): each loop a tree–cotree
loop of a shortest-path tree over the edges that are not on the unbroken region boundary nor on a loop drawn
before (edges touching those curves' vertices weighted ×(1 + 2 · touches), so loops cross rather than hug), of a
nonzero homology class independent of the other loop's; the loop set is drawn again from new roots when a loop
has no candidate, and the region is drawn again (same kind, per-case stream) after 6 failed sets. The regions,
their breaking, the loop count and each loop's deletion fraction are the default generator's draws; only the
loops differ (and, where a region was drawn again, the case)."""


DISJOINT_READING = """\
Reading (504-case run; scratch diagnoses of the generated cases, not kept as scripts):
- Edge-disjoint loops do not make the broken-loop cases easier for the full LP: 54.1 → 45.9 % under 0.5 %, mean
  4.14 → 4.62 % (21 cases fixed, 33 broken). The drop is as large where the default's parts share *no* edge
  (63 cases: 66.7 → 57.1 %) as where they share edges (94 cases: 45.7 → 38.3 %), although on the former only
  the loops changed. So the 68.3 / 45.7 % split of swn-ns-runs is not caused by the shared edges alone; the
  cases differ in other ways too. The reduced LP gains (35.7 → 38.2 %, mean 12.95 → 10.98 %); naive rounding
  stays at 0 %.
- Where the 33 newly failing cases lose area (mislabeled faces within 3 mean edge lengths of a crossing vertex,
  of a loop, of the region boundary): 18 are small (0.58–3.41 %), 70–96 % of it in thin strips along the loops
  and at their crossings with the region; the LP's nonbounding part holds only 36–86 % of the loops' input
  edges, so pieces of the loops stay in the bounding part. 15 are large (4.6–47 %), mostly away from all curves:
  the LP's cycle takes region sides (up to 27 % of the region's input edges) and little of the loop — on 7
  (knot1:4/8/24/40, author-torus:10/16/38) 0–14 % of the loop's edges: the cycle-choice failure of swn-ns-5.
- Loops homologous to a combination of the region's boundary components (the ties of thesis Fig. 6.10): 73
  cases with the default generator (46.6 % < 0.5 %), 58 with disjoint loops (34.5 %); the other cases 60.7 % →
  52.5 %. Disjoint loops are somewhat longer (median 76 vs 70 edges: trees that avoid the boundary and are
  weighted near it) and touch the boundary at fewer vertices (median 2 vs 6 shared); their share of vertices
  within 1.5 edge lengths of the boundary (not on it) is about the same (12.7 % vs 10.4 %)."""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="4 cases per mesh")
    ap.add_argument("--per-mesh", type=int, default=None)
    ap.add_argument("--time-limit", type=float, default=120.0)
    ap.add_argument("--loops", choices=list(B.LOOP_MODES), default="tree-cotree",
                    help="how the nonbounding loops are drawn (bench_swn.py MeshCases): 'disjoint' = no edge shared "
                         "with the region boundary or the other loop; section swn-ns-disjoint")
    ap.add_argument("--summary", action="store_true", help="rewrite the section from the per-case CSV of a run")
    ap.add_argument("--run-note", default=None, help="with --summary: the run's machine/load/time line, when the "
                    "CSV was made by another process calling run() (replaces the old section's run lines)")
    a = ap.parse_args()
    per = a.per_mesh or (4 if a.quick else 42)
    dis = a.loops == "disjoint"
    csv_path = os.path.join(HERE, f"swn_choice_cases{'_disjoint' if dis else ''}{'_quick' if a.quick else ''}.csv")
    old_csv = os.path.join(HERE, f"swn_choice_cases{'_quick' if a.quick else ''}.csv")
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    t0 = time.perf_counter()
    if a.summary:
        with open(csv_path) as fh:
            rows = list(csv.DictReader(fh))
    else:
        rows = run(per, csv_path, a.time_limit, loops=a.loops)
    load2 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    flags = "".join(" " + t for t in sys.argv[1:] if t != "--summary")
    name = ("swn-ns-disjoint" if dis else "swn-ns-5") + ("-quick" if a.quick else "")
    head = [f"Machine: {machine()}. Load at start: `{load}`; at end: `{load2}` (shared with other helpers; "
            "times are indicative, errors are not affected).",
            f"Command: `PYTHONPATH=src python3 bench/bench_swn_choice.py{flags}` ({time.perf_counter() - t0:.0f} s); "
            f"cases 0–{per - 1} of every not simply connected mesh of bench_swn.py, random breaking, full LP "
            f"(lp_algorithm=\"auto\"), reduced LP, naive rounding; loops: {a.loops}; rows in "
            f"bench/{os.path.basename(csv_path)}."]
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
    if dis:
        with open(old_csv) as fh:
            old_rows = list(csv.DictReader(fh))
        text = ["## Surface winding numbers, not simply connected: nonbounding loops that share no edge with the "
                "regions (issue 12)", ""] + head + \
            [f"Default generator: bench/{os.path.basename(old_csv)} (bench_swn_choice.py"
             f"{' --quick' if a.quick else ''}).", "", DISJOINT_NOTES, "", summarize_generators(old_rows, rows), ""] + \
            ([] if a.quick else [DISJOINT_READING, ""]) + [
             "cycle_choice and labels on the disjoint-loop cases (as in section swn-ns-5):", "", summarize(rows)]
    else:
        text = ["## Surface winding numbers, not simply connected: which homologous cycle carries the class "
                "(issue 12)", ""] + head + ["", NOTES, summarize(rows)]
    write_section(name, "\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
