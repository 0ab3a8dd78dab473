"""Shared helpers of the benchmarks: data location, machine description, timing, RESULTS.md sections.

Every table of RESULTS.md is one section ``<!-- name:start -->`` … ``<!-- name:end -->`` written by one part of
one script (:func:`write_section`); its text starts with :func:`heading`: the title, the machine, the load
average at start and end, and the command that prints it.
"""

from __future__ import annotations

import os
import platform
import re
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
#: Where the sections go: bench/RESULTS.md, or ``$GSDF_BENCH_RESULTS`` (a trial run that must not touch it).
RESULTS = os.environ.get("GSDF_BENCH_RESULTS") or os.path.join(HERE, "RESULTS.md")


def data_dir() -> str:
    """The CGAL data folder: ``$GSDF_CGAL_DATA``, else ~/.cache/gsdf-data/cgal/data or /work/cgal/data when they
    hold meshes/, else fetched by ../shared/tools/get-cgal-data."""
    env = os.environ.get("GSDF_CGAL_DATA")
    if env:
        return env
    for default in (os.path.expanduser("~/.cache/gsdf-data/cgal/data"), "/work/cgal/data"):
        if os.path.isdir(os.path.join(default, "meshes")):
            return default
    tool = os.path.join(HERE, "..", "..", "shared", "tools", "get-cgal-data")
    return subprocess.run(["bash", tool], check=True, capture_output=True, text=True).stdout.strip()


def machine() -> str:
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            m = re.search(r"model name\s*:\s*(.*)", f.read())
            if m:
                cpu = m.group(1)
    except OSError:
        pass
    import numba

    return (f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, numpy {np.__version__}, "
            f"numba {numba.__version__}, {platform.system()} {platform.release()}")


def command(script: str, argv=None, python: str = "python3", env: str = "") -> str:
    """The shell command that reruns ``script`` (a file name in bench/) with ``argv`` (default: this process's)."""
    args = sys.argv[1:] if argv is None else list(argv)
    return " ".join(x for x in [env, "PYTHONPATH=src", python, f"bench/{script}", *args] if x)


def heading(title: str, cmd: str, start_load: str | None = None) -> str:
    """A section's first lines: ``## title``, the machine, the load average (at start and now) and the command."""
    from load import uptime

    load = f"{start_load} at start, {uptime()} at end" if start_load else uptime()
    return f"## {title}\n\nMachine: {machine()}; {load} (shared machine). Command: `{cmd}`.\n\n"


def output_dir(path: str | None) -> str | None:
    """``path`` created if given: where a script writes its pictures and per-case files (never bench/)."""
    if path:
        os.makedirs(path, exist_ok=True)
    return path


def median_time(fn, repeat: int = 3):
    """Median wall time of ``fn()`` over ``repeat`` runs, and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), out


def batch_mean(fn, min_s: float = 0.1, min_calls: int = 1) -> float:
    """Mean wall time of ``fn()`` called back to back until at least ``min_s`` seconds and ``min_calls`` calls
    have passed (a millisecond call timed alone is either not preempted or loses a whole time slice)."""
    k, t0 = 0, time.perf_counter()
    while True:
        fn()
        k += 1
        t = time.perf_counter() - t0
        if t >= min_s and k >= min_calls:
            return t / k


def alternating_rounds(fns: dict, rounds: int = 7, nbusy: int = 2) -> dict:
    """The loaded protocol: ``rounds`` rounds alternating idle / loaded (``nbusy`` busy processes,
    bench/load.py BusyLoad, started and stopped per round; the order flips every round), each round timing
    every ``fns[name]()`` as :func:`batch_mean` (≥ 0.1 s back to back). Returns ``{("idle" | "loaded", name):
    [mean seconds per round]}``; ratios are best taken per round (same background load) and then the median."""
    from load import BusyLoad

    out = {(m, k): [] for m in ("idle", "loaded") for k in fns}
    for r in range(rounds):
        for mode in (("idle", "loaded") if r % 2 == 0 else ("loaded", "idle")):
            with BusyLoad(nbusy if mode == "loaded" else 0):
                for k, f in fns.items():
                    out[mode, k].append(batch_mean(f))
    return out


def write_section(name: str, text: str) -> None:
    """Replace (or append) the section between ``<!-- name:start -->`` and ``<!-- name:end -->``, then
    rebuild the index at the top of RESULTS.md (see :func:`results_index`)."""
    start, end = f"<!-- {name}:start -->", f"<!-- {name}:end -->"
    body = open(RESULTS).read() if os.path.exists(RESULTS) else "# gsdf benchmark results\n\n"
    block = f"{start}\n{text.rstrip()}\n{end}"
    if start in body and end in body:
        body = body[: body.index(start)] + block + body[body.index(end) + len(end):]
    else:
        body = body.rstrip() + "\n\n" + block + "\n"
    with open(RESULTS, "w") as f:
        f.write(with_index(body))


_SECTION = re.compile(r"<!-- ([A-Za-z0-9_-]+):start -->\n(.*?)<!-- \1:end -->", re.S)


def results_index(body: str) -> str:
    """A table of every section of RESULTS.md: its name, its heading and the command that rewrites it
    (the first quoted command of the section that runs a script in bench/)."""
    rows = []
    for name, text in _SECTION.findall(body):
        if name == "index":
            continue
        heading = next((ln.lstrip("#").strip() for ln in text.splitlines() if ln.startswith("#")), "")
        cmd = re.search(r"`[^`\n]*bench/[^`\n]+\.py[^`\n]*`", text)
        rows.append((f"`{name}`", heading.replace("|", "/"), cmd.group(0) if cmd else ""))
    return ("## Index\n\nCurrent figures only: every section below is rewritten by the command beside it; "
            "`bench/run_all.py` runs them all.\n\n" + table(["section", "heading", "command"], rows))


def with_index(body: str) -> str:
    """``body`` with its index block (placed after the title line) rebuilt from its sections."""
    start, end = "<!-- index:start -->", "<!-- index:end -->"
    if start in body and end in body:
        body = body[: body.index(start)].rstrip() + "\n\n" + body[body.index(end) + len(end):].lstrip()
    title, _, rest = body.partition("\n")
    return f"{title}\n\n{start}\n{results_index(body)}\n{end}\n\n{rest.lstrip()}"


def table(header, rows) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)
