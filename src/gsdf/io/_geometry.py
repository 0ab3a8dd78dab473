"""One loaded input of the command line and of batch jobs: a triangle mesh/soup or an oriented point cloud.

:func:`load_geometry` decides which from the file (a mesh unless the file has no faces or has a point-cloud
extension) and, for clouds without normals, can estimate them.
"""

from __future__ import annotations

import hashlib
import os

import numpy as np

POINT_EXTENSIONS = {".xyz", ".pwn", ".pc", ".npy", ".npz"}


class Geometry:
    """One loaded input: a triangle mesh/soup ``(X, F)`` or an oriented point cloud ``(X, N)``.

    Attributes
    ----------
    X : (n, 3) float64
        Vertex or point positions.
    F : (m, 3) int64 or None
        Triangles (None for a cloud).
    N : (n, 3) float64 or None
        Cloud normals (None for a mesh).
    path : str or None
        The file it was read from.

    Example
    -------
    >>> import numpy as np
    >>> g = Geometry(np.eye(3), F=np.array([[0, 1, 2]]))
    >>> g.is_mesh, g.counts()
    (True, {'vertices': 3, 'faces': 1})
    """

    def __init__(self, X, F=None, N=None, path=None):
        self.X, self.F, self.N, self.path = X, F, N, path

    @property
    def is_mesh(self) -> bool:
        return self.F is not None

    def counts(self) -> dict:
        if self.is_mesh:
            return {"vertices": int(len(self.X)), "faces": int(len(self.F))}
        return {"points": int(len(self.X))}

    def describe(self) -> str:
        """One line for logs: the file and what it holds."""
        if self.is_mesh:
            return f"{self.path}: mesh, {len(self.X)} vertices, {len(self.F)} triangles"
        return f"{self.path}: point cloud, {len(self.X)} oriented points"

    def winding(self, beta=None):
        """A reusable fast winding number evaluator for this input (β = 2 for meshes, 2.3 for clouds unless
        given)."""
        from gsdf.winding import FastWindingNumber, FastWindingNumberPoints

        if self.is_mesh:
            return FastWindingNumber(self.X, self.F, beta=2.0 if beta is None else beta)
        return FastWindingNumberPoints(self.X, self.N, beta=2.3 if beta is None else beta)

    def digest(self) -> bytes:
        """A hash of the geometry arrays (seeds a batch item's random samples)."""
        h = hashlib.sha256()
        for A in (self.X, self.F, self.N):
            if A is not None:
                h.update(np.ascontiguousarray(A).tobytes())
        return h.digest()


def load_geometry(path, estimate_normals: bool = False) -> Geometry:
    """Read a mesh, or a point cloud when the file has no faces or has a point-cloud extension.

    Parameters
    ----------
    path : str or os.PathLike
        Any file :func:`gsdf.read_mesh` or :func:`gsdf.read_points` reads.
    estimate_normals : bool
        For clouds without normals: PCA normals oriented away from the centroid; otherwise such a cloud
        is a ValueError (winding numbers need oriented normals).

    Returns
    -------
    Geometry

    Example
    -------
    >>> g = load_geometry("bunny.off")     # doctest: +SKIP
    >>> g.is_mesh, g.X.shape               # doctest: +SKIP
    (True, (34817, 3))
    """
    from gsdf.io._mesh import read_mesh
    from gsdf.io._points import read_points

    path = os.fspath(path)
    if os.path.splitext(path)[1].lower() not in POINT_EXTENSIONS:
        try:
            V, F = read_mesh(path)
        except ValueError as exc:
            if "no faces" not in str(exc):
                raise
        else:
            if len(F) == 0:
                raise ValueError(f"{path}: has no triangles")
            return Geometry(V, F=F, path=path)
    P, N = read_points(path)
    if N is None:
        if not estimate_normals:
            raise ValueError(f"{path}: the point cloud has no normals; winding numbers need oriented normals "
                             "(estimate_normals=True, or --estimate-normals on the command line, uses PCA "
                             "normals oriented away from the centroid)")
        from gsdf.winding._point_areas import estimate_normals as pca

        N = pca(P, orient_towards=P.mean(axis=0))
    return Geometry(P, N=N, path=path)
