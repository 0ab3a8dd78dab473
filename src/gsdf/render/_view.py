"""``gsdf.view``: meshes, clouds, curves and gsdf's results in polyscope, or as a headless screenshot."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The smallest ``ViewOptions.fill``: a scene spanning 1 % of the picture is already a dot; at 1e-308 the camera
#: distance radius / sin(atan(fill)) overflowed and the framing never ended.
MIN_FILL = 0.01


@dataclass(frozen=True)
class ViewOptions:
    """How :func:`gsdf.view` draws fields and frames the picture.

    Attributes
    ----------
    level : float, optional
        The level drawn as the isosurface of volume fields and as the thick isoline. Default: 0 for fields that
        change sign (signed distances), 1/2 for winding numbers and occupancies (values gathered at 0 and 1),
        none otherwise.
    isolines : int or sequence of float, default 16
        About this many isolines at round values (0: none), or the isovalues themselves.
    slice_axis : {"x", "y", "z"}, optional
        Axis across the slice shown of volume fields. Default: the horizontal axis facing the camera most.
    slice_at : float, optional
        Position of that slice along its axis, in model units. Default: the middle of the field's box.
    front : {"auto", "x", "-x", "y", "-y", "z", "-z"}, default "auto"
        The side the camera faces at azimuth 0: it looks towards ``-front``. "auto": the thinner of the two sides
        across the up axis (so the broad side faces the camera).
    fill : float, default 0.86
        Fraction of the picture's shorter side that the scene spans (perspective), in [0.01, 1] (below, the
        scene is a dot and the camera distance overflows).
    colormap : str, optional
        A polyscope colour map ("viridis", "coolwarm", "blues", "reds", "turbo", ...). Default: "coolwarm"
        (white at 0, or at 1/2 for winding numbers) for fields that change sign and for winding numbers,
        "viridis" for the others.
    vrange : (float, float), optional
        Values at the ends of the colour map. Default: symmetric about 0 with a rounded half-width for fields
        that change sign, [0, 1] for winding numbers and occupancies, else the range of the values.

    Examples
    --------
    >>> import gsdf
    >>> gsdf.ViewOptions(level=0.5, slice_axis="z").level
    0.5
    """

    level: float | None = None
    isolines: int | tuple = 16
    slice_axis: str | None = None
    slice_at: float | None = None
    front: str = "auto"
    fill: float = 0.86
    colormap: str | None = None
    vrange: tuple | None = None

    def __post_init__(self):
        from gsdf._checks import as_values, finite

        if self.level is not None:
            object.__setattr__(self, "level", finite(self.level, "level"))
        if self.slice_at is not None:
            object.__setattr__(self, "slice_at", finite(self.slice_at, "slice_at"))
        iso = self.isolines
        if isinstance(iso, (bool, np.bool_)) or not (isinstance(iso, (int, np.integer)) and 0 <= iso <= 1000):
            try:
                if isinstance(iso, (str, bytes, bool, np.bool_)) or np.ndim(iso) != 1:
                    raise ValueError
                iso = tuple(float(x) for x in as_values(iso, "isolines", finite=False, allow_empty=True))
            except (TypeError, ValueError):
                raise ValueError(f"isolines: expected a count (0..1000) or a sequence of isovalues, got "
                                 f"{self.isolines!r}") from None
            if not all(math.isfinite(x) for x in iso):
                raise ValueError("isolines: the isovalues must be finite")
            object.__setattr__(self, "isolines", iso)
        if self.slice_axis is not None and str(self.slice_axis).lower().lstrip("+-") not in ("x", "y", "z"):
            raise ValueError(f"slice_axis: expected 'x', 'y' or 'z', got {self.slice_axis!r}")
        if self.front != "auto":
            from gsdf.render._scene import axis_vector

            axis_vector(self.front, "front")
        from gsdf._checks import positive

        try:
            fill = positive(self.fill, "fill", most=1.0)
            if fill < MIN_FILL:
                raise ValueError
        except ValueError:
            raise ValueError(f"fill: expected a number in [{MIN_FILL}, 1], got {self.fill!r}") from None
        object.__setattr__(self, "fill", fill)       # a Python float: np.float32 would make the framing float32
        if self.colormap is not None and (not isinstance(self.colormap, str) or not self.colormap.strip()):
            raise ValueError(f"colormap: expected the name of a polyscope colour map such as 'viridis', got "
                             f"{self.colormap!r}")
        if self.vrange is not None:
            from gsdf.render._scene import colour_range

            object.__setattr__(self, "vrange", colour_range(np.zeros(1), "plain", self.vrange))


def view(*items, screenshot=None, size=(1200, 900), up="auto", azimuth: float = 35.0, elevation: float = 25.0,
         options: ViewOptions | None = None):
    """Show meshes, point clouds, curves and gsdf's results in polyscope, or render them to a PNG.

    Without ``screenshot``, a polyscope window opens (it needs a display; the call returns when the window is
    closed). With ``screenshot="out.png"`` the same scene is rendered without a window (EGL; on machines without a
    GPU Mesa's software renderer) from a 3/4 view that frames everything shown, with a colour bar per field titled
    with its name, and written to ``out.png``.

    Parameters
    ----------
    *items
        What to show, in any number and mix:

        * ``(V, F)`` a triangle (or quad) mesh, e.g. the output of :func:`gsdf.reconstruct_simply_connected`;
        * ``(V, F, values)`` with float values per vertex (n,), per face (m,) or per corner (m, 3): coloured by the
          values, isolines for per-vertex values; integer values are labels (one colour each, with a legend);
          ``(V, F, result)`` of :func:`gsdf.surface_winding_number` shows its face labels;
        * :class:`gsdf.SurfaceField` (e.g. a distance on a surface): per-vertex colours and isolines;
        * :class:`gsdf.GridField`, :class:`gsdf.TetField`: a slice through the field with isolines, and the
          isosurface at ``options.level`` cut open at the slice;
        * an (n, 3) float array (a point cloud), ``(P, N)`` (with normals: shaded by them, a subsample of the
          normals drawn), ``(P, values)``, or a :class:`gsdf.PointsAsTori`;
        * a list of (k, 3) float arrays: polylines in space;
        * :class:`gsdf.Curve`, a list of them or of vertex-index arrays, or the result of
          :func:`gsdf.read_curves`: curves on the mesh given before them;
        * ``(name, item)``: the item with its field titled ``name`` (put the units in it, e.g.
          ``("signed distance [mm]", field)``); the default titles are "value" and "label".
    screenshot : str or path, optional
        Render to this ``.png`` file (``size`` pixels) instead of opening a window.
    size : (int, int), default (1200, 900)
        Width and height of the screenshot in pixels.
    up : {"auto", "x", "y", "z", "-x", "-y", "-z"} or (3,) float, default "auto"
        The model's up axis. "auto": y, except that a flat scene (thinnest side below 10 % of the longest) is
        seen from above its normal axis.
    azimuth, elevation : float, default 35 and 25
        Camera angles in degrees: turn about the up axis, and height above the horizon (in [-89, 89]).
    options : ViewOptions, optional
        Levels, isolines, slices, colour maps and framing (:class:`gsdf.ViewOptions`).

    Returns
    -------
    (height, width, 3) uint8 array or None
        The picture written to ``screenshot``; None after a window.

    Raises
    ------
    ImportError
        Without polyscope (the ``view`` extra: ``pip install -e ".[view]"`` in a checkout of gsdf).
    RuntimeError
        Without a display and no ``screenshot``; or when EGL cannot start for a screenshot.
    ValueError
        For an item it cannot show, a bad option, or a screenshot name not ending in ``.png``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> img = gsdf.view((V, F, V[:, 0]), screenshot="tet.png")            # doctest: +SKIP
    >>> img.shape                                                          # doctest: +SKIP
    (900, 1200, 3)
    """
    from gsdf._checks import finite

    azimuth = finite(azimuth, "azimuth")
    elevation = finite(elevation, "elevation")
    if not -89.0 <= elevation <= 89.0:
        raise ValueError(f"elevation: expected degrees in [-89, 89], got {elevation:g}")
    return render(items, screenshot, size, up, (azimuth, elevation), options)


def render(items, screenshot, size, up, angles, options, view_dir=None):
    """:func:`view` with the camera given by ``angles`` (azimuth, elevation) or by ``view_dir`` (the direction from
    the scene towards the camera, as the ``--view x,y,z`` options of the commands)."""
    from gsdf._checks import integer
    from gsdf.render import _scene

    options = ViewOptions() if options is None else options
    if not isinstance(options, ViewOptions):
        raise ValueError(f"options: expected a gsdf.ViewOptions, got {type(options).__name__}")
    try:
        w, h = size
    except (TypeError, ValueError):
        raise ValueError(f"size: expected (width, height), got {size!r}") from None
    size = (integer(w, "size[0]", lo=64, hi=8192), integer(h, "size[1]", lo=64, hi=8192))
    if not (isinstance(up, str) and up == "auto"):
        _scene.axis_vector(up, "up")
    if screenshot is not None:
        from gsdf.io._safe_write import check_output_path

        screenshot = check_output_path(screenshot, extensions=(".png",), what="screenshot")
    things = _scene.coerce(items)
    lo, hi = _scene.extent_of(things)
    if view_dir is None:
        view_dir, upv = _scene.camera_direction(up, options.front, angles[0], angles[1], hi - lo)
    else:
        view_dir, upv = _scene.direction_camera(view_dir, up)
    scene = _scene.build(things, options, view_dir, upv)
    from gsdf.render import _polyscope

    if screenshot is None and not _polyscope.has_display():
        raise RuntimeError("gsdf.view: no display to open a window on; pass screenshot='out.png' to render to a "
                           "file instead")
    img = _polyscope.render(scene, size=size, view_dir=view_dir, upv=upv, fill=options.fill,
                            screenshot=screenshot)
    if screenshot is not None:
        from gsdf.render._png import write_png

        write_png(screenshot, img, min_size=1)
    return img
