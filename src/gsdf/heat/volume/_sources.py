"""Vector sources of the volumetric signed heat method (Feng & Crane 2024, §8.1–8.2, §8 "point clouds").

A source is a set of points b_i with vector charges w_i = a_i N_i: triangle barycenters with area-weighted
normals (triangle meshes, soups, fan-triangulated polygon meshes — the midpoint quadrature of §8.2), or cloud
points with unit normals times point areas (the tangent-plane Voronoi areas of :func:`gsdf.point_areas`). They
are :class:`gsdf.heat._sources.Sources` (fields ``B``, ``W``, ``a``), the one sources type of every domain.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf._checks import as_mesh, as_normals, as_points, as_weights
from gsdf.heat._sources import Sources

__all__ = ["Sources", "mesh_sources", "point_sources", "check_cloud", "cloud_components", "source_components"]


def mesh_sources(V, F) -> Sources:
    """Sources of a triangle mesh or soup: barycenters and area-weighted normals ½ (e₁ × e₂)."""
    return _mesh_sources(*as_mesh(V, F))


def _mesh_sources(V: np.ndarray, F: np.ndarray) -> Sources:
    """:func:`mesh_sources` of a validated mesh."""
    T = V[F]
    W = 0.5 * np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    a = np.linalg.norm(W, axis=1)
    keep = a > 0
    if not keep.any():
        raise ValueError("mesh: every face has zero area, so every normal is zero (no source to diffuse)")
    E = np.linalg.norm(T - T[:, [1, 2, 0]], axis=2)
    return Sources(B=np.ascontiguousarray(T[keep].mean(axis=1)), W=np.ascontiguousarray(W[keep]), a=a[keep],
                   kind="mesh", mean_spacing=float(E.mean()), extra={"faces": F[keep]})


def check_cloud(P, N) -> tuple[np.ndarray, np.ndarray]:
    """An oriented point cloud validated: ``P`` (n, 3) finite, ``N`` (n, 3) finite and not all zero (ValueError
    naming the problem; N None asks for normals)."""
    if N is None:
        raise ValueError("points: an oriented cloud is needed (normals N is None); estimate them with "
                         "gsdf.estimate_normals(P) or pass --estimate-normals on the command line")
    P = as_points(P, "P")
    return P, as_normals(N, len(P), "N")


def point_sources(P, N, areas=None, k: int = 20, candidates: int = 2) -> Sources:
    """Sources of an oriented point cloud: points, unit normals times point areas (estimated when omitted).

    The areas are :func:`gsdf.point_areas` with ``k`` neighbours chosen among the ``candidates · k`` nearest
    (Barill et al. 2018, §3.1).
    """
    return _cloud_sources(*check_cloud(P, N), areas=areas, k=k, candidates=candidates)


def _cloud_sources(P: np.ndarray, N: np.ndarray, areas=None, k: int = 20, candidates: int = 2) -> Sources:
    """:func:`point_sources` of a validated cloud (:func:`check_cloud`)."""
    nrm = np.linalg.norm(N, axis=1)
    keep = nrm > 0
    U = np.zeros_like(N)
    U[keep] = N[keep] / nrm[keep, None]
    if areas is None:
        if len(P) < 4:
            raise ValueError(f"points: need at least 4 points to estimate point areas, got {len(P)}")
        from gsdf.winding._point_areas import _point_areas

        areas = _point_areas(P, U, k=min(k, len(P) - 1), candidates=candidates)
    a = as_weights(areas, len(P), "areas")
    keep &= a > 0
    if not keep.any():
        raise ValueError("points: every point has a zero normal or zero area (no source to diffuse)")
    spacing = float(np.sqrt(a[keep].mean()))
    return Sources(B=np.ascontiguousarray(P[keep]), W=np.ascontiguousarray(U[keep] * a[keep, None]), a=a[keep],
                   kind="points", mean_spacing=spacing)


def cloud_components(Z: np.ndarray) -> np.ndarray:
    """Connected components of a point set: each point joined to its 8 nearest neighbours closer than 3 × the
    median nearest-neighbour distance. Returns labels (n,)."""
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    Z = np.asarray(Z, float)
    k = min(9, len(Z))
    d, nb = cKDTree(Z).query(Z, k=k, workers=-1)
    if k == 1:
        d, nb = d[:, None], nb[:, None]
    med = np.median(d[:, 1]) if k > 1 else 0.0
    ok = (d <= 3.0 * med) & (np.arange(k)[None, :] > 0)
    r = np.repeat(np.arange(len(Z)), k)[ok.ravel()]
    G = sp.coo_matrix((np.ones(len(r)), (r, nb.ravel()[ok.ravel()])), shape=(len(Z), len(Z)))
    return connected_components(G, directed=False)[1]


def source_components(src: Sources) -> np.ndarray:
    """Connected component of every source point: faces sharing a vertex (meshes), or
    :func:`cloud_components` (clouds). Returns labels (m,)."""
    from scipy.sparse.csgraph import connected_components

    F = src.extra.get("faces")
    if F is None:
        return cloud_components(src.B)
    m = len(F)
    n = int(F.max()) + 1
    r = np.repeat(np.arange(m), 3)
    G = sp.csr_matrix((np.ones(3 * m), (r, m + F.ravel())), shape=(m + n, m + n))
    return connected_components(G, directed=False)[1][:m]
