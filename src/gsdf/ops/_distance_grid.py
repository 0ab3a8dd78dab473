"""Signed distance sampled on a regular grid: the library form of ``gsdf sdf``.

Owns :func:`signed_distance_grid`: the box and node layout (as :func:`gsdf.field.grid_shape`: ``resolution``
nodes along the longest side, cubic cells), the exact unsigned distance (:class:`TriangleDistance`, or the nearest
point of a cloud), and the sign — from the fast winding number at 1/2 (Barill et al. 2018 §4, robust to holes and
soups) or from angle-weighted pseudonormals (Bærentzen & Aanæs 2005, closed manifold meshes). With
``return_closest=True`` it also returns what libigl's ``signed_distance`` does: closest face, closest point, normal.
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import as_mesh, as_normals, as_points, choice, integer, positive

__all__ = ["signed_distance_grid"]


def _grid_box(X, resolution, bbox_min, bbox_max, pad):
    from gsdf.grid import grid_shape

    if (bbox_min is None) != (bbox_max is None):
        raise ValueError("bbox_min, bbox_max: give both or neither")
    if bbox_min is None:
        pad = float(pad)
        if not np.isfinite(pad) or pad < 0:
            raise ValueError(f"pad: expected a finite number >= 0, got {pad}")
        lo, hi = X.min(axis=0), X.max(axis=0)
        d = float(np.linalg.norm(hi - lo)) or 1.0
        lo, hi = lo - pad * d, hi + pad * d
    else:
        lo = as_points(bbox_min, "bbox_min")[0]
        hi = as_points(bbox_max, "bbox_max")[0]
        if np.any(hi <= lo):
            raise ValueError(f"bbox_max {hi} must exceed bbox_min {lo} on every axis")
    shape = grid_shape(lo, hi, resolution)
    h = (hi - lo).max() / (resolution - 1)
    return lo, lo + (np.array(shape) - 1) * h, shape  # the upper corner grows so that cells are cubes


def signed_distance_grid(V, F=None, *, points=None, resolution: int = 64, bbox_min=None, bbox_max=None,
                         pad: float = 0.05, sign: str = "winding", beta: float | None = None,
                         return_closest: bool = False, progress=None):
    """Signed distance (negative inside) on the nodes of a regular grid around a mesh/soup or oriented cloud.

    Parameters
    ----------
    V : (n, 3) float, or a tuple ``(V, F)``
        Mesh vertices (or the whole mesh as one tuple). Omit (``None``) when ``points`` is given.
    F : (m, 3) int, optional
        Triangles (any soup: holes, duplicates, degenerate faces are fine with ``sign="winding"``).
    points : tuple ``(P, N)``, optional
        An oriented point cloud instead of a mesh, P and N (p, 3): distance to the nearest point, sign from the
        points' fast winding number.
    resolution : int, default 64
        Grid nodes along the longest side of the box (>= 2); the other sides get the same spacing.
    bbox_min, bbox_max : (3,) float, optional
        The box; default: the input's bounding box grown by ``pad`` times its diagonal. The upper corner is moved
        up to a whole number of cubic cells.
    pad : float, default 0.05
    sign : {"winding", "pseudonormal"}
        ``"pseudonormal"`` needs a mesh and is only meaningful for closed, consistently oriented manifolds.
    beta : float, optional
        Accuracy of the fast winding number (default 2 for meshes, 2.3 for points).
    return_closest : bool, default False
        Also return libigl's ``I, C, N``.
    progress : callable ``progress(done, total)``, optional
        Called while the winding numbers are evaluated.

    Returns
    -------
    S : gsdf.GridField
        Values of shape (nx, ny, nz); node ``(i, j, k)`` at ``S.bbox_min + (i, j, k) * S.spacing``.
    I : (nx*ny*nz,) int64
        With ``return_closest``: index of the closest triangle (of the nearest point for a cloud) for each node,
        in the C order of ``S.values`` (the order of ``S.grid_points()``).
    C : (nx*ny*nz, 3) float64
        The closest point on the surface (the nearest point of a cloud).
    N : (nx*ny*nz, 3) float64
        The normal there: the angle-weighted pseudonormal of the closest feature (face, edge or vertex) with
        ``sign="pseudonormal"``, the unit normal of the closest triangle with ``sign="winding"`` (zero for a
        degenerate triangle), the point's normal for a cloud.

    Examples
    --------
    >>> import gsdf, numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> S = gsdf.signed_distance_grid(V, F, resolution=16)
    >>> S.shape, bool(S([[0.1, 0.1, 0.1]])[0] < 0)
    ((16, 16, 16), True)
    >>> S, I, C, N = gsdf.signed_distance_grid((V, F), resolution=8, return_closest=True)
    """
    from gsdf.field import GridField
    from gsdf.grid import grid_points

    choice(sign, "sign", ("winding", "pseudonormal"))
    if not isinstance(return_closest, (bool, np.bool_)):
        raise ValueError(f"return_closest: expected True or False, got {return_closest!r}")
    resolution = integer(resolution, "resolution", 2)
    if points is not None:
        if V is not None or F is not None:
            raise ValueError("points: give either a mesh (V, F) or points=(P, N), not both")
        if sign == "pseudonormal":
            raise ValueError("sign: 'pseudonormal' needs a mesh, not a point cloud")
        try:
            P, Nrm = points
        except (TypeError, ValueError):
            raise ValueError("points: expected a tuple (P, N) of (p, 3) arrays") from None
        P = as_points(P, "P")
        Nrm = as_normals(Nrm, len(P), "N")
        X = P
    else:
        if F is None and isinstance(V, (tuple, list)) and len(V) == 2:
            V, F = V
        if V is None or F is None:
            raise ValueError("V, F: expected a triangle mesh (V, F) or points=(P, N)")
        V, F = as_mesh(V, F)
        X = V
    lo, hi, shape = _grid_box(X, resolution, bbox_min, bbox_max, pad)
    Q = grid_points(lo, hi, shape)

    if points is not None:
        from scipy.spatial import cKDTree

        from gsdf.winding import FastWindingNumberPoints

        d, idx = cKDTree(P).query(Q, workers=-1)
        b = positive(2.3 if beta is None else beta, "beta")
        w = FastWindingNumberPoints(P, Nrm, beta=b)(Q, progress=progress)
        s = np.where(w > 0.5, -d, d)  # Barill et al. 2018 §4: inside where the winding number exceeds 1/2
        S = GridField(s.reshape(shape), lo, hi)
        return (S, idx.astype(np.int64), P[idx], Nrm[idx]) if return_closest else S

    from gsdf.distance._signed import _pseudonormal_sign
    from gsdf.distance._triangles import TriangleDistance

    if sign == "pseudonormal":
        d, face, closest, bary = TriangleDistance(V, F).query_barycentric(Q)
        sgn = _pseudonormal_sign(V, F, Q, closest, face, bary)
        s = sgn * d
    else:
        from gsdf.winding import FastWindingNumber

        # the winding numbers first: on a cold cache `gsdf sdf` compiles the distance kernels in a background
        # process meanwhile (gsdf.cli._background), which are then ready when the distance is reached
        w = FastWindingNumber(V, F, beta=positive(2.0 if beta is None else beta, "beta"))(Q, progress=progress)
        d, face, closest = TriangleDistance(V, F).query(Q)
        s = np.where(w > 0.5, -d, d)  # Barill et al. 2018 §4: inside where the winding number exceeds 1/2
    S = GridField(s.reshape(shape), lo, hi)
    if not return_closest:
        return S
    if sign == "pseudonormal":
        N = _closest_pseudonormal(V, F, face, bary)
    else:
        n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        ln = np.linalg.norm(n, axis=1, keepdims=True)
        n = np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)
        N = n[face]
    return S, face, closest, N


def _closest_pseudonormal(V, F, face, bary):
    """Angle-weighted pseudonormal of the feature (face, edge, vertex) that holds each closest point."""
    from gsdf.mesh._pseudonormals import pseudonormals
    from gsdf.distance._signed import BARY_TOL

    pn = pseudonormals(V, F)
    zero = bary <= BARY_TOL
    nz = zero.sum(axis=1)
    n = pn.face[face].copy()
    on_edge = nz == 1
    if on_edge.any():
        k = np.argmax(zero[on_edge], axis=1)
        n[on_edge] = pn.edge[face[on_edge], k]
    on_vertex = nz >= 2
    if on_vertex.any():
        k = np.argmax(bary[on_vertex], axis=1)
        n[on_vertex] = pn.vertex[F[face[on_vertex], k]]
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)
