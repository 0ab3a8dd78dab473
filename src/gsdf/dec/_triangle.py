"""Discrete exterior calculus on a manifold, consistently oriented triangle mesh.

Owns: the coboundaries d0 (edges × vertices) and d1 (faces × edges) for the canonical edge orientation of
:mod:`gsdf.mesh._connectivity`; diagonal Hodge stars ⋆0 (lumped barycentric area), ⋆1 (cotan weights, clamped),
⋆2 (inverse face area); jump ("reduced") coordinates of an edge chain; the jump Laplace solve; the Darboux
derivative. The formulas follow the thesis (seed 000) §2.2–2.3 and §6.1 as worked out in the spec notes
(``wave2-swn-recon-voxel.md`` §1(b), steps ① and ②).

Conventions
-----------
- slot ``k`` of face ``f`` is the halfedge ``F[f,k] -> F[f,k+1]``; its cotan weight is ½ cot of the angle at
  corner ``k+2`` (the angle opposite it);
- a jump chain ``J`` (per edge, along the canonical direction lo -> hi) means: corner values in the left face of
  the edge (the face containing lo -> hi) exceed those in the right face by ``J_e`` ("+1 crossing from the
  right", thesis §2.3.3);
- "Mollify" (spec §1(b), as the authors' demo does): halfedge cotans are clamped to [1e-3, 1e3], NaN or inf
  become 1, so every ⋆1 entry is positive even on needle triangles.

Example
-------
>>> import numpy as np
>>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
>>> dec = TriangleDEC(V, np.array([[0, 1, 3], [0, 3, 2]]))
>>> float(abs(dec.d1 @ dec.d0).max())
0.0
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from gsdf._checks import as_mesh
from gsdf.linalg import Factorization, cached_factorization
from gsdf.mesh._connectivity import MeshTopology
from gsdf.linalg._graph import forest_potentials

__all__ = ["TriangleDEC", "JumpCoordinates", "COT_CLAMP"]

COT_CLAMP = (1e-3, 1e3)
REG = 1e-8          # diagonal added to the Laplacians before factorization (spec §1(b) "Mollify")
NEXT = np.array([1, 2, 0])
PREV = np.array([2, 0, 1])


@dataclass
class JumpCoordinates:
    """Per-corner offsets ``c`` (m, 3) realising a jump chain: ``u^f_i = u0_i + c^f_i``.

    Attributes
    ----------
    c : (m, 3) float, 0 at corners of vertices off the chain
    endpoints : (n,) bool, vertices excluded from the solve (no degree of freedom): the interior endpoints of the
        chain for :meth:`TriangleDEC.jump_coordinates`, none for :meth:`TriangleDEC.branch_coordinates`
    walked : (n,) bool, vertices whose corners got offsets
    """

    c: np.ndarray
    endpoints: np.ndarray
    walked: np.ndarray


class TriangleDEC:
    """DEC operators of a manifold, consistently oriented triangle mesh (built once).

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    topology : MeshTopology, optional (built when omitted)

    Attributes
    ----------
    topology : MeshTopology
    edges : (nE, 2); face_edges, face_edge_signs : (m, 3)
    d0 : (nE, n) csr, ``(d0 u)_e = u_hi - u_lo``
    d1 : (m, nE) csr, ``(d1 ω)_f = Σ_k sign_fk ω_{e_fk}``
    cot : (m, 3) clamped cotan of the angle opposite each slot; halfedge weight ``0.5 * cot``
    star0 : (n,) lumped (barycentric) vertex areas; star1 : (nE,) cotan edge weights; star2 : (m,) 1/area
    face_area : (m,) float
    edge_length : (nE,) float

    Example
    -------
    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> dec = TriangleDEC(V, np.array([[0, 1, 2]]))
    >>> dec.star1.round(4).tolist()          # ½ cot 45° twice; the right angle is clamped to cot = 1e-3
    [0.5, 0.5, 0.0005]
    """

    def __init__(self, V, F, topology: MeshTopology | None = None):
        V, F = as_mesh(V, F)
        self.V, self.F = V, F
        topo = topology if topology is not None else MeshTopology(F, len(V))
        topo.require_manifold("F")
        topo.require_oriented("F")
        self.topology = topo
        n, m, nE = len(V), len(F), topo.n_edges
        self.n_vertices, self.n_faces, self.n_edges = n, m, nE
        self.edges, self.face_edges, self.face_edge_signs = topo.edges, topo.face_edges, topo.face_edge_signs
        P = V[F]
        Evec = P[:, NEXT] - P                               # slot vectors v_k -> v_{k+1}
        cr = np.cross(Evec[:, 0], -Evec[:, 2])
        area2 = np.linalg.norm(cr, axis=1)
        self.face_area = 0.5 * area2
        # angle opposite slot k sits at corner k+2, between -E[k+1] and E[k+2]
        u, w = -Evec[:, NEXT], Evec[:, PREV]
        dot = np.einsum("fkj,fkj->fk", u, w)
        with np.errstate(divide="ignore", invalid="ignore"):
            cot = dot / area2[:, None]
        cot = np.where(np.isfinite(cot), cot, 1.0)
        self.cot = np.clip(cot, *COT_CLAMP)
        self.halfedge_weight = 0.5 * self.cot
        fe = self.face_edges.ravel()
        self.star1 = np.bincount(fe, weights=self.halfedge_weight.ravel(), minlength=nE)
        self.star0 = np.bincount(F.ravel(), weights=np.repeat(self.face_area / 3.0, 3), minlength=n)
        with np.errstate(divide="ignore"):
            self.star2 = np.where(self.face_area > 0, 1.0 / np.maximum(self.face_area, 1e-300), 1.0)
        self.edge_length = np.linalg.norm(V[self.edges[:, 1]] - V[self.edges[:, 0]], axis=1)
        r = np.arange(nE)
        self.d0 = sp.csr_matrix((np.concatenate([-np.ones(nE), np.ones(nE)]),
                                 (np.concatenate([r, r]), self.edges.T.ravel())), shape=(nE, n))
        self.d1 = sp.csr_matrix((self.face_edge_signs.ravel().astype(np.float64),
                                 (np.repeat(np.arange(m), 3), fe)), shape=(m, nE))
        self._fact_cache: dict = {}

    # ------------------------------------------------------------------------------------------- operators
    def laplacian(self, exclude: np.ndarray | None = None) -> sp.csr_matrix:
        """Cotan Laplacian L (n × n, positive semidefinite) from the clamped halfedge weights, optionally without
        the halfedges touching the vertices where ``exclude`` (n,) bool is set (their rows are then empty)."""
        F, w = self.F, self.halfedge_weight
        i, j = F.ravel(), F[:, NEXT].ravel()
        w = w.ravel()
        if exclude is not None and exclude.any():
            keep = ~(exclude[i] | exclude[j])
            i, j, w = i[keep], j[keep], w[keep]
        n = self.n_vertices
        L = sp.coo_matrix((np.concatenate([-w, -w, w, w]),
                           (np.concatenate([i, j, i, j]), np.concatenate([j, i, i, j]))), shape=(n, n))
        return L.tocsr()

    def _factor(self, exclude: np.ndarray):
        key = np.flatnonzero(exclude).tobytes()

        def build():
            L = self.laplacian(exclude)
            return Factorization((L + REG * sp.identity(self.n_vertices)).tocsc())

        return cached_factorization(self._fact_cache, key, build)

    # ---------------------------------------------------------------------------------------- jump chains
    def check_chain(self, g, name: str = "g") -> np.ndarray:
        """Validate an edge chain (nE,) of finite reals (bools refused); returns float64."""
        A = np.asarray(g)
        if A.dtype == bool or A.dtype == object or not np.issubdtype(A.dtype, np.number):
            raise ValueError(f"{name}: expected a numeric per-edge chain, got dtype {A.dtype}")
        if A.shape != (self.n_edges,):
            raise ValueError(f"{name}: expected shape ({self.n_edges},) (one value per edge), got {A.shape}")
        A = A.astype(np.float64)
        if not np.isfinite(A).all():
            raise ValueError(f"{name}: contains NaN or infinite values")
        return A

    def chain_endpoints(self, g, tol: float = 1e-9) -> np.ndarray:
        """Interior vertices where the chain ``g`` does not close: ``(d0ᵀ g)_i ≠ 0`` (n,) bool. Curves that end on
        the mesh boundary count as closed (spec §1(b) step 0)."""
        g = self.check_chain(g)
        g = np.where(self.topology.boundary_edges, 0.0, g)
        div = self.d0.T @ g
        return (np.abs(div) > tol) & ~self.topology.boundary_vertices

    def jump_coordinates(self, jump, endpoints: np.ndarray | None = None, tol: float = 1e-9) -> JumpCoordinates:
        """Per-corner offsets realising the jump chain (spec §1(b) step ①), endpoints excluded.

        Around every vertex touched by a nonzero jump (interior endpoints excepted) the corner offsets change by
        the jump when crossing an edge: the left face of an edge exceeds the right face by ``jump_e``. Boundary
        edges carry no jump. Around an interior vertex the offsets close up exactly when ``(d0ᵀ jump)_i = 0``;
        vertices where they do not are endpoints (given, or found from ``jump``); they get no offsets and
        :meth:`solve_jump` drops them (the authors' rule). :meth:`branch_coordinates` keeps them instead.

        Parameters
        ----------
        jump : (nE,) float
        endpoints : (n,) bool, optional
            Vertices to treat as endpoints (default: :meth:`chain_endpoints` of ``jump``).

        Returns
        -------
        JumpCoordinates
        """
        J, ends = self._jump_and_ends(jump, endpoints, tol)
        return self._corner_offsets(J, ends, branch=False)

    def branch_coordinates(self, jump, endpoints: np.ndarray | None = None, tol: float = 1e-9) -> JumpCoordinates:
        """Per-corner offsets of the jump chain with a discrete branch point at every interior endpoint.

        At an endpoint the jumps around the vertex do not sum to zero: the jump harmonic function is angle-valued
        there, ``u ≈ u_i − Σ θ/Θ`` plus the jumps crossed (thesis §2.3.3: "the angle-valued function u only
        fails to be harmonic at curve endpoints, where there is a branch-point singularity"; §6.2: ω "behaves
        locally like dθ around endpoints"). Walking counter-clockwise around endpoint i, the offsets change by
        the jump crossed minus ``Σ_i (θ_f + θ_f') / (2 Θ_i)`` between consecutive faces f, f', where θ are the
        corner angles at i, Θ_i their sum and Σ_i the total jump around i. The ramp closes the walk, so the
        endpoint keeps its degree of freedom and every halfedge stays in the energy; nothing is excluded and
        no projective interpolation is needed (``endpoints`` of the result is all False).

        Excluded endpoints would act as holes (their one-rings out of the solve); the figures are in
        docs/decisions.md, "Surface winding numbers".

        Parameters
        ----------
        jump : (nE,) float
        endpoints : (n,) bool, optional (default: :meth:`chain_endpoints` of ``jump``)

        Returns
        -------
        JumpCoordinates

        Example
        -------
        >>> import numpy as np
        >>> from gsdf.data._shapes import grid_mesh
        >>> V, F = grid_mesh(4)                      # 5 x 5 vertices; one edge from the centre (12) to 13
        >>> dec = TriangleDEC(V, F)
        >>> g = np.zeros(dec.n_edges); g[np.flatnonzero((dec.edges == [12, 13]).all(1))] = 1.0
        >>> jc = dec.branch_coordinates(g)
        >>> bool(jc.endpoints.any()), round(float(np.ptp(jc.c[F == 12])), 3)     # a full ramp around 12
        (False, 0.812)
        """
        J, ends = self._jump_and_ends(jump, endpoints, tol)
        return self._corner_offsets(J, ends, branch=True)

    def _jump_and_ends(self, jump, endpoints, tol):
        J = self.check_chain(jump, "jump")
        J = np.where(self.topology.boundary_edges, 0.0, J)
        if endpoints is None:
            ends = self.chain_endpoints(J, tol)
        else:
            ends = np.asarray(endpoints)
            if ends.shape != (self.n_vertices,):
                raise ValueError(f"endpoints: expected shape ({self.n_vertices},), got {ends.shape}")
            ends = ends.astype(bool)
        return J, ends

    @property
    def corner_angles(self) -> np.ndarray:
        """(m, 3) interior angle of every corner (radians), computed once."""
        if getattr(self, "_corner_angles", None) is None:
            from gsdf.mesh._pseudonormals import corner_angles

            self._corner_angles = corner_angles(self.V, self.F)
        return self._corner_angles

    def _corner_offsets(self, J, ends, branch: bool) -> JumpCoordinates:
        topo = self.topology
        n, m = self.n_vertices, self.n_faces
        on = np.abs(J) > 0
        walked = np.zeros(n, dtype=bool)
        walked[self.edges[on].ravel()] = True
        if not branch:
            walked &= ~ends
        c = np.zeros((m, 3))
        out_ends = ends if not branch else np.zeros(n, dtype=bool)
        if not walked.any():
            return JumpCoordinates(c, out_ends, walked)
        F = self.F
        # links between corners of the same vertex across the two slots of the corner touching it
        fi, ki = np.nonzero(walked[F])
        node_of = np.full(3 * m, -1, dtype=np.int64)
        flat = 3 * fi + ki
        node_of[flat] = np.arange(len(flat))
        a_list, b_list, d_list, ccw_list = [], [], [], []
        for s_off in (0, 2):                                  # slot k (out of i) and slot k+2 (into i)
            s = (ki + s_off) % 3
            e = self.face_edges[fi, s]
            sg = self.face_edge_signs[fi, s]
            other = np.where(sg > 0, topo.edge_faces[e, 1], topo.edge_faces[e, 0])
            ok = other >= 0
            f2 = other[ok]
            v = F[fi[ok], ki[ok]]
            k2 = np.argmax(F[f2] == v[:, None], axis=1)
            a_list.append(np.arange(len(flat))[ok])
            b_list.append(node_of[3 * f2 + k2])
            d_list.append(-sg[ok] * J[e[ok]])                # c^{other} = c^{f} - sign · J
            ccw_list.append(np.full(int(ok.sum()), s_off == 2))  # crossing slot k+2 turns counter-clockwise
        a, b, d = np.concatenate(a_list), np.concatenate(b_list), np.concatenate(d_list)
        if branch and ends.any():
            ccw = np.concatenate(ccw_list)
            vert = F[fi[a], ki[a]]
            sigma = np.bincount(vert[ccw], weights=d[ccw], minlength=n)       # total jump around each vertex
            sigma = np.where(ends, sigma, 0.0)
            ang = self.corner_angles
            big_theta = np.bincount(F.ravel(), weights=ang.ravel(), minlength=n)
            ang = np.where(big_theta[F] > 0, ang, 1.0)           # all-degenerate fan: spread by face count
            big_theta = np.bincount(F.ravel(), weights=ang.ravel(), minlength=n)
            step = 0.5 * (ang[fi[a], ki[a]] + ang[fi[b], ki[b]]) / big_theta[vert]
            d = d - np.where(ccw, 1.0, -1.0) * sigma[vert] * step               # the ramp −Σ θ/Θ
        pot = forest_potentials(len(flat), a, b, d)
        mis = np.abs(pot[b] - pot[a] - d)
        if mis.size and mis.max() > 1e-6 * max(1.0, np.abs(J).max()):
            bad = F[fi[a[np.argmax(mis)]], ki[a[np.argmax(mis)]]]
            raise ValueError(f"jump: the jumps around vertex {int(bad)} do not sum to zero; mark it as an endpoint")
        c[fi, ki] = pot
        return JumpCoordinates(c, out_ends, walked)

    def solve_jump(self, jc: JumpCoordinates) -> tuple[np.ndarray, np.ndarray]:
        """The jump Laplace solve (spec §1(b) step ①): minimise ``½ Σ_f Σ_{ij⊂f} w^f_ij ((u0_i + c^f_i) -
        (u0_j + c^f_j))²`` over u0 with the halfedges touching endpoints dropped.

        Normal equations ``L u0 = b``, ``b = -Σ_halfedges w (c_i - c_j)(e_i - e_j)``; ``L + 1e-8 I`` is
        factorized once per endpoint set (cached).

        Returns
        -------
        u0 : (n,) vertex values (0 at endpoints)
        u : (m, 3) corner values ``u0[F] + c``, with endpoint corners set by projective interpolation (the mean
            of the face's other corners: constant along rays from the endpoint)
        """
        F, W = self.F, self.halfedge_weight
        c, ends = jc.c, jc.endpoints
        i, j = F.ravel(), F[:, NEXT].ravel()
        dc = (c - c[:, NEXT]).ravel()
        w = W.ravel()
        keep = ~(ends[i] | ends[j])
        wd = (w * dc)[keep]
        n = self.n_vertices
        b = -np.bincount(i[keep], weights=wd, minlength=n) + np.bincount(j[keep], weights=wd, minlength=n)
        u0 = self._factor(ends).solve(b)
        u0[ends] = 0.0
        u = u0[F] + c
        return u0, self.projective_fill(u, ends)

    def projective_fill(self, u: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """Replace corner values at endpoint vertices by the mean of the face's other corners (0 if none)."""
        E = ends[self.F]
        if not E.any():
            return u
        u = u.copy()
        good = ~E
        cnt = good.sum(axis=1)
        mean = np.where(cnt > 0, (u * good).sum(axis=1) / np.maximum(cnt, 1), 0.0)
        u[E] = np.broadcast_to(mean[:, None], u.shape)[E]
        return u

    def darboux(self, u: np.ndarray, endpoints: np.ndarray | None = None) -> np.ndarray:
        """Darboux derivative ω (nE,) of per-corner values (spec §1(b) step ②): the corner difference along the
        canonical edge direction, averaged over the edge's faces; 0 on edges touching ``endpoints``."""
        u = np.asarray(u, dtype=np.float64)
        if u.shape != (self.n_faces, 3):
            raise ValueError(f"u: expected shape ({self.n_faces}, 3), got {u.shape}")
        diff = self.face_edge_signs * (u[:, NEXT] - u)
        fe = self.face_edges.ravel()
        om = np.bincount(fe, weights=diff.ravel(), minlength=self.n_edges) / self.topology.edge_face_count
        if endpoints is not None and np.any(endpoints):
            om[endpoints[self.edges].any(axis=1)] = 0.0
        return om

    def corner_jumps(self, u: np.ndarray) -> np.ndarray:
        """Jump of per-corner values across every edge, left face minus right face, averaged over the edge's two
        endpoints (nE,); 0 on boundary edges."""
        topo = self.topology
        L, R = topo.edge_faces[:, 0], topo.edge_faces[:, 1]
        sl, sr = topo.edge_slots[:, 0], topo.edge_slots[:, 1]
        ok = (L >= 0) & (R >= 0)
        out = np.zeros(self.n_edges)
        Lk, Rk, a, b = L[ok], R[ok], sl[ok], sr[ok]
        # in L the edge runs lo -> hi at slots (a, a+1); in R it runs hi -> lo at slots (b, b+1)
        lo_l, hi_l = u[Lk, a], u[Lk, (a + 1) % 3]
        hi_r, lo_r = u[Rk, b], u[Rk, (b + 1) % 3]
        out[ok] = 0.5 * ((lo_l - lo_r) + (hi_l - hi_r))
        return out
