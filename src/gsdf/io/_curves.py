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
    curves, signs, flips, points = [], [], [], []
    mode = None                      # None: no block; "curve"; "points"
    Fa = None if F is None else np.asarray(F, dtype=np.int64)
    edges = first = None
    import os

    if os.path.isdir(path):
        raise ValueError(f"{path}: is a directory, not a curve file")
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
                curves.append([])
                signs.append(key == "signed_curve")
                flips.append(bool(int(args[0])) if args else False)
                mode = "curve"
            elif key in ("unsigned_point", "signed_point"):
                mode = "points"
            elif key == "l":
                idx = [int(t.split("/")[0]) for t in args]
                if any(i <= 0 for i in idx):
                    raise ValueError("OBJ line indices must be positive (1-based)")
                nodes = [("v", i - 1) for i in idx]
                if mode == "curve":
                    curves[-1].extend(nodes)
                else:
                    curves.append(nodes)
                    signs.append(True)
                    flips.append(False)
            elif key in ("v", "e", "f") and mode is not None:
                if key == "v":
                    node = ("v", int(args[0]))
                elif key == "e":
                    if Fa is None:
                        raise ValueError("edge nodes 'e i t' need the mesh faces (pass F)")
                    if edges is None:
                        edges, first = gc_edges(Fa)
                    i, t = int(args[0]), float(args[1])
                    if not 0 <= i < len(edges):
                        raise ValueError(f"edge index {i} out of range for {len(edges)} edges")
                    f, s = divmod(int(first[i]), 3)
                    bary = np.zeros(3)
                    bary[s], bary[(s + 1) % 3] = 1 - t, t
                    node = ("f", f, bary)
                else:
                    node = ("f", int(args[0]), np.array([float(x) for x in args[1:4]]))
                    if len(args) < 4:
                        raise ValueError("face nodes need 'f i a b c'")
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
    signs = [True] * len(curves) if curve_signs is None else list(curve_signs)
    from gsdf.io._safe_write import atomic_output

    with atomic_output(path, extensions=(".txt",)) as tmp, open(tmp, "w") as fh:
        for c, s in zip(curves, signs):
            fh.write("signed_curve\n" if s else "unsigned_curve\n")
            if isinstance(c, np.ndarray) or all(np.isscalar(x) for x in c):
                fh.writelines(f"v {int(v)}\n" for v in c)
            else:
                for f, b in c:
                    b = np.asarray(b, float)
                    fh.write(f"v {int(f)}\n" if b.size == 0 else f"f {int(f)} {b[0]:.17g} {b[1]:.17g} {b[2]:.17g}\n")
        if len(points):
            fh.write("unsigned_point\n")
            for p in points:
                if np.isscalar(p):
                    fh.write(f"v {int(p)}\n")
                else:
                    b = np.asarray(p[1], float)
                    fh.write(f"f {int(p[0])} {b[0]:.17g} {b[1]:.17g} {b[2]:.17g}\n")
