"""Tetrahedral meshes as a signed-heat domain (Feng & Crane 2024, §8.1, App. B); meshing in
:mod:`gsdf.heat.tet._mesh`, operators from :class:`gsdf.mesh._tet_ops.TetOperators`.

Step I    per kept tet: the Yukawa sum at its barycenter (:class:`~gsdf.heat._yukawa.YukawaTree`), the closed
          form of the short-time heat flow in R³ that the authors' implementation also uses on tets.
Step II   normalized per tet (by the core).
Step III  the P1 (cotangent) Laplacian against the weak divergence b_i = Σ_T |T| ∇λ_i · Y_T (Eq. 22), natural
          Neumann boundary; solved by :class:`gsdf.linalg.SPDSolver` (factorized small, CG/AMG large) through
          the core's :class:`~gsdf.heat._core.FactorizedPoisson` with the exact gauge (no mass regularization:
          vertices in no kept tet get 0, the constant is fixed by one pinned unknown, then the shift).

Sources: the input points Z (the first ``n_input`` vertices) are the nodes: "zero" fixes φ = 0 on all of them
(Dirichlet rows, the seed's §8.1 choice; not shifted afterwards); "multiple" gives every connected component of
the input one unknown; the shift is the area-weighted mean of φ over the source points.

Example
-------
>>> # TetDomain is built by gsdf.signed_heat_volume(..., domain="tet"), see gsdf.heat.volume._solve.solve_tet
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf.linalg import SPDSolver
from gsdf.heat._core import FactorizedPoisson
from gsdf.heat._sources import Sources
from gsdf.mesh._tet_ops import TetOperators
from gsdf.heat._domain import HeatDomain

__all__ = ["TetDomain", "tet_interpolation_rows"]


def tet_interpolation_rows(P, T, D, Q) -> sp.csr_matrix:
    """Sparse (q, n) rows of barycentric interpolation in the tets ``T`` at ``Q`` — the rows of
    :meth:`gsdf.TetField.__call__` (``D``: scipy Delaunay whose simplices are T, or None); outside: the nearest
    vertex."""
    from gsdf.contour._tets import locate_in_tets

    n, q = len(P), len(Q)
    if D is not None:
        s = D.find_simplex(Q)
        inside = s >= 0
        Tr = D.transform[s[inside]]
        b = np.einsum("qij,qj->qi", Tr[:, :3], Q[inside] - Tr[:, 3])
        bary = np.column_stack([b, 1.0 - b.sum(axis=1)])
        cols = D.simplices[s[inside]]
    else:
        s, bary_all = locate_in_tets(P, T, Q)
        inside = s >= 0
        bary, cols = bary_all[inside], T[s[inside]]
    rows = [np.repeat(np.flatnonzero(inside), 4)]
    cs, vs = [cols.ravel()], [bary.ravel()]
    if (~inside).any():
        from scipy.spatial import cKDTree

        out = np.flatnonzero(~inside)
        rows.append(out)
        cs.append(cKDTree(P).query(Q[out])[1])
        vs.append(np.ones(len(out)))
    return sp.csr_matrix((np.concatenate(vs), (np.concatenate(rows), np.concatenate(cs))), shape=(q, n))


class TetDomain(HeatDomain):
    """A tet mesh (module docs).

    Parameters
    ----------
    P, T, D : vertices (n, 3), tets (m, 4), the scipy Delaunay locator (or None);
    keep : (m,) bool, tets used by the operators (:func:`~gsdf.heat.tet._mesh.tet_quality` above the front-end's
    threshold); n_input : number of input points (the first vertices); comp : (n_input,) their connected
    components; t : diffusion time; theta : Yukawa tree tolerance.
    """

    heat_form = "direct"
    difference_order = "first"
    shift_hard_zero = False

    def __init__(self, P, T, D, keep, n_input, comp, t, theta=1.5):
        self.P, self.T, self.D, self.keep = P, T, D, keep
        self.Tk = T[keep]
        self.ops = TetOperators(P, self.Tk)
        self.n_nodes = len(P)
        self.n_input, self.comp = int(n_input), np.asarray(comp)
        self.t, self.theta = float(t), theta
        self.used = np.zeros(self.n_nodes, bool)
        self.used[self.Tk.ravel()] = True
        self._K = None

    def assemble_sources(self, curves, points, **options):
        raise ValueError("curves: volume domains take mesh or point-cloud sources (see signed_heat_volume)")

    def prepare(self, src: Sources, shift: bool = True) -> Sources:
        """Nodes = the input points (with their components), shift rows = interpolation at the sources (point
        location of every source: skipped with ``shift=False``, for the unshifted hard "zero")."""
        nZ = self.n_input
        S = Sources(B=src.B, W=src.W, a=src.a, kind=src.kind, mean_spacing=src.mean_spacing, extra=dict(src.extra))
        S.node_rows = sp.csr_matrix((np.ones(nZ), (np.arange(nZ), np.arange(nZ))), shape=(nZ, self.n_nodes))
        S.node_vertex = np.arange(nZ)
        S.node_curve = np.zeros(nZ, np.int64)
        S.components = self.comp
        if shift:
            S.shift_rows = tet_interpolation_rows(self.P, self.T, self.D, S.B)
            S.shift_weights = S.a
        return S

    def diffuse(self, S: Sources):
        from gsdf.heat._yukawa import YukawaTree

        return YukawaTree(S.B, S.W, self.t, theta=self.theta)(self.P[self.Tk].mean(axis=1))

    def gather(self, X):
        return X

    def divergence(self, Y):
        return self.ops.divergence(Y)

    def laplacian(self):
        if self._K is None:
            self._K = self.ops.cotan_laplacian()
        return self._K

    def mass(self):
        M = self.ops.vertex_mass()
        return np.where(M > 0, M, M[M > 0].mean() if (M > 0).any() else 1.0)

    def poisson_solver(self):
        return FactorizedPoisson(self.laplacian(), self.mass(), spd=SPDSolver, exact_gauge=True)
