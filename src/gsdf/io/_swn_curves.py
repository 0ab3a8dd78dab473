"""Curve files of the surface-winding-number demo (nzfeng/SWN) and OBJ ``l`` lines, as surface points + segments.

Two formats, told apart by their node lines:

- the demo's barycentric curve files (``.txt``)::

      #offset 0          index base of the following lines (0: indices as written)
      v i                node at mesh vertex i
      e i t              node on mesh edge i at parameter t ∈ [0, 1] from the edge's first vertex, edges numbered
                         as geometry-central numbers them for the same face list (order of first appearance over
                         faces and their sides v0v1, v1v2, v2v0 — :func:`gsdf.io._curves.gc_edges`)
      f i a b c          node in face i with barycentric coordinates (a, b, c)
      l j k ...          segments between consecutive *nodes* j, k, ... (node indices, in order of appearance)

  ``#``-comment lines (including commented-out segments ``#l``) and the demo's ``n`` lines (not part of the
  curve) are skipped; ``c`` (dual chains) is refused;
- OBJ files: ``l`` lines are polylines of 1-based mesh vertex indices (negative = relative); ``v x y z`` lines are
  mesh vertices and ignored here.

Example
-------
>>> import numpy as np, tempfile, os
>>> p = os.path.join(tempfile.mkdtemp(), "c.txt")
>>> _ = open(p, "w").write("#offset 0\\nv 0\\ne 2 0.5\\nl 0 1\\n")
>>> c = read_swn_curves(p, np.array([[0, 1, 2], [0, 2, 3]]))
>>> c.kinds.tolist(), c.segments.tolist()
(['v', 'e'], [[0, 1]])
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

__all__ = ["SWNCurves", "read_swn_curves"]

_OBJ_KEYS = {"v", "vt", "vn", "vp", "f", "g", "o", "s", "usemtl", "mtllib", "p", "cstype", "deg", "curv", "parm",
             "end", "mg", "lod", "bevel", "c_interp", "d_interp", "shadow_obj", "trace_obj", "usemap", "maplib"}


@dataclass
class SWNCurves:
    """Curve nodes as surface points and the segments between them.

    Attributes
    ----------
    kinds : (k,) str array, "v" (vertex), "e" (edge point) or "f" (face point)
    index : (k,) int, vertex / edge (geometry-central numbering) / face index
    params : (k, 3) float: edge nodes ``(t, 0, 0)`` with t measured from ``edge_vertices[:, 0]``; face nodes
        the barycentric coordinates; vertex nodes zeros
    edge_vertices : (k, 2) int, for edge nodes the (first, second) vertices t refers to; -1 otherwise
    segments : (s, 2) int, pairs of node indices
    """

    kinds: np.ndarray
    index: np.ndarray
    params: np.ndarray
    edge_vertices: np.ndarray
    segments: np.ndarray

    @property
    def on_vertices(self) -> bool:
        """All nodes are mesh vertices (the curves run along edges, no insertion needed)."""
        return bool(np.all(self.kinds == "v"))


def _int(tok, path, ln, what):
    try:
        v = float(tok)
    except ValueError:
        raise ValueError(f"{path}: line {ln}: {what} {tok!r} is not a number") from None
    if not np.isfinite(v) or v != int(v):
        raise ValueError(f"{path}: line {ln}: {what} {tok!r} is not an integer")
    return int(v)


def _float(tok, path, ln, what):
    try:
        v = float(tok)
    except ValueError:
        raise ValueError(f"{path}: line {ln}: {what} {tok!r} is not a number") from None
    if not np.isfinite(v):
        raise ValueError(f"{path}: line {ln}: {what} is NaN or infinite")
    return v


def read_swn_curves(path, F) -> SWNCurves:
    """Read a demo curve file or an OBJ with ``l`` lines, resolved against the mesh faces ``F`` (m, 3).

    Raises ValueError (with the path and line number) on unknown directives, malformed numbers, indices out of
    range, edge parameters outside [0, 1], segments naming missing nodes, or a file without segments.
    """
    from gsdf.io._curves import gc_edges

    from gsdf._checks import readable_file

    p = readable_file(path, "path")
    F = np.asarray(F, dtype=np.int64)
    n = int(F.max()) + 1 if F.size else 0
    m = len(F)
    with open(p, "rb") as fh:
        raw = fh.read()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"{p}: not a text curve file") from None
    lines = text.splitlines()
    # format: barycentric nodes when some 'v' line has exactly one field
    bary = any(ln.split()[:1] in (["e"], ["#offset"]) or (ln.split()[:1] == ["v"] and len(ln.split()) == 2)
               or (ln.split()[:1] == ["f"] and len(ln.split()) == 5 and "/" not in ln) for ln in lines)
    kinds, index, params, segs = [], [], [], []
    offset = 0
    gce = None
    for ln_no, line in enumerate(lines, 1):
        tok = line.split()
        if not tok:
            continue
        key = tok[0]
        if key == "#offset":
            if len(tok) != 2:
                raise ValueError(f"{p}: line {ln_no}: '#offset' needs one integer")
            offset = _int(tok[1], p, ln_no, "offset")
            continue
        if key.startswith("#"):
            continue
        if not bary:
            if key == "l":
                if len(tok) < 3:
                    raise ValueError(f"{p}: line {ln_no}: an 'l' line needs at least two vertices")
                idx = []
                for t in tok[1:]:
                    i = _int(t.split("/")[0], p, ln_no, "vertex index")
                    i = i - 1 if i > 0 else (n + i if i < 0 else -1)
                    if not 0 <= i < n:
                        raise ValueError(f"{p}: line {ln_no}: vertex index {t} out of range for {n} vertices")
                    idx.append(i)
                base = len(kinds)
                for i in idx:
                    kinds.append("v")
                    index.append(i)
                    params.append((0.0, 0.0, 0.0))
                segs += [(base + k, base + k + 1) for k in range(len(idx) - 1)]
                continue
            if key not in _OBJ_KEYS:
                raise ValueError(f"{p}: line {ln_no}: unknown directive {key!r}")
            continue                                           # other OBJ statements (v x y z, f, vn, ...)
        if key == "v":
            if len(tok) != 2:
                raise ValueError(f"{p}: line {ln_no}: 'v' takes one vertex index")
            i = _int(tok[1], p, ln_no, "vertex index") + offset
            if not 0 <= i < n:
                raise ValueError(f"{p}: line {ln_no}: vertex {i} out of range for {n} vertices")
            kinds.append("v")
            index.append(i)
            params.append((0.0, 0.0, 0.0))
        elif key == "e":
            if len(tok) != 3:
                raise ValueError(f"{p}: line {ln_no}: 'e' takes an edge index and a parameter")
            if gce is None:
                gce, _ = gc_edges(F)
            i = _int(tok[1], p, ln_no, "edge index") + offset
            t = _float(tok[2], p, ln_no, "edge parameter")
            if not 0 <= i < len(gce):
                raise ValueError(f"{p}: line {ln_no}: edge {i} out of range for {len(gce)} edges")
            if not -1e-9 <= t <= 1 + 1e-9:
                raise ValueError(f"{p}: line {ln_no}: edge parameter {t} outside [0, 1]")
            kinds.append("e")
            index.append(i)
            params.append((min(max(t, 0.0), 1.0), 0.0, 0.0))
        elif key == "f":
            if len(tok) != 5:
                raise ValueError(f"{p}: line {ln_no}: 'f' takes a face index and three barycentric coordinates")
            i = _int(tok[1], p, ln_no, "face index") + offset
            b = [_float(x, p, ln_no, "barycentric coordinate") for x in tok[2:]]
            if not 0 <= i < m:
                raise ValueError(f"{p}: line {ln_no}: face {i} out of range for {m} faces")
            if min(b) < -1e-9 or abs(sum(b) - 1) > 1e-6:
                raise ValueError(f"{p}: line {ln_no}: barycentric coordinates {b} are not in the face")
            kinds.append("f")
            index.append(i)
            params.append(tuple(b))
        elif key == "l":
            if len(tok) < 3:
                raise ValueError(f"{p}: line {ln_no}: an 'l' line needs at least two nodes")
            idx = [_int(t, p, ln_no, "node index") + offset for t in tok[1:]]
            segs += [(idx[k], idx[k + 1], ln_no) for k in range(len(idx) - 1)]
        elif key == "n":
            continue                                           # demo's per-curve annotations, not geometry
        elif key == "c":
            raise ValueError(f"{p}: line {ln_no}: dual chains ('c' lines) are not supported")
        else:
            raise ValueError(f"{p}: line {ln_no}: unknown directive {key!r}")
    if bary:
        k = len(kinds)
        for a, b, ln_no in segs:
            for x in (a, b):
                if not 0 <= x < k:
                    raise ValueError(f"{p}: line {ln_no}: segment names node {x}, but the file has {k} nodes")
        segs = [(a, b) for a, b, _ in segs]
    if not segs:
        raise ValueError(f"{p}: no curve segments ('l' lines) found")
    kinds = np.array(kinds)
    index = np.array(index, dtype=np.int64)
    params = np.array(params, dtype=np.float64).reshape(-1, 3)
    ev = np.full((len(kinds), 2), -1, dtype=np.int64)
    if gce is not None:
        ise = kinds == "e"
        ev[ise] = gce[index[ise]]
    return SWNCurves(kinds, index, params, ev, np.array(segs, dtype=np.int64).reshape(-1, 2))
