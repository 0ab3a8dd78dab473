"""Run the code blocks of a documentation page in order, as a reader would.

``python docs/run_blocks.py PAGE.md [--cwd DIR]``: every ```` ```python ```` block is executed in one namespace
(so later blocks see earlier names), and every line of a ```` ```bash ```` block that starts with ``gsdf `` is run
as ``python -m gsdf.cli.main ...``, all in document order, in ``DIR`` (default: the current folder). Blocks
fenced as ```` ```text ```` or ```` ```console ```` are shown, not run. The first failure prints the page, the
block number and its first line, and exits with status 1.

tests/docs/test_docs.py runs every guide page this way in a temporary folder; ``--cwd docs/guide/img`` regenerates
the pictures the pages show.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import subprocess
import sys
import traceback

FENCE = re.compile(r"^```(\w+)[^\n]*\n(.*?)^```\s*$", re.M | re.S)


def blocks(text: str):
    """``(language, code, line)`` of each fenced block of a Markdown page, in order."""
    out = []
    for m in FENCE.finditer(text):
        out.append((m.group(1).lower(), m.group(2), text.count("\n", 0, m.start()) + 1))
    return out


def cli_lines(code: str):
    """The ``gsdf ...`` command lines of a shell block (continuations joined, comments dropped)."""
    code = code.replace("\\\n", " ")
    for line in code.splitlines():
        line = line.split(" #")[0].strip()
        if line.startswith("gsdf "):
            yield shlex.split(line)[1:]


def run_page(page: str) -> int:
    text = open(page, encoding="utf-8").read()
    namespace = {"__name__": "__main__"}
    for i, (lang, code, line) in enumerate(blocks(text), 1):
        label = f"{page}: block {i} (line {line}, {code.strip().splitlines()[0][:60]!r})" if code.strip() else ""
        if lang == "python":
            try:
                exec(compile(code, f"{page}:block{i}", "exec"), namespace)
            except BaseException:  # report the page and block, then fail
                traceback.print_exc()
                print(f"FAILED {label}", file=sys.stderr)
                return 1
        elif lang in ("bash", "sh", "shell"):
            for args in cli_lines(code):
                r = subprocess.run([sys.executable, "-m", "gsdf.cli.main", *args], capture_output=True, text=True)
                if r.returncode != 0:
                    sys.stderr.write(r.stdout + r.stderr)
                    print(f"FAILED {label}: gsdf {shlex.join(args)} exited with {r.returncode}", file=sys.stderr)
                    return 1
        print(f"ok {label}", flush=True)
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("page")
    ap.add_argument("--cwd", default=None, help="folder to run in (created if missing)")
    a = ap.parse_args(argv)
    page = os.path.abspath(a.page)
    sys.path[:] = [os.path.abspath(x) if x else x for x in sys.path]  # a relative PYTHONPATH survives the chdir
    if os.environ.get("PYTHONPATH"):  # ... and reaches the gsdf commands run in subprocesses
        os.environ["PYTHONPATH"] = os.pathsep.join(os.path.abspath(x) for x in os.environ["PYTHONPATH"].split(os.pathsep) if x)
    if a.cwd:
        os.makedirs(a.cwd, exist_ok=True)
        os.chdir(a.cwd)

    return run_page(page)


if __name__ == "__main__":
    sys.exit(main())
