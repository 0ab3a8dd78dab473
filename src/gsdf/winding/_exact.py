"""Exact generalized winding numbers: triangle soups in 3D, polylines in 2D, oriented point clouds.

* Triangles (Jacobson et al. 2013): w(q) = Σ_t Ω_t(q) / 4π with the signed solid angle of van Oosterom &
  Strackee (1983), Ω = 2 atan2(a·(b×c), |a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|), a, b, c = corners − q.
* Polylines in 2D: w(q) = Σ_e θ_e(q) / 2π with θ the signed angle subtended by edge e.
* Points (Barill et al. 2018, Eq. 5): w(q) = Σ_i a_i (p_i − q)·n_i / (4π |p_i − q|³).

All three are direct sums, O(queries × elements), numba-parallel over queries. For many elements use
:mod:`gsdf.winding._fast`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from gsdf._checks import as_faces, as_mesh, as_normals, as_points, as_weights, query_shaped
from gsdf._memory import SECONDS_PER_PAIR
from gsdf._normalize import Frame
from gsdf.winding._query import map_queries, query_array
from gsdf.winding._solid_angle import solid_angle_w

INV_4PI = 1.0 / (4.0 * np.pi)
INV_2PI = 1.0 / (2.0 * np.pi)


@njit(cache=True, inline="always")
def dipole_w(px, py, pz, nx, ny, nz, a, qx, qy, qz):
    """Area-weighted dipole a (p − q)·n / (4π|p − q|³) (Eq. 5); zero when q coincides with p."""
    rx, ry, rz = px - qx, py - qy, pz - qz
    r2 = rx * rx + ry * ry + rz * rz
    if r2 == 0.0:
        return 0.0
    return a * (rx * nx + ry * ny + rz * nz) * INV_4PI / (r2 * np.sqrt(r2))


@njit(parallel=True, cache=True)
def _wn_triangles(T, Q, out):
    m = T.shape[0]
    for i in prange(Q.shape[0]):
        qx, qy, qz = Q[i, 0], Q[i, 1], Q[i, 2]
        acc = 0.0
        for t in range(m):
            acc += solid_angle_w(T[t, 0] - qx, T[t, 1] - qy, T[t, 2] - qz,
                                 T[t, 3] - qx, T[t, 4] - qy, T[t, 5] - qz,
                                 T[t, 6] - qx, T[t, 7] - qy, T[t, 8] - qz)
        out[i] = acc


@njit(parallel=True, cache=True)
def _wn_points(P, NA, Q, out):
    m = P.shape[0]
    for i in prange(Q.shape[0]):
        qx, qy, qz = Q[i, 0], Q[i, 1], Q[i, 2]
        acc = 0.0
        for j in range(m):
            acc += dipole_w(P[j, 0], P[j, 1], P[j, 2], NA[j, 0], NA[j, 1], NA[j, 2], 1.0, qx, qy, qz)
        out[i] = acc


@njit(parallel=True, cache=True)
def _wn_polyline(S, Q, out):
    m = S.shape[0]
    for i in prange(Q.shape[0]):
        qx, qy = Q[i, 0], Q[i, 1]
        acc = 0.0
        for e in range(m):
            ax, ay = S[e, 0] - qx, S[e, 1] - qy
            bx, by = S[e, 2] - qx, S[e, 3] - qy
            acc += np.arctan2(ax * by - ay * bx, ax * bx + ay * by)
        out[i] = acc * INV_2PI


def triangle_corners(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Corner coordinates of every triangle, shape (m, 9), C-contiguous."""
    return np.ascontiguousarray(V[F].reshape(-1, 9))


@query_shaped()
def winding_number(V, F, Q, method: str = "auto") -> np.ndarray:
    """Exact generalized winding number of a triangle soup at query points.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles (any orientation mix, holes, self-intersections, degenerate faces: a zero-area face
        contributes zero).
    Q : (q, 3) float
        Query points.
    method : {"auto", "direct", "hierarchical"}
        ``direct``: the O(q m) sum; ``hierarchical``: the exact divide and conquer of Jacobson et al.
        2013 (:class:`gsdf.winding._hierarchical.ExactWindingNumber`); ``auto`` picks the direct sum only
        for a handful of queries.

    Returns
    -------
    (q,) float64
        Σ_t Ω_t(q) / 4π: 1 inside a closed outward-oriented surface, 0 outside, fractional near holes.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> gsdf.winding_number(V, F, [[0.1, 0.1, 0.1], [2, 2, 2]]).round(6)
    array([1., 0.])
    """
    if method not in ("auto", "direct", "hierarchical"):
        raise ValueError(f"method: must be 'auto', 'direct' or 'hierarchical', got {method!r}")
    V, F = as_mesh(V, F)
    query_array(Q)  # the size guard before any tree is built
    n_queries = np.shape(Q)[0] if np.ndim(Q) == 2 else 1
    if method == "hierarchical" or (method == "auto" and n_queries > 64 and F.shape[0] > 64):
        from gsdf.winding._hierarchical import ExactWindingNumber

        return ExactWindingNumber(V, F)(Q)
    frame = Frame.of_mesh(V, F)  # scale invariance: kernels run on O(1) coordinates (gsdf._normalize)
    T = triangle_corners(frame.geometry(V), F)
    return map_queries(lambda q, out: _wn_triangles(T, q, out), Q, frame=frame, cost=len(F) * SECONDS_PER_PAIR)


@query_shaped()
def winding_number_points(P, N, Q, areas=None) -> np.ndarray:
    """Exact (direct-sum) winding number of an oriented point cloud, Eq. 5 of Barill et al. 2018.

    Parameters
    ----------
    P, N : (m, 3) float
        Points and outward normals (normalized internally; zero normals contribute zero).
    Q : (q, 3) float
        Query points.
    areas : (m,) float, optional
        Area a_i of each point; estimated with :func:`gsdf.point_areas` when omitted.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> rng = np.random.default_rng(0)
    >>> P = rng.normal(size=(2000, 3)); P /= np.linalg.norm(P, axis=1, keepdims=True)   # unit sphere
    >>> w = gsdf.winding_number_points(P, P, [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    >>> bool(abs(w[0] - 1) < 0.05 and abs(w[1]) < 0.05)
    True
    """
    frame, P, NA = oriented_area_normals(P, N, areas)
    return map_queries(lambda q, out: _wn_points(P, NA, q, out), Q, frame=frame, cost=len(P) * SECONDS_PER_PAIR)


@query_shaped(2)
def winding_number_2d(V, E, Q) -> np.ndarray:
    """Exact winding number of 2D polylines (edge list ``E`` into ``V``) at 2D query points.

    The sum of the signed angles the edges subtend at each query, over 2π (Jacobson et al. 2013, Eq. 2): 1
    inside a closed counter-clockwise polygon, 0 outside, in between near gaps of an open one.

    Parameters
    ----------
    V : (n, 2) float
        Polyline vertices.
    E : (m, 2) int
        Directed edges ``i → j`` into ``V`` (a closed polygon, several, or open pieces).
    Q : (q, 2) float
        Query points.

    Returns
    -------
    (q,) float64

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, indices out of range.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0], [1, 0], [1, 1], [0, 1.]])
    >>> E = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    >>> gsdf.winding_number_2d(V, E, [[0.5, 0.5], [2, 0]]).round(6)
    array([1., 0.])
    """
    V = as_points(V, "V", dim=2)
    E = as_faces(E, V.shape[0], "E", corners=2)
    frame = Frame.of_mesh(V, E)
    S = np.ascontiguousarray(frame.geometry(V)[E].reshape(-1, 4))
    return map_queries(lambda q, out: _wn_polyline(S, q, out), Q, dim=2, frame=frame,
                       cost=len(S) * SECONDS_PER_PAIR)


def oriented_area_normals(P, N, areas=None):
    """Validate a cloud; return ``(frame, P', a'_i n_i)`` in the cloud's normalised frame
    (:class:`gsdf._normalize.Frame`): points P' = (P − c)/s, unit normals scaled by the point areas a' = a/s²."""
    P = as_points(P, "P")
    N = as_normals(N, P.shape[0], "N")
    frame = Frame.of(P)
    Pf = frame.geometry(P, "P")
    L = np.max(np.abs(N), axis=1, keepdims=True)  # normalise in two steps: |N| of tiny or huge rows stays finite
    U = np.zeros_like(N)
    np.divide(N, L, out=U, where=L > 0)
    L = np.linalg.norm(U, axis=1, keepdims=True)
    np.divide(U, L, out=U, where=L > 0)
    if areas is None:
        from gsdf.winding._point_areas import point_areas

        a = point_areas(Pf, U)
    else:
        a = frame.inverse_area(as_weights(areas, P.shape[0], "areas"))
    return frame, Pf, np.ascontiguousarray(U * a[:, None])
