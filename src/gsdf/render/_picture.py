"""The picture of a result that a command writes with ``--png``: polyscope's (:func:`gsdf.view`) when polyscope can
render headless in this process, else gsdf's own renderers (a grid slice, a rasterized mesh function, a
sphere-traced Points as Tori level set)."""

from __future__ import annotations

import numpy as np

_DECISION: dict = {}


def polyscope_reason() -> str | None:
    """None when polyscope renders headless here, else why not; decided once per process."""
    if "reason" not in _DECISION:
        from gsdf.render import _polyscope

        _DECISION["reason"] = _polyscope.available()
    return _DECISION["reason"]


def save_png(path, *items, view=None, size=(1200, 900), options=None, renderer: str = "auto") -> str:
    """Write a PNG picture of ``items`` (anything :func:`gsdf.view` shows) and say which renderer drew it.

    Parameters
    ----------
    path : str or path
        The ``.png`` to write (atomically).
    *items
        As for :func:`gsdf.view`.
    view : (3,) float, optional
        Direction from the scene towards the camera. Default: the 3/4 view of :func:`gsdf.view`.
    size : (int, int), default (1200, 900)
        Picture size for polyscope (gsdf's renderers size the picture to the object).
    options : gsdf.ViewOptions, optional
    renderer : {"auto", "polyscope", "gsdf"}
        "auto": polyscope when it can render headless in this process, else gsdf's renderers.

    Returns
    -------
    str
        "polyscope" or "gsdf": the renderer used.
    """
    from gsdf._checks import choice
    from gsdf.io._safe_write import check_output_path

    renderer = choice(renderer, "renderer", ("auto", "polyscope", "gsdf"))
    check_output_path(path, extensions=(".png",), what="png")
    if renderer == "polyscope" or (renderer == "auto" and polyscope_reason() is None):
        from gsdf.render._view import render

        render(items, path, size, "auto", (35.0, 25.0), options, view_dir=view)
        return "polyscope"
    _fallback(path, items, view, options)
    return "gsdf"


def _fallback(path, items, view, options):
    """gsdf's own renderers: the first item that one of them can draw."""
    from gsdf.render import _scene
    from gsdf.render._raster import render_function_png

    d = (0.3, 0.2, 1.0) if view is None else tuple(float(x) for x in view)
    for it in _scene.coerce(items):
        if isinstance(it, _scene.VolumeItem):
            from gsdf.field import GridField
            from gsdf.render._png import write_field_slice_png

            f = it.field
            if not isinstance(f, GridField):         # a tet field, resampled on a grid over its box
                n = 96
                ext = f.bbox_max - f.bbox_min
                shape = tuple(int(max(2, round(n * e / ext.max()))) for e in ext)
                probe = GridField(np.zeros(shape), f.bbox_min, f.bbox_max)
                f = GridField(f(probe.grid_points()).reshape(shape), f.bbox_min, f.bbox_max)
            level = options.level if options is not None and options.level is not None else \
                _scene.default_level(_scene.field_kind(f.values)) or 0.0
            write_field_slice_png(path, f, zero_level=level)
            return
        if isinstance(it, _scene.MeshItem):
            V, F, v = it.V, it.F, it.values
            if v is None:
                render_function_png(path, V, F, V[:, 1] - V[:, 1].mean(), view=d)
                return
            v = np.asarray(v, float)
            level = _scene.default_level(_scene.field_kind(v)) or 0.0
            if options is not None and options.level is not None:
                level = options.level
            if v.ndim == 1 and len(v) == len(V):
                render_function_png(path, V, F, v - level, view=d)
            else:                                      # per face / per corner: each face on its own corners
                corner = v if v.ndim == 2 else np.repeat(v[:, None], 3, axis=1)
                m = len(F)
                render_function_png(path, V[F].reshape(-1, 3), np.arange(3 * m).reshape(m, 3),
                                    corner.reshape(-1) - level, view=d)
            return
        if isinstance(it, _scene.CloudItem) and it.N is not None:
            from gsdf.tori import PointsAsTori
            from gsdf.render._trace import render_png

            render_png(PointsAsTori(it.P, it.N), path, 512, 512, view=d)
            return
    raise ValueError("save_png: gsdf's own renderers draw volume fields, meshes and oriented clouds; install "
                     "polyscope (pip install 'gsdf[view]') for the other items")
