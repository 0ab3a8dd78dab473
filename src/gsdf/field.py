"""Fields: values on a domain, evaluation anywhere, and isosurfaces — what every volumetric method returns."""

from __future__ import annotations

import numpy as np

from ._checks import as_points, positive


class Field:
    """Abstract scalar field on a domain in R^3.

    Subclasses implement ``__call__(Q) -> (q,)`` and ``isosurface(level) -> (V, F)``.
    """

    def __call__(self, Q) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def isosurface(self, level: float = 0.0):  # pragma: no cover - interface
        raise NotImplementedError


class GridField(Field):
    """Values on the nodes of a regular grid spanning ``[bbox_min, bbox_max]``.

    Parameters
    ----------
    values : (nx, ny, nz) float array
        Node values; node ``(i, j, k)`` sits at ``bbox_min + (i, j, k) * spacing``.
    bbox_min, bbox_max : (3,) float
        Corners of the grid.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.field import GridField
    >>> x = np.linspace(-1, 1, 33)
    >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    >>> f = GridField(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, [-1, -1, -1], [1, 1, 1])
    >>> round(float(f([[0.5, 0.0, 0.0]])[0]), 6)
    0.0
    """

    def __init__(self, values, bbox_min, bbox_max):
        values = np.asarray(values, dtype=np.float64)
        if values.ndim != 3 or min(values.shape) < 2:
            raise ValueError(f"values: expected a 3D grid with at least 2 nodes per axis, got shape {values.shape}")
        if not np.isfinite(values).all():
            raise ValueError("values: contains NaN or infinite entries")
        lo = as_points(bbox_min, "bbox_min")[0]
        hi = as_points(bbox_max, "bbox_max")[0]
        if np.any(hi <= lo):
            raise ValueError(f"bbox_max {hi} must exceed bbox_min {lo} on every axis")
        self.values = np.ascontiguousarray(values)
        self.bbox_min = lo
        self.bbox_max = hi

    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(self.values.shape)

    @property
    def spacing(self) -> np.ndarray:
        return (self.bbox_max - self.bbox_min) / (np.array(self.values.shape) - 1)

    def grid_points(self) -> np.ndarray:
        """Node positions, shape (nx*ny*nz, 3), in C order of ``values``."""
        return grid_points(self.bbox_min, self.bbox_max, self.values.shape)

    def __call__(self, Q) -> np.ndarray:
        """Trilinear interpolation at query points ``Q`` (q, 3); points outside are clamped to the box."""
        Q = as_points(Q, "Q", allow_empty=True)
        n = np.array(self.values.shape)
        t = (Q - self.bbox_min) / self.spacing
        t = np.clip(t, 0.0, n - 1.0)
        i0 = np.minimum(np.floor(t).astype(np.int64), n - 2)
        f = t - i0
        v = self.values
        out = np.zeros(Q.shape[0])
        for dx in (0, 1):
            wx = f[:, 0] if dx else 1.0 - f[:, 0]
            for dy in (0, 1):
                wy = f[:, 1] if dy else 1.0 - f[:, 1]
                for dz in (0, 1):
                    wz = f[:, 2] if dz else 1.0 - f[:, 2]
                    out += wx * wy * wz * v[i0[:, 0] + dx, i0[:, 1] + dy, i0[:, 2] + dz]
        return out

    def isosurface(self, level: float = 0.0):
        """Marching cubes (scikit-image) at ``level``; returns ``(V, F)`` in world coordinates.

        Raises ValueError if the level is outside the range of the field.
        """
        from skimage.measure import marching_cubes

        level = float(level)
        vmin, vmax = float(self.values.min()), float(self.values.max())
        if not (vmin < level < vmax):
            raise ValueError(f"level {level} is outside the field's range [{vmin:.6g}, {vmax:.6g}]: no surface")
        verts, faces, _, _ = marching_cubes(self.values, level=level, spacing=tuple(self.spacing))
        return verts + self.bbox_min, faces.astype(np.int64)

    def save(self, path) -> None:
        """Write the field to a ``.npz`` file (``values``, ``bbox_min``, ``bbox_max``)."""
        np.savez_compressed(path, values=self.values, bbox_min=self.bbox_min, bbox_max=self.bbox_max, kind="grid")

    @classmethod
    def load(cls, path) -> "GridField":
        try:
            with np.load(path) as d:
                return cls(d["values"], d["bbox_min"], d["bbox_max"])
        except (OSError, KeyError, ValueError) as exc:
            raise ValueError(f"{path}: not a gsdf grid field file ({exc})") from exc


def grid_points(bbox_min, bbox_max, shape) -> np.ndarray:
    """Positions of the nodes of a regular grid, shape (prod(shape), 3), C order."""
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
