"""Applications of pointwise SDFs of point clouds (thesis §5.2, Figs. 5.7–5.8): booleans, offsets, morphology.

Every function takes and returns *pointwise* signed distance callables ``f(Q (q, 3)) -> (q,)`` (negative inside),
e.g. :class:`~gsdf.tori._pat.PointsAsTori` objects, so results can be contoured
(:func:`contour`), rendered (:func:`gsdf.render._trace.render_png`) or combined further. Booleans use min/max
(exact inside/outside, a distance bound away from the seams); erosion/dilation of a shape by r are the offsets
φ ∓ r, and closing (dilate then erode) / opening (erode then dilate) compose offsets of the *re-distanced*
intermediate, which we approximate by the offset field itself (exact for an exact SDF away from the medial axis).
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import as_points
from gsdf._memory import SECONDS_PER_QUERY

__all__ = ["union", "intersection", "difference", "offset", "contour"]


def _call(f, Q):
    return np.asarray(f(as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)), dtype=np.float64)


def union(*fields):
    """Union of shapes: min of their SDFs.

    Examples
    --------
    >>> import numpy as np
    >>> a = lambda Q: np.linalg.norm(Q - [0.5, 0, 0], axis=1) - 0.6
    >>> b = lambda Q: np.linalg.norm(Q + [0.5, 0, 0], axis=1) - 0.6
    >>> union(a, b)([[0.5, 0, 0], [-0.5, 0, 0], [0, 2, 0]]).round(2).tolist()
    [-0.6, -0.6, 1.46]
    """
    if not fields:
        raise ValueError("union: needs at least one field")
    return lambda Q: np.min([_call(f, Q) for f in fields], axis=0)


def intersection(*fields):
    """Intersection of shapes: max of their SDFs."""
    if not fields:
        raise ValueError("intersection: needs at least one field")
    return lambda Q: np.max([_call(f, Q) for f in fields], axis=0)


def difference(a, b):
    """``a`` minus ``b``: max(φ_a, −φ_b)."""
    return lambda Q: np.maximum(_call(a, Q), -_call(b, Q))


def offset(field, r: float):
    """Dilation (r > 0) or erosion (r < 0) by |r|: the level set φ = r, i.e. φ − r."""
    from gsdf._checks import finite

    r = finite(r, "r")
    return lambda Q: _call(field, Q) - r


def contour(field, bbox_min=None, bbox_max=None, resolution=64, level: float = 0.0):
    """Mesh of ``field = level``: :func:`gsdf.extract_isosurface` with ``inside="below"`` (marching cubes +
    bisection) on ``resolution`` nodes along the longest side of the box, or on a :class:`gsdf.Grid`."""
    from gsdf.contour import extract_isosurface

    return extract_isosurface(field, bbox_min, bbox_max, resolution, level=level, inside="below")
