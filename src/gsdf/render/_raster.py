"""A small z-buffer rasterizer: pictures of a vertex function or of face labels on a triangle mesh, with isolines
and curves drawn over it (gsdf's own renderer where polyscope is missing)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _raster(P, depth, F, vals, W, H, out_val, out_depth, out_face):
    for f in range(F.shape[0]):
        a, b, c = F[f, 0], F[f, 1], F[f, 2]
        x0, y0, x1, y1, x2, y2 = P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[c, 0], P[c, 1]
        den = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2)
        if den == 0.0:
            continue
        xmin = max(int(np.floor(min(x0, min(x1, x2)))), 0)
        xmax = min(int(np.ceil(max(x0, max(x1, x2)))), W - 1)
        ymin = max(int(np.floor(min(y0, min(y1, y2)))), 0)
        ymax = min(int(np.ceil(max(y0, max(y1, y2)))), H - 1)
        for y in range(ymin, ymax + 1):
            for x in range(xmin, xmax + 1):
                px, py = x + 0.5, y + 0.5
                l0 = ((y1 - y2) * (px - x2) + (x2 - x1) * (py - y2)) / den
                l1 = ((y2 - y0) * (px - x2) + (x0 - x2) * (py - y2)) / den
                l2 = 1.0 - l0 - l1
                if l0 < -1e-9 or l1 < -1e-9 or l2 < -1e-9:
                    continue
                z = l0 * depth[a] + l1 * depth[b] + l2 * depth[c]
                if z < out_depth[y, x]:
                    out_depth[y, x] = z
                    out_val[y, x] = l0 * vals[a] + l1 * vals[b] + l2 * vals[c]
                    out_face[y, x] = f


def _frame(V, size, view, up):
    """Orthographic frame looking along ``-view``: (pixel coordinates (n, 2), depth (n,), W, H, view unit vector,
    the map from points to (pixels, depth))."""
    d = np.asarray(view, np.float64)
    d = d / np.linalg.norm(d)
    if up is None:
        up = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
    up = np.asarray(up, np.float64)
    ex = np.cross(up, d)
    if np.linalg.norm(ex) < 1e-9:
        raise ValueError(f"up {up.tolist()} is parallel to the view direction {d.tolist()}")
    ex /= np.linalg.norm(ex)
    ey = np.cross(d, ex)
    X = np.stack([V @ ex, V @ ey], 1)
    lo, hi = X.min(0), X.max(0)
    ext = float((hi - lo).max()) or 1.0
    m = max(10, size // 25)
    s = (size - 2 * m) / ext
    W = int(np.ceil((hi[0] - lo[0]) * s)) + 2 * m
    H = int(np.ceil((hi[1] - lo[1]) * s)) + 2 * m

    def to_pixels(Q):
        Q = np.asarray(Q, np.float64)
        return np.column_stack([(Q @ ex - lo[0]) * s + m, (hi[1] - Q @ ey) * s + m]), -(Q @ d)

    P, depth = to_pixels(V)
    return P, depth, W, H, d, to_pixels


def mesh_image(V, F, values=None, labels=None, curves=(), size: int = 900, view=(0.0, 0.0, 1.0), up=None,
               level: float = 0.0, n_isolines: int = 16):
    """A picture of the mesh seen along ``-view`` (orthographic), Lambert-shaded, on a white background.

    values : (n,) per vertex: the diverging map about ``level`` (blue below, red above), dark isolines, the level
        in black. labels : (m,) int per face: one colour per label (``gsdf.render._scene.PALETTE``), boundaries
        between labels dark. Neither: grey. curves : (k, 3) polylines drawn over it where visible.
    Returns (image (h, w, 3) uint8, the colour scale of ``values`` or None, {label: rgb}).
    """
    from gsdf.render._png import colour_scale, field_to_rgb

    V = np.asarray(V, np.float64)
    F = np.asarray(F, np.int64)
    P, depth, W, H, d, to_pixels = _frame(V, size, view, up)
    vals = np.zeros(len(V)) if values is None else np.asarray(values, np.float64)
    val = np.zeros((H, W))
    zb = np.full((H, W), np.inf)
    fid = np.full((H, W), -1, np.int64)
    _raster(P, depth, F, vals, W, H, val, zb, fid)
    bg = fid < 0
    if bg.all():
        raise ValueError("render: nothing visible")
    scale, palette = None, {}
    if values is not None:
        filled = val.copy()
        filled[bg] = np.median(val[~bg])
        scale = colour_scale(vals, level)
        rgb = field_to_rgb(filled, n_isolines=n_isolines, zero_level=level, scale=scale).astype(np.float64)
    elif labels is not None:
        from gsdf.render._scene import PALETTE

        lab = np.asarray(labels, np.int64)
        keys = np.unique(lab)
        palette = {int(k): PALETTE[i % len(PALETTE)] for i, k in enumerate(keys)}
        cols = 255 * np.array([palette[int(k)] for k in keys])[np.searchsorted(keys, lab)]
        pl = np.where(bg, -1, lab[np.maximum(fid, 0)])
        rgb = cols[np.maximum(fid, 0)]
        edge = np.zeros((H, W), bool)
        edge[:-1] |= pl[:-1] != pl[1:]
        edge[1:] |= pl[:-1] != pl[1:]
        edge[:, :-1] |= pl[:, :-1] != pl[:, 1:]
        edge[:, 1:] |= pl[:, :-1] != pl[:, 1:]
        rgb[edge & ~bg] *= 0.25
    else:
        rgb = np.full((H, W, 3), 200.0)
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)
    shade = 0.45 + 0.55 * np.abs(N @ d)
    rgb *= np.where(bg, 1.0, shade[np.maximum(fid, 0)])[..., None]
    rgb[bg] = 255
    if len(curves):
        _draw_curves(rgb, zb, curves, to_pixels, max(1, size // 300), float(np.ptp(depth)) or 1.0)
    return np.clip(rgb, 0, 255).astype(np.uint8), scale, palette


def _draw_curves(rgb, zb, curves, to_pixels, r, depth_span):
    """Paint the polylines green (gsdf.view's first curve colour) where they are not behind the surface (depth
    test against the z-buffer)."""
    from gsdf.render._scene import CURVE_COLORS

    H, W = zb.shape
    colour = 255.0 * np.asarray(CURVE_COLORS[0])
    for pl in curves:
        pl = np.asarray(pl, np.float64).reshape(-1, 3)
        if len(pl) == 1:
            pl = np.vstack([pl, pl])
        px, dep = to_pixels(pl)
        seg = np.linalg.norm(np.diff(px, axis=0), axis=1)
        k = np.maximum(1, np.ceil(seg).astype(int))
        t = np.concatenate([np.arange(n) / n for n in k] + [[1.0]])
        i = np.concatenate([np.full(n, j) for j, n in enumerate(k)] + [[len(k) - 1]])
        Q = px[i] + t[:, None] * (px[i + 1] - px[i])
        D = dep[i] + t * (dep[i + 1] - dep[i])
        x, y = np.round(Q[:, 0]).astype(int), np.round(Q[:, 1]).astype(int)
        ok = (x >= 0) & (x < W) & (y >= 0) & (y < H)
        x, y, D = x[ok], y[ok], D[ok]
        vis = D <= zb[y, x] + 0.02 * depth_span
        x, y = x[vis], y[vis]
        for dx in range(-r, r + 1):
            for dy in range(-r, r + 1):
                xx, yy = np.clip(x + dx, 0, W - 1), np.clip(y + dy, 0, H - 1)
                rgb[yy, xx] = colour


def render_function_png(path, V, F, values, size: int = 800, view=(0.0, 0.0, 1.0), n_isolines: int = 16) -> None:
    """Write a PNG of ``values`` (n,) on the mesh seen along ``-view`` (orthographic): blue negative, red
    positive, dark isolines, black zero set, Lambert shading; white background (:func:`mesh_image`).

    Examples
    --------
    >>> render_function_png("phi.png", V, F, phi)          # doctest: +SKIP
    """
    from gsdf.render._png import write_png

    img, _, _ = mesh_image(V, F, values, size=size, view=view, n_isolines=n_isolines)
    write_png(path, img, min_size=1)
