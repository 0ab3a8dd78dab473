"""Vector sources of the volumetric signed heat method (Feng & Crane 2024, §8.1–8.2, §8 "point clouds").

A source is a set of points b_i with vector charges w_i = a_i N_i: triangle barycenters with area-weighted
normals (triangle meshes, soups, fan-triangulated polygon meshes — the midpoint quadrature of §8.2), or cloud
points with unit normals times point areas (the tangent-plane Voronoi areas of :func:`gsdf.point_areas`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._checks import as_mesh, as_normals, as_points, as_weights


@dataclass(frozen=True)
class Sources:
    """Source points ``B`` (m, 3), charges ``W = a N`` (m, 3), weights ``a`` (m,), and the input geometry."""

    B: np.ndarray
    W: np.ndarray
    a: np.ndarray
    kind: str
    mean_spacing: float

    @property
    def bbox(self):
        return self.B.min(axis=0), self.B.max(axis=0)


def mesh_sources(V, F) -> Sources:
    """Sources of a triangle mesh or soup: barycenters and area-weighted normals ½ (e₁ × e₂)."""
    V, F = as_mesh(V, F)
    T = V[F]
    W = 0.5 * np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    a = np.linalg.norm(W, axis=1)
    keep = a > 0
    if not keep.any():
        raise ValueError("mesh: every face has zero area, so every normal is zero (no source to diffuse)")
    E = np.linalg.norm(T - T[:, [1, 2, 0]], axis=2)
    return Sources(np.ascontiguousarray(T[keep].mean(axis=1)), np.ascontiguousarray(W[keep]), a[keep], "mesh",
                   float(E.mean()))


def point_sources(P, N, areas=None, k: int = 20) -> Sources:
    """Sources of an oriented point cloud: points, unit normals times point areas (estimated when omitted)."""
    if N is None:
        raise ValueError("points: an oriented cloud is needed (normals N is None); estimate them with "
                         "gsdf.estimate_normals(P) or pass --estimate-normals on the command line")
    P = as_points(P, "P")
    N = as_normals(N, len(P), "N")
    nrm = np.linalg.norm(N, axis=1)
    keep = nrm > 0
    U = np.zeros_like(N)
    U[keep] = N[keep] / nrm[keep, None]
    if areas is None:
        if len(P) < 4:
            raise ValueError(f"points: need at least 4 points to estimate point areas, got {len(P)}")
        from ...winding.point_areas import point_areas

        areas = point_areas(P, U, k=min(k, len(P) - 1))
    a = as_weights(areas, len(P), "areas")
    keep &= a > 0
    if not keep.any():
        raise ValueError("points: every point has a zero normal or zero area (no source to diffuse)")
    spacing = float(np.sqrt(a[keep].mean()))
    return Sources(np.ascontiguousarray(P[keep]), np.ascontiguousarray(U[keep] * a[keep, None]), a[keep], "points",
                   spacing)
