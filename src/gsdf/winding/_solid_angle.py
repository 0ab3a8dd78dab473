"""The solid angle of one triangle seen from a point (van Oosterom & Strackee 1983), as a winding number
contribution Ω/4π: the kernel shared by the direct sums (:mod:`.exact`) and the hierarchical evaluation
(:mod:`.hierarchical`), in its own module so that neither imports the other's module at load time."""

from __future__ import annotations

import numpy as np
from numba import njit

INV_4PI = 1.0 / (4.0 * np.pi)


@njit(cache=True, inline="always")
def solid_angle_w(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Winding number contribution Ω/4π of one triangle with corners a, b, c relative to the query point.

    A query in the triangle's plane (det = 0: degenerate triangle, or q on the triangle) contributes 0, so
    zero-area faces never matter and a point on a closed surface gets w = 1/2 from the other faces.
    """
    la = np.sqrt(ax * ax + ay * ay + az * az)
    lb = np.sqrt(bx * bx + by * by + bz * bz)
    lc = np.sqrt(cx * cx + cy * cy + cz * cz)
    det = ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    den = la * lb * lc + (ax * bx + ay * by + az * bz) * lc + (bx * cx + by * cy + bz * cz) * la \
        + (cx * ax + cy * ay + cz * az) * lb
    if det == 0.0:
        return 0.0
    return 2.0 * np.arctan2(det, den) * INV_4PI
