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

    With polyscope installed and able to render without a display (EGL), the picture is the screenshot of
    :func:`gsdf.view`: a 3/4 view framing everything, a colour bar per field titled with its name (put the units
    in it: ``("signed distance [mm]", field)``), labels with a legend. Otherwise gsdf's own renderers draw the
    first item they can, from the same direction: a slice of a volume field, a mesh with its per-vertex,
    per-face or per-corner values or face labels (curves drawn over it), or the zero level set of an oriented
    cloud (sphere-traced Points as Tori), with a colour bar or legend beside it. This is the picture the
    command line's ``--png`` writes.

    Parameters
    ----------
    path : str or path
        The ``.png`` to write (atomically).
    *items
        As for :func:`gsdf.view`: meshes ``(V, F)``, ``(V, F, values)``, fields, clouds, curves, ``(name,
        item)``.
    view : (3,) float, optional
        Direction from the scene towards the camera. Default: the 3/4 view of :func:`gsdf.view` (y up, the
        broad side facing the camera; a flat scene seen from above).
    size : (int, int), default (1200, 900)
        Picture width and height in pixels for polyscope (gsdf's renderers make the longer side about 900
        pixels and fit the other to the object).
    options : gsdf.ViewOptions, optional
        Level, isolines, slice axis and position, colour map, framing (:class:`gsdf.ViewOptions`).
    renderer : {"auto", "polyscope", "gsdf"}, default "auto"
        "auto": polyscope when it can render headless in this process, else gsdf's renderers.

    Returns
    -------
    str
        "polyscope" or "gsdf": the renderer used.

    Raises
    ------
    ValueError
        A name not ending in ``.png``, an item that cannot be shown, bad options; with gsdf's renderers, items
        they cannot draw (bare clouds, curves alone).
    RuntimeError
        ``renderer="polyscope"`` where polyscope cannot start EGL.

    Examples
    --------
    >>> import numpy as np, os, tempfile, gsdf
    >>> x = np.linspace(-1, 1, 17)
    >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    >>> field = gsdf.GridField(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, [-1] * 3, [1] * 3)
    >>> out = os.path.join(tempfile.mkdtemp(), "ball.png")
    >>> gsdf.save_png(out, ("signed distance [m]", field), renderer="gsdf")
    'gsdf'
    >>> gsdf.save_png(out, ("signed distance [m]", field), options=gsdf.ViewOptions(slice_axis="x"))  # doctest: +SKIP
    'polyscope'
    """
    from gsdf._checks import choice
    from gsdf.io._safe_write import check_output_path

    from gsdf.render._scene import direction_camera
    from gsdf.render._view import ViewOptions

    renderer = choice(renderer, "renderer", ("auto", "polyscope", "gsdf"))
    check_output_path(path, extensions=(".png",), what="png")
    if view is not None:                     # every option checked before anything is drawn
        direction_camera(view)
    if options is not None and not isinstance(options, ViewOptions):
        raise ValueError(f"options: expected a gsdf.ViewOptions or None, got {type(options).__name__}")
    if renderer == "polyscope" or (renderer == "auto" and polyscope_reason() is None):
        from gsdf.render._view import render

        render(items, path, size, "auto", (35.0, 25.0), options, view_dir=view)
        return "polyscope"
    _fallback(path, items, view, options)
    return "gsdf"


def _fallback(path, items, view, options):
    """gsdf's own renderers: the first item that one of them can draw (curves are drawn over a mesh), from the
    camera direction of :func:`gsdf.view`, with a colour bar or a legend."""
    from gsdf.render import _scene
    from gsdf.render._png import annotate, field_slice_image, write_png
    from gsdf.render._view import ViewOptions

    options = ViewOptions() if options is None else options
    things = _scene.coerce(items)
    lo, hi = _scene.extent_of(things)
    if view is None:
        d, upv = _scene.camera_direction("auto", options.front, 35.0, 25.0, hi - lo)
    else:
        d, upv = _scene.direction_camera(view)
    curves = [p for it in things if isinstance(it, _scene.CurvesItem) for p in it.polylines if len(p)]
    for it in things:
        if isinstance(it, _scene.VolumeItem):
            from gsdf.field import GridField

            f = it.field
            if not isinstance(f, GridField):         # a tet field, resampled on a grid over its box
                n = 96
                ext = f.bbox_max - f.bbox_min
                shape = tuple(int(max(2, round(n * e / ext.max()))) for e in ext)
                probe = GridField(np.zeros(shape), f.bbox_min, f.bbox_max)
                f = GridField(f(probe.grid_points()).reshape(shape), f.bbox_min, f.bbox_max)
            kind = _scene.field_kind(f.values, it.name)
            level = options.level if options.level is not None else _scene.default_level(kind) or 0.0
            if options.slice_axis is None:           # as gsdf.view: the axis across up facing the camera most
                ax = max((i for i in range(3) if abs(upv[i]) < 0.5), key=lambda i: abs(d[i]))
            else:
                ax = int(np.argmax(np.abs(_scene.axis_vector(options.slice_axis))))
            img = field_slice_image(f, ax, options.slice_at, level, title=it.name or "value",
                                    vertical=int(np.argmax(np.abs(upv))))
            write_png(path, img, min_size=1)
            return
        if isinstance(it, _scene.MeshItem):
            from gsdf.render._raster import mesh_image

            V, F, v = it.V, it.F, it.values
            labels = values = None
            if v is not None and _scene._is_int(v) and v.ndim == 1 and len(v) == len(F):
                labels = v
            elif v is not None:
                values = np.asarray(v, float)
            level = 0.0
            if values is not None:
                level = options.level if options.level is not None else \
                    _scene.default_level(_scene.field_kind(values, it.name)) or 0.0
                if not (values.ndim == 1 and len(values) == len(V)):   # per face / corner: faces on own corners
                    corner = values if values.ndim == 2 else np.repeat(values[:, None], 3, axis=1)
                    m = len(F)
                    V, F, values = V[F].reshape(-1, 3), np.arange(3 * m).reshape(m, 3), corner.reshape(-1)
            img, scale, palette = mesh_image(V, F, values, labels, curves, view=d, up=upv, level=level)
            if scale is not None:
                img = annotate(img, bar=(it.name or "value", level, scale))
            elif palette:
                A = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
                share = {k: A[labels == k].sum() / max(A.sum(), 1e-300) for k in palette}
                rows = [(f"{k}   ({100 * share[k]:.1f} % of the area)", c) for k, c in palette.items()]
                img = annotate(img, legend=(it.name or "label", rows))
            write_png(path, img, min_size=1)
            return
        if isinstance(it, _scene.CloudItem) and it.N is not None:
            from gsdf.render._trace import render_png
            from gsdf.tori import PointsAsTori

            render_png(PointsAsTori(it.P, it.N), path, 900, 900, view=d, up=upv)
            return
    raise ValueError("save_png: gsdf's own renderers draw volume fields, meshes and oriented clouds; install "
                     "polyscope (the view extra: pip install -e '.[view]' in a checkout) for the other items")
