"""Triangle meshes as a signed-heat domain (Feng & Crane 2024, §5): Crouzeix–Raviart edges for step I, vertices
for step III.

Operators come from :class:`gsdf.heat.triangle._operators.TriangleMeshOperators` (CR mass and connection
Laplacian, Eqs. 6–9, complex — or real 2×2 blocks where face orientations disagree; cotan Laplacian, Eq. 10);
sources (curves along edges or through faces, points, unsigned curves, App. A) from
:func:`gsdf.heat.triangle._sources.build_sources`. :class:`TriangleDomain` turns them into the
:class:`~gsdf.heat._sources.Sources` the core consumes.

Example
-------
>>> from gsdf.data._shapes import grid_mesh
>>> d = TriangleDomain(*grid_mesh(4))
>>> d.n_nodes, d.heat_form
(25, 'complex')
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf.heat._sources import Sources
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.heat.triangle._sources import build_sources, per_curve_normals
from gsdf.heat._domain import HeatDomain

__all__ = ["TriangleDomain", "raw_curves", "raw_points", "to_core_sources"]

CONNECTIONS = ("auto", "complex", "real")


def raw_curves(curves, curve_normals=None):
    """Curves (list of :class:`~gsdf.curves.Curve`) in the raw form of ``build_sources``: vertex arrays or
    lists of (face, barycentric); edge curves are chained into polylines. Returns (raw, signs, normals)."""
    raw, signs, normals = [], [], [] if curve_normals is not None else None
    curve_normals = per_curve_normals(curve_normals, len(curves))
    for k, c in enumerate(curves):
        parts = c.polylines() if c.kind == "edges" else [c.nodes]
        if c.kind == "edges" and curve_normals is not None and curve_normals[k] is not None \
                and np.asarray(curve_normals[k]).shape != (3,):
            raise ValueError(f"curve_normals[{k}]: an edge-set curve takes one (3,) normal")
        for p in parts:
            raw.append(p)
            signs.append(c.signed)
            if normals is not None:
                normals.append(curve_normals[k])
    return raw, signs, normals


def raw_points(points):
    """Point sources (ints or (face, barycentric)) in the raw form of ``build_sources`` (None for none)."""
    return list(points) if points else None


def to_core_sources(S, n: int) -> Sources:
    """The legacy parsed sources of :func:`~gsdf.heat.triangle._sources.build_sources` as core
    :class:`~gsdf.heat._sources.Sources` (sparse interpolation rows)."""

    def rows(ids, w):
        k = len(ids)
        return sp.csr_matrix((w.ravel(), (np.repeat(np.arange(k), ids.shape[1]), ids.ravel())), shape=(k, n))

    out = Sources(X0=S.X0)
    if S.node_rows:
        out.node_rows = rows(np.concatenate([r[0] for r in S.node_rows]), np.concatenate([r[1] for r in S.node_rows]))
        out.node_vertex = np.concatenate(S.node_is_vertex).astype(np.int64)
        out.node_curve = np.concatenate([np.full(len(r[0]), k) for k, r in enumerate(S.node_rows)])
        out.shift_rows = rows(np.concatenate([m[0] for m in S.seg_mid]), np.concatenate([m[1] for m in S.seg_mid]))
        out.shift_weights = np.concatenate(S.seg_len)
    else:
        out.node_rows = sp.csr_matrix((0, n))
        out.node_vertex = out.node_curve = np.zeros(0, np.int64)
    if S.point_rows is not None:
        out.point_rows = rows(*S.point_rows)
        out.point_vertex = np.asarray(S.point_is_vertex, np.int64)
    out.extra["parsed"] = S
    return out


class TriangleDomain(HeatDomain):
    """A triangle mesh (any topology; see :class:`gsdf.SurfaceSignedHeatSolver`) as a signed-heat domain.

    Parameters
    ----------
    V, F : the mesh (validated by the caller), or ``ops`` : prebuilt :class:`TriangleMeshOperators` (intrinsic
        triangulations pass their layout-based operators);
    t : diffusion time (default ``h²``, h the mean spacing of edge midpoints, §6);
    connection : {"auto", "complex", "real"} — the form of the connection Laplacian (``"auto"``: complex when
        all faces are consistently oriented, else real 2×2 blocks).
    """

    difference_order = "first"
    cache_sources = True

    def __init__(self, V=None, F=None, t: float | None = None, connection: str = "auto", ops=None):
        self.ops = ops if ops is not None else TriangleMeshOperators(V, F)
        self.n_nodes = self.ops.n_vertices
        self.t = float(self.ops.h ** 2 if t is None else t)
        self.connection = connection
        real = connection == "real" or (connection == "auto" and not self.ops.consistent)
        self.heat_form = "real2" if real else "complex"
        self.C = self.ops.cotan_laplacian().tocsc()   # symmetric: the CSR arrays (transposed, exact copy)
        Mv = self.ops.vertex_mass()
        self._Mv = np.where(Mv > 0, Mv, Mv.mean())              # unreferenced vertices: keep the system regular

    # ---- operators
    def vector_heat_matrix(self):
        if self.heat_form == "real2":
            M = self.ops.cr_mass().diagonal()
            return sp.diags(np.repeat(M, 2)) + self.t * self.ops.cr_connection_laplacian_real()
        return self.ops.cr_vector_heat_matrix(self.t)

    def gather(self, X):
        """Edge vectors averaged onto the faces (Alg. 3), (m, 3)."""
        return self.ops.edge_to_face_vectors(X)

    def divergence(self, Y):
        return self.ops.divergence(Y)

    def laplacian(self):
        return self.C

    def mass(self):
        return self._Mv

    # ---- sources
    def assemble_sources(self, curves, points, curve_normals=None) -> Sources:
        raw, signs, normals = raw_curves(curves, curve_normals)
        S = build_sources(self.ops, raw, raw_points(points), signs, normals)
        return to_core_sources(S, self.n_nodes)
