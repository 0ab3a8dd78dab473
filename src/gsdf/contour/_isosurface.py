"""Isosurfaces of arbitrary scalar fields: marching cubes + bisection along grid edges.

Barill et al. 2018 (§3.1, Fig. 9): the winding number of a point cloud behaves like a sum of
dipoles, which is far from linear near each point, so placing marching-cubes vertices by linear
interpolation of the two node values gives bumpy surfaces.  "Iterative bisection, instead,
extracts clean isosurfaces."  :func:`extract_isosurface` runs marching cubes on the grid and then
moves every vertex to the root of ``func - level`` on its grid edge by vectorized bisection
(:func:`refine_on_edges`), calling ``func`` once per iteration for all vertices together.  This is
only possible because the fast winding number separates precomputation from evaluation (end of
§3.2: "we *must* (and do) separate precomputation from evaluation for applications such as
iso-surface polygonization").
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import _dtype_words, as_points, as_values, choice, finite, integer
from gsdf._memory import check_bytes, check_work, grid_bytes, seconds_per_point

#: More bisection steps than this cannot improve a float64 root (the bracket reaches one ulp well before).
MAX_BISECTION = 200

#: Most query points passed to the field in one call (bounds memory).
CHUNK = 1 << 20

__all__ = ["extract_isosurface", "refine_on_edges"]


# ----------------------------------------------------------------------------------------------
# argument checks shared with slicing.py
# ----------------------------------------------------------------------------------------------


def _check_func(func):
    if not callable(func):
        raise ValueError(f"func: expected a callable f(Q (q, 3)) -> (q,), got {type(func).__name__}")
    return func


_finite = finite  # one spelling: gsdf._checks.finite


def _grid(bbox_min, bbox_max, resolution):
    """The Grid of a contouring call: ``resolution`` itself (a Grid), or ``Grid.fit`` of the given box."""
    from gsdf.grid import Grid, as_grid

    if isinstance(resolution, Grid):
        if bbox_min is not None or bbox_max is not None:
            raise ValueError("bbox_min/bbox_max: a Grid as resolution already has its box; omit them")
        return resolution
    if bbox_min is None or bbox_max is None:
        raise ValueError("bbox_min, bbox_max: the box to sample is needed (or a gsdf.Grid as resolution)")
    return as_grid(resolution, box=_check_bbox(bbox_min, bbox_max))


def _check_bbox(bbox_min, bbox_max, axes=(0, 1, 2)) -> tuple[np.ndarray, np.ndarray]:
    lo = as_points(bbox_min, "bbox_min")
    hi = as_points(bbox_max, "bbox_max")
    if lo.shape[0] != 1 or hi.shape[0] != 1:
        raise ValueError(f"bbox_min/bbox_max: expected (3,) points, got shapes {lo.shape} and {hi.shape}")
    lo, hi = lo[0], hi[0]
    for a in axes:
        if not hi[a] > lo[a]:
            raise ValueError(f"bbox_max {hi} must exceed bbox_min {lo} on axis {a}")
    return lo, hi


def _evaluate(func, Q: np.ndarray, chunk: int) -> np.ndarray:
    """``func`` on the rows of ``Q`` in chunks of at most ``chunk`` rows, checking every answer."""
    q = Q.shape[0]
    out = np.empty(q)
    for s in range(0, q, chunk):
        part = Q[s : s + chunk]
        r = func(part)
        try:
            f = np.asarray(r)
        except (TypeError, ValueError) as exc:
            raise ValueError("func: returned something that is not a numeric array") from exc
        if f.dtype.kind not in "fiu":
            raise ValueError(f"func: expected real values, got {_dtype_words(f)}")
        f = f.astype(np.float64, copy=False)
        if f.shape != (part.shape[0],):
            raise ValueError(
                f"func: returned shape {f.shape} for {part.shape[0]} query points; expected ({part.shape[0]},)"
            )
        if not np.isfinite(f).all():
            bad = int(np.argmax(~np.isfinite(f)))
            raise ValueError(f"func: returned NaN or infinite values (first at query point {part[bad].tolist()})")
        out[s : s + chunk] = f
    return out


def _edges_of_vertices(X: np.ndarray, shape) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid edge of every vertex given in index coordinates ``X`` (k, d) (marching cubes/squares).

    A vertex placed by marching cubes/squares lies on a grid edge, so exactly one coordinate is
    fractional.  Returns ``(ok, i0, axis)``: ``ok`` marks vertices with such an edge, ``i0`` (k, d)
    is the edge's lower node and ``axis`` the edge direction.  Vertices whose coordinates are all
    integral (the level is hit exactly at a node, or the fraction was lost to float32 rounding,
    i.e. the vertex is within ~1e-7 cells of a node) are degenerate: ``ok`` is False.
    """
    X = np.asarray(X, dtype=np.float64)
    R = np.round(X)
    dev = np.abs(X - R)
    axis = np.argmax(dev, axis=1)
    k = np.arange(X.shape[0])
    frac = dev[k, axis]
    others = dev.sum(axis=1) - frac
    ok = (frac > 0) & (others == 0)
    i0 = R.astype(np.int64)
    i0[k, axis] = np.floor(X[k, axis]).astype(np.int64)
    top = np.asarray(shape, dtype=np.int64)[axis] - 1
    ok &= (i0[k, axis] >= 0) & (i0[k, axis] < top)
    return ok, i0, axis


# ----------------------------------------------------------------------------------------------
# public API
# ----------------------------------------------------------------------------------------------


def refine_on_edges(func, A, B, fa, fb, level: float = 0.5, steps: int = 10, chunk: int = 2**20) -> np.ndarray:
    """Vectorized bisection for the root of ``func - level`` on the segments ``[A_i, B_i]``.

    Barill et al. 2018, Fig. 9: isosurface vertices of a winding-number field are placed by
    bisection rather than linear interpolation.  Each of the ``steps`` iterations evaluates
    ``func`` once at the midpoints of all ``k`` segments and keeps the half whose end values still
    straddle ``level``; finally the root is placed by linear interpolation inside the last bracket
    (width ``|B - A| / 2**steps``), which can never leave the bracket.  ``steps=0`` is plain
    linear interpolation (what marching cubes does).

    Parameters
    ----------
    func : callable
        ``func(Q (q, 3)) -> (q,)``, any scalar field.
    A, B : (k, 3) array_like
        Segment end points.
    fa, fb : (k,) array_like
        ``func`` at ``A`` and ``B`` (already known, e.g. grid node values); they must straddle
        ``level``: ``(fa - level) * (fb - level) <= 0``.
    level : float
        Iso-value (1/2 for winding numbers, §3.2 / Fig. 8).
    steps : int >= 0
        Bisection iterations; the bracket shrinks by ``2**steps``.
    chunk : int
        Maximum number of points passed to ``func`` in one call.

    Returns
    -------
    (k, 3) float64 root positions.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.contour import refine_on_edges
    >>> f = lambda Q: Q[:, 0] ** 3          # root of x^3 - 1/8 at x = 0.5
    >>> A, B = np.array([[0.0, 0, 0]]), np.array([[1.0, 0, 0]])
    >>> X = refine_on_edges(f, A, B, f(A), f(B), level=0.125, steps=30)
    >>> round(float(X[0, 0]), 8)
    0.5
    """
    _check_func(func)
    A = as_points(A, "A", allow_empty=True)
    B = as_points(B, "B", allow_empty=True)
    k = A.shape[0]
    if B.shape[0] != k:
        raise ValueError(f"A and B: expected the same number of rows, got {k} and {B.shape[0]}")
    level = _finite(level, "level")
    steps = integer(steps, "steps", 0, hi=MAX_BISECTION)
    chunk = integer(chunk, "chunk", 1)
    fa = as_values(fa, "fa", (k,), allow_empty=True).copy()
    fb = as_values(fb, "fb", (k,), allow_empty=True).copy()
    if np.any((fa - level) * (fb - level) > 0):
        bad = int(np.argmax((fa - level) * (fb - level) > 0))
        raise ValueError(
            f"fa, fb: segment {bad} does not straddle level {level} (values {fa[bad]:.6g}, {fb[bad]:.6g})"
        )
    A = A.copy()
    B = B.copy()
    for _ in range(steps):
        if k == 0:
            break
        M = 0.5 * (A + B)
        fm = _evaluate(func, M, chunk)
        same = (fm - level) * (fa - level) > 0  # midpoint on A's side: the root is in [M, B]
        A[same] = M[same]
        fa[same] = fm[same]
        B[~same] = M[~same]
        fb[~same] = fm[~same]
    den = fb - fa
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(den != 0, (level - fa) / np.where(den != 0, den, 1.0), 0.5)
    t = np.clip(t, 0.0, 1.0)
    return A + t[:, None] * (B - A)


def extract_isosurface(
    func,
    bbox_min=None,
    bbox_max=None,
    resolution=128,
    level: float = 0.5,
    bisection_steps: int = 10,
    inside: str = "above",
) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of the level set ``func = level`` inside a box (Barill et al. 2018, Fig. 9).

    ``func`` is evaluated on the nodes of a :class:`gsdf.Grid` (``Grid.fit((bbox_min, bbox_max), resolution)``:
    ``resolution`` nodes along the longest side of the box, cubic cells), scikit-image's marching cubes
    extracts the level set, and each vertex is then moved to the root of ``func - level`` on its grid edge by
    ``bisection_steps`` vectorized bisection iterations (:func:`refine_on_edges`). Total cost: the number of
    nodes in evaluations plus ``bisection_steps * n_vertices``.

    Parameters
    ----------
    func : callable
        ``func(Q (q, 3) float64) -> (q,)`` finite values, e.g.
        ``FastWindingNumberPoints(...)`` or any signed distance.
    bbox_min, bbox_max : (3,) array_like
        Box to polygonize (pad it if the surface may touch its sides: the mesh is cut open at the box). Its
        upper corner moves up to the last node (by less than one cell). Omit them when ``resolution`` is a Grid.
    resolution : int >= 2 or gsdf.Grid, default 128
        Grid nodes along the longest box side; or the :class:`gsdf.Grid` to sample.
    level : float, default 0.5
        Iso-value; 1/2 separates inside from outside for winding numbers (§3.2, Fig. 8).
    bisection_steps : int >= 0, default 10
        ``0`` gives plain marching cubes (linear interpolation along edges); each step halves the
        bracket around the root (10 steps: 1/1024 of a cell).
    inside : {"above", "below"}
        Which side of ``level`` is the solid; faces are oriented with normals pointing out of
        it (``"above"`` for winding numbers / occupancy, ``"below"`` for signed distances).

    Returns
    -------
    V : (nv, 3) float64
        Vertices in world coordinates.
    F : (nf, 3) int64
        Triangles, outward oriented (positive signed volume for a closed solid).

    Raises
    ------
    ValueError
        Bad box or resolution, ``func`` returning a wrong shape or NaN/inf, or ``level`` not
        crossed by the grid values (no surface).

    Notes
    -----
    ``func`` is called with at most :data:`CHUNK` points at a time. The grid edge of a vertex is recovered from
    its index-space coordinates, exactly one of which is fractional. Vertices with all-integral coordinates (the
    field equals ``level`` exactly at a node, or lies within float32 rounding of it) stay where marching cubes
    put them.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.contour import extract_isosurface
    >>> ball = lambda Q: 1.0 / (1.0 + np.exp((np.linalg.norm(Q, axis=1) - 0.6) / 0.02))
    >>> V, F = extract_isosurface(ball, [-1, -1, -1], [1, 1, 1], resolution=32)
    >>> bool(np.abs(np.linalg.norm(V, axis=1) - 0.6).max() < 1e-4)
    True
    """
    from skimage.measure import marching_cubes

    _check_func(func)
    grid = _grid(bbox_min, bbox_max, resolution)
    level = _finite(level, "level")
    bisection_steps = integer(bisection_steps, "bisection_steps", 0, hi=MAX_BISECTION)
    choice(inside, "inside", {"above", "below"})
    chunk = CHUNK

    shape = grid.shape
    # values (8 B/node) and scikit-image's marching cubes (a float32 copy, edge caches: ~24 B/node measured
    # loosely), plus one chunk of query points
    what = f"extract_isosurface: resolution={resolution} gives a {shape[0]}x{shape[1]}x{shape[2]} grid"
    check_bytes(grid_bytes(shape, 32) + 48 * min(chunk, grid_bytes(shape, 1)), what)
    check_work(grid_bytes(shape, 1), seconds_per_point(func), what)
    lo, spacing = grid.bbox_min, grid.spacing
    total = grid.size
    values = np.empty(total)
    for s in range(0, total, chunk):
        Q = grid.points(np.arange(s, min(total, s + chunk)))
        values[s : s + Q.shape[0]] = _evaluate(func, Q, chunk)
    values = values.reshape(shape)

    vmin, vmax = float(values.min()), float(values.max())
    if not (vmin < level < vmax):
        raise ValueError(
            f"level {level} is not crossed: func ranges over [{vmin:.6g}, {vmax:.6g}] on the grid, so there is no "
            "surface in the box (wrong level, box, or resolution too coarse to see the shape?)"
        )
    # scikit-image works in float32: give it the values relative to the level, scaled to [-1, 1], so fields of
    # any magnitude (1e-150 or 1e150) keep their sign pattern (a float32 1e-151 would be 0)
    rel = values * 0.5 - level * 0.5
    rel /= float(np.abs(rel).max())
    verts, faces, _, _ = marching_cubes(
        rel, level=0.0, gradient_direction="ascent" if inside == "above" else "descent"
    )
    X = np.asarray(verts, dtype=np.float64)
    F = np.ascontiguousarray(faces, dtype=np.int64)

    ok, i0, axis = _edges_of_vertices(X, shape)
    sel = np.flatnonzero(ok)
    i1 = i0[sel].copy()
    i1[np.arange(sel.size), axis[sel]] += 1
    i0s = i0[sel]
    fa = values[i0s[:, 0], i0s[:, 1], i0s[:, 2]]
    fb = values[i1[:, 0], i1[:, 1], i1[:, 2]]
    straddle = (fa - level) * (fb - level) <= 0
    sel, i0s, i1, fa, fb = sel[straddle], i0s[straddle], i1[straddle], fa[straddle], fb[straddle]

    V = lo + X * spacing  # degenerate vertices keep marching cubes' position
    if sel.size:
        A = lo + i0s * spacing
        B = lo + i1 * spacing
        V[sel] = refine_on_edges(func, A, B, fa, fb, level, bisection_steps, chunk)
    return np.ascontiguousarray(V), F
