"""Curve sources on meshes: the text format of the signed heat method's demo program, and OBJ ``l`` lines.

Format (one directive per line; blank lines and ``#`` comments ignored)::

    signed_curve [flip]      start an oriented curve (flip = 1 reverses it)
    unsigned_curve [flip]    start an unoriented curve (unsigned distance)
    unsigned_point           the following nodes are isolated point sources (also ``signed_point``)
    v i                      node at vertex i (0-based)
    e i t                    node on edge i at parameter t from its first vertex (edges numbered in order of
                             first appearance scanning faces and their sides v0v1, v1v2, v2v0 — the numbering of
                             geometry-central for a mesh built from the same face list)
    f i a b c                node in face i with barycentric coordinates (a, b, c)
    l i j k ...              OBJ polyline, 1-based vertex indices: appended to the current curve, or a new
                             signed curve when no curve block is open (plain OBJ files)

Other OBJ lines (``v x y z`` with three coordinates, ``vn``, ``f`` of a mesh, ...) are skipped.
"""

from __future__ import annotations

import numpy as np


class CurveSources:
    """Parsed sources: ``curves`` (list of vertex-index arrays or lists of (face, barycentric)), ``curve_signs``
    (list of bool) and ``points`` (vertex indices or (face, barycentric) tuples) — the arguments of
    ``SurfaceSignedHeatSolver.compute_distance``."""

    def __init__(self, curves, curve_signs, points):
        self.curves, self.curve_signs, self.points = curves, curve_signs, points

    def __repr__(self):
        return f"CurveSources({len(self.curves)} curves, {len(self.points)} points)"


def gc_edges(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Edges in order of first appearance (faces in order, sides v0v1, v1v2, v2v0), each as (first, second)
    vertex of its first halfedge; and for each edge a face containing it and the slot there."""
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


def _int_token(t: str, what: str) -> int:
    """An integer token of a curve file (``7``; not ``7.5``, ``nan`` or ``x``)."""
    try:
        return int(t)
    except ValueError:
        raise ValueError(f"{what}: expected an integer, got {t!r}") from None


def read_curves(path: str, F=None) -> CurveSources:
    """Read curve sources from ``path`` (demo ``.txt`` format or OBJ ``l`` lines), see the module docstring.

    Parameters
    ----------
    path : str
    F : (m, 3) int array, optional
        The mesh faces; needed to resolve ``e`` (edge) nodes and to express mixed curves as surface points.

    Returns
    -------
    CurveSources

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "c.txt")
    >>> _ = open(p, "w").write("signed_curve\\nv 0\\nv 1\\nv 2\\nunsigned_point\\nv 5\\n")
    >>> src = read_curves(p)
    >>> [c.tolist() for c in src.curves], src.curve_signs, src.points
    ([[0, 1, 2]], [True], [5])
    """
    from gsdf._checks import as_faces, readable_file

    curves, signs, flips, points = [], [], [], []
    mode = None                      # None: no block; "curve"; "points"
    Fa = None if F is None else as_faces(F, 1 << 62, "F")
    n_vertices = None if Fa is None else int(Fa.max()) + 1
    n_faces = None if Fa is None else len(Fa)
    edges = first = None

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
    for lineno, line in enumerate(text.splitlines(), 1):
        tok = line.split("#", 1)[0].split()
        if not tok:
            continue
        key, args = tok[0], tok[1:]
        where = f"{path}:{lineno}"
        try:
            if key in ("signed_curve", "unsigned_curve"):
                flip = _int_token(args[0], "flip") if args else 0
                if flip not in (0, 1):
                    raise ValueError(f"flip: expected 0 or 1, got {args[0]!r}")
                curves.append([])
                signs.append(key == "signed_curve")
                flips.append(bool(flip))
                mode = "curve"
            elif key in ("unsigned_point", "signed_point"):
                mode = "points"
            elif key == "l":
                idx = [_int_token(t.split("/")[0], "vertex index") for t in args]
                if any(i <= 0 for i in idx):
                    raise ValueError("OBJ line indices must be positive (1-based)")
                nodes = [("v", _check_vertex(i - 1, n_vertices)) for i in idx]
                if mode == "curve":
                    curves[-1].extend(nodes)
                else:
                    curves.append(nodes)
                    signs.append(True)
                    flips.append(False)
            elif key in ("v", "e", "f") and mode is not None:
                if key == "v":
                    node = ("v", _check_vertex(_int_token(args[0], "vertex index"), n_vertices))
                elif key == "e":
                    if Fa is None:
                        raise ValueError("edge nodes 'e i t' need the mesh faces (pass F)")
                    if edges is None:
                        edges, first = gc_edges(Fa)
                    i, t = _int_token(args[0], "edge index"), float(args[1])
                    if not 0 <= i < len(edges):
                        raise ValueError(f"edge index {i} out of range for {len(edges)} edges")
                    if not 0.0 <= t <= 1.0:
                        raise ValueError(f"edge parameter t must be in [0, 1], got {args[1]!r}")
                    f, s = divmod(int(first[i]), 3)
                    bary = np.zeros(3)
                    bary[s], bary[(s + 1) % 3] = 1 - t, t
                    node = ("f", f, bary)
                else:
                    if len(args) < 4:
                        raise ValueError("face nodes need 'f i a b c'")
                    node = ("f", *_check_face_point(_int_token(args[0], "face index"),
                                                    np.array([float(x) for x in args[1:4]]), n_faces))
                if mode == "curve":
                    curves[-1].append(node)
                else:
                    points.append(node)
        except (IndexError, ValueError) as exc:
            raise ValueError(f"{where}: cannot parse {line.strip()!r} ({exc})") from exc
    out = []
    for k, (nodes, flip) in enumerate(zip(curves, flips)):
        if flip:
            nodes = nodes[::-1]
        if all(n[0] == "v" for n in nodes):
            out.append(np.array([n[1] for n in nodes], dtype=np.int64))
        else:
            out.append([_as_surface_point(n, Fa, f"{path}: curve {k}") for n in nodes])
    pts = [n[1] if n[0] == "v" else (n[1], n[2]) for n in points]
    if not out and not pts:
        raise ValueError(f"{path}: no curves or points found")
    return CurveSources(out, signs, pts)


def _as_surface_point(node, F, where):
    if node[0] == "f":
        return node[1], node[2]
    return node[1], ()                                # a vertex, as (vertex, ()) — see compute_distance


def write_curves(path: str, curves, curve_signs=None, points=()) -> None:
    """Write sources in the demo format (vertex-index curves as ``v`` nodes, surface points as ``f`` nodes) to a
    ``.txt`` file (atomically, :mod:`gsdf.io._safe_write`).

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
