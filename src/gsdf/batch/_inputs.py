"""Turn a batch's INPUTS (a folder, a glob, a list file, a CSV/JSON table, or a list of paths) into items.

An item is one input file, its output path relative to the output folder (the input's path relative to the
inputs' root, extension replaced by ``.npz``: a mirrored folder layout) and its per-item task options (from
CSV columns or JSON fields). When two inputs differ only by extension (``a.obj``, ``a.ply``) both keep it
(``a.obj.npz``, ``a.ply.npz``).
"""

from __future__ import annotations

import csv
import glob
import json
import os
from dataclasses import dataclass, field

from gsdf.io._mesh import MESH_FORMATS
from gsdf.io._points import POINTS_READ_FORMATS

INPUT_EXTENSIONS = tuple(sorted(set(MESH_FORMATS) | set(POINTS_READ_FORMATS)))
LIST_EXTENSIONS = (".txt", ".lst", ".list")
TABLE_EXTENSIONS = (".csv", ".json", ".jsonl")


@dataclass
class Item:
    """One input of a batch: ``path`` (absolute), ``output`` (relative ``.npz`` path), per-item ``options``."""

    path: str
    output: str
    options: dict = field(default_factory=dict)


def _is_glob(text: str) -> bool:
    return any(ch in text for ch in "*?[")


def _glob_root(pattern: str) -> str:
    parts = os.path.normpath(pattern).split(os.sep)
    fixed = []
    for p in parts:
        if _is_glob(p):
            break
        fixed.append(p)
    root = os.sep.join(fixed) or "."
    return os.path.abspath(root if os.path.isdir(root) else os.path.dirname(root) or ".")


def _input_files(folder: str) -> list[str]:
    found = []
    for base, dirs, files in os.walk(folder):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        found += [os.path.join(base, f) for f in sorted(files)
                  if not f.startswith(".") and os.path.splitext(f)[1].lower() in INPUT_EXTENSIONS
                  and os.path.isfile(os.path.join(base, f))]  # regular files only (no FIFO / device / socket)
    return found


def _read_list(path: str) -> list[tuple[str, dict]]:
    with open(path, encoding="utf-8") as fh:
        lines = [ln.strip() for ln in fh]
    return [(ln, {}) for ln in lines if ln and not ln.startswith("#")]


def _row(obj, where: str) -> tuple[str, dict]:
    if isinstance(obj, str):
        return obj, {}
    if not isinstance(obj, dict) or not isinstance(obj.get("path"), str):
        raise ValueError(f"{where}: expected a path or an object with a \"path\" field, got {obj!r}")
    opts = {k: v for k, v in obj.items() if k != "path"}
    return obj["path"], opts


def _read_table(path: str) -> list[tuple[str, dict]]:
    ext = os.path.splitext(path)[1].lower()
    rows = []
    try:
        if ext == ".csv":
            with open(path, newline="", encoding="utf-8") as fh:
                reader = csv.DictReader(fh)
                if not reader.fieldnames or "path" not in reader.fieldnames:
                    raise ValueError(f"{path}: a CSV manifest needs a 'path' column (got {reader.fieldnames})")
                for i, r in enumerate(reader, start=2):
                    if None in r:
                        raise ValueError(f"{path}: line {i} has more cells than the header")
                    p = (r.pop("path") or "").strip()
                    if not p:
                        raise ValueError(f"{path}: line {i} has an empty path")
                    rows.append((p, {k.strip(): v.strip() for k, v in r.items() if v is not None and v.strip()}))
        elif ext == ".json":
            with open(path, encoding="utf-8") as fh:
                data = json.load(fh)
            if isinstance(data, dict) and "items" in data:
                data = data["items"]
            if not isinstance(data, list):
                raise ValueError(f"{path}: a JSON manifest must be a list of paths or objects (or {{\"items\": [...]}})")
            rows = [_row(obj, f"{path}: item {i}") for i, obj in enumerate(data)]
        else:
            with open(path, encoding="utf-8") as fh:
                for i, ln in enumerate(fh, start=1):
                    if ln.strip():
                        rows.append(_row(json.loads(ln), f"{path}: line {i}"))
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: malformed JSON ({exc})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text manifest (not UTF-8)") from None
    return rows


def _from_manifest(path: str) -> tuple[list[tuple[str, dict]], str]:
    ext = os.path.splitext(path)[1].lower()
    rows = _read_table(path) if ext in TABLE_EXTENSIONS else _read_list(path)
    base = os.path.dirname(os.path.abspath(path))
    out = []
    for p, opts in rows:
        q = p if os.path.isabs(p) else os.path.join(base, p)
        if not os.path.isfile(q):
            raise ValueError(f"{path}: lists {p!r}, which is not a file")
        out.append((os.path.abspath(q), opts))
    if not out:
        raise ValueError(f"INPUTS: the manifest {path} lists no inputs")
    root = os.path.commonpath([os.path.dirname(q) for q, _ in out])
    return out, root


def _outputs(paths: list[str], root: str) -> list[str]:
    rel = [os.path.relpath(p, root) for p in paths]
    stems = [os.path.splitext(r)[0] for r in rel]
    seen: dict[str, int] = {}
    for s in stems:
        seen[s] = seen.get(s, 0) + 1
    outs = [(s if seen[s] == 1 else r) + ".npz" for s, r in zip(stems, rel)]
    if len(set(outs)) != len(outs):
        dup = next(o for o in outs if outs.count(o) > 1)
        raise ValueError(f"INPUTS: the same input is listed twice (output {dup!r})")
    return outs


def _inside(path: str, folder: str) -> bool:
    """``path`` is ``folder`` or lies below it (real paths: symlinks resolved)."""
    p, f = os.path.realpath(path), os.path.realpath(folder)
    return p == f or p.startswith(f.rstrip(os.sep) + os.sep)


def check_output_folder(inputs, items: list[Item], out) -> None:
    """Refuse an output folder that would feed a batch its own outputs: ``out`` equal to or inside the folder
    (or a glob's fixed root folder) that INPUTS searches — the ``.npz`` outputs are readable inputs, so the next
    run would take them as items — and any listed input that lies inside ``out``."""
    if isinstance(inputs, (str, os.PathLike)):
        text = os.fspath(inputs)
        root = text if os.path.isdir(text) else _glob_root(text) if _is_glob(text) and not os.path.isfile(text) \
            else None
        if root is not None and _inside(out, root):
            where = "is" if os.path.realpath(out) == os.path.realpath(root) else "is inside"
            raise ValueError(f"out: the output folder {out} {where} the input folder {root}: its outputs would be "
                             "read as inputs by the next run; choose an output folder outside the inputs")
    for it in items:
        if _inside(it.path, out):
            raise ValueError(f"INPUTS: {it.path} lies inside the output folder {out}; choose an output folder "
                             "that holds no inputs")


def collect_inputs(inputs) -> list[Item]:
    """The items of a batch.

    Parameters
    ----------
    inputs : str, os.PathLike or sequence of paths
        A folder (searched recursively for mesh and point-cloud files, hidden ones skipped), a glob pattern
        (``"data/**/*.off"``, recursive), a manifest file — ``.txt``/``.lst``/``.list`` with one path per
        line, ``.csv`` with a ``path`` column and option columns, ``.json`` (a list of paths or of objects
        with ``path`` and options) or ``.jsonl`` (one per line) — a single input file, or a list of paths.
        Relative paths in a manifest are relative to the manifest's folder.

    Returns
    -------
    list of Item
        Sorted as found; outputs mirror the inputs' layout below their common root.

    Raises
    ------
    ValueError
        Nothing to do (empty folder, a glob matching no file, an empty manifest), a missing path, a malformed
        manifest, or a file that is neither an input nor a manifest.

    Example
    -------
    >>> items = collect_inputs("meshes/")           # doctest: +SKIP
    >>> items[0].output                              # doctest: +SKIP
    'chairs/0001.npz'
    """
    if isinstance(inputs, (list, tuple)):
        if not inputs:
            raise ValueError("INPUTS: the list of inputs is empty")
        paths = []
        for p in inputs:
            if not isinstance(p, (str, os.PathLike)) or not os.path.isfile(p):
                raise ValueError(f"INPUTS: {p!r} is not a file")
            paths.append(os.path.abspath(p))
        root = os.path.commonpath([os.path.dirname(p) for p in paths])
        rows = [(p, {}) for p in paths]
    elif isinstance(inputs, (str, os.PathLike)):
        text = os.fspath(inputs)
        if os.path.isdir(text):
            files = _input_files(text)
            if not files:
                raise ValueError(f"INPUTS: the folder {text} holds no mesh or point-cloud files "
                                 f"({', '.join(INPUT_EXTENSIONS)})")
            root, rows = os.path.abspath(text), [(os.path.abspath(f), {}) for f in files]
        elif os.path.isfile(text):
            ext = os.path.splitext(text)[1].lower()
            if ext in LIST_EXTENSIONS + TABLE_EXTENSIONS:
                rows, root = _from_manifest(text)
            elif ext in INPUT_EXTENSIONS:
                p = os.path.abspath(text)
                rows, root = [(p, {})], os.path.dirname(p)
            else:
                raise ValueError(f"INPUTS: {text} is neither an input ({', '.join(INPUT_EXTENSIONS)}) nor a "
                                 f"manifest ({', '.join(LIST_EXTENSIONS + TABLE_EXTENSIONS)})")
        elif _is_glob(text):
            files = sorted(f for f in glob.glob(text, recursive=True) if os.path.isfile(f))
            if not files:
                raise ValueError(f"INPUTS: the glob {text!r} matches no file")
            root, rows = _glob_root(text), [(os.path.abspath(f), {}) for f in files]
        else:
            raise ValueError(f"INPUTS: {text} does not exist")
    else:
        raise ValueError(f"INPUTS: expected a folder, glob, manifest or list of paths, got {type(inputs).__name__}")
    outs = _outputs([p for p, _ in rows], root)
    return [Item(p, o, opts) for (p, opts), o in zip(rows, outs)]
