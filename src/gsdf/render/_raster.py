"""A small z-buffer rasterizer: PNG pictures of a vertex function on a triangle mesh, with isolines."""

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


def render_function_png(path, V, F, values, size: int = 800, view=(0.0, 0.0, 1.0), n_isolines: int = 16) -> None:
    """Write a PNG of ``values`` (n,) on the mesh seen along ``-view`` (orthographic): blue negative, red
    positive, dark isolines, black zero set, Lambert shading; white background.

    Example
    -------
    >>> render_function_png("phi.png", V, F, phi)          # doctest: +SKIP
    """
    from gsdf.render._png import field_to_rgb, write_png

    V = np.asarray(V, np.float64)
    F = np.asarray(F, np.int64)
    vals = np.asarray(values, np.float64)
    d = np.asarray(view, np.float64)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
    ex = np.cross(up, d)
    ex /= np.linalg.norm(ex)
    ey = np.cross(d, ex)
    X = np.stack([V @ ex, V @ ey], 1)
    lo, hi = X.min(0), X.max(0)
    ext = float((hi - lo).max()) or 1.0
    s = (size - 20) / ext
    W = int(np.ceil((hi[0] - lo[0]) * s)) + 20
    H = int(np.ceil((hi[1] - lo[1]) * s)) + 20
    P = np.empty_like(X)
    P[:, 0] = (X[:, 0] - lo[0]) * s + 10
    P[:, 1] = (hi[1] - X[:, 1]) * s + 10                     # image rows go down
    depth = -(V @ d)                                          # smaller = nearer the viewer
    val = np.zeros((H, W))
    zb = np.full((H, W), np.inf)
    fid = np.full((H, W), -1, np.int64)
    _raster(P, depth, F, vals, W, H, val, zb, fid)
    bg = fid < 0
    filled = val.copy()
    if bg.all():
        raise ValueError("render: nothing visible")
    filled[bg] = np.median(val[~bg])
    rgb = field_to_rgb(filled, n_isolines=n_isolines).astype(np.float64)
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)
    shade = 0.45 + 0.55 * np.abs(N @ d)
    rgb *= np.where(bg, 1.0, shade[np.maximum(fid, 0)])[..., None]
    rgb[bg] = 255
    write_png(path, np.clip(rgb, 0, 255).astype(np.uint8), min_size=1)
