"""PNG pictures: gsdf's one PNG writer (:func:`write_png`, atomic, ``.png`` only), the diverging colour map with
isolines and a bold zero contour that gsdf's own field pictures use, their colour bars and legends
(:func:`annotate`), and grid slices (:func:`field_slice_image`)."""

from __future__ import annotations

import numpy as np


NEG_COLOUR = np.array([0.23, 0.30, 0.75])   #: below the level (inside): blue
POS_COLOUR = np.array([0.71, 0.02, 0.15])   #: above the level (outside): red


def colour_scale(values, zero_level: float = 0.0) -> float:
    """Half-width of the diverging colour map of ``values`` about ``zero_level``: the 99th percentile of the
    distance to the level (robust to singular spikes), rounded up to two significant digits."""
    from gsdf.render._scene import round_up

    s = np.abs(np.asarray(values, dtype=np.float64) - zero_level)
    a = float(np.percentile(s, 99)) or float(s.max()) or 1.0
    return round_up(a)


def diverging(t) -> np.ndarray:
    """Colours (..., 3) in [0, 1] of ``t`` in [-1, 1]: blue below 0, white at 0, red above."""
    t = np.clip(np.asarray(t, dtype=np.float64), -1, 1)
    a = np.abs(t)[..., None] ** 0.6
    return np.where((t < 0)[..., None], (1 - a) + NEG_COLOUR * a, (1 - a) + POS_COLOUR * a)


def field_to_rgb(values: np.ndarray, n_isolines: int = 10, zero_level: float = 0.0, scale: float | None = None
                 ) -> np.ndarray:
    """Colour a 2D array: blue below ``zero_level`` (inside), red above, white at it; dark isolines, and a black
    line at the level. ``scale``: the distance to the level at the ends of the colour map (default
    :func:`colour_scale`).

    Returns an (h, w, 3) uint8 image whose first axis is the array's first axis.
    """
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 2 or min(v.shape) < 2:
        raise ValueError(f"values: expected a 2D array of at least 2x2, got shape {v.shape}")
    if not np.isfinite(v).all():
        raise ValueError("values: contains NaN or infinite entries")
    s = v - zero_level
    scale = colour_scale(v, zero_level) if scale is None else float(scale)
    rgb = diverging(s / scale)
    # isolines: where the band index changes between neighbouring pixels
    band = np.floor(s / (scale / n_isolines)).astype(np.int64)
    edge = np.zeros(v.shape, bool)
    edge[:-1, :] |= band[:-1, :] != band[1:, :]
    edge[:, :-1] |= band[:, :-1] != band[:, 1:]
    rgb[edge] *= 0.55
    zero = np.zeros(v.shape, bool)
    sg = s > 0
    zero[:-1, :] |= sg[:-1, :] != sg[1:, :]
    zero[:, :-1] |= sg[:, :-1] != sg[:, 1:]
    rgb[zero] = 0.0
    return (rgb * 255).round().astype(np.uint8)


def font(size: int):
    """DejaVu Sans at ``size`` pixels (Pillow's own font where it is missing)."""
    from PIL import ImageFont

    for name in ("DejaVuSans.ttf", "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"):
        try:
            return ImageFont.truetype(name, size)
        except OSError:
            pass
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # pragma: no cover - Pillow < 10.1
        return ImageFont.load_default()


def _tick(x: float) -> str:
    return f"{x:.3g}".replace("-", "\u2212")


def annotate(img, bar=None, legend=None) -> np.ndarray:
    """The picture with a panel on its right: a colour bar ``bar = (title, level, scale)`` of the diverging map
    (ticks at level - scale, level, level + scale) and/or a legend ``legend = (title, [(text, rgb), ...])``.
    The panel widens the picture (it never covers the object); it sits in the top right corner."""
    from PIL import Image, ImageDraw

    img = np.asarray(img)
    H, W = img.shape[:2]
    s = max(H, 600) / 900
    fs, ft = font(max(9, int(17 * s))), font(max(10, int(20 * s)))
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    texts = []
    if bar is not None:
        texts.append(probe.textlength(bar[0], font=ft))
        texts.append(int(60 * s) + max(probe.textlength(_tick(bar[1] + k * bar[2]), font=fs) for k in (-1, 0, 1)))
    if legend is not None:
        texts.append(probe.textlength(legend[0], font=ft))
        texts.extend(int(34 * s) + probe.textlength(t, font=fs) for t, _ in legend[1])
    pw = int(max(texts, default=0) + 40 * s)
    out = Image.new("RGB", (W + pw, H), (255, 255, 255))
    out.paste(Image.fromarray(img[..., :3]), (0, 0))
    d = ImageDraw.Draw(out)
    x, y = W + int(14 * s), int(20 * s)
    if bar is not None:
        title, level, scale = bar
        d.text((x, y), title, fill=(20, 20, 20), font=ft, anchor="lt")
        y += int(34 * s)
        bh, bw = int(0.30 * H), int(22 * s)
        t = np.linspace(1, -1, bh)
        ramp = (diverging(t)[:, None, :] * 255).round().astype(np.uint8).repeat(bw, axis=1)
        out.paste(Image.fromarray(ramp), (x, y))
        d.rectangle([x, y, x + bw, y + bh - 1], outline=(60, 60, 60))
        for k, yy in ((1, y), (0, y + bh // 2), (-1, y + bh - 1)):
            d.line([x + bw, yy, x + bw + int(6 * s), yy], fill=(60, 60, 60), width=max(1, int(s)))
            d.text((x + bw + int(10 * s), yy), _tick(level + k * scale), fill=(20, 20, 20), font=fs, anchor="lm")
        y += bh + int(26 * s)
    if legend is not None:
        title, rows = legend
        d.text((x, y), title, fill=(20, 20, 20), font=ft, anchor="lt")
        y += int(32 * s)
        sw = int(20 * s)
        for text, col in rows:
            c = tuple(int(round(255 * float(v))) for v in col)
            d.rectangle([x, y, x + sw, y + sw], fill=c, outline=(40, 40, 40))
            d.text((x + sw + int(10 * s), y + sw // 2), text, fill=(20, 20, 20), font=fs, anchor="lm")
            y += int(28 * s)
    return np.asarray(out)


def write_png(path, rgb: np.ndarray, min_size: int = 512) -> None:
    """Write an (h, w, 3) uint8 (or (h, w) grey) image as PNG, upscaled (nearest) so its shorter side is at least
    ``min_size``. The file is written atomically; a name not ending in ``.png`` is a ValueError.

    Examples
    --------
    >>> import os, tempfile, numpy as np
    >>> write_png(os.path.join(tempfile.mkdtemp(), "a.png"), np.zeros((4, 4, 3), np.uint8), min_size=4)
    """
    from PIL import Image

    from gsdf.io._safe_write import atomic_output, check_output_path

    check_output_path(path, extensions=(".png",))
    a = np.asarray(rgb)
    if a.dtype != np.uint8 or not (a.ndim == 2 or (a.ndim == 3 and a.shape[2] in (3, 4))) or min(a.shape[:2]) < 1:
        raise ValueError(f"rgb: expected an (h, w), (h, w, 3) or (h, w, 4) uint8 image, got {a.dtype} {a.shape}")
    img = Image.fromarray(np.ascontiguousarray(a))
    k = max(1, int(np.ceil(min_size / min(img.size))))
    if k > 1:
        img = img.resize((img.size[0] * k, img.size[1] * k), Image.NEAREST)
    with atomic_output(path, extensions=(".png",)) as tmp:
        img.save(tmp, format="PNG")


def slice_values(values, lo, hi, axis: int, at: float) -> np.ndarray:
    """The 2D slice ``x[axis] = at`` of grid node values over the box [lo, hi], linear between node layers; its
    axes are the two other axes in increasing order."""
    values = np.asarray(values, dtype=np.float64)
    n = values.shape[axis]
    t = float(np.clip((at - lo[axis]) / (hi[axis] - lo[axis]) * (n - 1), 0, n - 1))
    k0 = int(min(np.floor(t), n - 2))
    w = t - k0
    return np.take(values, k0, axis=axis) * (1 - w) + np.take(values, k0 + 1, axis=axis) * w


def field_slice_image(field, axis: int = 2, at: float | None = None, zero_level: float = 0.0, size: int = 900,
                      title: str | None = None, vertical: int | None = None) -> np.ndarray:
    """A picture of the slice ``x[axis] = at`` (default: the middle) of a :class:`gsdf.GridField`: the other two
    axes to the right and up in increasing order (for ``axis=2``: x right, y up; ``vertical``: the axis that goes
    up instead), square pixels, the longer side ``size`` pixels plus a white margin, isolines evenly spaced in
    value, the level ``zero_level`` in black; with a colour bar titled ``title`` when given. Returns an
    (h, w, 3) uint8 image."""
    from scipy.ndimage import map_coordinates

    vals = np.asarray(field.values, dtype=np.float64)
    lo, hi = np.asarray(field.bbox_min, float), np.asarray(field.bbox_max, float)
    if at is None:
        at = 0.5 * (lo[axis] + hi[axis])
    if not lo[axis] - 1e-12 * abs(hi[axis] - lo[axis]) <= at <= hi[axis] + 1e-12 * abs(hi[axis] - lo[axis]):
        raise ValueError(f"at: {at:g} is outside the field's box [{lo[axis]:g}, {hi[axis]:g}] along "
                         f"{'xyz'[axis]}")
    sl = slice_values(vals, lo, hi, axis, at)            # (u, v)
    u, v = [i for i in range(3) if i != axis]
    if vertical == u:
        sl, u, v = sl.T, v, u
    ext = np.array([hi[u] - lo[u], hi[v] - lo[v]])
    px = ext.max() / size
    w, h = (max(2, int(round(e / px))) for e in ext)
    cu = np.linspace(0, sl.shape[0] - 1, w)
    cv = np.linspace(sl.shape[1] - 1, 0, h)              # rows go down: v up
    V_, U_ = np.meshgrid(cv, cu, indexing="ij")
    img = map_coordinates(sl, [U_, V_], order=1)          # (h, w)
    scale = colour_scale(sl, zero_level)
    rgb = field_to_rgb(img, zero_level=zero_level, scale=scale)
    m = max(10, size // 25)                              # a white margin: the slice is framed, not cut off
    rgb = np.pad(rgb, ((m, m), (m, m), (0, 0)), constant_values=255)
    if title is not None:
        rgb = annotate(rgb, bar=(title, zero_level, scale))
    return rgb


def write_field_slice_png(path, field, axis: int = 2, index: int | None = None, zero_level: float = 0.0,
                          at: float | None = None, title: str | None = None) -> None:
    """PNG of one slice of a :class:`gsdf.GridField` (default: the middle z slice; ``index``: a node layer,
    ``at``: a coordinate along ``axis``), as :func:`field_slice_image`."""
    if index is not None:
        lo, hi = np.asarray(field.bbox_min, float), np.asarray(field.bbox_max, float)
        at = lo[axis] + (hi[axis] - lo[axis]) * index / (np.shape(field.values)[axis] - 1)
    write_png(path, field_slice_image(field, axis, at, zero_level, title=title), min_size=1)
