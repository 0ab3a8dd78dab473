"""What a test checks on a screenshot: not empty, the object framed (large, not cut off by the border) and the
annotations (colour bar, legend) in a top corner, apart from the object."""

from __future__ import annotations

import numpy as np


def load(png) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(png).convert("RGB"))


def inspect(img, tol: int = 12) -> dict:
    """Foreground (pixels differing from the most common border colour by more than ``tol`` in a channel), split
    into annotations (connected groups, after closing gaps of 1.2 % of the size, lying wholly in a top corner:
    a third of the width, 45 % of the height) and the object (the rest).

    Returns a dict: size (W, H), fill (object pixels / all), bbox (x0, y0, x1, y1) of the object or None,
    extent (the larger of its width and height fractions), margin (its distance to the border, pixels),
    annotations (boxes), bar_colours (distinct colours inside the annotations, 16 levels per channel).
    """
    from scipy import ndimage

    a = np.asarray(img)[..., :3].astype(int)
    H, W = a.shape[:2]
    border = np.concatenate([a[0], a[-1], a[:, 0], a[:, -1]])
    vals, cnt = np.unique(border, axis=0, return_counts=True)
    bg = vals[np.argmax(cnt)]
    fg = np.abs(a - bg).max(-1) > tol
    k = max(3, int(0.012 * max(H, W)))
    lab, _ = ndimage.label(ndimage.binary_dilation(fg, iterations=k))
    notes, mask = [], np.zeros_like(fg)
    for j, sl in enumerate(ndimage.find_objects(lab), start=1):
        y0, y1, x0, x1 = sl[0].start, sl[0].stop, sl[1].start, sl[1].stop
        if y1 <= 0.45 * H and (x1 <= W / 3 or x0 >= 2 * W / 3):
            notes.append((int(x0), int(y0), int(x1), int(y1)))
            mask[sl] |= lab[sl] == j
    obj = fg & ~mask
    rep = dict(size=(W, H), fill=float(obj.mean()), annotations=notes, bbox=None, extent=0.0, margin=-1)
    if obj.any():
        ys, xs = np.nonzero(obj)
        x0, y0, x1, y1 = int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())
        rep.update(bbox=(x0, y0, x1, y1), extent=max((x1 - x0 + 1) / W, (y1 - y0 + 1) / H),
                   margin=min(x0, y0, W - 1 - x1, H - 1 - y1))
    q = (a[fg & mask] // 16)
    rep["bar_colours"] = len(np.unique(q, axis=0)) if len(q) else 0
    return rep


def problems(img, min_fill: float = 0.04, min_extent: float = 0.45, margin: int = 2, colour_bar: bool = True):
    """The list of what is wrong with the picture (empty when it is fine)."""
    r = inspect(img)
    out = []
    if r["bbox"] is None:
        return ["empty: nothing but background and annotations"]
    if r["fill"] < min_fill:
        out.append(f"only {r['fill']:.1%} of the pixels show the object (< {min_fill:.0%})")
    if r["extent"] < min_extent:
        out.append(f"the object spans {r['extent']:.0%} of the picture (< {min_extent:.0%})")
    if r["margin"] < margin:
        out.append("the object touches the border (cut off)")
    if colour_bar and not r["annotations"]:
        out.append("no colour bar or legend in a top corner")
    if colour_bar and r["bar_colours"] < 12:
        out.append(f"the annotation has {r['bar_colours']} colours: no colour ramp")
    return out
