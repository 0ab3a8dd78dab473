"""Generation of the fuzz cases from the package itself: nothing per function or per option is written by hand.

Sources of the cases (run ``python -m tests.fuzz --list`` to see them):

``api:*``
    Every name of ``gsdf.__all__``: functions, class constructors and the public methods of the classes
    (``inspect.signature``). A valid *baseline* call is searched among the fixtures (:mod:`tests.fuzz._fixtures`,
    valid values by parameter name). Each parameter is then attacked alone with the mutations of its family —
    the family and what is invalid for it come from :mod:`tests.fuzz._knowledge` (numpydoc type line, annotation,
    default, name): arrays (``api:arrays``), scalars and choices (``api:scalars``), the fields of the options
    dataclasses through every function that takes them (``api:options``), file names (``api:paths``), sizes that
    the memory / work guard must refuse at once (``api:size``), every coordinate × 1e±150 (``api:scale``: the
    answer must be the baseline × s^p) and broken geometry drawn from hypothesis strategies
    (``api:geometry``, :mod:`tests.fuzz.strategies`).
``cli:*``
    Every subcommand of the ``gsdf`` click group: a baseline argv built from the parameters' names and types,
    then one mutation per argument / option by its click type (``IntRange`` bounds, float ranges, choices,
    lists, directions, sizes, flags, paths, output names) and malformed input files (``cli:files``), and the
    ``GSDF_*`` environment variables the package reads (``cli:env``).
``files:<ext>``
    Every public reader (``read_*``, ``load_*``, ``.load``) on every file the public writers produce, in every
    extension they accept, then the same file malformed (truncated, NUL byte, huge / negative counts, nan / inf /
    garbage tokens, flipped or inserted bytes, empty, garbage), tampered saved state (``.npz``: a key dropped,
    NaN, complex, strings, wrong shapes) and valid variants (CRLF, trailing blank lines, the file itself:
    read back equal to what was written).

A parameter whose valid value is unknown (no fixture for a required parameter, no type for an optional one) is
a *coverage gap*: :func:`coverage_gaps` lists them and the runner prints them — never skipped silently.

Case ids (``area|target|param|mutation``) are stable: a seed's sample only changes where the public surface does.
"""

from __future__ import annotations

import collections
import dataclasses
import hashlib
import inspect
import os
import re

from tests.fuzz._fixtures import Fixtures
from tests.fuzz._knowledge import option_classes, scalar_mutations, specs
from tests.fuzz._mutations import ARRAY_MUTATIONS, FILE_MUTATIONS, NPZ_MUTATIONS, PATH_MUTATIONS, value_kind

OUTCOMES = ["pass", "crash", "hang", "NaN", "wrong", "leak", "accepted bad", "refused valid", "file damage"]
FAILURES = OUTCOMES[1:]

#: coordinate parameters (scaled by the scale area; replaced by the geometry area)
COORD_NAMES = {"V", "P", "Q", "X", "vertices", "VA", "VB", "A", "B", "mesh", "points"}
MESH_PAIRS = (("V", "F"), ("VA", "FA"), ("VB", "FB"), ("vertices", "faces"))
N_GEOMETRY = 3          # hypothesis draws per target and geometry type


# ------------------------------------------------------------------------------------------------ API surface
def _gsdf():
    import gsdf

    return gsdf


def api_targets() -> list:
    """``[(target, signature, documented object)]`` for every public function, constructor and method."""
    gsdf = _gsdf()
    out = []
    for name in sorted(gsdf.__all__):
        obj = getattr(gsdf, name)
        if inspect.isclass(obj):
            try:
                out.append((name, inspect.signature(obj), obj))
            except (TypeError, ValueError):
                continue
            for m, fn in sorted(vars(obj).items()):
                if m.startswith("_") and m != "__call__":
                    continue
                f = fn.__func__ if isinstance(fn, (classmethod, staticmethod)) else fn
                if isinstance(fn, property) or not callable(f):
                    continue
                try:
                    msig = inspect.signature(f)
                except (TypeError, ValueError):
                    continue
                params = list(msig.parameters.values())
                if not isinstance(fn, staticmethod) and params:
                    params = params[1:]                          # self / cls
                out.append((f"{name}.{m}", msig.replace(parameters=params), f))
        elif callable(obj):
            try:
                out.append((name, inspect.signature(obj), obj))
            except (TypeError, ValueError):
                continue
    return out


def target_map() -> dict:
    return {t: (sig, obj) for t, sig, obj in api_targets()}


def resolve(target: str):
    """(object, method name or None)."""
    gsdf = _gsdf()
    parts = target.split(".")
    return getattr(gsdf, parts[0]), (parts[1] if len(parts) > 1 else None)


def is_instance_method(target: str) -> bool:
    if "." not in target:
        return False
    obj, meth = resolve(target)
    return not isinstance(vars(obj).get(meth), (classmethod, staticmethod))


def _params(sig):
    return [p for p in sig.parameters.values() if p.kind != p.VAR_KEYWORD and not p.name.startswith("_")]


def _area_of(kind: str, m: str) -> str:
    if m.startswith("huge") and (kind not in ("float",) or m != "huge"):
        return "api:size"
    if kind.startswith("path"):
        return "api:paths"
    if kind in ("coords", "index", "vector", "grid", "grid_bool", "mask", "list", "tuple", "callable_value",
                "object", "required"):
        return "api:arrays"
    return "api:scalars"


def api_cases(fx: Fixtures) -> list:
    gsdf = _gsdf()
    cases = []
    opt_specs = option_classes(gsdf)
    for target, sig, obj in api_targets():
        cases.append(dict(area="api:baseline", target=target, mutation="baseline", expect="accept"))
        sp = specs(target, sig, obj)
        names = {p.name for p in sig.parameters.values()}
        if names & {"V", "P", "Q", "X", "vertices", "VA", "VB", "mesh", "points"} or (
                is_instance_method(target) and {"Q"} & names):
            for m in ("scale_tiny", "scale_huge"):
                cases.append(dict(area="api:scale", target=target, mutation=m, expect="accept"))
        if not is_instance_method(target):
            has_mesh = any(a in names and b in names for a, b in MESH_PAIRS) or "mesh" in names
            has_cloud = "P" in names or "points" in names
            for g, ok in (("soup", has_mesh), ("cloud", has_cloud)):
                if ok:
                    for i in range(N_GEOMETRY):
                        cases.append(dict(area="api:geometry", target=target, mutation=f"{g}_{i}",
                                          expect="either"))
        if target in opt_specs:
            continue        # an options dataclass is attacked through the functions that take it (api:options)
        for p in _params(sig):
            s = sp.get(p.name)
            if p.kind == p.VAR_POSITIONAL:
                continue
            if s.kind in ("path_in", "path_out"):
                for m, e in PATH_MUTATIONS[s.kind].items():
                    cases.append(dict(area="api:paths", target=target, param=p.name, mutation=m, expect=e,
                                      kind=s.kind))
                continue
            if s.kind == "options" and s.options_class in opt_specs:
                for m, e in scalar_mutations(s).items():
                    if m == "none" and p.default is None:
                        continue
                    cases.append(dict(area="api:options", target=target, param=p.name, mutation=m, expect=e,
                                      kind="options"))
                for fname, fs in opt_specs[s.options_class].items():
                    for m, e in scalar_mutations(fs).items():
                        if m == "none" and (fs.optional and _field_default(s.options_class, fname) is None):
                            continue
                        cases.append(dict(area="api:options", target=target, param=f"{p.name}.{fname}",
                                          mutation=m, expect=e, kind=fs.kind))
                continue
            has_fixture = fx.has(p.name, target)
            if s.kind in ("required", "none", "object", "tuple") and has_fixture:
                kinds = sorted({value_kind(fx.get(p.name, target, i)) for i in range(fx.count(p.name, target))})
            elif s.kind == "required":
                kinds = []                                      # no fixture: a coverage gap of the target
            else:
                kinds = [s.kind]
            seen = set()
            for k in kinds:
                muts = ARRAY_MUTATIONS.get(k) or scalar_mutations(dataclasses.replace(s, kind=k))
                for m, e in muts.items():
                    if m in seen or (m == "none" and p.default is None):
                        continue
                    seen.add(m)
                    cases.append(dict(area=_area_of(k, m), target=target, param=p.name, mutation=m, expect=e,
                                      kind=k))
    return cases


def _field_default(cls_name: str, field: str):
    cls = getattr(_gsdf(), cls_name)
    for f in dataclasses.fields(cls):
        if f.name == field:
            return None if f.default is dataclasses.MISSING else f.default
    return None


def coverage_gaps(fx: Fixtures | None = None) -> list:
    """``[(target, parameter, why)]``: parameters without a known valid value (their target has no baseline, or
    the parameter is attacked with generic values only)."""
    fx = fx or Fixtures()
    gaps = []
    for target, sig, obj in api_targets():
        sp = specs(target, sig, obj)
        for p in _params(sig):
            if p.kind == p.VAR_POSITIONAL:
                if not fx.has(p.name, target):
                    gaps.append((target, "*" + p.name, "no fixture: called without positional items"))
                continue
            s = sp[p.name]
            if s.kind == "required" and not fx.has(p.name, target):
                gaps.append((target, p.name, "required, no fixture: the target has no baseline"))
            elif s.kind in ("none", "object") and not fx.has(p.name, target):
                gaps.append((target, p.name, "no known valid value: attacked with generic bad values only"))
    return gaps


# ------------------------------------------------------------------------------------------------ CLI
def cli_group():
    from gsdf.cli.main import main

    return main


def output_params() -> set:
    """Names of the CLI's output options: the package's own list plus folder outputs."""
    from gsdf.cli import _common

    return set(getattr(_common, "OUTPUT_PARAMS", ())) | {"output_dir", "out_alias"}


def _ptype(p):
    import click

    t = p.type
    if isinstance(p, click.Option) and p.is_flag:
        return "flag"
    if isinstance(t, click.Path):
        return "path"
    if isinstance(t, click.IntRange) or t is click.INT or isinstance(t, click.types.IntParamType):
        return "int"
    if isinstance(t, (click.FloatRange, click.types.FloatParamType)) or getattr(t, "name", "") == "float":
        return "float"
    if isinstance(t, click.Choice):
        return "choice"
    return "text:" + getattr(t, "name", "text")


SIZE_OPTIONS = {"resolution", "n_points", "layers", "size", "workers", "dask_local"}
#: options whose text is shown, not parsed (a colour-bar title): any text is valid
FREE_TEXT_OPTIONS = {"title"}

#: free-text values by the type's metavar (a new type gets the generic list)
TEXT_VALUES = {
    "x,y,...": [("", "refuse"), (",", "refuse"), ("nan", "refuse"), ("1,nan", "refuse"), ("inf", "refuse"),
                ("x", "refuse"), ("1e308", "either"), ("1,,2", "either")],
    "x,y,z": [("", "refuse"), ("0,0,0", "refuse"), ("1,2", "refuse"), ("nan,0,1", "refuse"), ("x", "refuse"),
              ("1,0,1e308", "either"), ("1,0,0,0", "refuse")],
    "N|WxH": [("0", "refuse"), ("-5", "refuse"), ("x", "refuse"), ("1000000000", "refuse"),
              ("100000x100000", "refuse"), ("16x", "refuse"), ("nan", "refuse")],
    "auto|axis|x,y,z": [("bogus", "refuse"), ("0,0,0", "refuse"), ("", "refuse"), ("w", "refuse")],
    "N": [("0", "either"), ("-1", "refuse"), ("x", "refuse"), ("1.5", "refuse"), ("1000000000", "either"),
          ("nan", "refuse")],
    "generic": [("", "refuse"), (",", "refuse"), ("nan", "refuse"), ("1,nan", "refuse"), ("x", "refuse"),
                ("1e308", "either"), ("inf", "refuse")],
    "free": [("", "either"), ("x", "either"), ("nan", "either"), ("1,nan", "either"), ("é ü", "either")],
}
PATH_ARG_MUTATIONS = ("missing", "directory", "fifo", "dev_zero", "empty_file", "garbage")
CLI_FILE_MUTATIONS = {m: e for m, e in FILE_MUTATIONS.items() if m not in ("empty", "garbage")}


def cli_mutations(cmd) -> list:
    """``[(param, mutation, flag or 'arg', expectation, area)]`` for every argument and option of ``cmd``."""
    import click

    outs = output_params()
    out = []
    for p in cmd.params:
        if getattr(p, "hidden", False) and p.name in outs:
            continue
        flag = max(p.opts, key=len) if isinstance(p, click.Option) else "arg"
        kind = _ptype(p)
        if isinstance(p, click.Argument):
            for m in PATH_ARG_MUTATIONS:
                out.append((p.name, m, "arg", "refuse", "cli:paths"))
            if kind == "path":                               # a file argument: malformed contents too
                for m, e in CLI_FILE_MUTATIONS.items():
                    out.append((p.name, "file:" + m, "arg", e, "cli:files"))
            continue
        if p.name in outs:
            folder = p.name in ("output_dir", "out_alias")
            main = p.name in ("output", "output_dir")
            clobber = any(q.name == "no_clobber" for q in cmd.params)
            for m in ("same_as_input", "directory", "bad_ext", "nested_new", "same_as_other_output",
                      "existing_no_clobber"):
                if (m == "bad_ext" and folder) or (m == "same_as_other_output" and main) or \
                        (m == "existing_no_clobber" and (folder or not clobber)) or \
                        (m == "same_as_input" and not any(isinstance(q, click.Argument) for q in cmd.params)):
                    continue
                out.append((p.name, m, flag, "accept" if m == "nested_new" else "refuse", "cli:outputs"))
            continue
        if kind == "flag":
            out.append((p.name, "flag_on", flag, "either", "cli:options"))
            continue
        t = p.type
        if kind == "int":
            lo, hi = getattr(t, "min", None), getattr(t, "max", None)
            if lo is not None:
                out.append((p.name, f"={lo - 1}", flag, "refuse", "cli:options"))
            if hi is not None:
                out.append((p.name, f"={hi + 1}", flag, "refuse", "cli:options"))
                if hi >= 1000:
                    out.append((p.name, f"={hi}", flag, "either", "cli:size"))
            else:
                out.append((p.name, "=1000000000", flag, "refuse" if p.name in SIZE_OPTIONS else "either",
                            "cli:size"))
            out += [(p.name, "=x", flag, "refuse", "cli:options"), (p.name, "=1.5", flag, "refuse", "cli:options")]
        elif kind == "float":
            vals = [("nan", "refuse"), ("inf", "refuse"), ("-inf", "refuse"), ("x", "refuse"), ("1e308", "either"),
                    ("-1", "either"), ("0", "either")]
            lo, hi = getattr(t, "min", None), getattr(t, "max", None)
            for v, e in vals:
                if e == "either" and (lo is not None or hi is not None):
                    x = float(v)
                    ok = (lo is None or (x > lo if getattr(t, "min_open", False) else x >= lo)) and \
                        (hi is None or (x < hi if getattr(t, "max_open", False) else x <= hi))
                    e = "either" if ok else "refuse"
                out.append((p.name, "=" + v, flag, e, "cli:options"))
        elif kind == "choice":
            out.append((p.name, "=bogus", flag, "refuse", "cli:options"))
        elif kind == "path":
            for m in PATH_ARG_MUTATIONS:
                out.append((p.name, m, flag, "refuse", "cli:paths"))
            for m, e in CLI_FILE_MUTATIONS.items():
                out.append((p.name, "file:" + m, flag, e, "cli:files"))
        else:
            metavar = "free" if p.name in FREE_TEXT_OPTIONS else kind.split(":", 1)[1]
            for v, e in TEXT_VALUES.get(metavar, TEXT_VALUES["generic"]):
                out.append((p.name, "=" + v, flag, e, "cli:options"))
    return out


def env_vars() -> list:
    """The ``GSDF_*`` environment variables the package reads (found in its source)."""
    import gsdf

    root = os.path.dirname(gsdf.__file__)
    names = set()
    for base, _, files in os.walk(root):
        for f in files:
            if f.endswith(".py"):
                with open(os.path.join(base, f), encoding="utf-8") as fh:
                    names |= set(re.findall(r"[\"'](GSDF_[A-Z_]+)[\"']", fh.read()))
    return sorted(names)


ENV_VALUES = [("nan", "refuse"), ("x", "refuse"), ("-1", "refuse"), ("0", "either"), ("", "either"),
              ("1e308", "either")]
ENV_COMMAND = "winding"          # the cheapest command with an input and an output


def cli_cases() -> list:
    group = cli_group()
    cases = []
    for name in sorted(group.commands):
        cmd = group.commands[name]
        cases.append(dict(area="cli:baseline", command=name, mutation="baseline", expect="accept"))
        for pname, m, where, expect, area in cli_mutations(cmd):
            cases.append(dict(area=area, command=name, param=pname, mutation=m, where=where, expect=expect))
    if ENV_COMMAND in group.commands:
        for var in env_vars():
            for v, e in ENV_VALUES:
                cases.append(dict(area="cli:env", command=ENV_COMMAND, param=var, mutation="=" + v, where="env",
                                  expect=e))
    return cases


# ------------------------------------------------------------------------------------------------ files
def readers() -> list:
    gsdf = _gsdf()
    out = []
    for name in sorted(gsdf.__all__):
        obj = getattr(gsdf, name)
        if inspect.isfunction(obj) and re.match(r"(read_|load_)", name):
            out.append(name)
        elif inspect.isclass(obj) and isinstance(vars(obj).get("load"), classmethod):
            out.append(f"{name}.load")
    return out


#: (file name, how it is written) — every writer, every extension; a writer that refuses one is skipped
def sample_file_specs() -> list:
    out = []
    for ext in (".obj", ".off", ".ply", ".stl", ".vtk", ".vtu"):
        out += [("mesh_bin" + ext, "write_mesh", {"binary": True}), ("mesh_txt" + ext, "write_mesh",
                                                                      {"binary": False})]
    out.append(("mesh_data.ply", "write_mesh_data", {"binary": False}))
    out.append(("mesh_data_bin.ply", "write_mesh_data", {"binary": True}))
    for ext in (".xyz", ".pwn", ".ply", ".npy", ".npz", ".obj", ".pc", ".off"):
        out += [("cloud_bin" + ext, "write_points", {"binary": True}), ("cloud_txt" + ext, "write_points",
                                                                         {"binary": False})]
    out.append(("curves.txt", "write_curves", {}))
    out.append(("curves_obj.obj", "obj_lines", {}))
    for ext in (".npz", ".npy", ".vtk", ".vti", ".vtu"):
        out.append(("grid" + ext, "grid_save", {}))
    for ext in (".npz", ".vtk", ".vtu"):
        out.append(("surface" + ext, "surface_save", {}))
        out.append(("tet" + ext, "tet_save", {}))
    out.append(("voxels.npz", "save_voxels", {}))
    out.append(("pat.npz", "pat_save", {}))
    return out


def write_sample_file(fx: Fixtures, name: str, how: str, opts: dict, d: str):
    """Write one sample file into ``d`` with the public writer; returns what was written (for round trips)."""
    import numpy as np

    gsdf = _gsdf()
    p = os.path.join(d, name)
    V, F = fx.V, fx.F
    if how == "write_mesh":
        gsdf.write_mesh(p, V, F, **opts)
        return {"V": V, "F": F}
    if how == "write_mesh_data":
        gsdf.write_mesh(p, V, F, vertex_data={"d": V[:, 2].copy()}, **opts)
        return {"V": V, "F": F, "d": V[:, 2].copy()}
    if how == "write_points":
        gsdf.write_points(p, V, V, **opts)
        return {"P": V, "N": V}
    if how == "write_curves":
        gsdf.write_curves(p, [fx.loop])
        return {"curves": [fx.loop]}
    if how == "obj_lines":
        with open(p, "w") as fh:
            fh.write("l " + " ".join(str(int(v) + 1) for v in fx.loop) + "\n")
        return {"curves": [fx.loop]}
    if how == "grid_save":
        gsdf.GridField(fx.grid_vals, [-1.5] * 3, [1.5] * 3).save(p)
        return {"values": fx.grid_vals}
    if how == "surface_save":
        gsdf.SurfaceField(V, F, V[:, 2].copy()).save(p)
        return {"values": V[:, 2].copy(), "V": V, "F": F}        # load_field reads the values, read_mesh the mesh
    if how == "tet_save":
        X = np.vstack([fx.Xt, [[1.0, 1.0, 1.0]]])
        T = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
        gsdf.TetField(X, T, X[:, 0].copy()).save(p)
        # read_mesh reads a tet file as the tets' boundary: the faces that belong to one tet only
        tri = np.sort(T[:, [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]].reshape(-1, 3), axis=1)
        u, cnt = np.unique(tri, axis=0, return_counts=True)
        return {"values": X[:, 0].copy(), "V": X, "F_unoriented": u[cnt == 1]}
    if how == "save_voxels":
        gsdf.save_voxels(p, fx.occ, [-1.5] * 3, [1.5] * 3)
        return {}
    if how == "pat_save":
        gsdf.PointsAsTori(V, V, k=16).save(p)
        return {}
    raise KeyError(how)


def file_cases(pairs) -> list:
    """Cases for the (reader, file name) pairs that read (found by the runner in a child)."""
    cases = []
    for rd, fname in sorted(pairs):
        ext = fname.rsplit(".", 1)[-1]
        muts = dict(FILE_MUTATIONS)
        if ext in ("npz",):
            muts = {m: e for m, e in muts.items() if m in ("truncate_half", "flip_bytes", "empty", "garbage",
                                                            "valid")}
            muts.update(NPZ_MUTATIONS)
        muts["roundtrip"] = "accept"
        for m, e in muts.items():
            cases.append(dict(area="files:" + ext, target=rd, file=fname, mutation=m, expect=e))
    return cases


# ------------------------------------------------------------------------------------------------ all, ids, sample
def case_id(c: dict) -> str:
    keys = ("area", "target", "command", "file", "param", "mutation")
    return "|".join(str(c[k]) for k in keys if c.get(k) not in (None, ""))


def all_cases(areas, pairs=None) -> list:
    """Every generated case of the given areas (``api``, ``cli``, ``files`` or full names like ``api:scale``);
    ``pairs``: the (reader, file) pairs that read, found by the runner in a child."""
    areas = set(areas)
    top = {a.split(":")[0] for a in areas}
    cases = []
    if "api" in top:
        cases += api_cases(Fixtures())
    if "cli" in top:
        cases += cli_cases()
    if "files" in top and pairs is not None:
        cases += file_cases(pairs)
    out, seen = [], set()
    for c in cases:
        c["id"] = case_id(c)
        if c["id"] in seen:
            continue
        seen.add(c["id"])
        if c["area"] in areas or c["area"].split(":")[0] in areas:
            out.append(c)
    return out


def _rank(seed: int, cid: str) -> str:
    return hashlib.sha1(f"{seed}|{cid}".encode()).hexdigest()


def sample(cases: list, n: int, seed: int) -> list:
    """Stratified sample of about ``n`` cases: every area gets its share (at least 2), and inside an area the cases
    with the smallest hash of (seed, id) — so adding cases elsewhere never changes an area's sample, and adding
    one to an area changes at most one of its picks."""
    by = collections.defaultdict(list)
    for c in cases:
        by[c["area"]].append(c)
    total = len(cases)
    out = []
    for area in sorted(by):
        lst = sorted(by[area], key=lambda c: _rank(seed, c["id"]))
        k = min(len(lst), max(2, round(n * len(lst) / total)))
        out += lst[:k]
    return sorted(out, key=lambda c: _rank(seed, c["id"]))
