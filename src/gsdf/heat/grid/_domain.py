"""Regular grids as a signed-heat domain (Feng & Crane 2024, §8.2); operators in :mod:`gsdf.heat.grid._poisson`.

Step I    X at the grid nodes: the Yukawa potential of the sources (``diffuse``: a tree walk,
          :mod:`gsdf.heat._yukawa`, or one screened solve on the grid itself, :mod:`gsdf.heat.grid._screened` —
          ``step1``, below).
Step II   normalized at the nodes (by the core).
Step III  the 7-point Neumann Laplacian against the forward-difference divergence; :class:`GridPoisson` solves it
          exactly by DCT (no constraint), by CG with the coarse-block + band Gauss–Seidel + DCT preconditioner
          (soft penalty), or by the augmented Lagrangian (hard rows), never by a factorization of the whole grid.

Constraint rows: one per grid cell holding sources — the area-weighted mean of their trilinear rows (one row per
source would force φ ≡ 0 on every cell a dense input crosses). ``"zero"`` imposes them exactly (φ is then not
shifted); ``"multiple"`` makes them equal within each connected component of the input (rows per component and
cell, differences to the first), then shifts; ``soft_weight=c`` penalizes c Σ_f a_f φ(b_f)² / h⁴ (φ at every
source, not differences — this pulls the zero level through the input), then shifts. The shift is the
area-weighted mean of φ over the sources (signedheat3d's evaluateAverageAlongSourceGeometry).

Example
-------
>>> import numpy as np
>>> from gsdf.heat.volume._sources import point_sources
>>> from gsdf.heat._core import SignedHeatCore
>>> i = np.arange(400) + 0.5
>>> ph, th = np.arccos(1 - 2 * i / 400), np.pi * (1 + 5 ** 0.5) * i
>>> P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
>>> d = GridDomain(np.full(3, -1.5), np.full(3, 1.5), (16, 16, 16), t=0.04)
>>> phi = SignedHeatCore(d).solve(d.prepare(point_sources(P, P)), "none")
>>> bool(phi.reshape(16, 16, 16)[8, 8, 8] < -0.5)
True
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf.heat._sources import Sources
from gsdf.heat.grid._poisson import (
    cell_constraint_matrix,
    divergence_rhs,
    dct_poisson,
    neumann_laplacian,
    penalty_matrix,
    solve_constrained,
    solve_poisson,
    trilinear_matrix,
)
from gsdf.heat._domain import HeatDomain, PoissonSolver

__all__ = ["GridDomain", "GridPoisson"]


class GridPoisson(PoissonSolver):
    """Step III on the grid without factorizing it (module docs). ``info`` holds the last constrained solve's
    residual, row count and outer iterations."""

    def __init__(self, domain: "GridDomain"):
        self.d = domain
        self.info: dict = {}

    def free(self, b):
        return dct_poisson(b, self.d.shape, self.d.spacing)

    #: CG's relative residual for the soft penalty (docs/decisions.md).
    penalty_tol = 1e-3

    def penalized(self, A, w, b):
        penalty = penalty_matrix(A, w, self.d.shape)
        return solve_poisson(b, self.d.shape, self.d.spacing, penalty, tol=self.penalty_tol)

    def dirichlet(self, fixed, b):
        raise ValueError("level_set_constraint: grid nodes are never sources (use the cell rows)")

    def constrained(self, A, b, tag, weights=None):
        d = self.d
        if weights is None:                                     # difference rows: the mean cell weight
            weights = np.full(A.shape[0], d.row_weight)
        phi, res, outer = solve_constrained(b, d.shape, d.spacing, sp.csr_matrix(A), weights, d.rho, d.tol * d.h,
                                            regularize=(tag != "zero"))
        self.info = {"constraint_residual": res, "constraint_rows": A.shape[0], "outer_iterations": outer}
        return phi


class GridDomain(HeatDomain):
    """A box ``[lo, hi]`` sampled by ``shape`` nodes (module docs).

    Parameters
    ----------
    lo, hi : (3,) box corners; shape : (3,) node counts; t : diffusion time;
    theta, eps : the Yukawa tree's cluster tolerance and source pruning (a source weighing less than ``eps`` ×
        the nearest one is skipped, :class:`~gsdf.heat._yukawa.YukawaTree`);
    rho, tol : penalty and tolerance (× h) of the augmented Lagrangian of the hard constraints;
    progress : ``progress(stage, fraction)`` for step I;
    step1 : {"auto", "yukawa", "heat"} — Step I by the Yukawa tree sum, or by the screened solve on the grid
        (:func:`~gsdf.heat.grid._screened.screened_heat`). "auto" (what :func:`gsdf.signed_heat_volume` uses):
        "heat" on cubic cells when t ≥ h²/2, every source lies in the box padded by
        :data:`~gsdf.heat.grid._screened.PAD` cells (the splat clamps the others to it) and the farthest node
        is within :data:`~gsdf.heat.grid._screened.MAX_DECAY` decay lengths of the sources, else "yukawa"
        (docs/decisions.md).
    """

    heat_form = "direct"
    difference_order = "first"
    shift_hard_zero = False

    def __init__(self, lo, hi, shape, t: float, theta: float = 1.5, eps: float = 1e-4, rho: float = 1e5,
                 tol: float = 1e-4, progress=None, step1: str = "auto"):
        from gsdf._checks import choice

        self.step1 = choice(step1, "step1", {"auto", "yukawa", "heat"})
        self.step1_used = None  # the path the last diffuse took
        self.lo, self.hi = np.asarray(lo, float), np.asarray(hi, float)
        self.shape = tuple(int(s) for s in shape)
        self.spacing = (self.hi - self.lo) / (np.array(self.shape) - 1)
        self.h = float(self.spacing.max())
        self.n_nodes = int(np.prod(self.shape))
        from gsdf._checks import nonnegative, positive

        # the Yukawa tree's options are checked here too: step1="auto" may not build the tree
        theta, eps = nonnegative(theta, "theta"), positive(eps, "eps", most=0.5)
        self.t, self.theta, self.eps, self.rho, self.tol = float(t), theta, eps, rho, tol
        self.row_weight = 1.0
        self._progress = progress or (lambda stage, fraction: None)

    # ---- sources
    def assemble_sources(self, curves, points, **options):
        raise ValueError("curves: volume domains take mesh or point-cloud sources (see signed_heat_volume)")

    def prepare(self, src: Sources, components: np.ndarray | None = None) -> Sources:
        """Add the constraint and shift rows to volume sources (``B``, ``W``, ``a``); ``components`` (m,) labels
        the connected components of the sources for ``"multiple"``."""
        S = Sources(B=src.B, W=src.W, a=src.a, kind=src.kind, mean_spacing=src.mean_spacing, extra=dict(src.extra))
        S.shift_rows = trilinear_matrix(S.B, self.lo, self.spacing, self.shape)
        S.shift_weights = S.a
        if components is not None:
            rows, comp = [], []
            for c in np.unique(components):
                sel = np.flatnonzero(components == c)
                C, w = cell_constraint_matrix(S.B[sel], S.a[sel], self.lo, self.spacing, self.shape)
                rows.append(C)
                comp.append(np.full(C.shape[0], c))
            S.node_rows = sp.vstack(rows).tocsr()
            S.components = np.concatenate(comp)
            S.node_curve = np.zeros(S.node_rows.shape[0], np.int64)
            S.node_vertex = np.full(S.node_rows.shape[0], -1)
            self.row_weight = float(S.a.sum() / S.node_rows.shape[0]) / self.h ** 4
        return S

    def zero_rows(self, S: Sources):
        C, w = cell_constraint_matrix(S.B, S.a, self.lo, self.spacing, self.shape)
        return C, np.full(C.shape[0], -1), w / self.h ** 4

    def soft_rows(self, S: Sources, mode: str, lam: float):
        if mode == "multiple":                                 # differences of the cell rows per component
            if S.node_rows is None:
                raise ValueError('level_set="multiple": the sources have no connected components here (a point '
                                 'cloud without component labels); use level_set="zero"')
            mats = []
            for c in np.unique(S.components):
                R = S.node_rows[np.flatnonzero(S.components == c)]
                if R.shape[0] > 1:
                    mats.append(R[1:] - sp.csr_matrix(np.ones((R.shape[0] - 1, 1))) @ R[:1])
            A = sp.vstack(mats).tocsr() if mats else sp.csr_matrix((0, self.n_nodes))
            return A, np.full(A.shape[0], lam * self.row_weight)
        return S.shift_rows, lam * S.a / self.h ** 4

    # ---- operators
    def diffuse(self, S: Sources) -> np.ndarray:
        from gsdf.grid import grid_points
        from gsdf.heat.grid._screened import MAX_DECAY, PAD, _cubic, screened_heat, screened_reach
        from gsdf.heat._yukawa import YukawaTree, grid_nearest_distance

        use_grid = self.step1 == "heat"
        margin = PAD * self.spacing
        if (self.step1 == "auto" and _cubic(self.spacing) and self.t >= 0.5 * self.h ** 2
                and (S.B >= self.lo - margin).all() and (S.B <= self.hi + margin).all()):
            # the farthest node's distance to the sources, bounded from the nodes of a grid twice as coarse
            # (8× fewer nodes to transform): each fine node is within half a coarse cell diagonal of one
            cs = 2.0 * self.spacing
            d, sl = grid_nearest_distance(S.B, self.lo, cs, tuple((s - 1) // 2 + 1 + (s - 1) % 2 for s in self.shape))
            use_grid = screened_reach(float(d.max()) + sl + 0.5 * float(np.linalg.norm(cs)), self.t,
                                      self.spacing) <= MAX_DECAY
        self.step1_used = "heat" if use_grid else "yukawa"
        if use_grid:
            self._progress("heat (step I)", 0.0)
            X = screened_heat(S.B, S.W, self.lo, self.spacing, self.shape, self.t)
            self._progress("heat (step I)", 1.0)
            return X
        dref, slack = grid_nearest_distance(S.B, self.lo, self.spacing, self.shape)
        tree = YukawaTree(S.B, S.W, self.t, theta=self.theta, eps=self.eps)
        Q = grid_points(self.lo, self.hi, self.shape)
        return tree(Q, dref, slack, progress=lambda stage, fraction: self._progress("heat (step I)", fraction))

    def gather(self, X):
        return X

    def divergence(self, Y):
        return divergence_rhs(Y.reshape(self.shape + (3,)), self.spacing)

    def laplacian(self):
        return neumann_laplacian(self.shape, self.spacing)

    def mass(self):
        return np.full(self.n_nodes, float(np.prod(self.spacing)))

    def poisson_solver(self):
        return GridPoisson(self)
