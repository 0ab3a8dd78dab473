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
from gsdf.spatial._triangle_tree import triangle_tree

__all__ = ["signed_distance", "signed_distance_points", "SIGN_MODES"]

#: Accepted values of ``signed_distance(..., sign=...)``.
SIGN_MODES = ("winding", "pseudonormal")

#: Barycentric coordinates at or below this count as zero when deciding whether the closest point lies
#: on an edge or a vertex (the region-based kernel returns exact zeros there; this only absorbs rounding
#: for points that project just inside a face, where the face and edge normals agree on the sign).
BARY_TOL = 1e-10


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

    Parameters
    ----------
    V, F : (n, 3) float, (m, 3) int
        Triangle mesh or soup.
    Q : (q, 3) float
        Query points.
    sign : {"winding", "pseudonormal"}
        How the inside is decided; see the module documentation. ``"pseudonormal"`` is only meaningful
        for closed, consistently oriented manifold meshes.
    beta : float
        Accuracy parameter of the fast winding number (``sign="winding"`` only): clusters farther than
        ``beta`` times their radius are approximated by their expansion.

    Returns
    -------
    (q,) float64

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
    tt = triangle_tree(V, F)  # one tree for the distance and the winding number
    td = TriangleDistance._of_tree(V, F, tt)
    if sign == "winding":
        from gsdf.winding import FastWindingNumber  # lazy: the winding module is independent of this one

        d, _, _ = td.query(Q)
        w = FastWindingNumber._of_tree(tt, beta=beta, order=2)(Q)
        return np.where(w > 0.5, -d, d)
    d, face, closest, bary = td.query_barycentric(Q)
    return _pseudonormal_sign(V, F, Q, closest, face, bary) * d


def signed_distance_points(P, N, Q, areas=None, beta: float = 2.3):
    """Signed distance to an oriented point cloud; negative inside.

    ``|d|`` is the distance to the nearest point of ``P`` (p, 3); the sign comes from the fast winding
    number of the oriented points (normals ``N`` (p, 3), optional per-point ``areas`` (p,)): inside where
    it exceeds 1/2 (Barill et al. 2018).

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
