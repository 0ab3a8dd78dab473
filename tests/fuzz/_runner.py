"""The runner: prepares fixtures, generates the cases, runs each in its own process, prints the table.

Each case runs in a child forked from this process (which has imported gsdf but never runs a kernel: fork safety
with numba's threads), in its own session (a hang is killed with its whole process group, batch workers
included), with ``nice 10``, an address-space cap (8 GiB) and ``PR_SET_PDEATHSIG`` (it dies with the runner), in
its own temporary folder; the answer comes back as a JSON file. Baselines (one per API target and per command)
are computed first, in parallel, and cached in the run folder.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import resource
import shutil
import signal
import sys
import tempfile
import time
import traceback

from tests.fuzz import _cases

COLS = _cases.OUTCOMES + ["review", "skip"]


def _child_limits(mem: int) -> None:
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    try:
        os.setsid()
    except OSError:
        pass
    try:
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)      # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    try:
        os.nice(10)
    except OSError:
        pass
    resource.setrlimit(resource.RLIMIT_AS, (mem, mem))


class Job:
    """One forked child running ``fn(*args)``; its (outcome, note) comes back through a JSON file."""

    def __init__(self, fn, args, out_path: str, limit: float, mem: int):
        self.out_path, self.limit, self.t0 = out_path, limit, time.time()
        sys.stdout.flush(), sys.stderr.flush()
        pid = os.fork()
        if pid == 0:                                            # the child
            code = 0
            try:
                _child_limits(mem)
                devnull = os.open(os.devnull, os.O_RDWR)
                os.dup2(devnull, 0)
                import warnings

                warnings.simplefilter("ignore")
                try:
                    res = fn(*args)
                except BaseException as e:  # noqa: BLE001 - a failure of the harness itself
                    res = ("skip", f"harness: {type(e).__name__}: {e} | {traceback.format_exc()[-400:]}")
                tmp = out_path + ".tmp"
                with open(tmp, "w") as fh:
                    json.dump(list(res) if isinstance(res, tuple) else res, fh, default=str)
                os.replace(tmp, out_path)
            except BaseException:  # noqa: BLE001
                code = 3
            finally:
                os._exit(code)
        self.pid = pid

    def poll(self):
        """None while running, else the result."""
        try:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
        except ChildProcessError:
            pid, status = self.pid, 0
        if pid == 0:
            if time.time() - self.t0 > self.limit:
                self.kill()
                return ("hang", f"no answer in {self.limit:.0f} s")
            return None
        self._reap_group()
        if os.path.exists(self.out_path):
            with open(self.out_path) as fh:
                res = json.load(fh)
            return tuple(res) if isinstance(res, list) else res
        if os.WIFSIGNALED(status):
            return ("crash", f"killed by signal {os.WTERMSIG(status)} ({signal.Signals(os.WTERMSIG(status)).name})")
        return ("crash", f"exit code {os.WEXITSTATUS(status)} without an answer")

    def _reap_group(self):
        try:
            os.killpg(self.pid, signal.SIGKILL)                  # leftovers of the case (workers ...)
        except (ProcessLookupError, PermissionError):
            pass

    def kill(self):
        self._reap_group()
        try:
            os.kill(self.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        try:
            os.waitpid(self.pid, 0)
        except ChildProcessError:
            pass


MEM_GB = [6.0]          # address-space cap of a case process (--mem-gb)


def run_jobs(specs, jobs: int, on_done=None):
    """Run ``[(key, fn, args, out_path, limit)]`` with ``jobs`` at a time; returns {key: result}."""
    results, running, queue = {}, [], list(specs)
    mem = int(MEM_GB[0] * (1 << 30))
    try:
        while queue or running:
            while queue and len(running) < jobs:
                key, fn, args, out, limit = queue.pop(0)
                running.append((key, Job(fn, args, out, limit, mem), time.time()))
            for item in list(running):
                key, job, ts = item
                r = job.poll()
                if r is not None:
                    running.remove(item)
                    results[key] = (r, time.time() - ts)
                    if on_done:
                        on_done(key, r, time.time() - ts)
            time.sleep(0.02)
    finally:
        for _, job, _ in running:
            job.kill()
    return results


def prepare(root: str) -> list:
    """Fixtures, sample files and the (reader, file) pairs, made in a child; returns the pairs."""
    from tests.fuzz import _execute

    for sub in ("cases", "baselines", "results"):
        os.makedirs(os.path.join(root, sub), exist_ok=True)

    def work():
        _execute.prepare_files(root)
        return ("pass", "")

    res = run_jobs([("prepare", work, (), os.path.join(root, "results", "prepare.json"), 900)], 1)
    if res["prepare"][0][0] != "pass":
        raise RuntimeError(f"preparing the fixtures failed: {res['prepare'][0]}")
    with open(os.path.join(root, "pairs.json")) as fh:
        return [tuple(x) for x in json.load(fh)]


def table(results: list) -> str:
    areas = sorted({r["area"] for r in results})
    cnt = collections.Counter((r["area"], r["outcome"]) for r in results)
    lines = ["| area | " + " | ".join(COLS) + " | cases |", "|---|" + "---|" * (len(COLS) + 1)]
    for a in areas:
        row = [cnt.get((a, o), 0) for o in COLS]
        lines.append(f"| {a} | " + " | ".join(str(x) if x else "." for x in row) + f" | {sum(row)} |")
    tot = [sum(cnt.get((a, o), 0) for a in areas) for o in COLS]
    lines.append("| **all** | " + " | ".join(str(x) for x in tot) + f" | {sum(tot)} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tests.fuzz", description=(
        "gsdf's generated fuzz suite: cases from the public API's signatures, the CLI's options and malformed "
        "files, each in its own process; prints the table area x outcome. Full by default."))
    ap.add_argument("--sample", type=int, default=None, help="a stratified sample of about N cases (default: all)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the sample")
    ap.add_argument("--areas", default="api,cli,files",
                    help="comma-separated areas: api, cli, files or full names such as api:scale, cli:env")
    ap.add_argument("--jobs", type=int, default=max(1, min(2, os.cpu_count() or 1)), help="cases run in parallel")
    ap.add_argument("--timeout", type=float, default=60.0,
                    help="seconds per case (at least 3x the target's baseline time + 10 s)")
    ap.add_argument("--max-seconds", type=float, default=None,
                    help="skip the cases of a target / command whose baseline takes longer (reported as skipped)")
    ap.add_argument("--mem-gb", type=float, default=6.0, help="address-space cap of each case process (GiB)")
    ap.add_argument("--only", default="", help="only cases whose id contains this text")
    ap.add_argument("--ids", default=None, help="only the cases whose ids this file lists, one per line (e.g. the "
                                               "failures of a --json report, to confirm their fixes)")
    ap.add_argument("--list", action="store_true", help="print the case ids and exit (no run)")
    ap.add_argument("--gaps", action="store_true", help="print the coverage gaps and exit (no run)")
    ap.add_argument("--json", default=None, help="write every case with its outcome (and the run's summary) here")
    ap.add_argument("--keep", action="store_true", help="keep the run folder (fixtures, cases, baselines)")
    ap.add_argument("-q", "--quiet", action="store_true", help="no line per failing case while running")
    args = ap.parse_args(argv)
    os.environ.setdefault("GSDF_NUM_THREADS", "1")
    # the size guard's limit below the case timeout: what it lets through must finish in time, so a hang is a
    # guard that underestimated (the default limit, 5 minutes, would let valid requests run past any timeout)
    os.environ.setdefault("GSDF_WORK_LIMIT", f"{max(5.0, args.timeout / 2):g}")
    # commands that start gsdf again (warmup, batch workers) run in the case folders: absolute import paths, the
    # gsdf under test and these tests first
    import gsdf

    here = [os.path.dirname(os.path.dirname(gsdf.__file__)),
            os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))]
    rest = [os.path.abspath(x) for x in os.environ.get("PYTHONPATH", "").split(os.pathsep) if x]
    os.environ["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(here + rest))
    MEM_GB[0] = args.mem_gb
    areas = {a.strip() for a in args.areas.split(",") if a.strip()}
    t_start = time.time()
    if args.gaps:
        for g in _cases.coverage_gaps():
            print(" | ".join(g))
        return 0
    root = tempfile.mkdtemp(prefix="gsdf-fuzz-")

    def stop(signum, frame):                   # SIGTERM / SIGINT (even when started in the background)
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    try:
        return _run(args, areas, root, t_start)
    finally:
        if args.keep:
            print("kept", root)
        else:
            shutil.rmtree(root, ignore_errors=True)


def _run(args, areas, root, t_start) -> int:
    from tests.fuzz import _execute

    pairs = prepare(root)
    cases = [c for c in _cases.all_cases(areas, pairs) if args.only in c["id"]]
    if args.ids:
        with open(args.ids) as fh:
            wanted = {line.strip() for line in fh if line.strip()}
        cases = [c for c in cases if c["id"] in wanted]
    n_all = len(cases)
    if args.sample:
        cases = _cases.sample(cases, args.sample, args.seed)
    if args.list:
        print("\n".join(c["id"] for c in cases))
        print(f"{len(cases)} of {n_all} generated cases", file=sys.stderr)
        return 0
    tmap = _cases.target_map()
    t_prep = time.time()
    # baselines: one child per API target and per command, in parallel
    res_dir = os.path.join(root, "results")
    api_targets = sorted({c["target"] for c in cases if c["area"].startswith("api")})
    need = set(api_targets) | {t.split(".")[0] for t in api_targets if _cases.is_instance_method(t)}

    def api_base(t):
        fx = _execute.Fixtures(root)
        d = tempfile.mkdtemp(prefix="base-", dir=os.path.join(root, "cases"))
        os.chdir(d)
        b = _execute.baseline_of(t, tmap, fx, d)
        return ("pass", json.dumps(b)[:200])

    # with --max-seconds a baseline search gets that long (its target's cases are then skipped as slow)
    base_limit = 700.0 if args.max_seconds is None else max(10.0, args.max_seconds)

    def mark_slow(prefix):
        def done(key, r, dt):
            if r[0] == "hang":
                with open(os.path.join(root, "baselines", f"{prefix}{key}.json"), "w") as fh:
                    json.dump({"error": f"slow baseline: no answer in {base_limit:.0f} s", "seconds": dt}, fh)
        return done

    commands = sorted({c["command"] for c in cases if c["area"].startswith("cli")})
    ctors = sorted(t for t in need if "." not in t)
    methods = sorted(t for t in need if "." in t)
    for group in (ctors, methods):                        # constructors first: methods reuse their baselines
        run_jobs([(t, api_base, (t,), os.path.join(res_dir, f"base-{t}.json"), base_limit) for t in group],
                 args.jobs, mark_slow(""))

    def cli_base(name):
        b = _execute.find_cli_baseline(name, root, 300.0)
        return ("pass", json.dumps(b)[:200])

    run_jobs([(n, cli_base, (n,), os.path.join(res_dir, f"clibase-{n}.json"), base_limit) for n in commands],
             args.jobs, mark_slow("cli-"))
    t_base = time.time()

    def limit_of(c):
        if c.get("target"):
            bp = os.path.join(root, "baselines", c["target"] + ".json")
        elif c.get("command"):
            bp = os.path.join(root, "baselines", f"cli-{c['command']}.json")
        else:
            return args.timeout
        try:
            with open(bp) as fh:
                s = (json.load(fh) or {}).get("seconds", 0) or 0
        except (OSError, ValueError, AttributeError):
            s = 0
        extra = 2 if c["mutation"] in ("scale_tiny", "scale_huge") or c["expect"] == "accept" else 1
        return max(args.timeout, extra * 3 * s + 10)

    def base_seconds(c):
        name = c["target"] + ".json" if c.get("target") else f"cli-{c.get('command')}.json"
        try:
            with open(os.path.join(root, "baselines", name)) as fh:
                return (json.load(fh) or {}).get("seconds", 0) or 0
        except (OSError, ValueError, AttributeError):
            return 0

    def slow(c):
        return args.max_seconds is not None and base_seconds(c) > args.max_seconds

    def fn_of(c):
        if slow(c):
            return (lambda: ("skip", f"slow baseline ({base_seconds(c):.0f} s > --max-seconds "
                                     f"{args.max_seconds:g})")), ()
        if c["area"].startswith("cli"):
            return _execute.run_cli_case, (c, root, tmap, limit_of(c))
        if c["area"].startswith("files"):
            return _execute.run_file_case, (c, root, tmap)
        return _execute.run_api_case, (c, root, tmap)

    results = []
    by_id = {c["id"]: c for c in cases}

    def done(cid, r, dt):
        c = dict(by_id[cid], outcome=r[0], note=r[1], seconds=round(dt, 2))
        results.append(c)
        if not args.quiet and r[0] in _cases.FAILURES and r[0] != "hang":     # hangs: after their retry
            print(f"{r[0]:13s} {cid}  -- {str(r[1])[:200]}", flush=True)

    specs = []
    for i, c in enumerate(cases):
        fn, fargs = fn_of(c)
        # the CLI's own timeout (env cases run a subprocess) sits below the runner's
        specs.append((c["id"], fn, fargs, os.path.join(res_dir, f"case-{i}.json"),
                      limit_of(c) + (15 if c.get("where") == "env" else 0)))
    run_jobs(specs, args.jobs, done)
    # a hang is run once more: a case whose code path compiles numba kernels the baselines did not (a cold cache,
    # e.g. a fresh checkout) can spend its whole timeout compiling; the second run finds them cached
    hung = {r["id"]: r for r in results if r["outcome"] == "hang"}
    if hung:
        retry = []

        def done_retry(cid, r, dt):
            first = hung[cid]
            first.update(outcome=r[0], seconds=round(dt, 2),
                         note=r[1] if r[0] == "hang" else f"{r[1]} (retried: the first run gave {first['note']})")
            if not args.quiet and r[0] in _cases.FAILURES:
                print(f"{r[0]:13s} {cid}  -- {str(r[1])[:200]}", flush=True)

        for cid, fn, fargs, out, limit in specs:
            if cid in hung:
                retry.append((cid, fn, fargs, out + ".retry", limit))
        run_jobs(retry, args.jobs, done_retry)
    dt = time.time() - t_start
    results.sort(key=lambda r: r["id"])
    print()
    print(table(results))
    cnt = collections.Counter(r["outcome"] for r in results)
    bad = sum(cnt[o] for o in _cases.FAILURES)
    print(f"\n{len(results)} cases run ({n_all} generated"
          + (f"; sample {args.sample} seed {args.seed}" if args.sample else "; full") + f") in {dt:.0f} s "
          f"(preparation {t_prep - t_start:.0f} s, baselines {t_base - t_prep:.0f} s, cases {time.time() - t_base:.0f}"
          f" s, {args.jobs} jobs): {bad} failed, {cnt['review']} to review, {cnt['skip']} skipped")
    gaps = _cases.coverage_gaps()
    skips = collections.Counter(r["note"][:110] for r in results if r["outcome"] == "skip"
                                and "coverage gap" in r["note"])
    if gaps or skips:
        print(f"coverage gaps: {len(gaps)} parameters without a known valid value "
              "(python -m tests.fuzz --gaps lists them)")
        for k, v in skips.most_common(12):
            print(f"  {v:4d} x {k}")
    try:
        with open(os.path.join(root, "written.json")) as fh:
            unread = sorted(set(json.load(fh)) - {f for _, f in pairs})
    except OSError:
        unread = []
    if unread and "files" in {a.split(":")[0] for a in areas}:
        print(f"written by a public writer but read by no public reader (no file cases): {', '.join(unread)}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"generated": n_all, "seconds": dt, "sample": args.sample, "seed": args.seed,
                       "areas": sorted(areas), "gaps": gaps, "unread_files": unread, "cases": results}, fh, indent=1, default=str)
    return 1 if bad else 0
