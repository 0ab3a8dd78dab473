"""Every call gsdf makes to polyscope (Sharp et al., polyscope.run): one session per process, the parts of a
:class:`gsdf.render._scene.Scene` registered as polyscope structures, a window or a headless screenshot.

Headless rendering uses polyscope's EGL backend; on a machine without a GPU, Mesa's software EGL (Debian:
``libegl1 libegl-mesa0 libgl1-mesa-dri``) renders the same pictures. The call sequence:

* ``set_use_prefs_file(False)`` before ``init`` (else ``.polyscope.ini`` and ``imgui.ini`` land in the working
  directory), ``set_verbosity(0)``;
* ``init("openGL3_egl")`` once per process (a second ``init`` is a no-op and the backend cannot change); a
  failed EGL ``init`` is followed by ``init("openGL_mock")`` so that polyscope's exit handler stays quiet;
* the default GUI panels off and the scalar quantities' own colour bars on (``include_UI=True`` in the
  screenshot captures them);
* transparency "pretty" with 3 depth-peeling passes when something is translucent, else "none" ("simple" makes
  opaque structures see-through);
* isolines drawn as thin curve networks, not polyscope's "contour" isoline style (drawn as black half-period bands
  by Mesa's llvmpipe).
"""

from __future__ import annotations

import os
import sys

import numpy as np

from gsdf.render._scene import CloudPart, CurvePart, SurfacePart, frame_camera

INSTALL_HINT = ("gsdf.view needs polyscope: pip install 'gsdf[view]' (from a checkout of gsdf: "
                "pip install -e '.[view]')")
EGL_HINT = ("rendering without a display needs EGL (on Debian/Ubuntu: apt-get install libegl1 libegl-mesa0 "
            "libgl1-mesa-dri)")

_STATE: dict = {"ps": None, "backend": None, "error": None}


def has_display() -> bool:
    """Can a window open? (Linux and BSD: $DISPLAY or $WAYLAND_DISPLAY; macOS and Windows: yes.)"""
    if sys.platform.startswith(("linux", "freebsd", "openbsd", "netbsd")):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


def _import():
    try:
        import polyscope as ps
    except ImportError as exc:
        raise ImportError(INSTALL_HINT) from exc
    return ps


def session(headless: bool):
    """polyscope, initialised once per process: the EGL backend when ``headless``, else a window. A process that
    opened a window can also take screenshots; one started headless cannot open a window."""
    if _STATE["error"] is not None:
        raise RuntimeError(_STATE["error"])
    ps = _STATE["ps"]
    if ps is not None:
        if not headless and _STATE["backend"] == "egl":
            raise RuntimeError("gsdf.view: this process already renders headless (EGL); a window needs a new "
                               "process")
        return ps
    ps = _import()
    ps.set_use_prefs_file(False)
    ps.set_verbosity(0)
    ps.set_program_name("gsdf")
    ps.set_errors_throw_exceptions(True)
    if headless:
        ps.set_allow_headless_backends(True)
        try:
            ps.init("openGL3_egl")
        except Exception as exc:
            _STATE["error"] = f"gsdf.view: polyscope could not start EGL ({' '.join(str(exc).split())}); {EGL_HINT}"
            try:
                ps.init("openGL_mock")             # an initialised polyscope exits quietly
            except Exception:  # pragma: no cover
                pass
            raise RuntimeError(_STATE["error"]) from exc
        _STATE["backend"] = "egl"
    else:
        ps.init()
        _STATE["backend"] = "window"
    _STATE["ps"] = ps
    return ps


def available() -> str | None:
    """None when headless screenshots work in this process, else why not (polyscope missing, no EGL)."""
    try:
        session(headless=True)
    except (ImportError, RuntimeError) as exc:
        return str(exc)
    return None


def render(scene, *, size, view_dir, upv, fill, screenshot=None):
    """Show ``scene`` in a window (``screenshot`` None) or render it to an (H, W, 3) uint8 image."""
    headless = screenshot is not None
    ps = session(headless)
    ps.remove_all_structures()
    ps.remove_all_slice_planes()
    width, height = (int(s) for s in size)
    if headless:
        ps.set_window_size(width, height)
        ps.set_ui_scale(1.3 * height / 900)
    ps.set_build_default_gui_panels(not headless)
    ps.set_ground_plane_mode("none")
    ps.set_background_color((1.0, 1.0, 1.0))
    a = int(np.argmax(np.abs(upv)))
    ps.set_up_dir(("" if upv[a] > 0 else "neg_") + "xyz"[a] + "_up")
    lo, hi = (np.min([p.min(0) for p in scene.frame], 0), np.max([p.max(0) for p in scene.frame], 0))
    length = float(np.linalg.norm(hi - lo)) or 1.0
    planes = []
    for k, pl in enumerate(scene.planes):
        sp = ps.add_slice_plane(f"gsdf cut {k}")
        sp.set_pose(tuple(pl.origin), tuple(pl.normal))
        sp.set_draw_plane(False)
        sp.set_draw_widget(False)
        planes.append(sp)
    bars, translucent = {}, False
    for part in scene.parts:
        st = _register(ps, part, length, bars, headless)
        for k, sp in enumerate(planes):
            if getattr(part, "cut", None) != k:
                st.set_ignore_slice_plane(sp, True)
        translucent |= getattr(part, "transparency", None) is not None
    if not headless:
        for vol in scene.volumes:
            _register_volume(ps, vol)
    ps.set_transparency_mode("pretty" if translucent else "none")
    if translucent:
        ps.set_transparency_render_passes(3)     # one translucent layer over opaque parts: 3 passes suffice
    pts = np.concatenate(scene.frame)
    clear = _overlay_boxes(ps, bars, scene.legends(), width, height) if headless else ()
    cam, target = frame_camera(pts, width, height, ps.get_vertical_fov_degrees(), view_dir, upv, fill, clear)
    ps.look_at_dir(tuple(cam), tuple(target), tuple(upv))
    try:
        if not headless:
            ps.show()
            return None
        img = np.ascontiguousarray(ps.screenshot_to_buffer(transparent_bg=False, include_UI=True)[..., :3])
    finally:
        ps.remove_all_structures()
        ps.remove_all_slice_planes()
    legends = scene.legends()
    if legends:
        img = draw_legends(img, legends, right=bool(bars))
    return img


def _bar_width(title: str, ui: float) -> float:
    """Width in pixels of polyscope's colour bar with this title (its font: about 6.5 px per character at UI
    scale 1)."""
    return max(6.6 * len(title), 75.0) * ui


def _bar_kw(ps, scalar, bars, headless):
    """Colour-map keywords; the first quantity of each title shows its colour bar (in screenshots top left, side
    by side; in a window where polyscope puts it, clear of its panels)."""
    kw = dict(enabled=True, cmap=scalar.cmap, vminmax=tuple(float(v) for v in scalar.vrange))
    if scalar.title not in bars:
        kw.update(onscreen_colorbar_enabled=True)
        if headless:
            ui = ps.get_ui_scale()
            x = 18 * ui + sum(_bar_width(t, ui) + 24 * ui for t in bars)
            kw.update(onscreen_colorbar_location=(x, 18 * ui))
        bars[scalar.title] = scalar
    return kw


def _overlay_boxes(ps, bars, legends, width, height):
    """Pixel boxes (x0, y0, x1, y1) of the colour bars (top left) and of the legends drawn afterwards."""
    ui = ps.get_ui_scale()
    out = []
    if bars:                                  # with a margin of about 2 % of the picture around the bars
        out.append((0, 0, 18 * ui + sum(_bar_width(t, ui) + 24 * ui for t in bars) + 0.02 * width,
                    300 * ui + 0.02 * height))
    if legends:
        s = height / 900
        rows = sum(len(lab.legend) for lab in legends)
        longest = max(len(lab.title) for lab in legends)
        w = max(10.5 * longest, 300) * s + 40 * s
        h = (24 + 44 * len(legends) + 28 * rows) * s
        out.append((width - w, 0, width, h) if bars else (0, 0, w, h))
    return out


def _register(ps, part, length, bars, headless):
    if isinstance(part, SurfacePart):
        st = ps.register_surface_mesh(part.name, part.V, part.F, color=part.color, smooth_shade=not part.flat,
                                      edge_width=1.0 if part.edges else 0.0, back_face_policy="identical",
                                      material="flat" if part.flat else "clay")
        if part.transparency is not None:
            st.set_transparency(part.transparency)
        if part.scalar is not None:
            s = part.scalar
            vals = s.values.reshape(-1)
            st.add_scalar_quantity(s.title, vals, defined_on=s.on, **_bar_kw(ps, s, bars, headless))
        if part.labels is not None:
            st.add_color_quantity(part.labels.title, part.labels.colors, defined_on=part.labels.on, enabled=True)
        return st
    if isinstance(part, CurvePart):
        st = ps.register_curve_network(part.name, part.nodes, part.edges, color=part.color,
                                       material="flat" if part.flat else "clay")
        st.set_radius(part.radius * length, relative=False)
        return st
    if isinstance(part, CloudPart):
        st = ps.register_point_cloud(part.name, part.P, color=part.color)
        st.set_radius(part.radius * length, relative=False)
        if part.scalar is not None:
            st.add_scalar_quantity(part.scalar.title, part.scalar.values,
                                   **_bar_kw(ps, part.scalar, bars, headless))
        elif part.colors is not None:
            st.add_color_quantity("normal shading", part.colors, enabled=True)
            st.set_material("flat")
        return st
    raise TypeError(type(part).__name__)  # pragma: no cover


def _register_volume(ps, vol):
    """The whole volume field in the window, disabled (enable it in polyscope's panel): a volume grid or a tet
    mesh with the field, its isosurface and a draggable slice plane."""
    from gsdf.field import GridField

    f, s = vol.field, vol.scalar
    kw = dict(enabled=True, cmap=s.cmap, vminmax=tuple(float(v) for v in s.vrange))
    if isinstance(f, GridField):
        g = ps.register_volume_grid(vol.name + " (volume)", f.values.shape, f.bbox_min, f.bbox_max, enabled=False)
        if vol.level is not None:
            kw.update(enable_isosurface_viz=True, isosurface_level=float(vol.level))
        g.add_scalar_quantity(s.title, f.values, defined_on="nodes", **kw)
    else:
        m = ps.register_volume_mesh(vol.name + " (volume)", f.vertices, tets=f.tets, enabled=False)
        m.add_scalar_quantity(s.title, f.values, defined_on="vertices", **kw)


# ---------------------------------------------------------------------------------------------------------------
# legends of categorical labels, drawn onto the screenshot (polyscope has no legend for colour quantities)
# ---------------------------------------------------------------------------------------------------------------

def _font(size: int):
    from gsdf.render._png import font

    return font(size)


def draw_legends(img, legends, right: bool = False):
    """Each :class:`~gsdf.render._scene.Labels` as a title and one swatch per label with its share of the area, in
    the top left corner (top right when colour bars take the left)."""
    from PIL import Image, ImageDraw

    im = Image.fromarray(img)
    d = ImageDraw.Draw(im)
    W, H = im.size
    s = H / 900
    fs, ft = _font(max(8, int(17 * s))), _font(max(9, int(19 * s)))
    sw, pad = int(20 * s), int(20 * s)
    lines = []
    for lab in legends:
        what = "area" if lab.on == "faces" else "vertices"
        rows = [(f"{k}   ({100 * share:.1f} % of the {what})", col) for k, (col, share) in lab.legend.items()]
        lines.append((lab.title, rows))
    width = max(max(d.textlength(t, font=ft), *(sw + 10 * s + d.textlength(r, font=fs) for r, _ in rows))
                for t, rows in lines)
    x = int(W - pad - width) if right else pad
    y = int(24 * s)
    for title, rows in lines:
        d.text((x, y), title, fill=(20, 20, 20), font=ft, anchor="lt")
        y += int(30 * s)
        for text, col in rows:
            d.rectangle([x, y, x + sw, y + sw], fill=tuple(int(round(255 * c)) for c in col), outline=(40, 40, 40))
            d.text((x + sw + int(10 * s), y + sw // 2), text, fill=(20, 20, 20), font=fs, anchor="lm")
            y += int(28 * s)
        y += int(14 * s)
    return np.asarray(im)
