"""Planar slices of a scalar field as closed polygons, and SVG export for 3D-printing toolpaths.

Barill et al. 2018, Fig. 3 and §4 ("3D printing"): to print the solid described by a winding
number field — even of a point cloud or a triangle soup — it is converted to a stack of 2D
polygons with marching squares, which the printer software then fills with toolpaths.  The *3D*
winding number is evaluated on each slicing plane (the 2D winding number of the cross-section is
not the same thing for open geometry).  As for isosurfaces (Fig. 9), contour vertices are
refined by bisection along their grid edges instead of linear interpolation.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from gsdf._checks import as_points, as_values, choice, integer
from gsdf._memory import SECONDS_PER_SLICE, _threads, check_bytes, check_work, seconds_per_point
from gsdf.contour._isosurface import (CHUNK, _check_bbox, _check_func, _edges_of_vertices, _evaluate, _finite,
                                      refine_on_edges)

__all__ = ["slice_contours", "write_svg", "write_slices_svg"]

#: Bisection steps that place each contour vertex on its grid edge (the bracket shrinks to 1/256 of a cell).
BISECTION_STEPS = 8

_SVG_NS = "http://www.w3.org/2000/svg"
_INKSCAPE_NS = "http://www.inkscape.org/namespaces/inkscape"


# ----------------------------------------------------------------------------------------------
# polygon helpers
# ----------------------------------------------------------------------------------------------


def _signed_area(P: np.ndarray) -> float:
    x, y = P[:, 0], P[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _points_in_polygon(X: np.ndarray, poly: np.ndarray, block: int = 4096) -> np.ndarray:
    """Even-odd ray casting: which rows of ``X`` (p, 2) are inside the closed polygon ``poly`` (m, 2)."""
    x0, y0 = poly[:, 0], poly[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    dy = np.where(y1 != y0, y1 - y0, 1.0)
    out = np.zeros(X.shape[0], dtype=bool)
    for s in range(0, X.shape[0], block):
        x = X[s : s + block, 0:1]
        y = X[s : s + block, 1:2]
        crosses = (y0 > y) != (y1 > y)
        xint = x0 + (y - y0) * (x1 - x0) / dy
        out[s : s + block] = (np.count_nonzero(crosses & (x < xint), axis=1) % 2) == 1
    return out


def _nesting(polys) -> tuple[np.ndarray, np.ndarray]:
    """Depth (number of enclosing polygons) and innermost enclosing polygon (-1: none) of each polygon.

    The polygons must not cross each other (true for level-set contours); one vertex of each
    polygon is tested against the others, with a bounding-box prefilter.
    """
    n = len(polys)
    depth = np.zeros(n, dtype=np.int64)
    parent = np.full(n, -1, dtype=np.int64)
    if n < 2:
        return depth, parent
    reps = np.array([p[0] for p in polys])
    lo = np.array([p.min(axis=0) for p in polys])
    hi = np.array([p.max(axis=0) for p in polys])
    containers = [[] for _ in range(n)]
    for j in range(n):
        cand = np.flatnonzero(np.all((reps >= lo[j]) & (reps <= hi[j]), axis=1))
        cand = cand[cand != j]
        if cand.size == 0:
            continue
        ins = _points_in_polygon(reps[cand], polys[j])
        for i in cand[ins]:
            containers[i].append(j)
            depth[i] += 1
    for i in range(n):
        if containers[i]:
            parent[i] = max(containers[i], key=lambda j: depth[j])
    return depth, parent


def _dedupe_closed(P: np.ndarray) -> np.ndarray:
    """Drop consecutive repeated vertices of a closed polyline (including last == first)."""
    if P.shape[0] < 2:
        return P
    keep = np.any(P != np.roll(P, -1, axis=0), axis=1)
    return P[keep] if keep.any() else P[:1]


# ----------------------------------------------------------------------------------------------
# slicing
# ----------------------------------------------------------------------------------------------


def _plane_grid(bbox_min, bbox_max, resolution, axis):
    """The Grid whose in-plane nodes (the axes other than ``axis``) are sampled on every slice."""
    from gsdf.grid import Grid, as_grid

    if isinstance(resolution, Grid):
        if bbox_min is not None or bbox_max is not None:
            raise ValueError("bbox_min/bbox_max: a Grid as resolution already has its box; omit them")
        return resolution
    if bbox_min is None or bbox_max is None:
        raise ValueError("bbox_min, bbox_max: the box to slice is needed (or a gsdf.Grid as resolution)")
    lo, hi = _check_bbox(bbox_min, bbox_max, axes=((axis + 1) % 3, (axis + 2) % 3))
    flat_hi = hi.copy()
    flat_hi[axis] = lo[axis]
    return as_grid(resolution, box=(lo, flat_hi))


def slice_contours(
    func,
    z_values,
    bbox_min=None,
    bbox_max=None,
    resolution=256,
    level: float = 0.5,
    axis: int = 2,
    inside: str = "above",
) -> list:
    """Closed polygons of the level set ``func = level`` on planes ``q[axis] = z`` (Barill et al. 2018, Fig. 3).

    For every height, ``func`` is evaluated on the nodes of a 2D grid over the box's cross-section (the
    in-plane axes of ``Grid.fit`` of the box flattened along ``axis``: ``resolution`` nodes along its longer
    side, cubic cells), the grid is padded with one ring of *outside* values so that every contour closes
    (shapes that leave the box are cut along its border), scikit-image's ``find_contours`` (marching squares)
    extracts the level set, and every contour vertex is moved to the root of ``func - level`` on its grid edge
    by :data:`BISECTION_STEPS` bisection iterations (Fig. 9; one ``func`` call per iteration for all vertices
    of all slices). Outer boundaries are oriented counter-clockwise and holes clockwise, by nesting parity.

    Parameters
    ----------
    func : callable
        ``func(Q (q, 3) float64) -> (q,)`` finite values (the *3D* field, e.g. a fast winding
        number; §4: the 2D winding number of the cross-section differs for open geometry).
    z_values : float or (s,) array_like
        Heights (coordinates along ``axis``); they need not lie inside the box.
    bbox_min, bbox_max : (3,) array_like
        Box whose cross-section is sampled (only the two in-plane axes matter). Omit them when
        ``resolution`` is a Grid.
    resolution : int >= 2 or gsdf.Grid, default 256
        Grid nodes along the longer in-plane side; or a :class:`gsdf.Grid` whose in-plane nodes are used.
    level : float, default 0.5
        Iso-value (1/2 for winding numbers).
    axis : {0, 1, 2}, default 2
        Slicing direction.  In-plane 2D coordinates are the cyclically next axes
        ``((axis + 1) % 3, (axis + 2) % 3)`` — (x, y) for z, (y, z) for x, (z, x) for y — so that
        counter-clockwise means counter-clockwise seen from the +axis side.
    inside : {"above", "below"}
        Which side of ``level`` is the solid (``"above"`` for winding numbers, ``"below"`` for
        signed distances); the padding ring uses outside values.

    Returns
    -------
    list, one entry per height, each a list of closed ``(k, 2)`` float64 polylines (the last
    vertex is *not* repeated; the edge back to the first vertex is implied).  A height where the
    plane misses the solid gives an empty list.

    Raises
    ------
    ValueError
        Bad arguments, ``func`` returning a wrong shape or NaN/inf, or ``level`` not crossed on
        any slice (all grid values on the same side: no contour anywhere).

    Notes
    -----
    ``func`` is called with at most :data:`gsdf.contour._isosurface.CHUNK` points at a time. Vertices on the
    box border (where the solid is cut by the box) are placed on the border nodes, not refined. Vertices of
    degenerate cases (the field equals ``level`` at a node) stay at the node.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.contour import slice_contours
    >>> ball = lambda Q: 1.0 / (1.0 + np.exp((np.linalg.norm(Q, axis=1) - 0.6) / 0.02))
    >>> (C,) = slice_contours(ball, [0.0], [-1, -1, -1], [1, 1, 1], resolution=64)
    >>> len(C), bool(np.abs(np.linalg.norm(C[0], axis=1) - 0.6).max() < 1e-4)
    (1, True)
    """
    from skimage.measure import find_contours

    _check_func(func)
    axis = integer(axis, "axis", 0)
    if axis > 2:
        raise ValueError(f"axis: must be 0, 1 or 2, got {axis}")
    ua, va = (axis + 1) % 3, (axis + 2) % 3
    grid = _plane_grid(bbox_min, bbox_max, resolution, axis)
    Z = np.atleast_1d(as_values(z_values, "z_values", finite=False, allow_empty=True))
    if Z.ndim != 1 or Z.size == 0:
        raise ValueError(f"z_values: expected a number or a non-empty 1D array of numbers, got shape {Z.shape}")
    if not np.isfinite(Z).all():
        raise ValueError("z_values: contains NaN or infinite values")
    level = _finite(level, "level")
    bisection_steps = BISECTION_STEPS
    chunk = CHUNK
    choice(inside, "inside", {"above", "below"})

    nu, nv = grid.shape[ua], grid.shape[va]
    ns = Z.size
    what = f"slice_contours: {ns:,} heights × a {nu}x{nv} grid ({ns * nu * nv:,} nodes)"
    # values (8 B) and inside/outside masks (2 B) per node of every slice; per plane node: its position (24 B),
    # meshgrid copies (16 B) and one chunk of queries; per slice: a padded copy for marching squares
    check_bytes(10 * ns * nu * nv + 64 * nu * nv + 48 * min(CHUNK, ns * nu * nv), what)
    # the nodes' evaluations (parallel) plus each slice's serial contouring, which dominates at low resolution
    check_work(1, ns * nu * nv * seconds_per_point(func) / _threads() + ns * SECONDS_PER_SLICE, what, parallel=False)
    ax = grid.axes()
    gu, gv = ax[ua], ax[va]
    h = grid.spacing[[ua, va]]
    o2 = grid.bbox_min[[ua, va]]
    U, W = np.meshgrid(gu, gv, indexing="ij")
    plane = np.empty((nu * nv, 3))
    plane[:, ua] = U.ravel()
    plane[:, va] = W.ravel()

    # --- field values on all slices (batched so each func call gets up to `chunk` points) ---
    values = np.empty((ns, nu * nv))
    per_call = max(1, chunk // (nu * nv))
    for s in range(0, ns, per_call):
        zs = Z[s : s + per_call]
        Q = np.tile(plane, (zs.size, 1))
        Q[:, axis] = np.repeat(zs, nu * nv)
        values[s : s + zs.size] = _evaluate(func, Q, chunk).reshape(zs.size, nu * nv)
    values = values.reshape(ns, nu, nv)
    is_in = values > level if inside == "above" else values < level
    is_out = values < level if inside == "above" else values > level
    if not is_in.any() or not is_out.any():
        vmin, vmax = float(values.min()), float(values.max())
        where = "inside" if is_in.any() else "outside"
        raise ValueError(
            f"level {level} is not crossed: func ranges over [{vmin:.6g}, {vmax:.6g}] on the slice grids "
            f"(every node is {where} with inside={inside!r}): no contour on any slice"
        )

    # --- marching squares on each padded slice; collect grid edges to refine ---
    raw = []  # (slice, vertex index coords in the unpadded grid (k,2) float, refine-request ids or -1)
    reqA, reqB, reqfa, reqfb = [], [], [], []
    n_req = 0
    fully = "low" if inside == "above" else "high"
    for s in range(ns):
        g = values[s]
        if not is_in[s].any():
            raw.append([])
            continue
        pad = (min(float(g.min()), level) - 1.0) if inside == "above" else (max(float(g.max()), level) + 1.0)
        gp = np.pad(g, 1, mode="constant", constant_values=pad)
        slice_raw = []
        for c in find_contours(gp, level, fully_connected=fully):
            if c.shape[0] >= 2 and np.array_equal(c[0], c[-1]):
                c = c[:-1]
            if c.shape[0] < 3:
                continue
            ok, i0, ax = _edges_of_vertices(c, gp.shape)
            k = c.shape[0]
            pos = c - 1.0  # unpadded index coordinates (fallback: marching squares' position)
            req = np.full(k, -1, dtype=np.int64)
            sel = np.flatnonzero(ok)
            e0 = i0[sel]
            e1 = e0.copy()
            e1[np.arange(sel.size), ax[sel]] += 1
            last = np.array(gp.shape) - 1
            e0_real = np.all((e0 > 0) & (e0 < last), axis=1)
            e1_real = np.all((e1 > 0) & (e1 < last), axis=1)
            on_pad = ~(e0_real & e1_real)
            # edges to the padding ring: the solid is cut by the box -> vertex on the border node
            if on_pad.any():
                real = np.where(e0_real[:, None], e0, e1)
                pos[sel[on_pad]] = real[on_pad] - 1.0
            inner = ~on_pad
            if inner.any():
                a0 = e0[inner] - 1
                a1 = e1[inner] - 1
                fa = g[a0[:, 0], a0[:, 1]]
                fb = g[a1[:, 0], a1[:, 1]]
                good = (fa - level) * (fb - level) <= 0
                idx = sel[inner][good]
                m = idx.size
                req[idx] = np.arange(n_req, n_req + m)
                n_req += m
                A3 = np.empty((m, 3))
                B3 = np.empty((m, 3))
                A3[:, axis] = Z[s]
                B3[:, axis] = Z[s]
                A3[:, [ua, va]] = o2 + a0[good] * h
                B3[:, [ua, va]] = o2 + a1[good] * h
                reqA.append(A3)
                reqB.append(B3)
                reqfa.append(fa[good])
                reqfb.append(fb[good])
            slice_raw.append((pos, req))
        raw.append(slice_raw)

    # --- one vectorized bisection over all vertices of all slices ---
    if n_req:
        R3 = refine_on_edges(
            func,
            np.concatenate(reqA),
            np.concatenate(reqB),
            np.concatenate(reqfa),
            np.concatenate(reqfb),
            level,
            bisection_steps,
            chunk,
        )
        R2 = R3[:, [ua, va]]
    else:
        R2 = np.zeros((0, 2))

    # --- world coordinates, cleanup, orientation by nesting parity ---
    result = []
    for slice_raw in raw:
        polys = []
        for pos, req in slice_raw:
            P = o2 + pos * h
            r = req >= 0
            P[r] = R2[req[r]]
            P = _dedupe_closed(P)
            if P.shape[0] >= 3 and _signed_area(P) != 0.0:
                polys.append(np.ascontiguousarray(P))
        depth, _ = _nesting(polys)
        for i, P in enumerate(polys):
            want_ccw = depth[i] % 2 == 0
            if (_signed_area(P) > 0) != want_ccw:
                polys[i] = np.ascontiguousarray(P[::-1])
        result.append(polys)
    return result


# ----------------------------------------------------------------------------------------------
# SVG export
# ----------------------------------------------------------------------------------------------


def _fmt(x: float) -> str:
    return f"{x:.10g}"


def write_svg(
    path,
    contours_per_slice,
    z_values=None,
    bbox=None,
    layout: str = "layers",
    unit_mm: float | None = 1.0,
    margin: float | None = None,
    style: dict | None = None,
) -> str:
    """Write slices (from :func:`slice_contours`) to one SVG file for toolpath software / inspection.

    Each slice becomes a group ``<g id="slice-0000" inkscape:groupmode="layer" inkscape:label="z=..."
    data-z="...">`` (an Inkscape layer; the ``data-z`` attribute carries the height).  Every
    *island* — an outer boundary together with the holes directly inside it, found by nesting —
    is one ``<path>`` with ``fill-rule="evenodd"`` (holes are also oppositely oriented, so
    ``nonzero`` gives the same picture).  Islands nested inside holes are separate paths.

    Coordinates: the ``viewBox`` spans the drawing (the contours' frame plus ``margin``) in data units; the
    2D ``y`` axis is flipped (SVG's points down) and the frame is shifted so that ``bbox`` (plus ``margin``)
    starts at the origin; the shift is recorded on the root element as ``data-origin="xmin ymax"`` so the
    original coordinates can be recovered (``x = X + xmin - margin``, ``y = ymax + margin - Y``). With
    ``unit_mm`` a number, ``width``/``height`` are given in millimetres (one data unit is ``unit_mm`` mm), so
    the drawing imports and prints at that size; with ``unit_mm=None`` they are left out and a browser or
    viewer fits the drawing to its window.

    The default style draws every contour as a thin line (1 screen pixel at any zoom) over a light fill, so
    the stacked layers of ``layout="layers"`` stay readable; ``style`` replaces any of its attributes.

    Parameters
    ----------
    path : str or os.PathLike
        Output file; must end in ``.svg``.
    contours_per_slice : list of lists of (k, 2) arrays
        One list of closed polylines per slice (float, data units), as returned by :func:`slice_contours`.
    z_values : (s,) array_like, optional
        Height of each slice, data units (stored as ``data-z`` and in the layer label). Default: none stored.
    bbox : ((xmin, ymin), (xmax, ymax)), optional
        2D frame of the drawing in data units (e.g. the print bed / the slicing box); default: the contours'
        bounding box.  Required when there are no contours at all.
    layout : {"layers", "stack"}, default "layers"
        ``"layers"``: all slices at their true coordinates, one layer each — the form a toolpath importer
        wants.  ``"stack"``: slices drawn one below the other (slice 0 on top), for looking at them.
    unit_mm : float or None, default 1.0
        Millimetres per data unit (1 for data in mm, 1000 for data in metres, 25.4 for inches), > 0; None: no
        physical size (the drawing fits the window it is opened in).
    margin : float, optional
        Blank border in data units, >= 0; default 2 % of the larger frame side.
    style : dict, optional
        SVG attributes of every path, over the defaults ``{"fill": "#4a78b0", "fill-opacity": "0.15",
        "fill-rule": "evenodd", "stroke": "#1b2f4f", "stroke-width": "1", "vector-effect":
        "non-scaling-stroke"}`` (e.g. ``{"fill": "#000000", "fill-opacity": "1", "stroke": "none"}`` for
        solid black regions).

    Returns
    -------
    str, the path written.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from gsdf.contour import write_svg
    >>> sq = np.array([[0.0, 0], [10, 0], [10, 10], [0, 10]])
    >>> hole = np.array([[3.0, 3], [3, 7], [7, 7], [7, 3]])
    >>> out = write_svg(os.path.join(tempfile.mkdtemp(), "s.svg"), [[sq, hole]], z_values=[0.2])
    >>> open(out).read().count("<path")
    1
    """
    from gsdf.io._safe_write import atomic_output, check_output_path

    path = check_output_path(path, extensions=(".svg",))
    choice(layout, "layout", {"layers", "stack"})
    unit = None if unit_mm is None else _finite(unit_mm, "unit_mm")
    if unit is not None and unit <= 0:
        raise ValueError(f"unit_mm: must be positive (or None: no physical size), got {unit_mm!r}")
    if isinstance(contours_per_slice, np.ndarray) or not hasattr(contours_per_slice, "__len__"):
        raise ValueError("contours_per_slice: expected a list (one entry per slice) of lists of (k, 2) polylines")
    slices = []
    for s, sl in enumerate(contours_per_slice):
        if isinstance(sl, np.ndarray) or not hasattr(sl, "__len__"):
            raise ValueError(
                f"contours_per_slice[{s}]: expected a list of (k, 2) polylines (wrap a single slice as [contours])"
            )
        polys = []
        for c, P in enumerate(sl):
            P = as_points(P, f"contours_per_slice[{s}][{c}]", dim=2)
            if P.shape[0] < 3:
                raise ValueError(f"contours_per_slice[{s}][{c}]: a closed polyline needs at least 3 vertices")
            polys.append(P)
        slices.append(polys)
    ns = len(slices)
    if ns == 0:
        raise ValueError("contours_per_slice: is empty (no slices)")
    if z_values is not None:
        Z = np.atleast_1d(as_values(z_values, "z_values", finite=False, allow_empty=True))
        if Z.shape != (ns,):
            raise ValueError(f"z_values: expected shape ({ns},), got {Z.shape}")
        if not np.isfinite(Z).all():
            raise ValueError("z_values: contains NaN or infinite values")
    else:
        Z = None
    if bbox is None:
        allp = [P for sl in slices for P in sl]
        if not allp:
            raise ValueError("contours_per_slice: no contours at all; pass bbox to write empty slices")
        stacked = np.concatenate(allp)
        bmin, bmax = stacked.min(axis=0), stacked.max(axis=0)
    else:
        bb = as_points(bbox, "bbox", dim=2)
        if bb.shape[0] != 2:
            raise ValueError(f"bbox: expected ((xmin, ymin), (xmax, ymax)), got shape {bb.shape}")
        bmin, bmax = bb[0], bb[1]
        if np.any(bmax < bmin):
            raise ValueError(f"bbox: max {bmax} is below min {bmin}")
    ext = bmax - bmin
    size = float(max(ext.max(), 1e-12))
    if margin is None:
        margin = 0.02 * size
    margin = _finite(margin, "margin")
    if margin < 0:
        raise ValueError(f"margin: must be >= 0, got {margin}")
    W = float(ext[0] + 2 * margin)
    H1 = float(ext[1] + 2 * margin)
    H = H1 * ns if layout == "stack" else H1
    if W <= 0 or H <= 0:
        W, H1 = max(W, size), max(H1, size)
        H = H1 * ns if layout == "stack" else H1
    if style is not None and not isinstance(style, dict):
        raise ValueError(f"style: expected a dict of SVG attributes, got {type(style).__name__}")
    attrs_path = {"fill": "#4a78b0", "fill-opacity": "0.15", "fill-rule": "evenodd", "stroke": "#1b2f4f",
                  "stroke-width": "1", "vector-effect": "non-scaling-stroke"}
    attrs_path.update({str(k): str(v) for k, v in (style or {}).items()})

    ET.register_namespace("", _SVG_NS)
    ET.register_namespace("inkscape", _INKSCAPE_NS)
    head = {"version": "1.1"}
    if unit is not None:
        head.update({"width": f"{_fmt(W * unit)}mm", "height": f"{_fmt(H * unit)}mm"})
    head.update({"viewBox": f"0 0 {_fmt(W)} {_fmt(H)}", "data-origin": f"{_fmt(bmin[0])} {_fmt(bmax[1])}",
                 "data-margin": _fmt(margin)})
    if unit is not None:
        head["data-unit-mm"] = _fmt(unit)
    root = ET.Element(f"{{{_SVG_NS}}}svg", head)
    for s, polys in enumerate(slices):
        label = f"slice {s}" if Z is None else f"z={_fmt(Z[s])}"
        attrs = {
            "id": f"slice-{s:04d}",
            f"{{{_INKSCAPE_NS}}}groupmode": "layer",
            f"{{{_INKSCAPE_NS}}}label": label,
        }
        if Z is not None:
            attrs["data-z"] = _fmt(Z[s])
        if layout == "stack" and s:
            attrs["transform"] = f"translate(0 {_fmt(s * H1)})"
        grp = ET.SubElement(root, f"{{{_SVG_NS}}}g", attrs)
        depth, parent = _nesting(polys)
        islands = {i: [i] for i in range(len(polys)) if depth[i] % 2 == 0}
        for i in range(len(polys)):
            if depth[i] % 2 == 1 and parent[i] in islands:
                islands[parent[i]].append(i)
        for n_isl, (_, members) in enumerate(sorted(islands.items())):
            parts = []
            for i in members:
                X = polys[i][:, 0] - bmin[0] + margin
                Y = bmax[1] + margin - polys[i][:, 1]
                pts = " L ".join(f"{_fmt(x)} {_fmt(y)}" for x, y in zip(X, Y))
                parts.append(f"M {pts} Z")
            ET.SubElement(
                grp,
                f"{{{_SVG_NS}}}path",
                {"id": f"slice-{s:04d}-island-{n_isl}", "d": " ".join(parts), **attrs_path},
            )
    tree = ET.ElementTree(root)
    ET.indent(tree)
    with atomic_output(path, extensions=(".svg",)) as tmp:
        tree.write(tmp, encoding="utf-8", xml_declaration=True)
    return path


def write_slices_svg(path, func, z_values, bbox_min=None, bbox_max=None, svg_options=None, **slice_options) -> list:
    """Slice ``func`` at ``z_values`` (:func:`slice_contours`) and write the SVG (:func:`write_svg`).

    The drawing frame is the cross-section of the sampled grid, so every slice shares the same coordinates.
    ``slice_options`` go to :func:`slice_contours` (``resolution``, ``level``, ``axis``, ...),
    ``svg_options`` (a dict) to :func:`write_svg`.  Returns the contours.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from gsdf.contour import write_slices_svg
    >>> ball = lambda Q: 1.0 / (1.0 + np.exp((np.linalg.norm(Q, axis=1) - 30.0) / 0.5))
    >>> f = os.path.join(tempfile.mkdtemp(), "ball.svg")
    >>> C = write_slices_svg(f, ball, np.arange(-25.0, 26.0, 5.0), [-32, -32, -32], [32, 32, 32], resolution=64)
    >>> len(C), sum(len(c) for c in C)
    (11, 11)
    """
    C = slice_contours(func, z_values, bbox_min, bbox_max, **slice_options)
    axis = int(slice_options.get("axis", 2))
    ua, va = (axis + 1) % 3, (axis + 2) % 3
    grid = _plane_grid(bbox_min, bbox_max, slice_options.get("resolution", 256), axis)
    lo, hi = grid.box
    opts = dict(svg_options or {})
    opts.setdefault("bbox", [[lo[ua], lo[va]], [hi[ua], hi[va]]])
    write_svg(path, C, z_values=np.atleast_1d(as_values(z_values, "z_values")), **opts)
    return C
