"""Curve files: one reader for the three formats curves on meshes come in.

1. The signed heat method's demo format (nzfeng/signed-heat-demo; one directive per line)::

       signed_curve [flip]      start an oriented curve (flip = 1 reverses it)
       unsigned_curve [flip]    start an unoriented curve (unsigned distance)
       unsigned_point           the following nodes are isolated point sources (also ``signed_point``)
       v i                      node at vertex i (0-based)
       e i t                    node on edge i at parameter t from its first vertex
       f i a b c                node in face i with barycentric coordinates (a, b, c)
       l i j k ...              OBJ polyline, 1-based vertex indices: appended to the current curve, or a new
                                signed curve when no curve block is open

   Lines that are none of these (e.g. ``v x y z`` of an OBJ mesh) are skipped.

2. The surface winding number demo's format (nzfeng/SWN)::

       #offset k                index base of the following lines (0: indices as written)
       v i / e i t / f i a b c  nodes, numbered in order of appearance
       l j k ...                a curve through the *nodes* j, k, ... (node indices, not vertices)
       n ...                    the demo's annotations: skipped; ``c`` (dual chains): refused

   ``#`` comments (including commented-out segments ``#l``) are skipped.

3. OBJ files: ``l`` lines are polylines of 1-based mesh vertex indices (negative: relative to the mesh's vertex
   count); ``v x y z`` and the other OBJ statements are skipped.

The format is told apart by its lines: a ``signed_curve`` / ``unsigned_curve`` / ``*_point`` line makes the
first; otherwise an ``#offset`` line, an ``e`` node, a ``v`` line with one field or an ``f`` line with four
numbers (no ``/``) makes the second; otherwise OBJ. Edges are numbered as geometry-central numbers them for the
same face list (order of first appearance over the faces and their sides v0v1, v1v2, v2v0: :func:`gc_edges`),
which is how both demos number them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["CurveSources", "SWNCurves", "read_curves", "read_swn_curves", "write_curves", "gc_edges"]

_HEAT_KEYS = {"signed_curve", "unsigned_curve", "unsigned_point", "signed_point"}
_OBJ_KEYS = {"v", "vt", "vn", "vp", "f", "g", "o", "s", "usemtl", "mtllib", "p", "cstype", "deg", "curv", "parm",
             "end", "mg", "lod", "bevel", "c_interp", "d_interp", "shadow_obj", "trace_obj", "usemap", "maplib"}


@dataclass
class SWNCurves:
    """Curve nodes as surface points and the segments between them (the form of the surface winding numbers).

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


class CurveSources:
    """Parsed curves: ``curves`` (list of vertex-index arrays or lists of (face, barycentric)), ``curve_signs``
    (list of bool) and ``points`` (vertex indices or (face, barycentric) tuples) — the arguments of
    ``SurfaceSignedHeatSolver.compute_distance``; :meth:`swn` gives the nodes and segments for
    :func:`gsdf.surface_winding_number`."""

    def __init__(self, curves, curve_signs, points, swn_curves=None):
        self.curves, self.curve_signs, self.points = curves, curve_signs, points
        self._swn = swn_curves

    def __repr__(self):
        return f"CurveSources({len(self.curves)} curves, {len(self.points)} points)"

    def swn(self) -> SWNCurves:
        """The curves as nodes and segments (consecutive nodes of every curve); point sources and unsigned
        curves have no meaning there and are refused."""
        if self._swn is None:
            raise ValueError("curves: the file has no curves for surface winding numbers")
        return self._swn


def gc_edges(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Edges in order of first appearance (faces in order, sides v0v1, v1v2, v2v0), each as (first, second)
    vertex of its first halfedge; and for each edge the flat index 3 f + side of its first halfedge."""
    F = np.asarray(F, dtype=np.int64)
    a = F.ravel()
    b = np.roll(F, -1, axis=1).ravel()
    n = int(F.max()) + 1
    key = np.minimum(a, b) * n + np.maximum(a, b)
    _, first = np.unique(key, return_index=True)
    first = np.sort(first)
    return np.stack([a[first], b[first]], axis=1), first


#: Tolerance of barycentric coordinates (as the surface solver's): each >= -BARY_TOL, their sum within BARY_TOL of 1.
BARY_TOL = 1e-6


def _check_vertex(i: int, n_vertices) -> int:
    if i < 0:
        raise ValueError(f"negative vertex index {i}")
    if n_vertices is not None and i >= n_vertices:
        raise ValueError(f"vertex index {i} out of range for a mesh of {n_vertices} vertices")
    return i


def _check_face_point(f: int, b: np.ndarray, n_faces) -> tuple:
    """A node ``f a b c``: face index in range, three finite barycentric coordinates of a point in the face."""
    if f < 0:
        raise ValueError(f"negative face index {f}")
    if n_faces is not None and f >= n_faces:
        raise ValueError(f"face index {f} out of range for {n_faces} faces")
    if b.size != 3:
        raise ValueError(f"a face node needs 3 barycentric coordinates, got {b.size}")
    if not np.isfinite(b).all():
        raise ValueError(f"barycentric coordinates are not finite: {b.tolist()}")
    if b.min() < -BARY_TOL or abs(b.sum() - 1.0) > BARY_TOL:
        raise ValueError(f"barycentric coordinates {b.tolist()} are not those of a point in the face (each >= 0, "
                         "sum 1)")
    return f, b


def _text(path) -> str:
    from gsdf._checks import readable_file

    path = readable_file(path, "path")
    with open(path, "rb") as fb:
        raw = fb.read()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ValueError(f"{path}:{line}: not a text curve file (undecodable byte 0x{raw[exc.start]:02x})") from None
    if "\x00" in text:
        raise ValueError(f"{path}:{text[:text.index(chr(0))].count(chr(10)) + 1}: not a text curve file (NUL byte)")
    return text


def _int(tok, where, what):
    try:
        v = float(tok)
    except ValueError:
        raise ValueError(f"{where}: {what} {tok!r} is not a number") from None
    if not np.isfinite(v) or v != int(v):
        raise ValueError(f"{where}: {what} {tok!r} is not an integer")
    return int(v)


def _float(tok, where, what):
    try:
        v = float(tok)
    except ValueError:
        raise ValueError(f"{where}: {what} {tok!r} is not a number") from None
    if not np.isfinite(v):
        raise ValueError(f"{where}: {what} is NaN or infinite")
    return v


class _Mesh:
    """What the nodes are checked and resolved against: the faces (optional)."""

    def __init__(self, F):
        from gsdf._checks import MAX_INT, as_faces

        self.F = None if F is None else as_faces(F, MAX_INT, "F", allow_empty=True)
        self.n = int(self.F.max()) + 1 if self.F is not None and self.F.size else None
        self.m = None if self.F is None else len(self.F)
        self._gce = None

    def edges(self, where):
        if self.F is None:
            raise ValueError(f"{where}: edge nodes 'e i t' need the mesh faces (pass F)")
        if self._gce is None:
            self._gce = gc_edges(self.F)
        return self._gce


def _node(key, args, mesh, where, offset=0):
    """A node ``(kind, index, params (3,), edge vertices (2,))`` from a ``v`` / ``e`` / ``f`` line."""
    if key == "v":
        if len(args) != 1:
            raise ValueError(f"{where}: 'v' takes one vertex index")
        i = _int(args[0], where, "vertex index") + offset
        if i < 0:
            raise ValueError(f"{where}: negative vertex index {i}")
        if mesh.n is not None and i >= mesh.n:
            raise ValueError(f"{where}: vertex {i} out of range for {mesh.n} vertices")
        return ("v", i, (0.0, 0.0, 0.0), (-1, -1))
    if key == "e":
        if len(args) != 2:
            raise ValueError(f"{where}: 'e' takes an edge index and a parameter")
        gce, _ = mesh.edges(where)
        i = _int(args[0], where, "edge index") + offset
        t = _float(args[1], where, "edge parameter")
        if not 0 <= i < len(gce):
            raise ValueError(f"{where}: edge {i} out of range for {len(gce)} edges")
        if not -1e-9 <= t <= 1 + 1e-9:
            raise ValueError(f"{where}: edge parameter {t} outside [0, 1]")
        return ("e", i, (min(max(t, 0.0), 1.0), 0.0, 0.0), (int(gce[i, 0]), int(gce[i, 1])))
    if len(args) != 4:
        raise ValueError(f"{where}: 'f' takes a face index and three barycentric coordinates")
    i = _int(args[0], where, "face index") + offset
    b = tuple(_float(x, where, "barycentric coordinate") for x in args[1:])
    if i < 0:
        raise ValueError(f"{where}: negative face index {i}")
    if mesh.m is not None and i >= mesh.m:
        raise ValueError(f"{where}: face {i} out of range for {mesh.m} faces")
    if min(b) < -1e-9 or abs(sum(b) - 1) > 1e-6:
        raise ValueError(f"{where}: barycentric coordinates {list(b)} are not in the face")
    return ("f", i, b, (-1, -1))


def _obj_vertices(args, mesh, where):
    idx = []
    for t in args:
        i = _int(t.split("/")[0], where, "vertex index")
        if i < 0 and mesh.n is not None:
            i = mesh.n + i + 1
        if i <= 0:
            raise ValueError(f"{where}: OBJ line indices must be positive (1-based), got {t}")
        if mesh.n is not None and i > mesh.n:
            raise ValueError(f"{where}: vertex index {t} out of range for {mesh.n} vertices")
        idx.append(("v", i - 1, (0.0, 0.0, 0.0), (-1, -1)))
    return idx


def _format(lines) -> str:
    heat = swn = False
    for _, tok, raw in lines:
        if tok[0] in _HEAT_KEYS:
            heat = True
        elif (tok[0] in ("#offset", "e") or (tok[0] == "v" and len(tok) == 2)
              or (tok[0] == "f" and len(tok) == 5 and "/" not in raw)):
            swn = True
    return "heat" if heat else "swn" if swn else "obj"


def _parse(path, F):
    """(format, curves as node lists, signs, point nodes)."""
    mesh = _Mesh(F)
    lines = []
    for ln, raw in enumerate(_text(path).splitlines(), 1):
        s = raw.strip()
        tok = s.split() if s.startswith("#offset") else s.split("#", 1)[0].split()
        if tok:
            lines.append((ln, tok, raw))
    fmt = _format(lines)
    curves, signs, flips, points, nodes = [], [], [], [], []
    mode, offset = None, 0
    for ln, tok, raw in lines:
        key, args = tok[0], tok[1:]
        where = f"{path}:{ln}"
        try:
            if fmt == "heat":
                if key in ("signed_curve", "unsigned_curve"):
                    curves.append([])
                    signs.append(key == "signed_curve")
                    flip = _int(args[0], where, "flip") if args else 0
                    if flip not in (0, 1):
                        raise ValueError(f"flip: expected 0 or 1, got {args[0]!r}")
                    flips.append(bool(flip))
                    mode = "curve"
                elif key in ("unsigned_point", "signed_point"):
                    mode = "points"
                elif key == "l":
                    idx = _obj_vertices(args, mesh, where)
                    if mode == "curve":
                        curves[-1].extend(idx)
                    else:
                        curves.append(idx)
                        signs.append(True)
                        flips.append(False)
                elif key in ("v", "e", "f") and mode is not None:
                    node = _node(key, args, mesh, where)
                    (curves[-1] if mode == "curve" else points).append(node)
            elif fmt == "swn":
                if key == "#offset":
                    if len(args) != 1:
                        raise ValueError("'#offset' needs one integer")
                    offset = _int(args[0], where, "offset")
                elif key in ("v", "e", "f"):
                    nodes.append(_node(key, args, mesh, where, offset))
                elif key == "l":
                    if len(args) < 2:
                        raise ValueError("an 'l' line needs at least two nodes")
                    curves.append([(_int(t, where, "node index") + offset, ln) for t in args])
                    signs.append(True)
                    flips.append(False)
                elif key == "c":
                    raise ValueError("dual chains ('c' lines) are not supported")
                elif key != "n":                      # the demo's per-curve annotations, not geometry
                    raise ValueError(f"unknown directive {key!r}")
            else:
                if key == "l":
                    if len(args) < 2:
                        raise ValueError("an 'l' line needs at least two vertices")
                    curves.append(_obj_vertices(args, mesh, where))
                    signs.append(True)
                    flips.append(False)
                elif key not in _OBJ_KEYS:
                    raise ValueError(f"unknown directive {key!r}")
        except (IndexError, ValueError) as exc:
            msg = str(exc)
            if msg.startswith(where + ": "):
                msg = msg[len(where) + 2:]
            raise ValueError(f"{where}: cannot parse {raw.strip()!r} ({msg})") from None
    if fmt == "swn":  # node indices -> nodes (the curves keep their node indices: closed loops share nodes)
        for c in curves:
            for j, ln in c:
                if not 0 <= j < len(nodes):
                    raise ValueError(f"{path}:{ln}: segment names node {j}, but the file has {len(nodes)} nodes")
        curves = [[j for j, _ in c] for c in curves]
    else:  # equal nodes are one node (a closed curve of surface points repeats its first one)
        index = {}
        for c in curves:
            for n in c:
                if n not in index:
                    index[n] = len(nodes)
                    nodes.append(n)
        curves = [[index[n] for n in c] for c in curves]
    curves = [c[::-1] if flip else c for c, flip in zip(curves, flips)]
    return fmt, nodes, curves, signs, points, mesh


def _surface_point(node, mesh):
    kind, i, p, ev = node
    if kind == "v":
        return i, ()                                  # a vertex, as (vertex, ()) — see compute_distance
    if kind == "f":
        return i, np.array(p)
    _, first = mesh.edges("")
    f, s = divmod(int(first[i]), 3)
    bary = np.zeros(3)
    bary[s], bary[(s + 1) % 3] = 1 - p[0], p[0]
    return f, bary


def read_curves(path, F=None) -> CurveSources:
    """Read curves on a mesh from ``path``: the signed heat demo's format, the surface winding number demo's
    format, or OBJ ``l`` lines (see the module documentation; the format is recognized from the lines).

    Parameters
    ----------
    path : str or os.PathLike
    F : (m, 3) int array, optional
        The mesh faces: needed for edge nodes ``e i t``; when given, indices are checked against it.

    Returns
    -------
    CurveSources
        ``curves``, ``curve_signs``, ``points`` for :meth:`gsdf.SurfaceSignedHeatSolver.compute_distance`;
        ``swn()`` for :func:`gsdf.surface_winding_number` (nodes and segments).

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "c.txt")
    >>> _ = open(p, "w").write("signed_curve\\nv 0\\nv 1\\nv 2\\nunsigned_point\\nv 5\\n")
    >>> src = read_curves(p)
    >>> [c.tolist() for c in src.curves], src.curve_signs, src.points
    ([[0, 1, 2]], [True], [5])
    >>> _ = open(p, "w").write("#offset 0\\nv 0\\nv 1\\nl 0 1\\n")            # the SWN demo's format
    >>> src = read_curves(p)
    >>> [c.tolist() for c in src.curves], src.swn().segments.tolist()
    ([[0, 1]], [[0, 1]])
    """
    from gsdf._checks import readable_file

    path = readable_file(path, "path")
    fmt, nodes, curves, signs, points, mesh = _parse(path, F)
    if not curves and not points:
        if fmt == "swn":
            raise ValueError(f"{path}: no curve segments ('l' lines) found")
        raise ValueError(f"{path}: no curves or points found")
    out = []
    for c in curves:
        cn = [nodes[j] for j in c]
        if all(n[0] == "v" for n in cn):
            out.append(np.array([n[1] for n in cn], dtype=np.int64))
        else:
            out.append([_surface_point(n, mesh) for n in cn])
    pts = [n[1] if n[0] == "v" else _surface_point(n, mesh) for n in points]
    swn = None
    if curves and not points and all(signs):
        segs = [(c[k], c[k + 1]) for c in curves for k in range(len(c) - 1)]
        swn = SWNCurves(np.array([n[0] for n in nodes]), np.array([n[1] for n in nodes], dtype=np.int64),
                        np.array([n[2] for n in nodes], dtype=np.float64).reshape(-1, 3),
                        np.array([n[3] for n in nodes], dtype=np.int64).reshape(-1, 2),
                        np.array(segs, dtype=np.int64).reshape(-1, 2))
    return CurveSources(out, signs, pts, swn)


def read_swn_curves(path, F) -> SWNCurves:
    """:func:`read_curves` as nodes and segments (``.swn()``), resolved against the mesh faces ``F`` (m, 3).

    Raises ValueError (with the path and line number) on unknown directives, malformed numbers, indices out of
    range, edge parameters outside [0, 1], segments naming missing nodes, or a file without segments.
    """
    return read_curves(path, F).swn()


def write_curves(path: str, curves, curve_signs=None, points=()) -> None:
    """Write sources in the demo format (vertex-index curves as ``v`` nodes, surface points as ``f`` nodes) to a
    ``.txt`` file (atomically), which :func:`gsdf.read_curves` and ``gsdf heat-surface --curves`` read.

    Parameters
    ----------
    path : str or os.PathLike
        The file; it must end in ``.txt``.
    curves : list
        Each curve a sequence of vertex indices or a list of ``(face, barycentric (3,))`` surface points
        (``(vertex, ())`` is a vertex).
    curve_signs : list of bool, optional
        Per curve: True writes a ``signed_curve`` block, False an ``unsigned_curve`` block. Default: all signed.
    points : sequence, default ()
        Isolated point sources (vertex indices or ``(face, barycentric)``), written as one ``unsigned_point``
        block.

    Raises
    ------
    ValueError
        Another extension, or a failed write.

    ``curves``, ``curve_signs`` and ``points`` are what ``compute_distance`` takes (:func:`gsdf.curves.as_curves`,
    :func:`gsdf.curves.as_point_sources`), checked as :func:`read_curves` checks a file: integer indices >= 0
    (no bools, no fractions), one sign per curve, barycentric coordinates of a point in the face; edge-set
    curves are written as their chained vertex polylines. A ValueError names the first bad entry, before the
    file is touched.

    Examples
    --------
    >>> import os, tempfile, gsdf
    >>> path = os.path.join(tempfile.mkdtemp(), "curves.txt")
    >>> gsdf.write_curves(path, [[0, 1, 2, 0]])          # one closed signed curve through vertices 0, 1, 2
    >>> print(open(path).read().strip())
    signed_curve
    v 0
    v 1
    v 2
    v 0
    """
    from gsdf.curves import as_curves, as_point_sources
    from gsdf.io._safe_write import atomic_output, check_output_path

    check_output_path(path, extensions=(".txt",))
    blocks = []                                           # (header, node lines)
    for k, c in enumerate(as_curves(curves, curve_signs)):
        head = "signed_curve\n" if c.signed else "unsigned_curve\n"
        if c.kind == "points":
            blocks.append((head, [_node_line(e, b, f"curves[{k}][{q}]") for q, (e, b) in enumerate(c.nodes)]))
        else:
            for poly in (c.polylines() if c.kind == "edges" else [c.nodes]):
                blocks.append((head, [_node_line(int(v), (), f"curves[{k}]") for v in poly]))
    pts = []
    for q, p in enumerate(as_point_sources(points)):
        pts.append(_node_line(p, (), f"points[{q}]") if isinstance(p, int) else _node_line(*p, f"points[{q}]"))
    with atomic_output(path, extensions=(".txt",)) as tmp, open(tmp, "w") as fh:
        for head, lines in blocks:
            fh.write(head)
            fh.writelines(lines)
        if pts:
            fh.write("unsigned_point\n")
            fh.writelines(pts)


def _node_line(e: int, b, name: str) -> str:
    """One node of a curve file: ``v i`` (a vertex: ``b`` empty) or ``f i a b c``, checked."""
    b = np.asarray(b, dtype=np.float64).ravel()
    try:
        if b.size == 0:
            return f"v {_check_vertex(e, None)}\n"
        f, b = _check_face_point(e, b, None)
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None
    return f"f {f} {b[0]:.17g} {b[1]:.17g} {b[2]:.17g}\n"
