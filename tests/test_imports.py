"""No import cycles anywhere in src/gsdf: every module's imports (top-level, function-level, relative) parsed
with ast, resolved to modules of the package, and the graph checked for cycles."""

import ast
import importlib
import pathlib

import pytest

SRC = pathlib.Path(__file__).resolve().parents[1] / "src"


def _modules():
    out = {}
    for p in sorted((SRC / "gsdf").rglob("*.py")):
        rel = p.relative_to(SRC).with_suffix("")
        parts = list(rel.parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        out[".".join(parts)] = (p, is_pkg)
    return out


def _resolve(name, modules):
    """The longest prefix of dotted ``name`` that is a module of the package (None outside gsdf)."""
    parts = name.split(".")
    while parts:
        cand = ".".join(parts)
        if cand in modules:
            return cand
        parts = parts[:-1]
    return None


def import_graph():
    modules = _modules()
    graph = {m: set() for m in modules}
    for mod, (path, is_pkg) in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
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
                # "from pkg import name": name may be a submodule
                targets = [f"{prefix}.{a.name}" for a in node.names] + [prefix]
            for t in targets:
                r = _resolve(t, modules)
                if r is not None and r != mod and not mod.startswith(r + "."):
                    # a package's own submodules importing the package (or a parent) are how Python loads
                    # them; only edges to other modules count as dependencies
                    graph[mod].add(r)
    return graph


def find_cycle(graph):
    """A cycle as a list of modules, or None (iterative DFS with colours)."""
    WHITE, GREY, BLACK = 0, 1, 2
    colour = {m: WHITE for m in graph}
    for root in sorted(graph):
        if colour[root] != WHITE:
            continue
        stack = [(root, iter(sorted(graph[root])))]
        path = [root]
        colour[root] = GREY
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                colour[node] = BLACK
                stack.pop()
                path.pop()
                continue
            if colour[nxt] == GREY:
                return path[path.index(nxt):] + [nxt]
            if colour[nxt] == WHITE:
                colour[nxt] = GREY
                stack.append((nxt, iter(sorted(graph[nxt]))))
                path.append(nxt)
    return None


def test_graph_sees_relative_and_function_level_imports():
    g = import_graph()
    assert "gsdf.linalg" in g["gsdf.heat._core"]                 # relative, top level
    assert "gsdf.winding._hierarchical" in g["gsdf.winding._exact"]   # relative, inside a function
    assert "gsdf.winding._exact" not in g["gsdf.winding._hierarchical"]


def test_find_cycle_detects_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycles_in_gsdf():
    cycle = find_cycle(import_graph())
    if cycle:
        pytest.fail("import cycle: " + " -> ".join(cycle))


def package_graph(graph):
    """Modules grouped by package (gsdf.heat.grid._poisson -> gsdf.heat; top-level modules are their own
    package): an edge a -> b when any module of a imports any module of b, function-level imports included."""
    def pkg(m):
        return ".".join(m.split(".")[:2])

    out = {}
    for m, deps in graph.items():
        out.setdefault(pkg(m), set())
        for d in deps:
            if pkg(d) not in (pkg(m), "gsdf"):
                out[pkg(m)].add(pkg(d))
    return out


def test_no_package_cycles_in_gsdf():
    pg = package_graph(import_graph())
    assert "gsdf.linalg" in pg["gsdf.heat"] and "gsdf.heat" not in pg["gsdf.linalg"]
    cycle = find_cycle(pg)
    if cycle:
        pytest.fail("package import cycle: " + " -> ".join(cycle))


def test_package_graph_sees_a_package_cycle():
    g = {"gsdf.a._x": {"gsdf.b._y"}, "gsdf.b._y": set(), "gsdf.b._z": {"gsdf.a._x"}}
    assert find_cycle(package_graph(g)) in (["gsdf.a", "gsdf.b", "gsdf.a"], ["gsdf.b", "gsdf.a", "gsdf.b"])


def test_stub_lists_every_public_name_where_it_lives():
    """src/gsdf/__init__.pyi (what editors and type checkers read) names exactly gsdf.__all__, each imported
    from the module that gsdf's lazy loader takes it from."""
    import gsdf

    tree = ast.parse((SRC / "gsdf" / "__init__.pyi").read_text(encoding="utf-8"))
    stub = {}
    for node in tree.body:
        if isinstance(node, ast.ImportFrom):
            for a in node.names:
                assert a.asname == a.name, f"re-export {a.name} as itself in the stub"
                stub[a.name] = node.module
    assert sorted(stub) == sorted(gsdf.__all__)
    for name, module in stub.items():
        assert module == f"gsdf.{gsdf._EXPORTS[name]}", name
        assert getattr(importlib.import_module(module), name) is getattr(gsdf, name)
