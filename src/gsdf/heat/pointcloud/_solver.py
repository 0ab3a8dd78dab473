"""Front-end of the signed heat method with a point cloud as the domain (Feng & Crane 2024, §8.4): operators
in :mod:`gsdf.heat.pointcloud._domain`, steps I–III in :mod:`gsdf.heat._core`.

Sign convention: gsdf's left-negative. potpourri3d's ``PointCloudHeatSolver.compute_signed_distance`` has the
same sign (unlike its triangle-mesh solver): on a Fibonacci unit sphere with the equator loop both approximate
−asin z, gsdf within 1.3 %, potpourri3d 2.1 % (tests/conformance/test_potpourri3d.py).
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
    P : (n, 3) float
        Points (at least 4, spanning a surface), model units.
    N : (n, 3) float, optional
        Consistently oriented normals. Default: PCA normals oriented away from the centroid (fine for
        star-shaped clouds).
    k : int, default 30
        Neighbours per local triangulation of the tufted cover (``n_neighbors`` of robust-laplacian).
    t_coef : float, default 1.0
        Diffusion time ``t = t_coef · ℓ̄²``, ℓ̄ the mean cover edge length; larger smooths over gaps.

    Attributes
    ----------
    L : (n, n) sparse float64
        Tufted-cover Laplacian.
    M : (n,) float64
        Lumped masses (square model units).
    N, e1, e2 : (n, 3) float64
        Per-point frames (normal and two tangents).
    n_edges : int
        Edges of the cover.
    t : float
        The diffusion time, square model units.
    domain, core
        The :class:`~gsdf.heat.pointcloud._domain.PointCloudDomain` and its
        :class:`~gsdf.heat._core.SignedHeatCore`.

    Raises
    ------
    ValueError
        Fewer than 4 distinct points, identical or collinear points, bad normals, ``k`` or ``t_coef``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> i = np.arange(1500) + 0.5
    >>> ph, th = np.arccos(1 - 2 * i / 1500), np.pi * (1 + 5 ** 0.5) * i
    >>> P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])   # unit sphere
    >>> ring = np.flatnonzero(np.abs(P[:, 2]) < 0.03)
    >>> loop = ring[np.argsort(np.arctan2(P[ring, 1], P[ring, 0]))]      # counter-clockwise seen from +z
    >>> phi = gsdf.PointCloudSignedHeatSolver(P, P).compute_distance([np.append(loop, loop[0])])
    >>> round(float(phi[np.argmax(P[:, 2])]), 1)                            # the north pole, inside
    -1.6
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
        """Generalized signed distance at the points to curves through them (signed heat method, §8.4).

        Parameters
        ----------
        curves : list of int arrays
            Each curve a sequence of point indices (a polyline through the cloud; repeat the first index to
            close it) or a :class:`gsdf.Curve` of them. The region on the left of a curve (seen from the
            normals) is negative.
        points : sequence of int, default ()
            Isolated point sources (unsigned distance).
        curve_signs : list of bool, optional
            Per curve: True = signed (default), False = unsigned distance to it.
        level_set_constraint : {"zero", "multiple", "none"}, default "zero"
            φ = 0 at the curve points, constant along each connected curve component, or no constraint (for
            broken curves) (§7.1).
        soft_weight : float, optional
            Impose the constraint by a penalty of this weight instead of exactly (§7.1).
        progress : callable, optional
            ``progress(stage, fraction)`` during the solves.

        Returns
        -------
        (n,) float64
            Signed distance per point, model units; negative on the left of the curves.

        Raises
        ------
        ValueError
            Indices out of range, bad ``curve_signs``, an unknown constraint, ``soft_weight <= 0``.

        Examples
        --------
        >>> phi = solver.compute_distance([loop], level_set_constraint="none")     # doctest: +SKIP
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
