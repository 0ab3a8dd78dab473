"""The signed heat method, written once (Feng & Crane 2024, §3 Alg. 1, §7.1, Alg. 13), for every domain.

A *domain* (one subpackage of :mod:`gsdf.heat` each: triangle mesh, intrinsic Delaunay, polygon mesh, point
cloud, grid, tet mesh, voxel surface) supplies operators and assembled sources
(:class:`~gsdf.heat._domain.HeatDomain`);
:class:`SignedHeatCore` does the rest:

Step I    X = (M + t L∇)⁻¹ X⁰ (Eq. 12) — factorized once per domain (complex Hermitian, or the real 2×2-block
          form), or computed by the domain (Yukawa sums in volumes);
Step II   Y = X / |X| on the domain's divergence elements (zero where X vanishes: far from the sources |X|
          decays like exp(-d/√t) yet its direction still counts, so there is no relative threshold, §3.1);
Step III  L φ = ∇·Y with the level-set constraint (§7.1):

          * ``"zero"`` — hard: φ = 0 at every source node. Sources all at vertices are eliminated (Dirichlet
            rows, as geometry-central does); otherwise the saddle system of Eq. 14 (a tiny −δI block keeps it
            nonsingular). The result is not shifted (it already vanishes on the sources);
          * ``"multiple"`` — hard: φ constant along each connected curve component (curves sharing a vertex
            are one component), then shifted;
          * ``"none"`` — no constraint, then shifted;
          * ``soft_weight=λ`` (with "zero" or "multiple") — the penalty λ Σ (φ(p_i) − φ(p_0))² instead of the
            hard rows (domains may define their own penalty rows: the grid penalizes φ(b_f)²), then shifted.

Shift (Alg. 13): subtract the length-weighted mean of φ along the curves (``Sources.shift_rows``), or the
minimum when there are only point sources.

Every factorization is kept: the Poisson operator per domain, constrained systems per constraint set (a
repeated call with the same sources costs only solves).

Progress: every heat path reports through one callback signature, ``progress(stage: str, fraction: float)``
with ``fraction`` in [0, 1]; stages are ``"sources"``, ``"heat (step I)"``, ``"poisson (step III)"`` (and
``"tet mesh"`` on tets).

Example
-------
>>> import numpy as np
>>> from gsdf.data._shapes import grid_mesh
>>> from gsdf.contour._surface_curves import level_set_curves
>>> from gsdf.heat.triangle._domain import TriangleDomain
>>> V, F = grid_mesh(32)
>>> core = SignedHeatCore(TriangleDomain(V, F))
>>> circle = level_set_curves(V, F, np.linalg.norm(V, axis=1) - 0.5)
>>> phi = core.compute_distance(circle)
>>> round(float(phi[np.argmin(np.linalg.norm(V, axis=1))]), 1)
-0.5
"""

from __future__ import annotations

import hashlib

import numpy as np
import scipy.sparse as sp

from gsdf import _checks
from gsdf.linalg import (
    BlockHermitianFactorization,
    Factorization,
    HermitianFactorization,
    cached_factorization,
    saddle_matrix,
    spd_factorization,
)
from gsdf.linalg._assembly import principal_submatrix
from gsdf.threads import blas_region
from gsdf.heat._domain import PoissonSolver
from gsdf.heat._sources import Sources
from gsdf.curves import as_curves, as_point_sources

__all__ = ["SignedHeatCore", "FactorizedPoisson", "LEVEL_SETS", "unique_rows", "reporter", "normalize"]

LEVEL_SETS = ("zero", "multiple", "none")


def hash_key(*arrays) -> str:
    """A cache key for constraint sets: sha1 over shapes and bytes."""
    h = hashlib.sha1()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def normalize(Y: np.ndarray) -> np.ndarray:
    """Step II: Y / |Y| per row; rows with |Y| = 0 stay 0."""
    sq = Y[:, 0] * Y[:, 0]                                  # |Y|² summed left to right, as np.linalg.norm does
    for j in range(1, Y.shape[1]):
        sq += Y[:, j] * Y[:, j]
    nrm = np.sqrt(sq)
    out = np.zeros_like(Y)
    np.divide(Y, nrm[:, None], out=out, where=nrm[:, None] > 0)
    return out


def unique_rows(A, order: str = "first"):
    """Drop duplicate rows of a sparse matrix (repeated nodes would make the saddle system singular).

    ``order="first"`` keeps the rows in the order of their first occurrence, ``"sorted"`` in lexicographic
    order of (column indices, values) — for one-hot rows, ascending vertex index."""
    A = sp.csr_matrix(A)
    A.sum_duplicates()
    A.eliminate_zeros()
    A.sort_indices()
    k = A.shape[0]
    nnz = np.diff(A.indptr)
    width = int(nnz.max()) if k else 0
    key = np.full((k, 2 * width), -1.0)
    pos = np.arange(A.nnz) - np.repeat(A.indptr[:-1], nnz)
    row = np.repeat(np.arange(k), nnz)
    key[row, pos] = A.indices
    key[row, width + pos] = np.round(A.data, 12)
    _, idx = np.unique(key, axis=0, return_index=True)
    return A[np.sort(idx) if order == "first" else idx]


def curve_components(S: Sources, n: int) -> np.ndarray:
    """Connected component of every curve: curves sharing a vertex node belong together."""
    from scipy.sparse.csgraph import connected_components

    k = int(S.node_curve.max()) + 1 if len(S.node_curve) else 0
    isv = S.node_vertex >= 0
    r, c = S.node_curve[isv], S.node_vertex[isv]
    G = sp.csr_matrix((np.ones(len(r)), (r, k + c)), shape=(k + n, k + n))
    return connected_components(G, directed=False)[1][:k]


class _NoKey(Exception):
    pass


def source_key(curves, points, curve_signs, options):
    """A content key (sha1 digest) of one call's source arguments, or None when they are not plain index arrays
    and :class:`~gsdf.curves.Curve` objects of vertices / edges (then the sources are assembled anew).

    Two calls with equal keys get the same assembled sources: the key covers the container type, every array's
    dtype, shape and bytes, each Curve's kind and sign, the points, the signs and the (all-None) options.
    """
    from gsdf.curves import Curve

    h = hashlib.sha1()

    def add(tag, a):
        if not isinstance(a, np.ndarray) or a.dtype == object:
            raise _NoKey
        h.update(tag + a.dtype.str.encode() + str(a.shape).encode())
        h.update(np.ascontiguousarray(a).tobytes())

    try:
        if any(v is not None for v in options.values()):
            raise _NoKey
        if isinstance(curves, (np.ndarray, Curve)):
            h.update(b"one")
            items = [curves]
        elif isinstance(curves, (list, tuple)):
            h.update(b"list")
            items = curves
        else:
            raise _NoKey
        for c in items:
            if isinstance(c, Curve):
                if c.kind == "points":
                    raise _NoKey
                add(b"C" + c.kind.encode() + (b"+" if c.signed else b"-"), c.nodes)
            else:
                add(b"A", c)
        if isinstance(points, np.ndarray):
            add(b"P", points)
        elif isinstance(points, (list, tuple)) and all(type(p) is int for p in points):
            add(b"p", np.array(points, np.int64))
        else:
            raise _NoKey
        if curve_signs is None:
            h.update(b"S")
        elif isinstance(curve_signs, (list, tuple)) and all(type(x) is bool for x in curve_signs):
            h.update(b"s" + bytes(bytearray(curve_signs)))
        else:
            raise _NoKey
    except _NoKey:
        return None
    return h.digest()


class FactorizedPoisson(PoissonSolver):
    """Step III by sparse factorizations, kept per constraint set.

    By default ``L + ε M`` is factorized (ε = 1e-10 · mean diag(L) / mean(M) fixes the constant of every
    component: L is only semidefinite). With ``exact_gauge=True`` (tets) there is no ε: nodes in no element
    (zero rows of L) get φ = 0 and the constant is fixed by pinning the first unknown (then the core's shift).

    ``spd``: the factory of SPD solves (default :class:`gsdf.linalg.Factorization`; tets use
    :class:`gsdf.linalg.SPDSolver`, CG/AMG above a size).

    ``ordering``: a callable returning a fill-reducing permutation (n,) of all nodes, or None. When given (and
    ``spd`` is not), a Dirichlet system's LDLᵀ is ordered by that permutation restricted to its free nodes, with
    no ordering pass of its own (AMD too only when that factor is flop-heavy, :data:`gsdf.linalg._ldl.HINT_AMD_FLOPS`;
    the elimination graph of a principal submatrix under the induced order is a subgraph of the full one, so
    its fill is at most the full factor's). Polygon meshes: Step I's ordering of the same vertex graph.
    """

    def __init__(self, L, Mv, spd=None, exact_gauge: bool = False, renumber: bool = True, ordering=None):
        self.L = sp.csr_matrix(L).tocsc()
        self.L.sum_duplicates()                      # canonical (principal_submatrix reads sorted columns)
        self.Mv = np.asarray(Mv, np.float64)
        self.n = self.L.shape[0]
        self.exact_gauge = bool(exact_gauge)
        self._eps = 0.0 if exact_gauge else 1e-10 * float(np.abs(self.L.diagonal()).mean()) / float(self.Mv.mean())
        self._active = self.L.diagonal() != 0 if exact_gauge else np.ones(self.n, bool)
        self._spd = spd or (lambda A: Factorization(sp.csc_matrix(A)))
        # the Dirichlet systems (no ε: well-conditioned) may take a bandwidth renumbering before the ordering
        renumber = bool(renumber)
        self._spd_dirichlet = (lambda A, hint=None: spd_factorization(A, reorder=renumber, hint=hint)) \
            if spd is None else (lambda A, hint=None: self._spd(A))
        self._ordering = ordering
        self._cache: dict = {}
        self._last_fixed = None                      # (fixed array, key, free) of the last Dirichlet solve

    def _cached(self, key, build):
        return cached_factorization(self._cache, key, build)

    def _reduced(self, key, Pm, b):
        """Solve ``Pmᵀ (L + εM) Pm u = Pmᵀ b`` (pinning u_0 with the exact gauge) and return ``Pm u``."""
        def build():
            A = (Pm.T @ (self.L + sp.diags(self._eps * self.Mv)) @ Pm).tocsc() if self._eps else \
                (Pm.T @ self.L @ Pm).tocsc()
            if self.exact_gauge:
                A = A[1:][:, 1:]
            return self._spd(A)

        rhs = Pm.T @ b
        u = np.zeros(Pm.shape[1])
        if self.exact_gauge:
            u[1:] = self._cached(key, build).solve(rhs[1:])
        else:
            u = self._cached(key, build).solve(rhs)
        return Pm @ u

    def free(self, b):
        if not self.exact_gauge:
            fact = self._cached("free", lambda: self._spd((self.L + sp.diags(self._eps * self.Mv)).tocsc()))
            return fact.solve(b)
        idx = np.flatnonzero(self._active)
        Pm = sp.csr_matrix((np.ones(len(idx)), (idx, np.arange(len(idx)))), shape=(self.n, len(idx)))
        return self._reduced("free", Pm, b)

    def dirichlet(self, fixed, b):
        last = self._last_fixed
        if last is not None and last[0] is fixed:     # the same array again (cached sources): reuse its set
            key, free = last[1], last[2]
        else:
            given = fixed
            fixed = np.unique(np.asarray(fixed, np.int64))
            mask = np.zeros(self.n, bool)
            mask[fixed] = True
            free = np.flatnonzero(~mask & self._active)
            key = hash_key(np.array([0]), fixed)
            self._last_fixed = (given, key, free) if isinstance(given, np.ndarray) and not given.flags.writeable \
                else None

        def build():
            # L[free][:, free] + diag(ε M[free]), in L's CSC format, in one pass
            A = principal_submatrix(self.L, free, 1.0, self._eps * self.Mv[free] if self._eps else None)
            full = self._ordering() if self._ordering is not None else None
            if full is None:
                return self._spd_dirichlet(A)
            rank = np.full(self.n, -1, np.int64)            # the full order restricted to the free nodes
            rank[free] = np.arange(len(free))
            sub = rank[full]
            return self._spd_dirichlet(A, sub[sub >= 0])

        phi = np.zeros(self.n)
        if len(free):
            phi[free] = self._cached(key, build).solve(b[free])
        return phi

    def merged(self, groups, b):
        """Hard "multiple" for vertex sources: every group of vertices shares one unknown (substitution)."""
        col = np.full(self.n, -1)
        free = self._active.copy()
        for g in groups:
            free[g] = False
        fidx = np.flatnonzero(free)
        col[fidx] = np.arange(len(fidx))
        for k, g in enumerate(groups):
            col[g[self._active[g]]] = len(fidx) + k
        rows = np.flatnonzero(col >= 0)
        Pm = sp.csr_matrix((np.ones(len(rows)), (rows, col[rows])), shape=(self.n, len(fidx) + len(groups)))
        key = hash_key(np.array([4]), col)
        return self._reduced(key, Pm, b)

    def constrained(self, A, b, tag, weights=None):
        A = sp.csr_matrix(A)
        key = hash_key(np.array([hash(tag) % 2**31]), A.indptr, A.indices, A.data)
        delta = 1e-12 * float(self.L.diagonal().mean())

        def build():
            return Factorization(saddle_matrix(self.L + sp.diags(self._eps * self.Mv), A, delta))

        rhs = np.concatenate([b, np.zeros(A.shape[0])])
        return self._cached(key, build).solve(rhs)[: self.n]

    def penalized(self, A, w, b):
        A = sp.csr_matrix(A)
        w = np.broadcast_to(np.asarray(w, np.float64), (A.shape[0],))
        key = hash_key(np.array([3]), w, A.indptr, A.indices, A.data)

        # the exact gauge: the penalty (differences) leaves the constants free, so the first active unknown is
        # pinned and nodes in no element get 0, as for the free solve
        keep = np.flatnonzero(self._active)[1:] if self.exact_gauge else None

        def build():
            if np.all(w == w[0]):
                K = self.L + w[0] * (A.T @ A) + sp.diags(self._eps * self.Mv)
            else:
                K = self.L + A.T @ sp.diags(w) @ A + sp.diags(self._eps * self.Mv)
            K = K.tocsc()
            return self._spd(K if keep is None else K[keep][:, keep])

        if keep is None:
            return self._cached(key, build).solve(b)
        phi = np.zeros(self.n)
        phi[keep] = self._cached(key, build).solve(b[keep])
        return phi


class SignedHeatCore:
    """Steps I–III, the level-set constraints and the shift for one domain (module docs).

    Parameters
    ----------
    domain : HeatDomain
        The operators of one discretization (``gsdf.heat.triangle``, ``gsdf.heat.grid``, …).

    Attributes
    ----------
    poisson : PoissonSolver — the domain's own, or :class:`FactorizedPoisson` of its Laplacian.
    """

    MAX_STATES = 4

    def __init__(self, domain):
        self.domain = domain
        self._states: dict = {}
        self._last_sources = None                 # (source_key, Sources) of the last call

    def _state(self) -> dict:
        """Factorizations of the domain's current operators (domains that switch triangulations, like the
        intrinsic one, expose ``state_key``; a few states are kept)."""
        key = getattr(self.domain, "state_key", None)
        st = self._states.get(key)
        if st is None:
            if len(self._states) >= self.MAX_STATES:
                self._states.pop(next(iter(self._states)))
            st = self._states[key] = {"vec": None, "poisson": None}
        return st

    # ------------------------------------------------------------------ steps
    @property
    def vector_heat_factorization(self):
        """The factorization of ``M + t L∇`` (Eq. 12), built on first use."""
        st = self._state()
        if st["vec"] is None:
            form = self.domain.heat_form
            if form == "complex":
                st["vec"] = HermitianFactorization(self.domain.vector_heat_matrix(),
                                                   reorder=getattr(self.domain, "renumber", True),
                                                   ordering=getattr(self.domain, "heat_ordering", "auto"))
            elif form == "real2":
                st["vec"] = BlockHermitianFactorization(self.domain.vector_heat_matrix())
            else:
                raise ValueError(f"domain: heat_form {form!r} has no vector heat operator")
        return st["vec"]

    @property
    def poisson(self) -> PoissonSolver:
        """The domain's Step III solver (its own, or :class:`FactorizedPoisson` of its Laplacian)."""
        st = self._state()
        if st["poisson"] is None:
            share = getattr(self.domain, "heat_on_nodes", False) and self.domain.heat_form == "complex"
            st["poisson"] = self.domain.poisson_solver() or FactorizedPoisson(
                self.domain.laplacian(), self.domain.mass(), renumber=getattr(self.domain, "renumber", True),
                ordering=(lambda: self._step1_ordering(st)) if share else None)
        return st["poisson"]

    @staticmethod
    def _step1_ordering(st):
        """Step I's fill-reducing permutation of the nodes (None before Step I or off the LDLᴴ backend)."""
        vec = st["vec"]
        return getattr(vec, "ordering", None) if vec is not None else None

    def diffuse(self, S: Sources) -> np.ndarray:
        """Step I."""
        if self.domain.heat_form == "direct":
            return self.domain.diffuse(S)
        return self.vector_heat_factorization.solve(S.X0)

    def unit_field(self, X) -> np.ndarray:
        """Step II: the normalized vectors on the domain's divergence elements."""
        return normalize(self.domain.gather(X))

    # ------------------------------------------------------------------ public
    def sources(self, curves, points=(), curve_signs=None, **options) -> Sources:
        """Type-check curves and points (:func:`~gsdf.curves.as_curves`) and assemble them on the domain."""
        cs = as_curves(curves, curve_signs)
        ps = as_point_sources(points)
        return self.domain.assemble_sources(cs, ps, **options)

    def compute_distance(self, curves, *, points=(), curve_signs=None, level_set_constraint: str = "zero",
                         soft_weight=None, progress=None, **options) -> np.ndarray:
        """Validate, assemble and solve (Alg. 1 with §7.1); returns φ (n,) on the domain's nodes."""
        mode = _checks.choice(level_set_constraint, "level_set_constraint", LEVEL_SETS)
        lam = None if soft_weight is None else _checks.positive(soft_weight, "soft_weight")
        report = _checks.progress_callback(progress)
        report("sources", 0.0)
        # repeated calls with the same curves reuse the validated, assembled sources (domains whose sources do
        # not depend on a changing state declare ``cache_sources``)
        key = source_key(curves, points, curve_signs, options) if getattr(self.domain, "cache_sources", False) \
            else None
        if key is not None and self._last_sources is not None and self._last_sources[0] == key:
            S = self._last_sources[1]
        else:
            S = self.sources(curves, points, curve_signs, **options)
            self._last_sources = (key, S) if key is not None else None
        return self.solve(S, mode, lam, report)

    def solve(self, S: Sources, mode: str = "zero", lam=None, report=None) -> np.ndarray:
        """Steps I–III for assembled sources; ``mode`` a level-set constraint, ``lam`` the soft weight or None."""
        report = report or _checks.progress_callback(None)
        if S.X0 is not None and not np.any(S.X0):
            raise ValueError("curves: the sources have zero total length / weight")
        with blas_region():               # one BLAS limit for all factorizations and solves of the call
            return self._solve(S, mode, lam, report)

    def _solve(self, S: Sources, mode: str, lam, report) -> np.ndarray:
        report("heat (step I)", 0.0)
        X = self.diffuse(S)
        report("heat (step I)", 1.0)
        report("poisson (step III)", 0.0)
        b = self.domain.divergence(self.unit_field(X))
        phi, shift = self.poisson_step(S, b, mode, lam)
        if shift:
            phi = self.shift(S, phi)
        report("poisson (step III)", 1.0)
        return phi

    def poisson_step(self, S: Sources, b, mode: str, lam):
        """Step III with the level-set constraint; returns (φ, whether to shift)."""
        P = self.poisson
        if mode == "none":
            return P.free(b), True
        if lam is not None:
            custom = self.domain.soft_rows(S, mode, lam)
            if custom is None:
                A, w = self.difference_rows(S, single=(mode != "multiple")), lam
            else:
                A, w = custom
            if A.shape[0] == 0:
                return P.free(b), True
            return P.penalized(A, w, b), True
        if mode == "zero":
            rows = self.domain.zero_rows(S)
            again = getattr(self.domain, "shift_hard_zero", True)
            A, vert = rows[0], rows[1]
            if len(rows) == 3:                                  # the domain's own (weighted) rows
                return P.constrained(A, b, "zero", weights=rows[2]), again
            if len(vert) and np.all(vert >= 0):
                return P.dirichlet(vert, b), again
            return P.constrained(unique_rows(A), b, "zero"), again
        groups = self.vertex_groups(S)
        if groups is not None and hasattr(P, "merged"):
            if not groups:
                return P.free(b), True
            return P.merged(groups, b), True
        A = self.difference_rows(S, single=False)
        if A.shape[0] == 0:
            return P.free(b), True
        return P.constrained(A, b, "multiple"), True

    def vertex_groups(self, S: Sources):
        """For "multiple" with every curve node at a vertex: the vertex set of each connected component with
        more than one vertex (None when some node lies inside an element)."""
        if S.node_vertex is None or not len(S.node_vertex) or np.any(S.node_vertex < 0):
            return None if S.node_vertex is None or np.any(S.node_vertex < 0) else []
        if S.components is not None:
            lab = S.components
        else:
            lab = curve_components(S, self.domain.n_nodes)[S.node_curve]
        out = []
        for g in np.unique(lab):
            v = np.unique(S.node_vertex[lab == g])
            if len(v) > 1:
                out.append(v)
        return out

    def difference_rows(self, S: Sources, single: bool = False):
        """Rows φ(p_i) − φ(p_0) = 0 per connected curve component (over all nodes and points when ``single``)."""
        n = self.domain.n_nodes
        order = self.domain.difference_order
        if S.components is not None and not single:
            groups = S.components
        elif single:
            groups = np.zeros(len(S.node_curve), np.int64)
        else:
            groups = curve_components(S, n)[S.node_curve] if len(S.node_curve) else np.zeros(0, np.int64)
        mats = []
        gs = np.unique(groups)
        if single and len(gs) == 0 and S.point_rows is not None:
            gs = np.array([0])
        for g in gs:
            R = S.node_rows[np.flatnonzero(groups == g)]
            if single and S.point_rows is not None:
                R = sp.vstack([R, S.point_rows])
            Pm = unique_rows(R, order)
            if Pm.shape[0] > 1:
                mats.append(Pm[1:] - sp.csr_matrix(np.ones((Pm.shape[0] - 1, 1))) @ Pm[:1])
        if not mats:
            return sp.csr_matrix((0, n))
        return sp.vstack(mats).tocsr()

    @staticmethod
    def shift(S: Sources, phi):
        """Alg. 13: subtract the weighted mean of φ along the curves (the minimum with only point sources)."""
        if S.shift_rows is not None and S.shift_rows.shape[0]:
            w = S.shift_weights
            if w.sum() > 0:
                return phi - float(((S.shift_rows @ phi) * w).sum() / w.sum())
        return phi - float(phi.min())
