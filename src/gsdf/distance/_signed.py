"""Signed distance: exact unsigned distance, sign from the winding number or from pseudonormals.

Convention: negative inside, positive outside, ``|signed| == unsigned`` everywhere.

* ``sign="winding"`` (default; Barill et al. 2018, §4 "signing distances"): a query is inside where the
  fast generalized winding number exceeds 1/2. This is robust to holes, self-intersections, duplicated
  or flipped-in-place faces and other defects of triangle soups: far from a defect the sign is right.
* ``sign="pseudonormal"`` (Bærentzen & Aanæs 2005): the sign of ``(q - c) . n`` where ``c`` is the
  closest point and ``n`` the angle-weighted pseudonormal of the feature (face interior, edge or vertex)
  containing it. Much cheaper (no winding number), exact on **closed, consistently oriented 2-manifold**
  meshes, but meaningless on open or broken geometry (a hole flips the sign of whole regions).

A single-layer sheet (an open surface, e.g. the wings of a ShapeNet airplane) bounds nothing: its winding number
is ±1/2 on its two sides, so no query is inside it. ``shell=t`` asks for it explicitly: the result is the signed
distance to the union of the winding-number solid and the shell of thickness ``t`` around the surface,
``min(s, |s| − t/2)`` (mesh2sdf's ``fix=True, level=t/2`` gives that shell too). It is never a default.
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import as_mesh, as_normals, as_points, as_weights, choice, flag, positive, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf.mesh._pseudonormals import pseudonormals
from gsdf.distance._points import point_cloud_distance
from gsdf.distance._triangles import TriangleDistance
from gsdf.spatial._triangle_tree import triangle_tree

__all__ = ["signed_distance", "signed_distance_points", "SIGN_MODES", "PseudonormalWarning",
           "warn_pseudonormal"]

#: Accepted values of ``signed_distance(..., sign=...)``.
SIGN_MODES = ("winding", "pseudonormal")

#: Barycentric coordinates at or below this count as zero when deciding whether the closest point lies
#: on an edge or a vertex (the region-based kernel returns exact zeros there; this only absorbs rounding
#: for points that project just inside a face, where the face and edge normals agree on the sign).
BARY_TOL = 1e-10


class PseudonormalWarning(UserWarning):
    """``sign="pseudonormal"`` on a mesh that is open, non-manifold or not consistently oriented, where that sign
    can be wrong on whole regions."""


def warn_pseudonormal(V, F, stacklevel: int = 3) -> dict:
    """Warn (:class:`PseudonormalWarning`) when the pseudonormal sign is unreliable on the mesh ``(V, F)``: it is
    open, non-manifold or not consistently oriented (:func:`gsdf.mesh_topology`). Returns the topology."""
    import warnings

    from gsdf.mesh._topology import mesh_topology

    t = mesh_topology(V, F)
    problems = []
    if not t["closed"]:
        problems.append("open (it has boundary edges)")
    if not (t["edge_manifold"] and t["vertex_manifold"]):
        problems.append("non-manifold")
    elif not t["oriented"]:
        problems.append("not consistently oriented")
    if problems:
        warnings.warn(f"sign='pseudonormal' on a mesh that is {' and '.join(problems)}: the pseudonormal sign is "
                      "exact only for closed, consistently oriented manifold meshes and can be wrong on whole "
                      "regions here; sign='winding' is robust to holes and soups", PseudonormalWarning,
                      stacklevel=stacklevel)
    return t


def _pseudonormal_sign(V, F, Q, closest, face, bary) -> np.ndarray:
    """+1 outside, -1 inside from the pseudonormal of the closest feature (0-normals count as outside)."""
    pn = pseudonormals(V, F)
    zero = bary <= BARY_TOL
    nz = zero.sum(axis=1)
    n = pn.face[face]
    on_edge = nz == 1
    if on_edge.any():
        k = np.argmax(zero[on_edge], axis=1)  # the corner opposite the edge
        n[on_edge] = pn.edge[face[on_edge], k]
    on_vertex = nz >= 2
    if on_vertex.any():
        k = np.argmax(bary[on_vertex], axis=1)
        n[on_vertex] = pn.vertex[F[face[on_vertex], k]]
    D = Q - closest
    D /= np.maximum(np.max(np.abs(D), axis=1, keepdims=True), np.finfo(float).tiny)  # no under/overflow
    s = np.einsum("ij,ij->i", D, n)
    return np.where(s < 0, -1.0, 1.0)


@query_shaped()
def signed_distance(V, F, Q, sign: str = "winding", beta: float = 2.0, return_closest: bool = False,
                    shell: float | None = None):
    """Signed distance from points ``Q`` (q, 3) to the triangle mesh/soup ``(V, F)``; negative inside.

    ``|d|`` is the exact distance to the nearest triangle. ``sign="winding"`` (Barill et al. 2018, §4): inside
    where the fast winding number exceeds 1/2, robust to holes, self-intersections and soups.
    ``sign="pseudonormal"`` (Bærentzen & Aanæs 2005): the sign of ``(q - c) . n``, ``c`` the closest point and
    ``n`` the angle-weighted pseudonormal of its face, edge or vertex; cheaper, exact on closed, consistently
    oriented manifold meshes, wrong on whole regions of open or broken ones (then it warns).

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions, model units.
    F : (m, 3) int
        Triangles (a mesh or a soup).
    Q : (q, 3) float
        Query points.
    sign : {"winding", "pseudonormal"}, default "winding"
        How the inside is decided (above).
    beta : float, default 2.0
        Accuracy parameter of the fast winding number (``sign="winding"`` only): clusters farther than
        ``beta`` times their radius are approximated by their expansion; larger is more accurate and slower.
    return_closest : bool, default False
        Also return the closest triangle, closest point and normal, as libigl's ``signed_distance``
        (``S, I, C, N``; as :func:`gsdf.signed_distance_grid` does on a grid).
    shell : float, optional
        Thickness of a shell around the surface added to the inside (see the module documentation): the signed
        distance to the union of the winding-number solid and the points within ``shell / 2`` of the surface.
        For open single-layer sheets, which otherwise have no inside. Off by default.

    Returns
    -------
    S : (q,) float64
        Signed distances (``Q`` of shape (..., 3) gives shape (...)).
    I : (q,) int64
        With ``return_closest``: index of the closest triangle.
    C : (q, 3) float64
        The closest point on the surface.
    N : (q, 3) float64
        The normal there: the angle-weighted pseudonormal of the closest feature (face, edge or vertex) with
        ``sign="pseudonormal"``, the unit normal of the closest triangle with ``sign="winding"`` (zero for a
        degenerate triangle).

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range, an unknown ``sign``, ``beta <= 0``.

    Warns
    -----
    PseudonormalWarning
        A ``UserWarning``: ``sign="pseudonormal"`` on a mesh that is open, non-manifold or not consistently
        oriented.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> d = gsdf.signed_distance(V, F, [[0.1, 0.1, 0.1], [-1.0, 0.0, 0.0]])
    >>> np.round(d, 3).tolist()                 # negative inside
    [-0.1, 1.0]
    >>> S, I, C, N = gsdf.signed_distance(V, F, [[0.5, 0.5, 0.5]], return_closest=True)   # libigl's outputs
    >>> I.tolist(), np.round(C, 3).tolist()
    ([3], [[0.333, 0.333, 0.333]])
    """
    V, F = as_mesh(V, F)
    Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
    choice(sign, "sign", SIGN_MODES)
    beta = positive(beta, "beta")
    return_closest = flag(return_closest, "return_closest")
    if shell is not None:
        shell = positive(shell, "shell")
    tt = triangle_tree(V, F)  # one tree for the distance and the winding number
    td = TriangleDistance._of_tree(V, F, tt)
    if sign == "winding":
        from gsdf.winding import FastWindingNumber  # lazy: the winding module is independent of this one

        d, face, closest = td.query(Q)
        w = FastWindingNumber._of_tree(tt, beta=beta, order=2)(Q)
        S = np.where(w > 0.5, -d, d)
    else:
        warn_pseudonormal(V, F)
        d, face, closest, bary = td.query_barycentric(Q)
        S = _pseudonormal_sign(V, F, Q, closest, face, bary) * d
    if shell is not None:
        S = with_shell(S, shell)
    if not return_closest:
        return S
    if sign == "pseudonormal":
        N = closest_pseudonormal(V, F, face, bary)
    else:
        n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        ln = np.linalg.norm(n, axis=1, keepdims=True)
        N = np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)[face]
    return S, face, closest, N


def with_shell(S, thickness: float):
    """Signed distance to the union of the region ``S < 0`` and the shell of the given thickness around the
    surface ``S = 0``: ``min(S, |S| - thickness / 2)``."""
    return np.minimum(S, np.abs(S) - 0.5 * thickness)


def closest_pseudonormal(V, F, face, bary):
    """Angle-weighted pseudonormal of the feature (face, edge, vertex) that holds each closest point, unit."""
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


@query_shaped()
def signed_distance_points(P, N, Q, areas=None, beta: float = 2.3):
    """Signed distance to an oriented point cloud; negative inside.

    ``|d|`` is the distance to the nearest point of ``P``; the sign comes from the fast winding number of the
    oriented points: inside where it exceeds 1/2 (Barill et al. 2018, §4 and Eq. 5).

    Parameters
    ----------
    P : (p, 3) float
        Points, model units.
    N : (p, 3) float
        Outward normals (any length; normalized internally).
    Q : (q, 3) float
        Query points.
    areas : (p,) float, optional
        Point areas for the winding number (square model units); default: estimated by :func:`gsdf.point_areas`
        with k = 20.
    beta : float, default 2.3
        Accuracy of the fast winding number: larger is more accurate and slower.

    Returns
    -------
    (q,) float64
        Signed distance, negative inside.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite values, negative areas, ``beta <= 0``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> rng = np.random.default_rng(0)
    >>> P = rng.normal(size=(2000, 3)); P /= np.linalg.norm(P, axis=1, keepdims=True)   # unit sphere
    >>> d = gsdf.signed_distance_points(P, P, [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    >>> np.round(d, 1).tolist()                 # negative inside
    [-1.0, 1.0]
    """
    P = as_points(P, "P")
    N = as_normals(N, P.shape[0], "N")
    Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
    if areas is not None:
        areas = as_weights(areas, P.shape[0], "areas")
    beta = positive(beta, "beta")
    d = point_cloud_distance(P, Q)
    from gsdf.winding import fast_winding_number_points  # lazy import

    w = np.asarray(fast_winding_number_points(P, N, Q, areas=areas, beta=beta), dtype=np.float64)
    return np.where(w > 0.5, -d, d)
