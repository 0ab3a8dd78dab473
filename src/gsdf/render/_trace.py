"""Sphere-traced images of a level set from pointwise signed distance queries (Hart 1996; thesis §5.2, Fig. 5.3).

Every pixel's ray advances by the signed distance to the level set, x ← x + (φ(x) − level)·d, until
|φ − level| is below a tolerance (hit) or it leaves the box; all live rays are queried together each step, so
the renderer needs only pointwise evaluation ``sdf(Q (q, 3)) -> (q,)``. Normals are the gradient (analytic for
:class:`~gsdf.tori._pat.PointsAsTori`, central differences otherwise). Self-normalized formulas can overestimate
distance (§5.4.2), so steps are scaled by 0.9.
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import as_points, as_values, finite, integer, positive
from gsdf._memory import check_bytes

__all__ = ["sphere_trace", "render_png"]


def _gradient(sdf, X, h):
    if hasattr(sdf, "gradient"):
        return sdf.gradient(X)
    G = np.empty_like(X)
    for a in range(3):
        e = np.zeros(3)
        e[a] = h
        G[:, a] = (sdf(X + e) - sdf(X - e)) / (2 * h)
    return G


def _box(bbox_min, bbox_max):
    lo, hi = as_points(bbox_min, "bbox_min"), as_points(bbox_max, "bbox_max")
    if lo.shape[0] != 1 or hi.shape[0] != 1:
        raise ValueError(f"bbox_min/bbox_max: expected 3 numbers each, got shapes {lo.shape} and {hi.shape}")
    lo, hi = lo[0], hi[0]
    if np.any(hi <= lo) or not np.isfinite(hi - lo).all():
        raise ValueError(f"bbox_min/bbox_max: the box {lo.tolist()}..{hi.tolist()} is empty, flat or too large "
                         "to view (need bbox_max > bbox_min on every axis)")
    return lo, hi


def _direction(x, name):
    v = as_points(x, name)
    if v.shape[0] != 1:
        raise ValueError(f"{name}: expected a (3,) direction, got shape {np.shape(x)}")
    v = v[0] / max(float(np.abs(v[0]).max()), 1e-300)
    n = float(np.linalg.norm(v))
    if not n > 0:
        raise ValueError(f"{name}: the zero vector is not a direction")
    return v / n


def _values(sdf, X):
    try:
        v = as_values(sdf(X), "sdf", finite=False, allow_empty=True)
    except ValueError as exc:
        raise ValueError(f"sdf: did not return real numbers for {len(X)} points ({exc})") from None
    if v.shape != (len(X),):
        raise ValueError(f"sdf: expected shape ({len(X)},) from {len(X)} points, got {v.shape}")
    if not np.isfinite(v).all():
        raise ValueError("sdf: returned NaN or infinite values")
    return v


def sphere_trace(sdf, bbox_min, bbox_max, width: int = 256, height: int = 256, level: float = 0.0,
                 view=(1.0, 0.6, 1.4), up=(0.0, 1.0, 0.0), fov: float = 35.0, max_steps: int = 96,
                 step_scale: float = 0.9) -> np.ndarray:
    """Render the level set ``sdf = level`` inside a box to an RGB image (height, width, 3) uint8.

    Small first pictures (at most 96 pixels) find the level set; the camera is then moved along ``view`` so
    that what they hit spans about 86 % of the tighter side of the picture, centred.

    Parameters
    ----------
    sdf : callable or PointsAsTori
        Pointwise signed distance ``sdf(Q) -> (q,)``; negative inside.
    bbox_min, bbox_max : (3,) float
        Box containing the surface, model units; rays start where they enter it.
    width, height : int, default 256
        Image size in pixels.
    level : float, default 0
        Which level set, model units (offset surfaces: level != 0).
    view : (3,) float, default (1, 0.6, 1.4)
        Direction from the surface towards the camera (any length).
    up : (3,) float, default (0, 1, 0)
        The direction that points up in the picture; not parallel to ``view``.
    fov : float, default 35
        Vertical field of view, degrees, in (0, 179].
    max_steps : int, default 96
        Sphere-tracing steps per ray; a ray that has not converged then shows background.
    step_scale : float, default 0.9
        Fraction of the signed distance each step advances, in (0, 1] (below 1 for distances that overestimate).

    Returns
    -------
    (height, width, 3) uint8
        Lambert-shaded surface on a white background.

    Examples
    --------
    >>> import numpy as np
    >>> img = sphere_trace(lambda Q: np.linalg.norm(Q, axis=1) - 0.5, [-1, -1, -1], [1, 1, 1], 32, 32)
    >>> img.shape, bool((img[16, 16] < 255).any()), bool((img[0, 0] == 255).all())
    ((32, 32, 3), True, True)
    """
    if not callable(sdf):
        raise ValueError(f"sdf: expected a callable sdf(Q (q, 3)) -> (q,), got {type(sdf).__name__}")
    lo, hi = _box(bbox_min, bbox_max)
    width, height = integer(width, "width", hi=1 << 15), integer(height, "height", hi=1 << 15)
    check_bytes(120 * width * height, f"sphere_trace: a {width}x{height} image")
    level = finite(level, "level")
    fov = positive(fov, "fov", most=179.0)
    max_steps = integer(max_steps, "max_steps", hi=1 << 20)
    step_scale = positive(step_scale, "step_scale", most=1.0)
    f, up = _direction(view, "view"), _direction(up, "up")
    # the image frame needs up not parallel to the viewing direction
    if np.linalg.norm(np.cross(f, up)) < 1e-9:
        raise ValueError(f"up: {up.round(6).tolist()} is parallel to the view direction {f.round(6).tolist()}; the view is degenerate")
    c, diag = 0.5 * (lo + hi), float(np.linalg.norm(hi - lo))
    tol = 1e-3 * diag
    eye = c + f * diag * 0.5 / np.tan(np.radians(fov) / 2) * 1.1
    fwd = -f
    # small first pictures find the level set; the camera then frames what they hit (86 % of the tighter side):
    # twice, the second time with the level set filling the small picture, so its silhouette is sampled finely
    k = min(1.0, 96.0 / max(width, height))
    pw, ph = max(8, int(round(width * k))), max(8, int(round(height * k)))
    for _ in range(2):
        D, _, _ = _rays(fwd, up, fov, pw, ph)
        t, hit = _march(sdf, eye, D, lo, hi, level, tol, max_steps, step_scale)
        if hit.sum() < 3:
            break
        from gsdf.render._scene import frame_camera

        fill = max(0.5, 0.86 - 2.0 / min(pw, ph))        # hits lie up to a pixel inside the silhouette
        cam, target = frame_camera(eye + t[hit, None] * D[hit], width, height, fov, f, up, fill=fill)
        eye, fwd = cam, (target - cam) / np.linalg.norm(target - cam)
    D, right, upv = _rays(fwd, up, fov, width, height)
    t, hit = _march(sdf, eye, D, lo, hi, level, tol, max_steps, step_scale)
    img = np.full((len(D), 3), 255, np.uint8)
    if hit.any():
        X = eye + t[hit, None] * D[hit]
        G = _gradient(sdf, X, 1e-4 * diag)
        G /= np.maximum(np.linalg.norm(G, axis=1, keepdims=True), 1e-300)
        light = -fwd + 0.5 * upv + 0.3 * right
        light /= np.linalg.norm(light)
        lam = np.clip(G @ light, 0, 1)
        base = np.array([0.55, 0.7, 0.95])
        img[hit] = (255 * np.clip(0.2 + 0.8 * lam[:, None] * base + 0.05, 0, 1)).astype(np.uint8)
    return img.reshape(height, width, 3)


def _rays(fwd, up, fov, width, height):
    """Unit ray directions (height * width, 3), row by row from the top left, of a camera looking along ``fwd``."""
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    th = np.tan(np.radians(fov) / 2)
    ys, xs = np.mgrid[0:height, 0:width]
    px = (2 * (xs + 0.5) / width - 1) * th * width / height
    py = (1 - 2 * (ys + 0.5) / height) * th
    D = fwd + px.reshape(-1, 1) * right + py.reshape(-1, 1) * upv
    D /= np.linalg.norm(D, axis=1, keepdims=True)
    return D, right, upv


def _march(sdf, eye, D, lo, hi, level, tol, max_steps, step_scale):
    """Sphere tracing of the rays ``eye + t D`` inside the box: (t, hit)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (lo - eye) / D, (hi - eye) / D
    tmin = np.nanmax(np.minimum(t1, t2), axis=1).clip(0)
    tmax = np.nanmin(np.maximum(t1, t2), axis=1)
    t = tmin.copy()
    alive = tmax > tmin
    hit = np.zeros(len(D), bool)
    for _ in range(max_steps):
        idx = np.flatnonzero(alive)
        if idx.size == 0:
            break
        X = eye + t[idx, None] * D[idx]
        v = _values(sdf, X) - level
        done = np.abs(v) < tol
        hit[idx[done]] = True
        t[idx] += step_scale * np.where(done, 0.0, v)  # v < 0 (overshoot) steps back
        alive[idx[done]] = False
        alive[idx[t[idx] > tmax[idx]]] = False
    return t, hit


def render_png(sdf, path, width: int = 256, height: int = 256, level: float = 0.0, bbox_min=None,
               bbox_max=None, **kw) -> None:
    """Sphere-trace ``sdf`` (a :class:`PointsAsTori` or any pointwise SDF) and write a PNG.

    Only pointwise queries are used (Hart 1996; thesis §5.2, Fig. 5.3): no grid, no mesh. The camera frames
    the level set (see :func:`gsdf.render.sphere_trace`).

    Parameters
    ----------
    sdf : PointsAsTori or callable
        A pointwise signed distance ``sdf(Q (q, 3)) -> (q,)``, negative inside.
    path : str or os.PathLike
        The ``.png`` file to write (atomically).
    width, height : int, default 256
        Picture size in pixels.
    level : float, default 0.0
        The level set drawn, model units (an offset surface for level != 0).
    bbox_min, bbox_max : (3,) float, optional
        The box rays are traced in. Default (for a PointsAsTori): the cloud's bounding box padded by 10 % of
        its diagonal plus ``|level|``.
    **kw
        ``view`` (direction towards the camera, default (1, 0.6, 1.4)), ``up`` (default (0, 1, 0)), ``fov``
        (degrees, default 35), ``max_steps`` (default 96) and ``step_scale`` (default 0.9) of
        :func:`gsdf.render.sphere_trace`.

    Raises
    ------
    ValueError
        Another extension, no box for a plain callable, a degenerate view, no ray hitting the level set, an sdf
        returning NaN.

    Examples
    --------
    >>> import numpy as np, os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "ball.png")
    >>> render_png(lambda Q: np.linalg.norm(Q, axis=1) - 0.5, f, 16, 16, bbox_min=[-1] * 3, bbox_max=[1] * 3)
    >>> os.path.getsize(f) > 0
    True
    """
    from gsdf.render._png import write_png
    from gsdf.io._safe_write import check_output_path

    check_output_path(path, extensions=(".png",))
    level = finite(level, "level")
    if bbox_min is None or bbox_max is None:
        if not hasattr(sdf, "P"):
            raise ValueError("bbox_min/bbox_max: required when sdf is not a PointsAsTori")
        lo, hi = sdf.P.min(0), sdf.P.max(0)
        m = 0.1 * np.linalg.norm(hi - lo) + abs(level)
        bbox_min, bbox_max = lo - m, hi + m
    img = sphere_trace(sdf, bbox_min, bbox_max, width, height, level, **kw)
    if (img == 255).all():
        raise ValueError(f"no ray hit the level set {float(level):g} inside the box (nothing to render): wrong "
                         "level, box or view?")
    write_png(path, img, min_size=1)
