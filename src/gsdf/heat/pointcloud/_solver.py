"""Front-end of the signed heat method with a point cloud as the domain (Feng & Crane 2024, §8.4): operators
in :mod:`gsdf.heat.pointcloud._domain`, steps I–III in :mod:`gsdf.heat._core`.

Sign convention: gsdf's left-negative; potpourri3d's ``PointCloudHeatSolver.compute_signed_distance`` is
left-positive (its values are the negative of these).
"""

from __future__ import annotations

import numpy as np

from gsdf import _checks
from gsdf._normalize import Frame
from gsdf.heat._core import SignedHeatCore
from gsdf.heat.pointcloud._domain import PointCloudDomain, point_cloud_operators  # noqa: F401

__all__ = ["PointCloudSignedHeatSolver", "point_cloud_operators"]


class PointCloudSignedHeatSolver:
    """Generalized signed distance to curves drawn on a point cloud (§8.4; :mod:`gsdf.heat.pointcloud._domain`).

    Parameters
    ----------
    P : (n, 3) points; N : (n, 3) consistently oriented normals, or None for PCA normals oriented away from
        the centroid (fine for star-shaped clouds); k : neighbours per local triangulation of the tufted cover
        (``n_neighbors`` of robust-laplacian); t_coef : diffusion time ``t = t_coef · ℓ̄²``, ℓ̄ the mean cover
        edge length.

    Attributes
    ----------
    L : (n, n) tufted-cover Laplacian; M : (n,) lumped masses; N, e1, e2 : frames; n_edges : cover edges;
    domain, core : the :class:`~gsdf.heat.pointcloud._domain.PointCloudDomain` and its
    :class:`~gsdf.heat._core.SignedHeatCore`.

    Examples
    --------
    >>> solver = PointCloudSignedHeatSolver(P, N)                       # doctest: +SKIP
    >>> phi = solver.compute_distance([np.array([3, 17, 42, 8, 3])])    # doctest: +SKIP
    """

    def __init__(self, P, N=None, k: int = 30, t_coef: float = 1.0):
        P = _checks.as_points(P, "P")
        _check_spread(P)
        # scale invariance: the cloud is solved in its frame (centred, power-of-two scale: exact), distances
        # are mapped back on output (gsdf._normalize); the attributes below are in input units
        self.frame = Frame.of(P)
        self.P_world = P
        self.domain = d = PointCloudDomain(self.frame.geometry(P, "P"), N, k=k, t_coef=t_coef)
        self.core = SignedHeatCore(d)
        fr = self.frame  # attributes in input units (L, Lconn and the frames are scale-free)
        self.P, self.N, self.L, self.M, self.Lconn = P, d.N, d.L, fr.area(d.M), d.Lconn
        self.e1, self.e2, self.n_edges = d.e1, d.e2, d.n_edges
        self.t, self.mean_edge = float(fr.area(d.t)), float(fr.length(d.mean_edge))

    def compute_distance(self, curves, *, points=(), curve_signs=None, level_set_constraint: str = "zero",
                         soft_weight=None, progress=None):
        """Signed distance (n,) at the points to curves given as sequences of point indices (left negative).

        ``level_set_constraint``: "zero" (φ = 0 at the curve points), "multiple" (constant along each connected
        curve component) or "none"; ``soft_weight`` replaces the hard constraint by a penalty (§7.1).
        ``points``: isolated point sources (unsigned); ``curve_signs``: False makes a curve unsigned.
        """
        phi = self.core.compute_distance(curves, points=points, curve_signs=curve_signs,
                                         level_set_constraint=level_set_constraint, soft_weight=soft_weight,
                                         progress=progress)
        return self.frame.length(phi)


def _check_spread(P: np.ndarray) -> None:
    """Refuse clouds that span no surface: all points equal, or all on one line (ValueError naming it)."""
    if len(P) < 4:
        raise ValueError(f"P: need at least 4 points, got {len(P)}")
    lo, hi = P.min(axis=0), P.max(axis=0)
    if not np.any(hi > lo):
        raise ValueError("P: all points are identical (a point cloud domain needs points spanning a surface)")
    Y = Frame.of(P).geometry(P, "P")
    sv = np.linalg.svd(Y - Y.mean(axis=0), compute_uv=False)
    if sv[1] <= 1e-12 * sv[0]:
        raise ValueError("P: all points are collinear (a point cloud domain needs points spanning a surface)")
    if len(np.unique(Y, axis=0)) < 4:
        raise ValueError("P: fewer than 4 distinct points (a point cloud domain needs points spanning a surface)")
