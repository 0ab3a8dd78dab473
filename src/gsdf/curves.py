"""Curves as sources: :class:`Curve`, the typed curve of the signed heat method, surface winding numbers and curve
files — a vertex polyline, surface points ``(face, barycentric)``, or a set of (oriented) edges, with a ``signed``
flag. Raw arrays and lists are accepted everywhere a curve is; :func:`as_curves` turns whatever the user passed
into a list of :class:`Curve` and rejects what is not a curve (bools, floats that are not whole numbers, strings,
…) with a ValueError naming the argument.

Example
-------
>>> import numpy as np
>>> from gsdf.curves import Curve, as_curves
>>> c = Curve([0, 1, 2, 0])
>>> c.kind, c.signed
('vertices', True)
>>> [k.kind for k in as_curves([np.array([3, 4]), Curve([[0, 1], [1, 2]], signed=False)])]
['vertices', 'edges']
"""


from __future__ import annotations

import numpy as np

__all__ = ["Curve", "as_curves", "as_point_sources", "index_array", "chain_edges"]

CURVE_KINDS = ("vertices", "points", "edges")


def _is_index_scalar(x) -> bool:
    """True for Python / numpy integers and whole floats; False for bools and everything else."""
    if isinstance(x, (bool, np.bool_)):
        return False
    if isinstance(x, (int, np.integer)):
        return True
    return isinstance(x, (float, np.floating)) and np.isfinite(x) and float(x) == int(x)

def _surface_point(item, name: str, expected: str):
    """One ``(element index, barycentric coordinates)`` pair, validated (ValueError naming ``name``)."""
    try:
        e, b = item
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: expected {expected}, got {item!r}") from exc
    if not _is_index_scalar(e) or e < 0:
        raise ValueError(f"{name}: element index must be an integer >= 0, got {e!r}")
    from gsdf._checks import as_values

    try:
        b = as_values(b, name, finite=False, allow_empty=True).ravel()
    except ValueError as exc:
        raise ValueError(f"{name}: barycentric coordinates must be real numbers ({exc})") from None
    return int(e), b



def index_array(a, name: str, ndim: int | None = 1) -> np.ndarray:
    """``a`` as an int64 array of indices; bools, non-whole floats, objects and strings raise ValueError naming
    ``name`` (range is checked by the domain, which knows the number of elements)."""
    arr = np.asarray(a)
    if arr.dtype == bool:
        raise ValueError(f"{name}: expected integer indices, got booleans ({arr.tolist()!r:.60})")
    if arr.dtype == object or arr.dtype.kind in "USV":
        raise ValueError(f"{name}: expected integer indices, got {arr.dtype} values")
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: expected a {ndim}-D index array, got shape {arr.shape}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        if not (np.issubdtype(arr.dtype, np.floating) and np.isfinite(arr).all() and np.all(arr == np.round(arr))):
            raise ValueError(f"{name}: vertex indices must be integers, got dtype {arr.dtype}")
    out = arr.astype(np.int64)
    if out.size and out.min() < 0:
        k = int(np.argmax(out.ravel() < 0))
        raise ValueError(f"{name}: negative vertex index {out.ravel()[k]} out of range (at flat position {k})")
    return out


def _looks_like_point_list(items) -> bool:
    """A list of ``(element, barycentric)`` pairs (a surface-point curve)?"""
    if not items:
        return False
    for it in items:
        if isinstance(it, (str, bytes)) or np.isscalar(it):
            return False
        try:
            if len(it) != 2:
                return False
        except TypeError:
            return False
        if not _is_index_scalar(it[0]) or np.isscalar(it[1]):
            return False
    return True


class Curve:
    """A source curve of the signed heat method.

    Parameters
    ----------
    nodes : array-like
        One of

        * ``(k,)`` int: a polyline through vertices (consecutive vertices joined by a mesh edge on meshes; any
          two points on point clouds); closed when the first index equals the last;
        * a list of ``(face_index, barycentric (3,))`` surface points (``(vertex, ())`` also means a vertex),
          on triangle meshes;
        * ``(k, 2)`` int: a set of edges ``i → j`` (oriented when ``signed``); chained into polylines.
    signed : bool, default True
        True: an oriented curve; the region on its left (the inside of a counter-clockwise loop seen from the
        normal side) gets negative distance. False: unsigned distance to the curve (App. A.2).
    name : str, default "curve"
        How error messages name the curve (e.g. ``"curves[3]"``).

    Attributes
    ----------
    kind : {"vertices", "points", "edges"}
        Which of the three forms ``nodes`` has.
    nodes : (k,) int64, (k, 2) int64 or list of (int, float64 array)
        The validated nodes.
    signed : bool
        As given.

    Raises
    ------
    ValueError
        Fewer than 2 nodes, an empty edge list, negative or non-integer indices, malformed surface points (the
        message starts with ``name``), a ``name`` that is not a string.

    Examples
    --------
    >>> import gsdf
    >>> gsdf.Curve([[0, 1], [1, 2], [2, 0]]).polylines()
    [array([0, 1, 2, 0])]
    >>> gsdf.Curve([3, 4, 5], signed=False).kind
    'vertices'
    """

    def __init__(self, nodes, signed: bool = True, name: str = "curve"):
        if not isinstance(name, str):
            raise ValueError(f"name: expected a string, got {type(name).__name__}")
        if isinstance(nodes, Curve):
            nodes = nodes.nodes
        if not isinstance(signed, (bool, np.bool_)):
            raise ValueError(f"signed: expected True or False, got {signed!r}")
        self.signed = bool(signed)
        arr = None
        if isinstance(nodes, np.ndarray) and nodes.dtype != object:
            arr = nodes
        elif isinstance(nodes, (list, tuple)) and not _looks_like_point_list(list(nodes)):
            try:
                arr = np.asarray(nodes)
            except ValueError as exc:
                raise ValueError(f"{name}: expected a vertex polyline (k,), edges (k, 2) or a list of "
                                 "(face, barycentric) points") from exc
            if arr.dtype == object:
                raise ValueError(f"{name}: expected a vertex polyline (k,), edges (k, 2) or a list of "
                                 "(face, barycentric) points")
        if arr is not None:
            if arr.ndim == 2 and arr.shape[1] == 2:
                self.kind = "edges"
                self.nodes = index_array(arr, name, ndim=2)
                if len(self.nodes) == 0:
                    raise ValueError(f"{name}: the edge list is empty")
            else:
                self.kind = "vertices"
                self.nodes = index_array(arr, name, ndim=1)
                if self.nodes.size < 2:
                    raise ValueError(f"{name}: a curve needs at least 2 points, got {self.nodes.size}")
            return
        try:
            items = list(nodes)
        except TypeError as exc:
            raise ValueError(f"{name}: expected a vertex polyline, edges or a list of (face, barycentric) "
                             f"points, got {type(nodes).__name__}") from exc
        if len(items) < 2:
            raise ValueError(f"{name}: a curve needs at least 2 points, got {len(items)}")
        out = []
        for q, it in enumerate(items):
            out.append(_surface_point(it, f"{name}[{q}]", "(face_index, barycentric (3,))"))
        self.kind = "points"
        self.nodes = out

    def __repr__(self):
        n = len(self.nodes)
        return f"Curve({self.kind}, {n} {'edges' if self.kind == 'edges' else 'nodes'}, signed={self.signed})"

    def polylines(self) -> list:
        """The curve as vertex polylines (kind "vertices" or "edges").

        Edges are chained ``i → j → …`` into maximal paths (orientation followed when signed, ignored
        otherwise); a path closes when it returns to its start.

        Returns
        -------
        list of (k,) int64 arrays
            One vertex path each (the nodes themselves for kind "vertices").

        Raises
        ------
        ValueError
            For a curve of surface points (kind "points"), which has no vertex polylines.

        Examples
        --------
        >>> import gsdf
        >>> gsdf.Curve([[2, 3], [0, 1], [1, 2]]).polylines()
        [array([0, 1, 2, 3])]
        """
        if self.kind == "vertices":
            return [self.nodes]
        if self.kind != "edges":
            raise ValueError("curve: surface-point curves have no vertex polylines")
        return chain_edges(self.nodes, directed=self.signed)


def chain_edges(E: np.ndarray, directed: bool = True) -> list:
    """Chain edges (k, 2) into maximal vertex paths; each edge is used once.

    Paths start at a vertex with more outgoing than incoming edges (any vertex when none is left), and follow
    unused edges (out-edges only when ``directed``). Python over edges: curves are small next to meshes.

    Example
    -------
    >>> [p.tolist() for p in chain_edges(np.array([[2, 3], [0, 1], [1, 2]]))]
    [[0, 1, 2, 3]]
    """
    E = np.asarray(E, np.int64)
    E = E[E[:, 0] != E[:, 1]]
    adj: dict = {}
    deg: dict = {}
    for k, (i, j) in enumerate(E.tolist()):
        adj.setdefault(i, []).append((j, k))
        deg[i] = deg.get(i, 0) + 1
        deg[j] = deg.get(j, 0) - 1
        if not directed:
            adj.setdefault(j, []).append((i, k))
    used = np.zeros(len(E), bool)
    paths = []
    if not directed:
        odd = [v for v, nb in adj.items() if len(nb) % 2 == 1]
        starts = odd + [int(v) for v in E[:, 0]]
    else:
        starts = [v for v, d in deg.items() if d > 0] + [int(v) for v in E[:, 0]]
    for s in starts:
        while True:
            nxt = next(((j, k) for j, k in adj.get(s, []) if not used[k]), None)
            if nxt is None:
                break
            path = [s]
            v = s
            while nxt is not None:
                j, k = nxt
                used[k] = True
                path.append(j)
                v = j
                nxt = next(((j2, k2) for j2, k2 in adj.get(v, []) if not used[k2]), None)
            paths.append(np.array(path, np.int64))
    return paths


def as_curves(curves, curve_signs=None, name: str = "curves") -> list:
    """Normalize the ``curves`` argument of every ``compute_distance`` into a list of :class:`Curve`.

    Accepted: None or ``[]`` (no curves), one :class:`Curve`, one 1-D int array (one vertex polyline), or a
    list whose entries are :class:`Curve`, index arrays / lists, or lists of ``(face, barycentric)`` points.
    ``curve_signs`` (one bool per curve) sets ``signed`` of raw entries and must agree with the ``signed`` of
    :class:`Curve` entries.
    """
    if curves is None:
        curves = []
    elif isinstance(curves, Curve):
        curves = [curves]
    elif isinstance(curves, np.ndarray) and curves.dtype != object and curves.ndim == 1:
        curves = [curves]
    elif isinstance(curves, (str, bytes)) or np.isscalar(curves):
        raise ValueError(f"{name}: expected a list of curves, got {curves!r}")
    try:
        curves = list(curves)
    except TypeError as exc:
        raise ValueError(f"{name}: expected a list of curves, got {type(curves).__name__}") from exc
    if curves and all(_is_index_scalar(c) or isinstance(c, (bool, np.bool_)) for c in curves):
        curves = [curves]                                      # one curve given as a flat list of indices
    signs = None
    if curve_signs is not None:
        if isinstance(curve_signs, (bool, np.bool_)):
            curve_signs = [curve_signs]
        try:
            signs = list(curve_signs)
        except TypeError as exc:
            raise ValueError(f"curve_signs: expected one bool per curve, got {curve_signs!r}") from exc
        for k, s in enumerate(signs):
            if not isinstance(s, (bool, np.bool_)) and not (isinstance(s, (int, np.integer)) and s in (0, 1)):
                raise ValueError(f"curve_signs[{k}]: expected True or False, got {s!r}")
        if len(signs) != len(curves):
            raise ValueError(f"curve_signs: has {len(signs)} entries but there are {len(curves)} curves")
    out = []
    for k, c in enumerate(curves):
        if isinstance(c, Curve):
            if signs is not None and bool(signs[k]) != c.signed:
                raise ValueError(f"curve_signs[{k}]: {bool(signs[k])} contradicts {name}[{k}].signed={c.signed}")
            out.append(c)
            continue
        if isinstance(c, (bool, np.bool_)) or np.isscalar(c):
            raise ValueError(f"{name}[{k}]: expected a curve (index array or list of surface points), got {c!r}")
        out.append(Curve(c, signed=True if signs is None else bool(signs[k]), name=f"{name}[{k}]"))
    return out


def as_point_sources(points, name: str = "points") -> list:
    """Normalize the ``points`` argument: a list whose entries are vertex indices (int) or ``(face,
    barycentric)`` pairs. Bools and other non-index values raise ValueError naming ``points[k]``."""
    if points is None:
        return []
    if isinstance(points, (bool, np.bool_)) or _is_index_scalar(points):
        points = [points]
    if isinstance(points, np.ndarray):
        if points.dtype == bool:
            raise ValueError(f"{name}: expected vertex indices, got booleans")
        if points.dtype != object:
            if points.ndim > 1:
                raise ValueError(f"{name}: expected vertex indices or (face, barycentric) tuples, got shape "
                                 f"{points.shape}")
            return list(index_array(points, name))
    try:
        items = list(points)
    except TypeError as exc:
        raise ValueError(f"{name}: expected a list of vertex indices or (face, barycentric) tuples") from exc
    out = []
    for q, it in enumerate(items):
        if _is_index_scalar(it):
            out.append(int(it))
            continue
        if isinstance(it, (bool, np.bool_)) or np.isscalar(it):
            raise ValueError(f"{name}[{q}]: expected a vertex index or (face, barycentric), got {it!r}")
        out.append(_surface_point(it, f"{name}[{q}]", "a vertex index or (face, barycentric)"))
    return out
