"""The signed heat method with a point cloud as the domain (Feng & Crane 2024, §8.4), approximated.

The paper uses the tufted-cover Laplacian of Sharp & Crane 2020 with per-point tangent planes and a
vertex-based connection Laplacian. Here the domain is instead a *local-triangulation cover*: around every point
its k nearest neighbours are projected to the tangent plane, the Gabriel neighbours are kept and sorted by angle,
and consecutive ones span fan triangles, oriented by the point's normal; the union of all fans (duplicates
removed) is a nonmanifold triangle soup on which the triangle-mesh solver runs unchanged (its operators are sums
over faces, §9.4). Curves are sequences of point indices; as in §8.4 the source at curve point i is the
in-plane normal of the projected γ_{i-1} γ_i γ_{i+1}, weighted by half the incident lengths, spread over the
faces around i (by corner angle) and expressed in their edge bases.
"""

from __future__ import annotations

import numpy as np

from ... import _checks
from .solver import SurfaceSignedHeatSolver
from .sources import Sources


def local_triangulation_cover(P: np.ndarray, N: np.ndarray, k: int = 12) -> np.ndarray:
    """Fan triangles (m, 3) around every point of the cloud, oriented counter-clockwise about N."""
    from scipy.spatial import cKDTree

    n = len(P)
    k = min(k, n - 1)
    _, nb = cKDTree(P).query(P, k=k + 1)
    nb = nb[:, 1:]
    # tangent frames
    a = np.where(np.abs(N[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    e1 = np.cross(N, a)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(N, e1)
    D = P[nb] - P[:, None, :]
    x, y = np.einsum("nkj,nj->nk", D, e1), np.einsum("nkj,nj->nk", D, e2)
    Q = np.stack([x, y], -1)                                  # (n, k, 2)
    # Gabriel test in the tangent plane: j is kept unless some l lies inside the circle on diameter (0, q_j)
    mid = 0.5 * Q
    r2 = (mid ** 2).sum(-1)                                   # (n, k)
    d2 = ((Q[:, None, :, :] - mid[:, :, None, :]) ** 2).sum(-1)   # (n, j, l)
    blocked = (d2 < r2[:, :, None] * (1 - 1e-9))
    blocked[:, np.arange(k), np.arange(k)] = False
    keep = ~blocked.any(-1)
    ang = np.where(keep, np.arctan2(Q[..., 1], Q[..., 0]), np.inf)
    order = np.argsort(ang, axis=1)
    nkeep = keep.sum(1)
    tris = []
    idx = np.flatnonzero(nkeep >= 3)
    for c in range(1, k + 1):                                  # fans: consecutive kept neighbours
        i = idx[nkeep[idx] > c - 1]
        j0 = order[i, c - 1]
        j1 = np.where(c < nkeep[i], order[i, np.minimum(c, k - 1)], order[i, 0])
        a0 = ang[i, j0]
        a1 = np.where(c < nkeep[i], ang[i, j1], ang[i, j1] + 2 * np.pi)
        ok = (a1 - a0 > 1e-9) & (a1 - a0 < np.radians(150))  # large gaps: boundary, no triangle
        tris.append(np.stack([i[ok], nb[i[ok], j0[ok]], nb[i[ok], j1[ok]]], 1))
    T = np.concatenate(tris) if tris else np.zeros((0, 3), np.int64)
    key = np.sort(T, axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    T = T[np.sort(first)]
    e_a, e_b = P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]
    cr = np.cross(e_a, e_b)
    area = np.linalg.norm(cr, axis=1)
    L2 = max(float((e_a ** 2).sum(1).mean()), 1e-300)
    return T[area > 1e-8 * L2].astype(np.int64)


class PointCloudSignedHeatSolver:
    """Generalized signed distance to curves drawn on a point cloud (§8.4, approximated; see module docs).

    Parameters
    ----------
    P : (n, 3) points; N : (n, 3) consistently oriented normals, or None for PCA normals oriented away from
        the centroid; k : neighbours per local triangulation; t_coef : as for the mesh solver.

    Example
    -------
    >>> solver = PointCloudSignedHeatSolver(P, N)                       # doctest: +SKIP
    >>> phi = solver.compute_distance([np.array([3, 17, 42, 8, 3])])    # doctest: +SKIP
    """

    def __init__(self, P, N=None, k: int = 12, t_coef: float = 1.0):
        P = _checks.as_points(P, "P")
        if len(P) < 4:
            raise ValueError(f"P: need at least 4 points, got {len(P)}")
        if N is None:
            from ...winding.point_areas import estimate_normals

            N = estimate_normals(P, orient_towards=P.mean(axis=0))
        N = _checks.as_normals(N, len(P))
        nrm = np.linalg.norm(N, axis=1, keepdims=True)
        if (nrm == 0).any():
            raise ValueError("N: contains zero normals")
        self.P, self.N = P, N / nrm
        self.F = local_triangulation_cover(P, self.N, _checks.integer(k, "k", lo=3))
        self.mesh = SurfaceSignedHeatSolver(P, self.F, t_coef=t_coef)
        used = np.zeros(len(P), bool)
        used[self.F.ravel()] = True
        self._orphans = np.flatnonzero(~used)
        if len(self._orphans):                                # points in no triangle: copy the nearest used one
            from scipy.spatial import cKDTree

            ui = np.flatnonzero(used)
            self._orphan_src = ui[cKDTree(P[ui]).query(P[self._orphans])[1]]

    def compute_distance(self, curves, level_set_constraint: str = "zero", soft_weight=None) -> np.ndarray:
        """Signed distance (n,) at the points to curves given as sequences of point indices (left negative)."""
        mode = _checks.choice(level_set_constraint, "level_set_constraint", ("zero", "multiple", "none"))
        lam = None if soft_weight is None else _checks.positive(soft_weight, "soft_weight")
        ops = self.mesh.ops
        n = len(self.P)
        curves = [curves] if isinstance(curves, np.ndarray) and curves.ndim == 1 else list(curves)
        if not curves:
            raise ValueError("curves: no sources given (empty curve list)")
        vec = np.zeros((n, 3))
        S = Sources()
        for c_i, c in enumerate(curves):
            g = np.asarray(c)
            if g.ndim != 1 or len(g) < 2 or not np.issubdtype(g.dtype, np.integer):
                raise ValueError(f"curves[{c_i}]: expected at least 2 point indices (1-D int array)")
            if g.min() < 0 or g.max() >= n:
                raise ValueError(f"curves[{c_i}]: point index {int(g[(g < 0) | (g >= n)][0])} out of range "
                                 f"for {n} points")
            closed = g[0] == g[-1] and len(g) > 2
            prv = np.concatenate([[g[-2] if closed else g[0]], g[:-1]])
            nxt = np.concatenate([g[1:], [g[1] if closed else g[-1]]])
            if closed:
                prv, nxt, pts = prv[:-1], nxt[:-1], g[:-1]
            else:
                pts = g
            Ni = self.N[pts]
            t = self.P[nxt] - self.P[prv]
            t -= Ni * np.einsum("kj,kj->k", t, Ni)[:, None]
            tn = np.linalg.norm(t, axis=1, keepdims=True)
            seg = np.linalg.norm(np.diff(self.P[g], axis=0), axis=1)
            w = 0.5 * (np.concatenate([[seg[-1] if closed else 0.0], seg]) +
                       np.concatenate([seg, [seg[0] if closed else 0.0]]))[: len(pts)]
            nvec = np.cross(t / np.maximum(tn, 1e-300), Ni) * w[:, None]   # in-plane normal, τ × n (left < 0)
            np.add.at(vec, pts, nvec)
            ids = np.repeat(g[:, None], 3, axis=1)
            ww = np.zeros((len(g), 3))
            ww[:, 0] = 1
            S.node_rows.append((ids, ww))
            S.node_is_vertex.append(g.astype(np.int64))
            S.seg_len.append(seg)
            mw = np.zeros((len(seg), 6))
            mw[:, :2] = 0.5
            S.seg_mid.append((np.stack([g[:-1], g[1:]] * 3, 1), mw))
        S.signed = [True] * len(curves)
        # spread the vertex vectors over the faces around each point (by corner angle), then to edge bases
        F = ops.F
        Theta = np.bincount(F.ravel(), weights=ops.angles.ravel(), minlength=n)
        f, kk = np.nonzero(np.linalg.norm(vec[F], axis=2) > 0)
        v = F[f, kk]
        Nf = vec[v] - ops.normals[f] * np.einsum("kj,kj->k", vec[v], ops.normals[f])[:, None]
        Nf *= (ops.angles[f, kk] / np.maximum(Theta[v], 1e-300))[:, None]
        X0 = np.zeros(ops.n_edges, np.complex128)
        ee, zz = ops.slot_coords(f, Nf)
        np.add.at(X0, ee.ravel(), zz.ravel())
        S.X0 = X0
        phi = self.mesh._solve_sources(S, mode, lam)
        if len(self._orphans):
            phi[self._orphans] = phi[self._orphan_src]
        return phi


__all__ = ["PointCloudSignedHeatSolver", "local_triangulation_cover"]
