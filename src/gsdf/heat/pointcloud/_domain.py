"""The signed heat method with a point cloud as the domain (Feng & Crane 2024, §8.4).

Operators (§8.4): the Laplacian L and lumped mass M of the *tufted cover* of Sharp & Crane 2020 (§5.7 and
§3.3), from the ``robust-laplacian`` package (``robust_laplacian.point_cloud_laplacian``: local Delaunay
triangulations of the k nearest neighbours in each tangent plane, glued into a tufted cover, intrinsically
mollified and flipped to Delaunay); per-point tangent frames from the normals (given, or PCA normals oriented
away from the centroid); the connection Laplacian multiplies every off-diagonal entry L_ij by the rotation
r_ij between the frames of j and i (the smallest rotation aligning their normals — Sharp et al. 2019 §6.2.2,
geometry-central's ``PointPositionGeometry::computeConnectionLaplacian``).

Sources: curves are sequences of point indices; every segment γ_i γ_{i+1} is projected into the tangent plane
of each end point, its in-plane normal (T × n: the left of the curve is negative, gsdf's convention) is weighted
by half the segment length and accumulated at the point — so X⁰_i is the in-plane normal of the projected
γ_{i−1} γ_i γ_{i+1}, weighted by half the incident lengths (§8.4, "as in Section 8.3").

Steps: ``(M + t L∇) X = X⁰`` with ``t = t_coef · ℓ̄²`` (ℓ̄ the mean length of the Laplacian's edges, the
tufted-cover edges); the paper then averages X onto the faces of the tufted cover and applies the divergence of
§5.5. ``robust-laplacian`` does not expose the cover's faces, so here the same cotan-weighted sum is evaluated
per cover *edge*: ``b_i = Σ_j w_ij (x_i − x_j) · Y_ij`` with w_ij = −L_ij and Y_ij the normalized mean of X_i
and X_j — the face formula of §5.5 with the vector averaged over the edge instead of the face (identical for a
constant field). Then ``L φ = b`` with the level-set constraints of §7.1.

Sign convention: gsdf's left-negative. potpourri3d's ``PointCloudHeatSolver.compute_signed_distance`` has the
same sign (unlike its triangle-mesh solver): on a Fibonacci unit sphere with the equator loop both approximate
−asin z, gsdf within 1.3 %, potpourri3d 2.1 % (tests/conformance/test_potpourri3d.py).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf import _checks
from gsdf.heat._domain import VertexSurfaceDomain, tangent_frames
from gsdf.heat.polygon._domain import connection_laplacian


def point_cloud_operators(P: np.ndarray, k: int = 30, mollify_factor: float = 1e-5):
    """Tufted-cover Laplacian (PSD, n × n) and lumped masses (n,) of a point cloud (Sharp & Crane 2020), with
    robust-laplacian's intrinsic mollification ``mollify_factor``."""
    try:
        import robust_laplacian
    except ImportError as exc:                                   # pragma: no cover - a declared dependency
        raise ImportError("PointCloudSignedHeatSolver needs the 'robust-laplacian' package "
                          "(pip install robust-laplacian)") from exc
    L, M = robust_laplacian.point_cloud_laplacian(np.ascontiguousarray(P, dtype=np.float64),
                                                  mollify_factor=float(mollify_factor), n_neighbors=int(k))
    L = sp.csr_matrix(L)
    L = 0.5 * (L + L.T)
    return L.tocsr(), np.asarray(M.diagonal(), dtype=np.float64)


class PointCloudDomain(VertexSurfaceDomain):
    """A point cloud as the domain (§8.4; see module docs).

    Parameters: those of :class:`gsdf.heat.pointcloud._solver.PointCloudSignedHeatSolver`, the public
    front-end (points, normals, neighbours k, diffusion-time coefficient).

    Example
    -------
    >>> from gsdf.heat._core import SignedHeatCore                       # doctest: +SKIP
    >>> phi = SignedHeatCore(PointCloudDomain(P, N)).compute_distance([loop])   # doctest: +SKIP
    """

    def __init__(self, P, N=None, k: int = 30, t_coef: float = 1.0):
        P = _checks.as_points(P, "P")
        if len(P) < 4:
            raise ValueError(f"P: need at least 4 points, got {len(P)}")
        k = _checks.neighbours(k, len(P), "k", lo=3, default=30)
        t_coef = _checks.positive(t_coef, "t_coef", most=_checks.T_COEF_MAX)
        if N is None:
            from gsdf.winding._point_areas import estimate_normals

            N = estimate_normals(P, k=min(k, len(P) - 1), orient_towards=P.mean(axis=0))
        N = _checks.as_normals(N, len(P))
        nrm = np.linalg.norm(N, axis=1, keepdims=True)
        if (nrm == 0).any():
            raise ValueError("N: contains zero normals")
        self.P, N = P, N / nrm
        L, self.M = point_cloud_operators(P, min(k, len(P) - 1))
        C = sp.triu(L, k=1).tocoo()
        self._ei, self._ej, self._w = C.row, C.col, -C.data          # cover edges i < j, cotan weights
        self.n_edges = len(self._w)
        if self.n_edges == 0:
            raise ValueError("P: the tufted cover has no edges (degenerate point cloud)")
        self.mean_edge = float(np.linalg.norm(P[self._ej] - P[self._ei], axis=1).mean())
        e1, e2 = tangent_frames(N)
        Lconn = connection_laplacian(L, N, e1, e2)
        super().__init__(P, L, self.M, Lconn, N, e1, e2, t_coef * self.mean_edge ** 2)

    def gather(self, X) -> np.ndarray:
        """Y_ij = X_i + X_j per cover edge (3D; normalized by the core)."""
        Xv = self.to_3d(X)
        return Xv[self._ei] + Xv[self._ej]

    def divergence(self, Y) -> np.ndarray:
        """b_i = Σ_j w_ij (x_i − x_j) · Y_ij (§5.5 per cover edge; module docs)."""
        i, j, w = self._ei, self._ej, self._w
        f = w * np.einsum("kj,kj->k", self.P[i] - self.P[j], Y)
        n = len(self.P)
        return np.bincount(i, weights=f, minlength=n) - np.bincount(j, weights=f, minlength=n)


__all__ = ["PointCloudDomain", "point_cloud_operators"]
