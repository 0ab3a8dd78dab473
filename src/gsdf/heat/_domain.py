"""The domain protocol of the signed heat core: what a discretization must supply (operators and sources only).

:class:`gsdf.heat._core.SignedHeatCore` runs the three steps of the signed heat method (Feng & Crane 2024, §3,
Alg. 1), the level-set constraints of §7.1 and the shift of Alg. 13 *once*, for every domain. A domain is an
object with the attributes and methods of :class:`HeatDomain`; it never solves the Poisson problem itself and
never normalizes vectors. The core calls, in order:

1. ``assemble_sources(curves, points, **options) -> Sources`` — curves is a list of
   :class:`gsdf.curves.Curve`, points a list of vertex indices or ``(face, barycentric)`` pairs (both
   already type-checked; the domain checks ranges, mesh edges, …). The result (:class:`gsdf.heat._sources.Sources`)
   carries X⁰ (or point charges), the interpolation rows of the source nodes and the shift rows.
2. Step I: if ``heat_form`` is ``"complex"`` the core factorizes ``vector_heat_matrix()`` (M + t L∇, complex
   Hermitian positive definite, Eq. 12) once and solves with ``Sources.X0``; ``"real2"``: the same operator as a
   real 2n×2n SPD matrix of 2×2 blocks (reflections across orientation flips), X⁰ still complex; ``"direct"``:
   the domain computes X itself by ``diffuse(sources)`` (the Yukawa sums of the volume domains).
3. Step II: ``gather(X) -> Y`` (k, d) — the vectors on the elements where the divergence is taken (faces, fine
   triangles, cover edges, grid nodes, tets), not yet normalized; the core normalizes them (zero stays zero).
4. Step III: ``divergence(Y) -> b`` (n,) with the convention ``L φ = b`` ⇔ ∇φ ≈ Y, ``laplacian()`` (n, n) real
   PSD and ``mass()`` (n,) positive lumped masses (they regularize the constant modes). A domain whose Poisson
   problem has a better solver than a sparse factorization (the DCT of the grid) returns a
   :class:`PoissonSolver` from ``poisson_solver()``; otherwise None and the core factorizes.

Optional hooks (defaults here): ``zero_rows(S)`` — the rows of the hard ``"zero"`` constraint (default: every
source node); ``soft_rows(S, mode, lam)`` — rows and weights of the ``soft_weight=`` penalty (default: differences
φ(p_i) − φ(p_0) over all nodes, or per connected curve for ``"multiple"``); ``difference_order`` — which node is
p_0 (``"first"``: the first node given; ``"sorted"``: the lowest vertex index).

:class:`VertexSurfaceDomain` implements the sources of a *vertex-based* surface domain (polygon meshes §8.3,
point clouds §8.4, voxel surfaces §8.5): a subclass gives positions, a PSD Laplacian, lumped masses, unit
normals with tangent frames, a Hermitian connection Laplacian, and ``gather`` / ``divergence``.

Example
-------
A flat triangle mesh as a vertex domain (``test_a_new_vertex_domain_plugs_into_the_core`` in
tests/heat/test_core.py runs it against the exact distance to a circle)::

    class FlatVertexDomain(VertexSurfaceDomain):
        def __init__(self, V, F):
            self.ops = TriangleOperators(V, F)
            L = self.ops.cotan_laplacian()
            N = np.tile([0.0, 0, 1], (len(V), 1))
            e1, e2 = tangent_frames(N)
            h = self.ops.edge_len.mean()
            super().__init__(V, L, self.ops.vertex_mass(), L.astype(complex), N, e1, e2, t=h * h)

        def gather(self, X):                      # vertex vectors summed over every face (the core normalizes)
            return self.to_3d(X)[self.ops.F].sum(axis=1)

        def divergence(self, Y):
            return self.ops.divergence(Y)

    phi = SignedHeatCore(FlatVertexDomain(V, F)).compute_distance([loop])
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
import scipy.sparse as sp

from gsdf.linalg._assembly import principal_submatrix
from gsdf.heat._sources import Sources
from gsdf.curves import Curve

__all__ = ["HeatDomain", "PoissonSolver", "VertexSurfaceDomain", "tangent_frames"]

HEAT_FORMS = ("complex", "real2", "direct")


class PoissonSolver(ABC):
    """Step III solves of one domain, each ``(n,) -> (n,)``; the core's default factorizes (see
    :class:`gsdf.heat._core.FactorizedPoisson`). A solver that cannot impose some constraint raises ValueError
    naming it."""

    @abstractmethod
    def free(self, b):                          # L φ = b, up to a constant (regularized by the mass)
        ...

    @abstractmethod
    def dirichlet(self, fixed, b):              # L φ = b on the other nodes, φ = 0 on the node indices ``fixed``
        ...

    @abstractmethod
    def constrained(self, A, b, tag, weights=None):   # min ½φᵀLφ − bᵀφ subject to A φ = 0 (Eq. 14)
        ...

    # optional: merged(groups, b) — "multiple" for vertex sources by substitution (one unknown per group)

    @abstractmethod
    def penalized(self, A, w, b):               # (L + Aᵀ diag(w) A) φ = b
        ...


class HeatDomain(ABC):
    """Base class of signed-heat domains (module docs). Subclasses set ``n_nodes``, ``t``, ``heat_form`` and
    implement the operators; everything a solve does beyond operators is :mod:`gsdf.heat._core`'s."""

    n_nodes: int = 0
    t: float = 1.0
    heat_form: str = "complex"
    difference_order: str = "first"
    shift_hard_zero: bool = True        # apply the shift of Alg. 13 after a hard "zero" constraint too
    cache_sources: bool = False         # sources depend only on the arguments: the core may reuse the last ones
    renumber: bool = True               # RCM renumbering before SuperLU's ordering
    heat_ordering: str = "auto"         # the LDLᴴ ordering of Step I's operator (gsdf.linalg._ldl)
    heat_on_nodes: bool = False         # Step I's unknowns are the Laplacian's nodes, same pattern: Step III
    #                                     reuses Step I's fill-reducing ordering (core.FactorizedPoisson)

    # ---- sources
    @abstractmethod
    def assemble_sources(self, curves: list, points: list, **options) -> Sources:
        """Validate ranges / edges of typed curves and points and assemble :class:`Sources`."""

    # ---- step I (one of the two, by ``heat_form``)
    def vector_heat_matrix(self):
        """M + t L∇ (complex Hermitian, or its real 2n×2n block form for ``heat_form == "real2"``)."""
        raise ValueError(f"domain: {type(self).__name__} has no vector heat operator (heat_form={self.heat_form!r})")

    def diffuse(self, sources: Sources) -> np.ndarray:
        """Step I computed by the domain (``heat_form == "direct"``)."""
        raise ValueError(f"domain: {type(self).__name__} does not compute step I itself (heat_form="
                         f"{self.heat_form!r})")

    # ---- step II / III
    @abstractmethod
    def gather(self, X) -> np.ndarray:
        """Step-I vectors onto the divergence elements (k, d), not normalized."""

    @abstractmethod
    def divergence(self, Y) -> np.ndarray:
        """Unit vectors (k, d) -> b (n,), with L φ = b ⇔ ∇φ ≈ Y."""

    @abstractmethod
    def laplacian(self) -> sp.csr_matrix:
        """(n, n) real PSD Laplacian of step III."""

    @abstractmethod
    def mass(self) -> np.ndarray:
        """(n,) positive lumped masses."""

    def poisson_solver(self):
        """A :class:`PoissonSolver` specific to the domain, or None (the core factorizes ``laplacian()``)."""
        return None

    # ---- constraint rows (defaults)
    def zero_rows(self, S: Sources):
        """Rows of the hard "zero" constraint and, for one-hot rows, their vertices (-1 otherwise); a domain may
        return a third entry, per-row weights, to have its rows used as they are (the grid's cell rows)."""
        return S.all_rows()

    def soft_rows(self, S: Sources, mode: str, lam: float):
        """Rows A and weights w (λ included) of the soft penalty Σ w (A φ)²; None: the core's difference rows
        with weight λ."""
        return None


def _one_hot_rows(v, n: int) -> sp.csr_matrix:
    """(len(v), n) CSR with a one in column v[i] of row i (canonical, built directly)."""
    return sp.csr_matrix((np.ones(len(v)), np.asarray(v), np.arange(len(v) + 1)), shape=(len(v), n))


def tangent_frames(N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """An arbitrary orthonormal tangent basis (e1, e2) per unit normal N (n, 3), e1 × e2 = N.

    Example
    -------
    >>> e1, e2 = tangent_frames(np.array([[0.0, 0, 1]]))
    >>> np.cross(e1, e2).round(12).tolist()
    [[0.0, 0.0, 1.0]]
    """
    a = np.where(np.abs(N[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    e1 = a - N * np.einsum("ij,ij->i", a, N)[:, None]
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(N, e1)


class VertexSurfaceDomain(HeatDomain):
    """A surface domain with unknowns at vertices (polygon meshes §8.3, point clouds §8.4, voxel surfaces §8.5).

    Parameters
    ----------
    X : (n, 3) vertex positions
    L : (n, n) real PSD Laplacian (Step III and the sources' Laplacian weights)
    M : (n,) lumped masses (non-positive entries are replaced by the mean of the positive ones)
    Lconn : (n, n) complex Hermitian connection Laplacian in the frames (e1, e2)
    N, e1, e2 : (n, 3) unit normals and tangent frames (e1 × e2 = N)
    t : diffusion time

    Subclasses implement ``gather(X)`` (complex vertex vectors (n,) → vectors on the divergence elements,
    projected into them, *not* normalized) and ``divergence(Y)`` (unit vectors → b (n,)); ``to_3d`` maps the
    complex vertex vectors to 3D. ``check_curve_edges(a, k)`` may reject polylines that do not run along edges.

    Sources: curves are vertex polylines (or edge sets, chained); X⁰ at a curve vertex accumulates the in-plane
    normals of its incident segments times half their lengths (§8.3); unsigned curves act as point sources at
    their vertices; point sources are vertex indices (App. A.1 on vertices: ``-L_vj (x_j − x_v)`` at the
    neighbours j of a source v).
    """

    heat_form = "complex"
    difference_order = "sorted"
    cache_sources = True

    def __init__(self, X, L, M, Lconn, N, e1, e2, t):
        self.X = np.asarray(X, np.float64)
        self.n_nodes = self.n = len(self.X)
        self.L = sp.csr_matrix(L)
        M = np.asarray(M, dtype=np.float64)
        self.Mv = np.where(M > 0, M, M[M > 0].mean() if (M > 0).any() else 1.0)
        self.Lconn, self.t = Lconn, float(t)
        self.N, self.e1, self.e2 = N, e1, e2

    # ---- operators
    def vector_heat_matrix(self):
        """M + t L∇ (Eq. 12) in one pass over L∇ (:func:`~gsdf.linalg._assembly.principal_submatrix`; the same
        matrix as ``diags(M) + t * Lconn``)."""
        Lc = self.Lconn
        if Lc.format != "csr" or Lc.dtype != np.complex128 or not Lc.has_canonical_format:
            Lc = sp.csr_matrix(Lc, dtype=np.complex128, copy=True)
            Lc.sum_duplicates()
        return principal_submatrix(Lc, None, self.t, self.Mv)

    def laplacian(self):
        return self.L

    def mass(self):
        return self.Mv

    def to_3d(self, X) -> np.ndarray:
        """Complex vertex vectors (n,) as 3D vectors (n, 3) in the tangent frames."""
        return X.real[:, None] * self.e1 + X.imag[:, None] * self.e2

    def check_curve_edges(self, a, k):
        """Raise ValueError when polyline ``a`` (curve number k) does not run along edges (default: any pair)."""

    # ---- sources
    def _polylines(self, curves):
        out, signs = [], []
        for k, c in enumerate(curves):
            if c.kind == "points":
                raise ValueError(f"curves[{k}]: surface points (face, barycentric) are not available on this domain; "
                                 "give vertex indices")
            for a in c.polylines():
                if a.min() < 0 or a.max() >= self.n:
                    raise ValueError(f"curves[{k}]: vertex index {int(a[(a < 0) | (a >= self.n)][0])} out of range "
                                     f"for {self.n} vertices")
                a = a[np.concatenate([[True], a[1:] != a[:-1]])]
                if len(a) < 2:
                    raise ValueError(f"curves[{k}]: a curve needs at least 2 distinct points")
                self.check_curve_edges(a, k)
                out.append(a)
                signs.append(c.signed)
        return out, signs

    def _points(self, points):
        for q, p in enumerate(points):
            if not isinstance(p, int):
                raise ValueError(f"points[{q}]: expected a vertex index on this domain, got {p!r}")
            if not 0 <= p < self.n:
                raise ValueError(f"points[{q}]: vertex index {p} out of range for {self.n} vertices")
        return np.unique(np.array(points, np.int64))

    def assemble_sources(self, curves, points, normals=None) -> Sources:
        curves, signs = self._polylines(curves)
        pts = self._points(points)
        if not curves and len(pts) == 0:
            raise ValueError("curves: no sources given (empty curve list and no points)")
        X0 = np.zeros(self.n, np.complex128)
        self.curve_source([c for c, s in zip(curves, signs) if s], X0, normals)
        unsigned = [c for c, s in zip(curves, signs) if not s]
        self.point_source(np.unique(np.concatenate(unsigned + [pts])), X0)
        n = self.n
        S = Sources(X0=X0)
        if curves:
            v = np.concatenate(curves)
            S.node_rows = _one_hot_rows(v, n)
            S.node_vertex = v
            S.node_curve = np.repeat(np.arange(len(curves)), [len(c) for c in curves])
            a = np.concatenate([c[:-1] for c in curves])
            b = np.concatenate([c[1:] for c in curves])
            s = len(a)
            # ½ (φ_a + φ_b) per segment, in canonical CSR directly (a ≠ b: repeated points were dropped)
            cols = np.stack([np.minimum(a, b), np.maximum(a, b)], 1).ravel()
            S.shift_rows = sp.csr_matrix((np.full(2 * s, 0.5), cols, np.arange(0, 2 * s + 1, 2)), shape=(s, n))
            S.shift_weights = np.linalg.norm(self.X[b] - self.X[a], axis=1)
        else:
            S.node_rows = sp.csr_matrix((0, n))
            S.node_vertex = S.node_curve = np.zeros(0, np.int64)
        if len(pts):
            S.point_rows = _one_hot_rows(pts, n)
            S.point_vertex = pts
        return S

    def curve_source(self, curves, X0, normals=None):
        """Accumulate ½ ℓ · (in-plane curve normal) of every segment at both its end points (§8.3, §8.4);
        the normal is the segment projected into the end point's tangent plane, turned clockwise (T × n, left
        negative). ``normals`` (n, 3): the normals n to use (default: the frame normals)."""
        Nn = self.N if normals is None else normals
        for g in curves:
            a, b = g[:-1], g[1:]
            T = self.X[b] - self.X[a]
            ell = np.linalg.norm(T, axis=1)
            for v in (a, b):
                Tv = T - self.N[v] * np.einsum("kj,kj->k", T, self.N[v])[:, None]
                nrm = np.linalg.norm(Tv, axis=1)
                nv = np.cross(Tv / np.maximum(nrm, 1e-300)[:, None], Nn[v]) * (0.5 * ell)[:, None]
                z = np.einsum("kj,kj->k", nv, self.e1[v]) + 1j * np.einsum("kj,kj->k", nv, self.e2[v])
                np.add.at(X0, v, z)

    def point_source(self, ids, X0):
        """Isolated vertex sources (App. A.1 on a vertex discretization): at every Laplacian neighbour j of a
        source v the vector -L_vj (x_j - x_v), in j's tangent plane — radially outward, and balanced (Σ = 0 on
        flat regions by the linear precision of L), so no net vector dominates the far field after diffusion."""
        if len(ids) == 0:
            return
        Lr = self.L[ids].tocoo()
        v, j, w = ids[Lr.row], Lr.col, -Lr.data
        keep = (j != v) & (w > 0)
        v, j, w = v[keep], j[keep], w[keep]
        d = self.X[j] - self.X[v]
        d -= self.N[j] * np.einsum("kj,kj->k", d, self.N[j])[:, None]
        d *= w[:, None]
        z = np.einsum("kj,kj->k", d, self.e1[j]) + 1j * np.einsum("kj,kj->k", d, self.e2[j])
        np.add.at(X0, j, z)


Curve  # re-exported for domain authors: ``from gsdf.heat._domain import Curve``
