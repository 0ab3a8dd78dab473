"""Regular grids of nodes in a box: node counts from a resolution, node positions."""

from __future__ import annotations

import numpy as np

from gsdf._checks import positive

__all__ = ["grid_points", "grid_shape"]


def grid_points(bbox_min, bbox_max, shape) -> np.ndarray:
    """Positions of the nodes of a regular grid, shape (prod(shape), 3), C order."""
    from gsdf._memory import check_bytes, grid_bytes

    # the node positions (24 B) and, in every caller, at least one float per node and its meshgrid copies
    check_bytes(grid_bytes(shape, 56), f"a {'x'.join(str(int(s)) for s in shape)} grid of nodes (lower the resolution)")
    axes = [np.linspace(bbox_min[d], bbox_max[d], int(shape[d])) for d in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return np.column_stack((X.ravel(), Y.ravel(), Z.ravel()))


def grid_shape(bbox_min, bbox_max, resolution) -> tuple[int, int, int]:
    """Grid node counts: ``resolution`` nodes along the longest axis, the same spacing on the others."""
    r = int(resolution)
    if r < 2:
        raise ValueError(f"resolution must be at least 2, got {resolution}")
    ext = np.asarray(bbox_max, float) - np.asarray(bbox_min, float)
    h = positive(ext.max(), "bounding box size") / (r - 1)
    return tuple(int(max(2, np.ceil(e / h - 1e-9) + 1)) for e in ext)
