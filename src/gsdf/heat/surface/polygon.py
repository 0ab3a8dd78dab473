"""The signed heat method on polygon meshes (Feng & Crane 2024, §8.3), via a virtual-vertex refinement.

Like Bunge et al. 2020, every polygon with more than three corners gets a virtual vertex at the point that
minimizes the sum of squared areas of the fan triangles (x, v_i, v_{i+1}) — a 3×3 linear system per polygon —
and is split into that fan. The paper then Galerkin-projects vertex operators back to the polygon vertices and
adds a vertex-based connection Laplacian; here the refined triangle mesh is solved directly with the
Crouzeix–Raviart solver (the virtual vertices are just extra unknowns), and φ is returned at the original
vertices. Curves run along polygon edges (vertex-index polylines), which the fans keep.
"""

from __future__ import annotations

import numpy as np

from ... import _checks
from .solver import SurfaceSignedHeatSolver


def virtual_vertex_refinement(V: np.ndarray, polygons) -> tuple[np.ndarray, np.ndarray]:
    """Triangles (and extra virtual vertices appended to V) refining a list of polygons.

    Returns ``(V_refined, F_refined)``; the first ``len(V)`` vertices are the input ones.

    Example
    -------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    >>> Vr, Fr = virtual_vertex_refinement(V, [[0, 1, 2, 3]])
    >>> (Vr[4].round(3) + 0.0).tolist(), len(Fr)
    ([0.5, 0.5, 0.0], 4)
    """
    polys = [np.asarray(p, dtype=np.int64).ravel() for p in polygons]
    n = len(V)
    for k, p in enumerate(polys):
        if len(p) < 3:
            raise ValueError(f"polygons[{k}]: a polygon needs at least 3 vertices, got {len(p)}")
        if p.min() < 0 or p.max() >= n:
            raise ValueError(f"polygons[{k}]: vertex index out of range for {n} vertices")
    sizes = np.array([len(p) for p in polys])
    tri3 = [p for p in polys if len(p) == 3]
    tris = [np.stack(tri3)] if tri3 else []
    newV, fans = [], []
    for s in np.unique(sizes[sizes > 3]):
        P = np.stack([p for p in polys if len(p) == s])          # (q, s) polygons of this size
        A = V[P]                                                 # (q, s, 3)
        B = np.roll(A, -1, axis=1)
        # minimize Σ |(a - x) × (b - x)|² = Σ |a × b - x × (b - a)|²: linear least squares in x
        D = B - A                                                # (q, s, 3)
        cross_ab = np.cross(A, B)
        # x × d = -[d]_× x  ->  residual r = a×b + [d]_× x
        Dx = np.zeros(D.shape[:2] + (3, 3))
        Dx[..., 0, 1], Dx[..., 0, 2] = -D[..., 2], D[..., 1]
        Dx[..., 1, 0], Dx[..., 1, 2] = D[..., 2], -D[..., 0]
        Dx[..., 2, 0], Dx[..., 2, 1] = -D[..., 1], D[..., 0]
        M = np.einsum("qsij,qsik->qjk", Dx, Dx) + 1e-12 * np.eye(3)
        rhs = -np.einsum("qsij,qsi->qj", Dx, cross_ab)
        x = np.linalg.solve(M, rhs[..., None])[..., 0]
        bad = ~np.isfinite(x).all(1) | (np.linalg.cond(M) > 1e12)
        x[bad] = A[bad].mean(1)                                  # degenerate polygons: the centroid
        ids = n + sum(len(v) for v in newV) + np.arange(len(P))
        newV.append(x)
        fans.append(np.stack([np.repeat(ids, s), P.ravel(), np.roll(P, -1, axis=1).ravel()], 1))
    Vr = np.concatenate([V] + newV) if newV else V.copy()
    Fr = np.concatenate(tris + fans) if (tris or fans) else np.zeros((0, 3), np.int64)
    return Vr, Fr


class PolygonMeshSignedHeatSolver:
    """Signed heat method on a polygon mesh (§8.3, via virtual-vertex refinement; see module docs).

    Parameters
    ----------
    V : (n, 3) float; polygons : list of int sequences (or an (m, k) array); t_coef : float

    Example
    -------
    >>> solver = PolygonMeshSignedHeatSolver(V, quads)                  # doctest: +SKIP
    >>> phi = solver.compute_distance([loop_along_edges])               # doctest: +SKIP
    """

    def __init__(self, V, polygons, t_coef: float = 1.0):
        V = _checks.as_points(V, "V")
        if isinstance(polygons, np.ndarray) and polygons.ndim == 2:
            polygons = list(polygons)
        if len(polygons) == 0:
            raise ValueError("polygons: is empty (0 faces)")
        self.n_vertices = len(V)
        self.V_refined, self.F_refined = virtual_vertex_refinement(V, polygons)
        self.mesh = SurfaceSignedHeatSolver(self.V_refined, self.F_refined, t_coef=t_coef)

    def compute_distance(self, curves, points=(), curve_signs=None, level_set_constraint="zero",
                         soft_weight=None) -> np.ndarray:
        """As :meth:`SurfaceSignedHeatSolver.compute_distance`, curves as vertex-index polylines along polygon
        edges; returns φ at the original vertices (n,)."""
        for k, c in enumerate([curves] if isinstance(curves, np.ndarray) else curves):
            a = np.asarray(c)
            if a.dtype == object or a.ndim != 1:
                raise ValueError(f"curves[{k}]: polygon meshes take vertex-index polylines along edges")
            if a.size and (a.min() < 0 or a.max() >= self.n_vertices):
                raise ValueError(f"curves[{k}]: vertex index {int(a.max())} out of range for "
                                 f"{self.n_vertices} vertices")
        phi = self.mesh.compute_distance(curves, points=points, curve_signs=curve_signs,
                                         level_set_constraint=level_set_constraint, soft_weight=soft_weight)
        return phi[: self.n_vertices]
