"""Print the package's shape: modules, lines, the largest functions, package-level import cycles (function-level
imports counted), public names and their option counts, bench scripts, and src/ mentions of bench/RESULTS.

    python scripts/layout_report.py [--root PATH] [--json]

``--root`` points at another checkout (to compare before / after side by side). Options of a public callable are
its parameters other than ``self`` (``*args`` / ``**kwargs`` count one each); a class counts its ``__init__`` and
each public method separately. An options dataclass counts as one option of the callable that takes it.
"""

from __future__ import annotations

import argparse
import ast
import json
import pathlib
import re
import subprocess
import sys


def modules(src: pathlib.Path) -> dict[str, tuple[pathlib.Path, bool]]:
    out = {}
    for p in sorted((src / "gsdf").rglob("*.py")):
        parts = list(p.relative_to(src).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        out[".".join(parts)] = (p, is_pkg)
    return out


def _resolve(name, mods):
    parts = name.split(".")
    while parts:
        cand = ".".join(parts)
        if cand in mods:
            return cand
        parts = parts[:-1]
    return None


def module_graph(src: pathlib.Path) -> dict[str, set[str]]:
    mods = modules(src)
    graph = {m: set() for m in mods}
    for mod, (path, is_pkg) in mods.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        package = mod if is_pkg else mod.rpartition(".")[0]
        for node in ast.walk(tree):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - (node.level - 1)]
                    prefix = ".".join(base + ([node.module] if node.module else []))
                else:
                    prefix = node.module or ""
                targets = [f"{prefix}.{a.name}" for a in node.names] + [prefix]
            for t in targets:
                r = _resolve(t, mods)
                if r is not None and r != mod and not mod.startswith(r + "."):
                    graph[mod].add(r)
    return graph


def package_of(mod: str) -> str:
    """gsdf.heat.grid._poisson -> gsdf.heat; top-level modules (gsdf.field) are their own package."""
    parts = mod.split(".")
    return ".".join(parts[:2])


def package_graph(graph):
    pg: dict[str, set[str]] = {}
    for m, deps in graph.items():
        a = package_of(m)
        pg.setdefault(a, set())
        for d in deps:
            b = package_of(d)
            if b != a and b != "gsdf":
                pg[a].add(b)
    return pg


def strongly_connected(graph):
    """Tarjan's SCCs with more than one member (the cycles)."""
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def function_sizes(src: pathlib.Path):
    sizes = []
    for p in (src / "gsdf").rglob("*.py"):
        tree = ast.parse(p.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                sizes.append((node.end_lineno - node.lineno + 1, f"{p.relative_to(src)}:{node.name}"))
    return sorted(sizes, reverse=True)


def _n_options(fn) -> int:
    import inspect

    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return 0
    return sum(1 for name in sig.parameters if name != "self")


def public_options(src: pathlib.Path):
    """(name, options) for every public callable: functions, class constructors and public methods."""
    sys.path.insert(0, str(src))
    for k in [k for k in sys.modules if k == "gsdf" or k.startswith("gsdf.")]:
        del sys.modules[k]
    import inspect

    import gsdf

    rows = []
    for name in sorted(set(gsdf.__all__)):
        obj = getattr(gsdf, name)
        if inspect.isclass(obj):
            rows.append((name, _n_options(obj.__init__)))
            for meth, fn in inspect.getmembers(obj, predicate=inspect.isfunction):
                if not meth.startswith("_") and fn.__qualname__.startswith(obj.__name__ + "."):
                    rows.append((f"{name}.{meth}", _n_options(fn)))
        elif callable(obj):
            rows.append((name, _n_options(obj)))
    sys.path.pop(0)
    return rows


def cli_options(src: pathlib.Path):
    """(command, options) for every subcommand of the `gsdf` command."""
    code = (
        "import sys, json; sys.path.insert(0, %r)\n"
        "from gsdf.cli.main import cli\n"
        "out = {n: sorted(o for p in c.params for o in p.opts) for n, c in cli.commands.items()}\n"
        "print(json.dumps(out))" % str(src)
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    return json.loads(r.stdout) if r.returncode == 0 else {}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=str(pathlib.Path(__file__).resolve().parents[1]))
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    root = pathlib.Path(args.root)
    src = root / "src"
    mods = modules(src)
    lines = sum(len(p.read_text(encoding="utf-8").splitlines()) for p, _ in mods.values())
    graph = module_graph(src)
    pg = package_graph(graph)
    cycles = strongly_connected(pg)
    module_cycles = strongly_connected(graph)
    sizes = function_sizes(src)
    text = "\n".join(p.read_text(encoding="utf-8") for p, _ in mods.values())
    mentions = len(re.findall(r"bench/", text)) + len(re.findall(r"RESULTS", text))
    bench = root / "bench"
    scripts = sorted(p.name for p in bench.glob("*.py")) if bench.is_dir() else []
    bench_scripts = [s for s in scripts if s not in ("common.py", "load.py", "__init__.py")]
    opts = public_options(src)
    over = [(n, k) for n, k in opts if k > 8]
    private = sum(1 for m in mods if m.rsplit(".", 1)[-1].startswith("_"))
    report = {
        "modules": len(mods),
        "private_modules": private,
        "lines": lines,
        "largest_functions": sizes[:5],
        "package_cycles": cycles,
        "module_cycles": module_cycles,
        "public_names": len(opts),
        "public_callables_over_8_options": over,
        "max_options": max((k for _, k in opts), default=0),
        "bench_scripts": len(bench_scripts),
        "results_md_lines": len((bench / "RESULTS.md").read_text().splitlines()) if (bench / "RESULTS.md").exists() else 0,
        "src_mentions_of_bench_or_RESULTS": mentions,
    }
    if args.json:
        print(json.dumps(report, indent=1))
        return
    print(f"root: {root}")
    print(f"modules: {report['modules']} ({private} private), lines: {lines}")
    print("largest functions: " + "; ".join(f"{n} lines {w}" for n, w in sizes[:5]))
    print(f"package-level import cycles (function-level imports counted): {len(cycles)}")
    for c in cycles:
        print("   ", " <-> ".join(c))
    print(f"module-level import cycles: {len(module_cycles)}")
    print(f"public callables (functions, constructors, public methods): {len(opts)}; most options: "
          f"{report['max_options']}; above 8: {len(over)}")
    for n, k in sorted(over, key=lambda t: -t[1]):
        print(f"    {k:3d}  {n}")
    print(f"bench scripts: {len(bench_scripts)}; RESULTS.md lines: {report['results_md_lines']}")
    print(f"src/ mentions of bench/ or RESULTS: {mentions}")


if __name__ == "__main__":
    main()
