"""Running one case (in its own forked process, see :mod:`tests.fuzz._runner`) and classifying what happened.

Classification (one rule set for every area):

* ``crash``: the case process died by a signal (segfault, abort, out-of-memory kill) — decided by the runner;
* ``hang``: no answer before the timeout — decided by the runner;
* ``leak``: an exception other than ``ValueError`` (``FileNotFoundError`` for a missing input file is the
  documented exception), a ``ValueError`` subclass that is not gsdf's own (``UnicodeDecodeError``,
  ``LinAlgError``, ``JSONDecodeError`` ...), or a ``ValueError`` whose message is numpy's / Python's / SciPy's
  internal text (:data:`INTERNALS`); on the command line: a traceback, or an error line made of an ``OSError``'s
  ``[Errno N]`` text or internal text (click's usage errors and gsdf's one-line errors are clean);
* ``NaN``: a returned array (or a written ``.npz`` / ``.npy`` / text output) with NaN or inf from finite input;
* ``wrong``: a valid variant (list for array, float32, ``pathlib.Path``, int for float, a scaled input, a file
  read back) answers differently from the baseline;
* ``accepted bad``: a value the parameter's spec says is invalid was taken (the call returned, the command
  exited 0);
* ``refused valid``: a valid variant or a baseline refused with a clean error;
* ``file damage``: an input file changed, or a failing call / command left a file behind (in its case folder:
  the output folder of the call);
* ``review`` (not a failure): a soft value (``either``) was accepted; ``skip``: the case does not apply (no
  baseline — a coverage gap —, or the mutation does not fit the baseline value).
"""

from __future__ import annotations

import hashlib
import inspect
import io
import json
import os
import re
import shutil
import sys
import tempfile
import time
import traceback

import numpy as np

from tests.fuzz import _cases
from tests.fuzz._fixtures import Fixtures
from tests.fuzz._knowledge import scalar_mutations, specs
from tests.fuzz._mutations import (
    ARRAY_KINDS,
    ARRAY_MUTATIONS,
    FILE_MUTATIONS,
    NPZ_MUTATIONS,
    PATH_MUTATIONS,
    malform,
    mutate_scalar,
    mutate_value,
    tamper_npz,
    value_kind,
)

INTERNALS = re.compile(
    r"could not convert|invalid literal|setting an array element|inhomogeneous|operands could not be broadcast|"
    r"truth value of an array|cannot reshape array|values to unpack|must be finite, check for nan|object of type|"
    r"context manager|cannot convert float|zero-size array|out of bounds for axis|ufunc|Buffer dtype mismatch|"
    r"array must not contain infs|math domain error|need at least one array|unhashable type|is not subscriptable|"
    r"object is not iterable|has no attribute|unsupported operand|only integer scalar arrays|list index out of range|"
    r"allow_pickle|codec can't decode|Expecting value: line|index \d+ is out of bounds|integer division|"
    r"array is too big|Maximum allowed dimension|negative dimensions|data type .* not understood|"
    r"Unable to allocate|cannot be safely cast|Cannot cast|mmap length|embedded null|"
    r"^\w+Error: |not enough values|too many values|invalid index to scalar|"
    r"axis \d+ is out of bounds|Singular matrix|cannot unpack|could not broadcast|must be real number|"
    r"The truth value", re.I | re.M)

ERRNO = re.compile(r"\[Errno \d+\]")
MEM_CAP = 8 << 30


# ------------------------------------------------------------------------------------------------ helpers
def finite(x, depth: int = 0) -> bool:
    """No NaN / inf in a result (arrays, scalars, and the arrays of dicts / tuples / fields)."""
    if depth > 4:
        return True
    if isinstance(x, dict):
        return all(finite(v, depth + 1) for v in x.values())
    if isinstance(x, (list, tuple)):
        return all(finite(v, depth + 1) for v in list(x)[:1000])
    if isinstance(x, (np.ndarray, float, complex, np.floating, np.complexfloating)):
        a = np.asarray(x)
        return not (a.dtype.kind in "fc" and not np.isfinite(a).all())
    for attr in ("values", "face_labels", "corner_values", "vertices"):
        v = getattr(x, attr, None)
        if isinstance(v, np.ndarray):
            return finite(v, depth + 1)
    return True


def arrays(x, depth: int = 0) -> list:
    """Numeric arrays of a result in a stable order (to compare variants)."""
    if depth > 3:
        return []
    if isinstance(x, np.ndarray) and x.dtype.kind in "fiub":
        return [x]
    if isinstance(x, (float, int, np.number)) and not isinstance(x, bool):
        return [np.asarray(x)]
    if isinstance(x, (list, tuple)):
        return [a for y in list(x)[:50] for a in arrays(y, depth + 1)]
    if isinstance(x, dict):
        return [a for k in sorted(x, key=str) for a in arrays(x[k], depth + 1)]
    for attr in ("values", "face_labels", "corner_values", "curves"):
        v = getattr(x, attr, None)
        if isinstance(v, np.ndarray):
            return [v]
        if attr == "curves" and isinstance(v, list):
            return arrays(v, depth + 1)
    return []


def close(a, b, rtol=1e-5) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape != b.shape:
        return False
    scale = max(1.0, float(np.abs(b).max()) if b.size else 1.0)
    return bool(np.allclose(a, b, rtol=rtol, atol=1e-7 * scale, equal_nan=True))


def snapshot(d: str) -> dict:
    """{path: content hash} of every file under ``d`` (folders: 'dir')."""
    out = {}
    for base, dirs, files in os.walk(d):
        for f in files:
            q = os.path.join(base, f)
            try:
                if os.path.islink(q) or not os.path.isfile(q):
                    out[q] = "special"
                    continue
                with open(q, "rb") as fh:
                    out[q] = hashlib.sha1(fh.read()).hexdigest()
            except OSError:
                out[q] = "?"
        for sd in dirs:
            out.setdefault(os.path.join(base, sd) + "/", "dir")
    return out


def query_shaped(target: str) -> bool:
    """Whether the target takes its query points ``Q`` in any shape (..., 3): it is wrapped by
    :func:`gsdf._checks.query_shaped`."""
    obj, meth = _cases.resolve(target)
    code = getattr(getattr(obj, meth, None) if meth else obj, "__code__", None)
    return code is not None and code.co_name == "wrapper" and code.co_filename.endswith("_checks.py")


def clean_exception(e: BaseException) -> bool:
    """A ValueError raised by gsdf itself (or plain ValueError) with a message of its own."""
    if not isinstance(e, ValueError):
        return False
    t = type(e)
    if t is not ValueError and not t.__module__.startswith(("gsdf", "click")):
        return False
    return not INTERNALS.search(str(e))


def classify_exception(e: BaseException, mutation: str, expect: str):
    if isinstance(e, FileNotFoundError) and mutation == "missing":
        return "pass", f"FileNotFoundError: {e}"[:160]
    if not clean_exception(e):
        return "leak", f"{type(e).__name__}: {e}"[:240]
    if expect == "accept":
        return "refused valid", f"{type(e).__name__}: {e}"[:240]
    return "pass", str(e)[:160]


# ------------------------------------------------------------------------------------------------ API
def _positional(fn, args, kwargs):
    """``fn(*args, **kwargs)`` with the parameters before a ``*items`` parameter moved into ``args`` when
    ``*items`` gets values (``save_png(path, *items)``: ``path=`` as a keyword would be given twice)."""
    if not args:
        return args, kwargs
    try:
        ps = list(inspect.signature(fn).parameters.values())
    except (TypeError, ValueError):
        return args, kwargs
    if not any(p.kind == p.VAR_POSITIONAL for p in ps):
        return args, kwargs
    lead, kw = [], dict(kwargs)
    for p in ps:
        if p.kind == p.VAR_POSITIONAL:
            break
        if p.kind != p.POSITIONAL_OR_KEYWORD:
            return args, kwargs
        if p.name in kw:
            lead.append(kw.pop(p.name))
        elif p.default is not p.empty:
            lead.append(p.default)
        else:
            return args, kwargs
    return lead + list(args), kw


def call_target(target: str, args, kwargs, ctor=None):
    obj, meth = _cases.resolve(target)
    if meth is None:
        a, k = _positional(obj, args, kwargs)
        return obj(*a, **k)
    raw = vars(obj).get(meth)
    if isinstance(raw, (classmethod, staticmethod)):
        fn = getattr(obj, meth)
    else:
        fn = getattr(obj(*ctor[0], **ctor[1]), meth)
    a, k = _positional(fn, args, kwargs)
    return fn(*a, **k)


def build(sig, combo: dict, fx: Fixtures, target: str):
    """(args, kwargs) of a baseline from per-parameter candidate indices (-1 / absent: the default)."""
    args, kwargs = [], {}
    for p in sig.parameters.values():
        if p.kind == p.VAR_KEYWORD or p.name.startswith("_"):
            continue
        i = combo.get(p.name, -1)
        if p.kind == p.VAR_POSITIONAL:
            if i >= 0:
                args.append(fx.get(p.name, target, i))
            continue
        if i >= 0:
            v = fx.get(p.name, target, i)
            if p.kind == p.POSITIONAL_ONLY:
                args.append(v)
            else:
                kwargs[p.name] = v
        elif p.default is p.empty:
            raise LookupError(p.name)
    return args, kwargs


def combos(sig, fx: Fixtures, target: str) -> list:
    """Candidate-index combinations for the required parameters (and optional ones that have fixtures)."""
    import itertools

    names, choices = [], []
    for p in sig.parameters.values():
        if p.kind == p.VAR_KEYWORD or p.name.startswith("_"):
            continue
        has = fx.has(p.name, target)
        n = fx.count(p.name, target)
        if p.kind == p.VAR_POSITIONAL:
            if has:
                names.append(p.name)
                choices.append(range(-1, n))
            continue
        if p.default is p.empty:
            if not has:
                raise LookupError(p.name)
            names.append(p.name)
            choices.append(range(n))
        elif has and p.default is None:
            names.append(p.name)
            choices.append(range(-1, n))
    out = [dict(zip(names, c)) for c in itertools.product(*choices)]
    out.sort(key=lambda c: sum(v >= 0 for v in c.values()))
    return out[:96] or [{}]


def find_baseline(target: str, tmap: dict, fx: Fixtures, casedir: str) -> dict:
    """The first candidate combination the target accepts: {'combo', 'ctor', 'finite', 'seconds'} or {'error'}."""
    sig, _ = tmap[target]
    ctor = None
    cls_name = target.split(".")[0]
    if _cases.is_instance_method(target):
        cb = baseline_of(cls_name, tmap, fx, casedir)
        if "error" in cb:
            return {"error": f"constructor: {cb['error']}"}
        ctor = cb["combo"]
    try:
        cs = combos(sig, fx, target)
    except LookupError as e:
        return {"error": f"no fixture for parameter {e.args[0]!r}"}
    last = ""
    for combo in cs:
        try:
            args, kwargs = build(sig, combo, fx, target)
            cargs = build(tmap[cls_name][0], ctor, fx, cls_name) if ctor is not None else None
            t0 = time.time()
            r = call_target(target, args, kwargs, cargs)
            return {"combo": combo, "ctor": ctor, "finite": finite(r), "seconds": time.time() - t0}
        except Exception as e:  # noqa: BLE001 - try the next combination
            last = f"{type(e).__name__}: {e}"[:200]
    return {"error": f"no candidate accepted ({last})"}


def baseline_of(target: str, tmap: dict, fx: Fixtures, casedir: str) -> dict:
    path = os.path.join(fx.root, "baselines", target + ".json")
    if os.path.exists(path):
        with open(path) as fh:
            return json.load(fh)
    old = os.getcwd()
    base = find_baseline(target, tmap, fx, casedir)
    os.chdir(old)
    tmp = path + f".{os.getpid()}.tmp"
    with open(tmp, "w") as fh:
        json.dump(base, fh)
    os.replace(tmp, path)
    return base


def _scaled(kwargs: dict, s: float):
    """The coordinate arguments scaled by s; None when the call is not scale-homogeneous."""
    out = {}
    for k, v in kwargs.items():
        if k in _cases.COORD_NAMES:
            if isinstance(v, tuple):
                v = (np.asarray(v[0], float) * s,) + tuple(v[1:])
            elif isinstance(v, np.ndarray) and v.dtype.kind == "f":
                v = v * s
            else:
                return None
        elif isinstance(v, (float, np.floating)) or callable(v) or \
                (isinstance(v, np.ndarray) and v.dtype.kind == "f") or k in ("path", "source", "inputs"):
            return None
        out[k] = v
    return out


def _geometry(kwargs: dict, m: str):
    """kwargs with the mesh / cloud replaced by a hypothesis draw (None: nothing to replace)."""
    from tests.fuzz import strategies

    kind, i = m.rsplit("_", 1)
    seed = int(hashlib.sha1(m.encode()).hexdigest()[:6], 16) + int(i)
    out = dict(kwargs)
    if kind == "soup":
        V, F = strategies.draw(strategies.soups(), seed)
        done = False
        for a, b in _cases.MESH_PAIRS:
            if a in out and b in out and np.asarray(out[b]).ndim == 2 and np.asarray(out[a]).shape[-1] == 3:
                out[a], out[b] = V, F
                done = True
        if isinstance(out.get("mesh"), tuple):
            out["mesh"] = (V, F)
            done = True
        return out if done else None
    P, N = strategies.draw(strategies.clouds(), seed)
    if "P" in out and np.asarray(out["P"]).shape[-1] == 3:
        out["P"] = P
        if "N" in out:
            out["N"] = N
        for k in ("areas",):
            out.pop(k, None)
        return out
    if isinstance(out.get("points"), tuple):
        out["points"] = (P, N)
        return out
    return None


def _diff(A: list, B: list) -> str:
    """How two answers' arrays differ, in a few words."""
    if len(A) != len(B):
        return f"{len(B)} arrays instead of {len(A)}"
    for i, (a, b) in enumerate(zip(A, B)):
        if a.shape != b.shape:
            return f"array {i}: shape {b.shape} instead of {a.shape}"
        d = np.abs(np.asarray(a, float) - np.asarray(b, float))
        if d.size and not close(a, b):
            return f"array {i} {a.shape}: {int((d > 0).sum())} entries differ, by up to {d.max():.3g}"
    return "within tolerance"


def _same_value(v, m: str):
    """The float64 value of the float32 variant ``v`` (the reference it must answer like: a float32 input rounds
    the baseline's value, and an answer may move with the value, e.g. a picture's framing)."""
    if m != "float32":
        return v
    if isinstance(v, np.ndarray):
        return v.astype(np.float64)
    return float(v) if isinstance(v, (np.floating, float)) else v


def run_api_case(case: dict, root: str, tmap: dict):
    """Executed in a forked child: returns (outcome, note)."""
    fx = Fixtures(root)
    casedir = tempfile.mkdtemp(prefix="case-", dir=os.path.join(root, "cases"))
    os.chdir(casedir)
    target, pname, m = case["target"], case.get("param"), case["mutation"]
    sig, obj = tmap[target]
    base = baseline_of(target, tmap, fx, casedir)
    os.chdir(casedir)
    if "error" in base:
        return "skip", "no baseline (coverage gap): " + base["error"]
    combo, ctor = base["combo"], base["ctor"]
    cls_name = target.split(".")[0]
    cargs = build(tmap[cls_name][0], ctor, fx, cls_name) if ctor is not None else None
    args, kwargs = build(sig, combo, fx, target)
    expect, ref = case["expect"], None
    s = None
    if m == "baseline":
        pass
    elif m in ("scale_tiny", "scale_huge"):
        sc = 1e-150 if m == "scale_tiny" else 1e150
        kw2 = _scaled(kwargs, sc)
        c2 = None if cargs is None else _scaled(cargs[1], sc)
        if kw2 is None or (cargs is not None and c2 is None) or args:
            return "skip", "n/a: not scale-homogeneous (lengths other than coordinates)"
        if not any(k in _cases.COORD_NAMES for k in list(kw2) + list((c2 or {}))):
            return "skip", "n/a: no coordinates in the baseline"
        ref = call_target(target, args, kwargs, cargs)
        kwargs, cargs = kw2, (None if cargs is None else ([], c2))
    elif m.startswith(("soup_", "cloud_")):
        kw2 = _geometry(kwargs, m)
        if kw2 is None:
            return "skip", "n/a: the baseline has no 3D mesh / cloud to replace"
        kwargs = kw2
    elif "." in (pname or ""):                                 # a field of an options dataclass
        oname, field = pname.split(".", 1)
        s = specs(target, sig, obj)[oname]
        cls = getattr(__import__("gsdf"), s.options_class)
        fs = specs(s.options_class, inspect.signature(cls), cls)[field]
        default = inspect.signature(cls).parameters[field].default
        try:
            v = mutate_scalar(default, m, fs.kind, fs)
        except (KeyError, TypeError, ValueError):
            return "skip", f"n/a: {m} on {fs.kind}"
        if expect == "accept" and m == "none" and default is not None:
            pass                                   # None is another valid setting, not the default: no reference
        elif expect == "accept":                   # a float32 variant: the reference takes the same value
            ref = call_target(target, args, dict(kwargs, **{oname: cls(**{field: _same_value(v, m)})})
                              if m == "float32" else kwargs, cargs)
        try:
            opts = cls(**{field: v})
        except BaseException as e:  # noqa: BLE001
            return classify_exception(e, m, expect)
        kwargs = dict(kwargs, **{oname: opts})
    else:
        params = sig.parameters
        p = params[pname]
        s = specs(target, sig, obj)[pname]
        if pname in kwargs or (p.kind == p.VAR_POSITIONAL and args):
            value = kwargs[pname] if pname in kwargs else args[0]
            kind = case["kind"] if case["kind"].startswith("path") else value_kind(value)
        else:
            value, kind = p.default, s.kind
            if fx.has(pname, target) and s.kind in ("none", "object", "tuple", "required") \
                    and p.default is None:
                value = fx.get(pname, target, 0)        # an optional input: attack a given one ...
                kind = value_kind(value)
                try:                                     # ... whose unmutated call is the reference
                    call_target(target, args, dict(kwargs, **{pname: value}), cargs)
                except Exception:  # noqa: BLE001
                    return "skip", f"n/a: optional {pname} not combinable with the baseline"
                kwargs = dict(kwargs, **{pname: value})
        if kind in ARRAY_MUTATIONS:
            table = ARRAY_MUTATIONS[kind]
        elif kind in PATH_MUTATIONS:
            table = PATH_MUTATIONS[kind]
        else:
            import dataclasses as dc

            table = scalar_mutations(dc.replace(s, kind=kind))
        if kind.startswith("path") and not isinstance(value, str):
            return "skip", "n/a: path parameter without a string baseline"
        if kind.startswith("path") and not os.path.splitext(str(value))[1]:       # a folder, not a file
            table = {k: v for k, v in table.items() if k in ("missing", "int", "pathlib", "nested_new",
                                                              "garbage")}
        expect = table.get(m)
        if expect is None:
            return "skip", f"n/a: {m} on {kind}"
        if m in ("out_of_range", "huge_index") and not any(k in _cases.COORD_NAMES for k in list(kwargs) + list((cargs or ([], {}))[1])):
            expect = "either"                                   # no vertex count to be out of range of
        if m == "dim3" and kind == "coords" and pname == "Q" and query_shaped(target):
            expect = "accept"                                   # Q of any shape (..., 3), documented
        try:
            if kind in ARRAY_KINDS or kind in PATH_MUTATIONS or kind in ("list", "tuple", "callable_value",
                                                                          "object"):
                newv = mutate_value(value, m, kind, fx, casedir)
            else:
                newv = mutate_scalar(value, m, kind, s)
        except (KeyError, IndexError, ValueError, TypeError) as e:
            return "skip", f"n/a: {m} on {kind} ({type(e).__name__})"
        if expect == "accept" and m == "float32":    # the reference takes the same value in float64
            same = _same_value(newv, m)
            ref = call_target(target, [same] if p.kind == p.VAR_POSITIONAL else args,
                              kwargs if p.kind == p.VAR_POSITIONAL else dict(kwargs, **{pname: same}), cargs)
        elif expect == "accept" and not (m == "none" and value is not None):
            ref = call_target(target, args, kwargs, cargs)     # (None, when not the default, is another setting)
        if p.kind == p.VAR_POSITIONAL:
            args = [newv]
        else:
            kwargs = dict(kwargs, **{pname: newv})
    before = snapshot(casedir) | snapshot(fx.fdir)
    try:
        r = call_target(target, args, kwargs, cargs)
    except BaseException as e:  # noqa: BLE001
        outcome, note = classify_exception(e, m, expect)
        if m == "baseline" and outcome == "refused valid":
            outcome = "refused valid"
        after = snapshot(casedir) | snapshot(fx.fdir)
        new = sorted(k for k in after if k not in before and not k.endswith("/"))
        changed = sorted(k for k in before if k in after and before[k] != after[k] and not k.endswith("/"))
        if new or changed:
            return "file damage", (f"left {[os.path.relpath(x, casedir) for x in new]} " if new else "") + \
                (f"changed {[os.path.relpath(x, root) for x in changed]} " if changed else "") + \
                f"after {type(e).__name__}: {str(e)[:80]}"
        return outcome, note
    after = snapshot(fx.fdir)
    changed = sorted(k for k in before if k in after and before[k] != after[k] and k.startswith(fx.fdir))
    if changed:
        return "file damage", f"input changed: {[os.path.relpath(x, root) for x in changed]}"
    shown = repr(r)[:140].replace("\n", " ")
    if expect == "refuse":
        return ("NaN" if not finite(r) else "accepted bad"), f"{pname}={m}: {shown}"
    if not finite(r) and (base.get("finite", True) or m == "baseline"):
        return "NaN", f"{pname or ''}={m}: {shown}"
    if m in ("scale_tiny", "scale_huge"):
        sc = 1e-150 if m == "scale_tiny" else 1e150
        A, B = arrays(ref), arrays(r)
        if len(A) != len(B):
            return "wrong", "scaled result has another structure"
        for a, b in zip(A, B):
            if a.dtype.kind != "f":
                if a.shape != b.shape or not np.array_equal(a, b):
                    return "wrong", f"integer/bool output differs at scale {sc:g}"
                continue
            if not any(close(b / sc ** q if q >= 0 else b * sc ** (-q), a) for q in (0, 1, 2, 3, -1, -2)):
                return "wrong", f"not baseline*s^p at scale {sc:g}: {np.ravel(b)[:3]} vs {np.ravel(a)[:3]}"
        return "pass", ""
    if ref is not None and expect == "accept":
        A, B = arrays(ref), arrays(r)
        if m == "dim3":                                          # a leading axis of length 1 on every result
            B = [b[0] if b.ndim == a.ndim + 1 and b.shape[:1] == (1,) else b for a, b in zip(A, B)]
        same = len(A) == len(B) and all(
            a.shape == b.shape and (close(a, b) or (m in ("float32",) and np.allclose(
                np.asarray(a, float), np.asarray(b, float), rtol=1e-3, atol=1e-3))) for a, b in zip(A, B))
        if not same:
            return "wrong", f"{pname}={m} (a valid variant) answers differently from the baseline: {_diff(A, B)}"
    if expect == "either" and m != "baseline" and not m.startswith(("soup_", "cloud_")):
        return "review", f"{pname}={m} accepted: {shown[:80]}"
    return "pass", ""


# ------------------------------------------------------------------------------------------------ files
def prepare_files(root: str) -> None:
    """In a child: fixtures, one sample file per writer × extension, and the (reader, file) pairs that read."""
    import warnings

    warnings.simplefilter("ignore")
    fx = Fixtures(root)
    fx.prepare()
    d = os.path.join(root, "files")
    os.makedirs(d, exist_ok=True)
    written = {}
    for name, how, opts in _cases.sample_file_specs():
        try:
            exp = _cases.write_sample_file(fx, name, how, opts, d)
        except Exception:  # noqa: BLE001 - a format this writer does not write
            p = os.path.join(d, name)
            if os.path.exists(p):
                os.remove(p)
            continue
        written[name] = exp
        np.savez(os.path.join(d, name + ".expect.npz"),
                 **{k: (np.asarray(v[0]) if k == "curves" else np.asarray(v)) for k, v in exp.items()})
    pairs = []
    for rd in _cases.readers():
        obj, meth = _cases.resolve(rd)
        fn = getattr(obj, meth) if meth else obj
        for name in written:
            try:
                fn(os.path.join(d, name))
                pairs.append((rd, name))
            except Exception:  # noqa: BLE001
                pass
    with open(os.path.join(root, "pairs.json"), "w") as fh:
        json.dump(pairs, fh)
    with open(os.path.join(root, "written.json"), "w") as fh:
        json.dump(sorted(written), fh)


def _triangles(T: np.ndarray, oriented: bool) -> np.ndarray:
    """Triangles (k, 3, 3) by their corners, in a canonical order (a reader may reorder faces): each rotated to
    start at its smallest corner (``oriented``: keeping the orientation; else its corners sorted), then sorted."""
    key = np.round(T, 6)
    if oriented:
        first = np.lexsort(key.transpose(2, 0, 1)[::-1], axis=-1)[:, 0] if len(T) else np.zeros(0, int)
        idx = (first[:, None] + np.arange(3)) % 3
        T, key = np.take_along_axis(T, idx[:, :, None], 1), np.take_along_axis(key, idx[:, :, None], 1)
    else:
        o = np.lexsort(key.transpose(2, 0, 1)[::-1], axis=-1)
        T, key = np.take_along_axis(T, o[:, :, None], 1), np.take_along_axis(key, o[:, :, None], 1)
    return T[np.lexsort(key.reshape(len(T), -1).T[::-1])]


def _roundtrip(r, exp: dict):
    """None when ``r`` (a reader's answer) holds what was written, else what differs."""
    if not exp:
        return None
    tol = 1e-6
    if "V" in exp and isinstance(r, tuple) and len(r) == 2 and r[1] is not None \
            and np.asarray(r[1]).dtype.kind in "iu":
        V, F = np.asarray(r[0]), np.asarray(r[1])
        oriented = "F" in exp
        a, b = _triangles(V[F], oriented), _triangles(exp["V"][exp["F" if oriented else "F_unoriented"]], oriented)
        if a.shape != b.shape or not np.allclose(a, b, atol=tol):
            return "mesh read back differs"
        return None
    pts = exp.get("P", exp.get("V"))
    if pts is not None and isinstance(r, tuple) and len(r) == 2:
        P = np.asarray(r[0], float)
        if P.shape != pts.shape:
            if P.ndim == 2 and {tuple(x) for x in np.round(P, 5)} == {tuple(x) for x in np.round(pts, 5)}:
                return None
            return f"points read back: shape {P.shape} vs {pts.shape}"
        if not np.allclose(P, pts, atol=tol):
            return "points read back differ"
        if r[1] is not None and "N" in exp:
            N = np.asarray(r[1], float)
            n1 = N / np.linalg.norm(N, axis=1, keepdims=True)
            n2 = exp["N"] / np.linalg.norm(exp["N"], axis=1, keepdims=True)
            if N.shape != exp["N"].shape or not np.allclose(n1, n2, atol=1e-5):
                return "normals read back differ"
        return None
    if "d" in exp and isinstance(r, dict):
        if "d" not in r or not np.allclose(np.asarray(r["d"], float), exp["d"], atol=tol):
            return "vertex data read back differs"
        return None
    if "curves" in exp:
        c = getattr(r, "curves", None)
        if not c or not np.array_equal(np.asarray(c[0]).ravel(), exp["curves"].ravel()):
            return "curves read back differ"
        return None
    if "values" in exp:
        v = getattr(r, "values", None)
        if v is None or not np.allclose(np.asarray(v, float).ravel(), exp["values"].ravel(), atol=tol):
            return "field values read back differ"
        return None
    return None


def _unread_change(m: str, r, fn, src: str) -> bool:
    """Whether the value mutation ``m`` (a changed number token, a tampered array of a saved state) hit a value the
    reader ignores: its answer on the changed file holds the same arrays, bit for bit, as on the unmodified one
    (e.g. ``inf`` in a PLY vertex property that ``read_mesh`` does not read, a tampered ``tori`` array of a
    Points-as-Tori state read by ``read_points``, which reads ``P`` and ``N`` only)."""
    if not (m.endswith("_token") or m in NPZ_MUTATIONS):
        return False
    a, b = arrays(r), arrays(fn(src))
    return bool(a) and len(a) == len(b) and all(x.shape == y.shape and x.dtype == y.dtype and np.array_equal(x, y)
                                                for x, y in zip(a, b))


def run_file_case(case: dict, root: str, tmap: dict):
    casedir = tempfile.mkdtemp(prefix="case-", dir=os.path.join(root, "cases"))
    os.chdir(casedir)
    src = os.path.join(root, "files", case["file"])
    if not os.path.exists(src):
        return "skip", f"no writer produced {case['file']}"
    with open(src, "rb") as fh:
        data = fh.read()
    obj, meth = _cases.resolve(case["target"])
    fn = getattr(obj, meth) if meth else obj
    m = case["mutation"]
    p = os.path.join(casedir, case["file"])
    expect = FILE_MUTATIONS.get(m) or NPZ_MUTATIONS.get(m) or "accept"
    if expect == "refuse" and m.endswith("_token") and not arrays(fn(src)):
        expect = "either"           # the reader takes nothing from this file (e.g. no vertex data in it)
    if m == "roundtrip":
        r = fn(src)
        with np.load(src + ".expect.npz") as z:
            exp = {k: z[k] for k in z.files}
        why = _roundtrip(r, exp)
        return ("wrong", why) if why else ("pass", "")
    try:
        if m in NPZ_MUTATIONS:
            tamper_npz(src, p, m)
        else:
            with open(p, "wb") as fh:
                fh.write(malform(data, m, case["file"]))
    except KeyError:
        return "skip", f"n/a: {m} does not apply to {case['file']}"
    with open(p, "rb") as fh:
        digest = hashlib.sha1(fh.read()).hexdigest()
    before = set(os.listdir(casedir))
    try:
        r = fn(p)
    except BaseException as e:  # noqa: BLE001
        res = classify_exception(e, m, expect)
    else:
        if not finite(r):
            res = ("NaN", repr(r)[:120])
        elif expect == "refuse" and _unread_change(m, r, fn, src):
            res = ("pass", f"{m} changed a value this reader does not read (same answer as the unmodified file)")
        elif expect == "refuse":
            res = ("accepted bad", repr(r)[:120].replace("\n", " "))
        elif expect == "either":
            res = ("review", "read: " + repr(r)[:100].replace("\n", " "))
        else:
            res = ("pass", "")
    with open(p, "rb") as fh:
        if hashlib.sha1(fh.read()).hexdigest() != digest:
            return "file damage", "the reader modified its input"
    if set(os.listdir(casedir)) - before:
        return "file damage", f"the reader left {sorted(set(os.listdir(casedir)) - before)}"
    return res


# ------------------------------------------------------------------------------------------------ CLI
SPEED = {"resolution": 8, "n_points": 200, "layers": 2, "size": "16", "max_iterations": 1, "heat_resolution": 8}
ROLE_FILES = {"input": "mesh.off", "mesh": "mesh.off", "a": "mesh.off", "b": "mesh2.off", "cloud": "cloud.xyz",
              "points": "cloud.xyz", "queries": "queries.npy", "curves": "curves.obj", "curves_path": "curves.obj",
              "files": "mesh.off", "inputs": "in_dir"}
#: other valid files for a role, tried when a command refuses the first (the refusal stays reported: the
#: command's baseline case is "refused valid")
ROLE_ALTERNATIVES = {"curves.obj": ["curves_swn.txt", "curves.txt"]}


def _ext_from_help(p) -> str:
    m = re.search(r"\.(npz|npy|ply|obj|off|svg|png|vtk|vti|vtu|stl|txt)\b", p.help or "") or \
        re.search(r"\b(NPZ|NPY|PLY|OBJ|OFF|SVG|PNG|VTK|STL)\b", p.help or "")
    return "." + m.group(1).lower() if m else ""


def cli_baseline_argv(cmd):
    """A valid argv of ``cmd`` built from its parameters' names and types (None: an argument without a role)."""
    import click

    outs = _cases.output_params()
    argv = []
    for p in cmd.params:
        if isinstance(p, click.Argument):
            f = ROLE_FILES.get(p.name)
            if f is None:
                return None
            argv.append(f)
    for p in cmd.params:
        if not isinstance(p, click.Option) or getattr(p, "hidden", False):
            continue
        flag = max(p.opts, key=len)
        if p.name in outs and (p.required or p.name in ("output", "output_dir")):
            if p.name == "output_dir":
                argv += [flag, "out_dir"]
            else:
                argv += [flag, "result" + (_ext_from_help(p) or ".npz")]
        elif p.required and isinstance(p.type, click.Choice):
            argv += [flag, p.type.choices[0]]
        elif p.name in SPEED and not (isinstance(p, click.Option) and p.is_flag):
            lo = getattr(p.type, "min", None) or 0
            v = SPEED[p.name]
            argv += [flag, str(max(lo, v)) if isinstance(v, int) else v]
        elif p.name == "curves_path":
            argv += [flag, ROLE_FILES["curves_path"]]
        elif p.name == "quiet":
            argv += [flag]
    return argv


def prepare_cli_dir(fx: Fixtures, d: str) -> None:
    for f in ("mesh.off", "mesh2.off", "cloud.xyz", "curves.obj", "curves.txt", "curves_swn.txt", "queries.npy"):
        shutil.copy(fx.path(f), d)
    os.makedirs(os.path.join(d, "in_dir"))
    shutil.copy(fx.path("mesh.off"), os.path.join(d, "in_dir", "m.off"))


def run_cli_inprocess(cmdname: str, argv: list, casedir: str, outdir: str):
    """Run ``gsdf <cmdname> <argv>`` in this (forked) process; returns (exit code, stdout, stderr)."""
    from tests.fuzz._cases import cli_group

    so, se = os.path.join(outdir, "stdout"), os.path.join(outdir, "stderr")
    sys.stdout.flush(), sys.stderr.flush()
    fo, fe = os.open(so, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), os.open(se, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    save1, save2 = os.dup(1), os.dup(2)
    os.dup2(fo, 1), os.dup2(fe, 2)
    sys.stdout = io.TextIOWrapper(os.fdopen(os.dup(1), "wb"), write_through=True)
    sys.stderr = io.TextIOWrapper(os.fdopen(os.dup(2), "wb"), write_through=True)
    os.chdir(casedir)
    rc = 0
    try:
        cli_group().main(args=[cmdname, *argv], prog_name="gsdf", standalone_mode=True)
    except SystemExit as e:
        rc = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    except BaseException:  # noqa: BLE001 - what Python would print for an uncaught exception
        traceback.print_exc()
        rc = 1
    sys.stdout.flush(), sys.stderr.flush()
    os.dup2(save1, 1), os.dup2(save2, 2)
    with open(so, errors="replace") as fh:
        out = fh.read()
    with open(se, errors="replace") as fh:
        err = fh.read()
    return rc, out, err


def run_cli_subprocess(cmdname: str, argv: list, casedir: str, env: dict, timeout: float):
    import subprocess

    import gsdf

    src = os.path.dirname(os.path.dirname(gsdf.__file__))
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(env, PYTHONPATH=os.pathsep.join([src, os.path.dirname(repo)] +
                                               [x for x in os.environ.get("PYTHONPATH", "").split(os.pathsep) if x]))
    code = "import sys; from gsdf.cli.main import main; sys.argv[0] = 'gsdf'; main()"
    p = subprocess.run([sys.executable, "-c", code, cmdname, *argv], cwd=casedir, env=env, capture_output=True,
                       text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def _cli_path_mutation(cur: str, m: str, casedir: str) -> str:
    ext = os.path.splitext(cur)[1] or ".off"
    name = {"missing": "missing", "directory": "dir", "fifo": "pipe", "dev_zero": "zero", "empty_file": "empty",
            "garbage": "garbage"}[m] + ext
    p = os.path.join(casedir, name)
    if m == "directory":
        os.makedirs(p, exist_ok=True)
    elif m == "fifo":
        os.mkfifo(p)
    elif m == "dev_zero":
        os.symlink("/dev/zero", p)
    elif m == "empty_file":
        open(p, "wb").close()
    elif m == "garbage":
        from tests.fuzz._mutations import garbage_bytes

        with open(p, "wb") as fh:
            fh.write(garbage_bytes(4096, 3))
    return name


def _bad_outputs(new: list, casedir: str):
    """NaN / inf in a numeric output file written by a command (None: none found)."""
    for k in new:
        try:
            if k.endswith((".npz", ".npy")):
                z = np.load(k, allow_pickle=False)
                arrs = [z[n] for n in z.files] if hasattr(z, "files") else [z]
                if any(a.dtype.kind in "fc" and not np.isfinite(a).all() for a in arrs):
                    return os.path.relpath(k, casedir)
            elif k.endswith((".txt", ".csv", ".off", ".obj", ".xyz", ".svg", ".ply", ".vtk", ".vtu")) \
                    and os.path.getsize(k) < 50 << 20:
                with open(k, "rb") as fh:
                    head = fh.read()
                if re.search(rb"(?<![\w.])-?(nan|inf)(?![\w])", head, re.I):
                    return os.path.relpath(k, casedir)
        except Exception:  # noqa: BLE001
            continue
    return None


def find_cli_baseline(name: str, root: str, timeout: float) -> dict:
    """In a child: run the built argv; an extension the command asks for replaces ours; an option the command says
    does not apply is dropped (up to 6 tries). Cached in root/baselines/cli-<name>.json."""
    import click

    cmd = _cases.cli_group().commands[name]
    argv = cli_baseline_argv(cmd)
    fx = Fixtures(root)
    res = {"error": "no role file for an argument"}
    tried, first_refusal = set(), None
    for _ in range(10):
        if argv is None:
            break
        d = tempfile.mkdtemp(prefix="clibase-", dir=os.path.join(root, "cases"))
        prepare_cli_dir(fx, d)
        t0 = time.time()
        io_d = tempfile.mkdtemp(prefix="io-", dir=os.path.join(root, "cases"))
        pid = os.fork()                      # each try in its own process (a command may change this one)
        if pid == 0:
            code = 1
            try:
                rc, out, err = run_cli_inprocess(name, argv, d, io_d)
                with open(os.path.join(io_d, "result.json"), "w") as fh:
                    json.dump([rc, out[-2000:], err[-4000:]], fh)
                code = 0
            finally:
                os._exit(code)
        os.waitpid(pid, 0)
        try:
            with open(os.path.join(io_d, "result.json")) as fh:
                rc, out, err = json.load(fh)
        except OSError:
            res = {"error": "the baseline run died", "argv": argv}
            break
        if rc == 0:
            res = {"argv": argv, "seconds": time.time() - t0}
            if first_refusal:
                res["refused_first"] = first_refusal
            break
        ext = re.search(r"(?:extensions?|one of|expected)[^.\n]*?(\.[a-z0-9]+)", err)
        cur = [a for a in argv if a.startswith("result.")]
        if ext and cur and not cur[0].endswith(ext.group(1)):
            argv[argv.index(cur[0])] = "result" + ext.group(1)
            continue
        flags = [f for f in re.findall(r"--[\w-]+", err) if f in argv]
        if flags:
            i = argv.index(flags[0])
            takes_value = not any(isinstance(q, click.Option) and q.is_flag and flags[0] in q.opts
                                  for q in cmd.params)
            del argv[i: i + (2 if takes_value else 1)]
            continue
        alt = [a for a in argv if a in ROLE_ALTERNATIVES and a in err and a not in tried]
        if alt and "Traceback" not in err:        # the command refuses a conventional file: try another one
            tried.add(alt[0])
            first_refusal = first_refusal or err.strip().splitlines()[-1][:200]
            nxt = [f for f in ROLE_ALTERNATIVES[alt[0]] if f not in tried]
            if nxt:
                argv[argv.index(alt[0])] = nxt[0]
                tried.add(nxt[0])
                continue
        speed = [f for f in argv if f.startswith("--") and f[2:].replace("-", "_") in SPEED]
        if speed and "Traceback" not in err:     # a speed value the command does not take: its default then
            i = argv.index(speed[0])
            del argv[i: i + 2]
            continue
        last = err.strip().splitlines()[-1][:200] if err.strip() else f"exit {rc}"
        res = {"refused": last, "argv": argv, "traceback": "Traceback" in err}
        break
    with open(os.path.join(root, "baselines", f"cli-{name}.json"), "w") as fh:
        json.dump(res, fh)
    return res


def run_cli_case(case: dict, root: str, tmap: dict, timeout: float = 60.0):
    """Executed in a forked child: a ``gsdf`` command in a fresh folder holding copies of the role files."""
    import click

    fx = Fixtures(root)
    casedir = tempfile.mkdtemp(prefix="cli-", dir=os.path.join(root, "cases"))
    iodir = tempfile.mkdtemp(prefix="io-", dir=os.path.join(root, "cases"))
    prepare_cli_dir(fx, casedir)
    cmd = _cases.cli_group().commands[case["command"]]
    bpath = os.path.join(root, "baselines", "cli-" + case["command"] + ".json")
    if not os.path.exists(bpath):
        return "skip", "no baseline computed"
    with open(bpath) as fh:
        base = json.load(fh)
    m, pname, where, expect = case["mutation"], case.get("param"), case.get("where"), case["expect"]
    if "refused" in base:
        if m == "baseline":
            kind = "leak" if base.get("traceback") else "refused valid"
            return kind, f"gsdf {case['command']} {' '.join(base['argv'])}: {base['refused']}"
        return "skip", "no baseline (the command refused its baseline)"
    if "error" in base:
        return "skip", "no baseline (coverage gap): " + base["error"]
    if m == "baseline" and base.get("refused_first"):
        return "refused valid", f"gsdf {case['command']} with the conventional file: {base['refused_first']}"
    argv = list(base["argv"])
    p = next((q for q in cmd.params if q.name == pname), None)
    args_names = [q.name for q in cmd.params if isinstance(q, click.Argument)]
    outs = _cases.output_params()

    def set_opt(val):
        if where in argv:
            argv[argv.index(where) + 1] = val
        else:
            argv.extend([where, val])

    env = None
    if m == "baseline":
        pass
    elif where == "env":
        env = dict(os.environ, **{pname: m[1:]})
    elif m.startswith("file:"):
        fm = m[5:]
        if where == "arg":
            idx = args_names.index(pname)
            cur = argv[idx]
        else:
            cur = argv[argv.index(where) + 1] if where in argv else ROLE_FILES.get(pname, "mesh.off")
        src = os.path.join(casedir, cur)
        if not os.path.isfile(src):
            return "skip", f"n/a: {cur} is not a file"
        with open(src, "rb") as fh:
            data = fh.read()
        try:
            bad = malform(data, fm, cur)
        except KeyError:
            return "skip", f"n/a: {fm} does not apply to {cur}"
        newname = "bad_" + os.path.basename(cur)
        with open(os.path.join(casedir, newname), "wb") as fh:
            fh.write(bad)
        if where == "arg":
            argv[idx] = newname
        else:
            set_opt(newname)
    elif where == "arg":
        idx = args_names.index(pname)
        argv[idx] = _cli_path_mutation(argv[idx], m, casedir)
    elif m.startswith("="):
        set_opt(m[1:])
    elif m == "flag_on":
        if where not in argv:
            argv.append(where)
    elif pname in outs:
        cur = argv[argv.index(where) + 1] if where in argv else None
        ext = _ext_from_help(p) or (os.path.splitext(cur)[1] if cur else ".png")
        if pname == "output_dir":
            ext = ""
        main_out = next((argv[i + 1] for i, a in enumerate(argv) if a in ("--output", "--output-dir")), None)
        if m == "same_as_input":
            if not args_names:
                return "skip", "n/a: the command has no input argument"
            val = argv[0]
        elif m == "directory":
            val = "adir" + ext
            os.makedirs(os.path.join(casedir, val), exist_ok=True)
            if pname == "output_dir":
                with open(os.path.join(casedir, val, "keep.txt"), "w") as fh:
                    fh.write("x")            # a non-empty folder (an empty one is a valid output folder)
        elif m == "bad_ext":
            if pname == "output_dir":
                return "skip", "n/a: a folder has no extension"
            val = "result.badext"
        elif m == "nested_new":
            val = os.path.join("n1", "n2", "r" + ext)
        elif m == "same_as_other_output":
            if main_out is None or where in ("--output", "--output-dir"):
                return "skip", "n/a: no other output"
            val = main_out
        elif m == "existing_no_clobber":
            if not any(q.name == "no_clobber" for q in cmd.params):
                return "skip", "n/a: the command has no --no-clobber"
            val = cur or ("existing" + ext)
            if pname == "output_dir":
                return "skip", "n/a: --no-clobber on a folder"
            with open(os.path.join(casedir, val), "w") as fh:
                fh.write("keep me\n")
            argv.append("--no-clobber")
        else:
            return "skip", f"n/a: {m}"
        if m == "directory" and pname == "output_dir":
            expect = "either"                # writing into an existing folder is allowed
        set_opt(val)
    else:
        cur = argv[argv.index(where) + 1] if where in argv else "curves.obj"
        set_opt(_cli_path_mutation(cur, m, casedir))
    before = snapshot(casedir)
    cmdline = f"gsdf {case['command']} {' '.join(argv)}"
    if env is not None:
        try:
            rc, out, err = run_cli_subprocess(case["command"], argv, casedir, env, timeout)
        except Exception:  # noqa: BLE001 - TimeoutExpired
            return "hang", f"no exit in {timeout:g} s: {pname}={m[1:]} {cmdline}"[:240]
        cmdline = f"{pname}={m[1:]} " + cmdline
    else:
        rc, out, err = run_cli_inprocess(case["command"], argv, casedir, iodir)
    after = snapshot(casedir)
    changed = [k for k in before if k in after and before[k] != after[k] and before[k] != "dir"]
    gone = [k for k in before if k not in after and before[k] != "dir"]
    new = [k for k in after if k not in before and not k.endswith("/")]
    last = err.strip().splitlines()[-1][:160] if err.strip() else f"exit {rc}"
    if m == "existing_no_clobber":
        changed = [k for k in changed if not k.endswith("existing" + ext)] if rc == 0 else changed
    if changed or gone:
        return "file damage", f"input changed {[os.path.relpath(k, casedir) for k in changed + gone]}: " \
                              f"{cmdline}"[:240]
    if rc < 0 or rc >= 128:
        return "crash", f"rc={rc}: {cmdline}"[:240]
    if "Traceback (most recent call last)" in err:
        return "leak", f"{last}: {cmdline}"[:240]
    # gsdf batch exits 3 when the run finished but items failed (docs/decisions.md, Robustness): its manifest,
    # which records the failures for the next run, is the run's record, not a half-done output
    finished_with_failures = case["command"] == "batch" and rc == 3 and new and all(
        os.path.basename(k) == "manifest.jsonl" for k in new)
    if rc != 0:
        if new and not finished_with_failures:
            return "file damage", f"rc={rc} left {[os.path.relpath(k, casedir) for k in new]}: {cmdline}"[:240]
        msg = "\n".join(x for x in err.strip().splitlines() if x.startswith("Error"))
        if ERRNO.search(msg) or INTERNALS.search(msg.replace("Error: ", "", 1)):
            return "leak", f"{last}: {cmdline}"[:240]
        if expect == "accept":
            return "refused valid", f"{last}: {cmdline}"[:240]
        return "pass", last
    bad = _bad_outputs(new, casedir)
    if bad:
        return "NaN", f"{bad}: {cmdline}"[:240]
    if expect == "refuse":
        return "accepted bad", f"exit 0: {cmdline}"[:240]
    if expect == "either" and m not in ("baseline", "flag_on"):
        return "review", f"exit 0: {cmdline}"[:240]
    return "pass", ""
