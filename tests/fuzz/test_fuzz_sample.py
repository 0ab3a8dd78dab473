"""CI: a fixed sample of the generated fuzz cases (``python -m tests.fuzz --sample N --seed S``), in a subprocess.

The test fails when a case fails (crash, hang, NaN, wrong, leak, accepted bad, refused valid, file damage) that is
not in :data:`KNOWN_OPEN`, and also when a case of :data:`KNOWN_OPEN` passes or is no longer in the sample — so the
list only shrinks, to empty, as the defects are fixed. A failure prints each new case's id, outcome and note
(the note holds the call or the command line); ``python -m tests.fuzz --only '<id>'`` reruns one case.
The whole generated suite: ``python -m tests.fuzz`` (hours on 2 cores).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import pytest

SAMPLE, SEED, TIMEOUT, JOBS, MAX_SECONDS = 120, 1, 20, 2, 30

#: cases of the sample that fail because of a known open defect: id -> the defect (repro in the note).
#: Remove an entry when its fix lands (the test fails while a listed case passes).
KNOWN_OPEN: dict[str, str] = {}

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _run_sample(tmp_path):
    out = tmp_path / "fuzz.json"
    env = dict(os.environ)
    import gsdf

    src = os.path.dirname(os.path.dirname(gsdf.__file__))
    env["PYTHONPATH"] = os.pathsep.join([REPO, src] + [x for x in env.get("PYTHONPATH", "").split(os.pathsep) if x])
    t0 = time.time()
    p = subprocess.run([sys.executable, "-m", "tests.fuzz", "--sample", str(SAMPLE), "--seed", str(SEED),
                        "--timeout", str(TIMEOUT), "--jobs", str(JOBS), "--max-seconds", str(MAX_SECONDS),
                        "--json", str(out), "-q"],
                       cwd=REPO, env=env, capture_output=True, text=True, timeout=1800)
    dt = time.time() - t0
    if not out.exists():
        pytest.fail(f"the fuzz runner wrote no report (exit {p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    with open(out) as fh:
        return json.load(fh), p.stdout, dt


def test_fuzz_sample(tmp_path, capsys):
    from tests.fuzz._cases import FAILURES

    report, stdout, dt = _run_sample(tmp_path)
    cases = report["cases"]
    with capsys.disabled():                      # the table and the timing, also when the test passes
        print("\n" + (stdout[stdout.find("| area"):] if "| area" in stdout else stdout[-3000:]))
        print(f"fuzz sample: {len(cases)} of {report['generated']} generated cases in {dt:.0f} s "
              f"(sample {SAMPLE}, seed {SEED}, {JOBS} jobs)")
    failed = {c["id"]: c for c in cases if c["outcome"] in FAILURES}
    ids = {c["id"] for c in cases}
    new = {i: c for i, c in failed.items() if i not in KNOWN_OPEN}
    fixed = [i for i in KNOWN_OPEN if i in ids and i not in failed]
    stale = [i for i in KNOWN_OPEN if i not in ids]
    msg = []
    if new:
        msg.append(f"{len(new)} case(s) fail outside KNOWN_OPEN:")
        msg += [f"  {c['outcome']:13s} {i}\n      {c['note']}" for i, c in sorted(new.items())]
    if fixed:
        msg.append(f"{len(fixed)} KNOWN_OPEN case(s) pass now — remove them from KNOWN_OPEN:")
        msg += [f"  {i}  ({KNOWN_OPEN[i]})" for i in fixed]
    if stale:
        msg.append(f"{len(stale)} KNOWN_OPEN case(s) are not in the sample any more — remove them:")
        msg += [f"  {i}" for i in stale]
    assert not msg, "\n".join(msg)
