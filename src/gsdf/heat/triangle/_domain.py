"""Triangle meshes as a signed-heat domain (Feng & Crane 2024, §5): Crouzeix–Raviart edges for step I, vertices
for step III.

Operators come from :class:`gsdf.heat.triangle._operators.TriangleMeshOperators` (CR mass and connection
Laplacian, Eqs. 6–9, complex — or real 2×2 blocks where face orientations disagree; cotan Laplacian, Eq. 10);
sources (curves along edges or through faces, points, unsigned curves, App. A) are assembled from the typed
curves by :mod:`gsdf.heat.triangle._sources` into the :class:`~gsdf.heat._sources.Sources` the core consumes.

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

from gsdf._checks import choice
from gsdf.heat._domain import HeatDomain
from gsdf.heat._sources import Sources
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.heat.triangle._sources import assemble, parse_curves, parse_points

__all__ = ["TriangleDomain"]

CONNECTIONS = ("auto", "complex", "real")


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
        self.connection = choice(connection, "connection", CONNECTIONS)
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
        pts = parse_points(self.ops, points)
        return assemble(self.ops, parse_curves(self.ops, curves, curve_normals), pts)
