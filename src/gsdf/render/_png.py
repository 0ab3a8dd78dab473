"""PNG pictures: gsdf's one PNG writer (:func:`write_png`, atomic, ``.png`` only) and the diverging colour map
with isolines and a bold zero contour that the field pictures use."""

from __future__ import annotations

import numpy as np


def field_to_rgb(values: np.ndarray, n_isolines: int = 10, zero_level: float = 0.0) -> np.ndarray:
    """Colour a 2D array: blue below ``zero_level`` (inside), red above, white at it; dark isolines.

    Returns an (h, w, 3) uint8 image whose first axis is the array's first axis.
    """
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 2 or min(v.shape) < 2:
        raise ValueError(f"values: expected a 2D array of at least 2x2, got shape {v.shape}")
    if not np.isfinite(v).all():
        raise ValueError("values: contains NaN or infinite entries")
    s = v - zero_level
    scale = float(np.percentile(np.abs(s), 99)) or float(np.abs(s).max()) or 1.0  # robust to singular spikes
    t = np.clip(s / scale, -1, 1)
    neg, pos = np.array([0.23, 0.30, 0.75]), np.array([0.71, 0.02, 0.15])
    white = np.ones(3)
    a = np.abs(t)[..., None] ** 0.6
    rgb = np.where((t < 0)[..., None], white * (1 - a) + neg * a, white * (1 - a) + pos * a)
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


def write_png(path, rgb: np.ndarray, min_size: int = 512) -> None:
    """Write an (h, w, 3) uint8 (or (h, w) grey) image as PNG, upscaled (nearest) so its shorter side is at least
    ``min_size``. The file is written atomically; a name not ending in ``.png`` is a ValueError.

    Example
    -------
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


def write_field_slice_png(path, field, axis: int = 2, index: int | None = None, zero_level: float = 0.0) -> None:
    """PNG of one grid slice of a :class:`gsdf.GridField` (default: the middle z slice).

    The image shows x to the right and y up (for ``axis=2``); isolines are evenly spaced in value.
    """
    vals = np.asarray(field.values)
    if index is None:
        index = vals.shape[axis] // 2
    sl = np.take(vals, index, axis=axis)  # (u, v) with u the first remaining axis
    img = np.flipud(sl.T)  # rows = v (up), cols = u (right)
    write_png(path, field_to_rgb(upsample(img), zero_level=zero_level))


def upsample(img: np.ndarray, min_size: int = 512) -> np.ndarray:
    """Bilinear upsampling of a 2D array so that its shorter side has at least ``min_size`` samples."""
    from scipy.ndimage import zoom

    k = min_size / min(img.shape)
    return zoom(img, k, order=1) if k > 1 else img
