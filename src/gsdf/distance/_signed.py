"""Signed distance: exact unsigned distance, sign from the winding number or from pseudonormals.

Convention: negative inside, positive outside, ``|signed| == unsigned`` everywhere.

* ``sign="winding"`` (default; Barill et al. 2018, §4 "signing distances"): a query is inside where the
  fast generalized winding number exceeds 1/2. This is robust to holes, self-intersections, duplicated
  or flipped-in-place faces and other defects of triangle soups: far from a defect the sign is right.
* ``sign="pseudonormal"`` (Bærentzen & Aanæs 2005): the sign of ``(q - c) . n`` where ``c`` is the
  closest point and ``n`` the angle-weighted pseudonormal of the feature (face interior, edge or vertex)
  containing it. Much cheaper (no winding number), exact on **closed, consistently oriented 2-manifold**
  meshes, but meaningless on open or broken geometry (a hole flips the sign of whole regions).
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import as_mesh, as_normals, as_points, as_weights, choice, positive
from gsdf.mesh._pseudonormals import pseudonormals
from gsdf.distance._points import point_cloud_distance
from gsdf.distance._triangles import TriangleDistance

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


def signed_distance(V, F, Q, sign: str = "winding", beta: float = 2.0):
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

    Returns
    -------
    (q,) float64
        Signed distance, negative inside, model units.

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
    """
    V, F = as_mesh(V, F)
    Q = as_points(Q, "Q")
    choice(sign, "sign", SIGN_MODES)
    beta = positive(beta, "beta")
    td = TriangleDistance(V, F)
    if sign == "winding":
        from gsdf.winding import fast_winding_number  # lazy: the winding module is independent of this one

        d, _, _ = td.query(Q)
        w = np.asarray(fast_winding_number(V, F, Q, beta=beta, order=2), dtype=np.float64)
        return np.where(w > 0.5, -d, d)
    warn_pseudonormal(V, F)
    d, face, closest, bary = td.query_barycentric(Q)
    return _pseudonormal_sign(V, F, Q, closest, face, bary) * d


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
    Q = as_points(Q, "Q")
    if areas is not None:
        areas = as_weights(areas, P.shape[0], "areas")
    beta = positive(beta, "beta")
    d = point_cloud_distance(P, Q)
    from gsdf.winding import fast_winding_number_points  # lazy import

    w = np.asarray(fast_winding_number_points(P, N, Q, areas=areas, beta=beta), dtype=np.float64)
    return np.where(w > 0.5, -d, d)
