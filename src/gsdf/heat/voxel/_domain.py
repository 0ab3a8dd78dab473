"""The signed heat method on digital surfaces — boundaries of binary volumes (Feng & Crane 2024, §8.5).

:class:`VoxelSurfaceDomain` owns the operators and the sources (a
:class:`~gsdf.heat._domain.VertexSurfaceDomain`); steps I–III, the constraints and the shift are
:class:`gsdf.heat._core.SignedHeatCore`'s. :class:`VoxelSurfaceSignedHeatSolver` is the front-end.

Pipeline:

1. **Surface** (:mod:`._digital`): the quads between occupied and empty 6-neighbours, outward, split into a
   closed 2-manifold by a fixed gluing rule at edges shared by four quads (occupied voxels 6-connected);
   vertices are the pointels, split where the surface is pinched.
2. **Corrected normals** u_f per quad: integral invariants (covariance of the occupied voxel centres in a ball
   of radius ``normal_radius`` voxels around the quad centre, Coeurjolly et al. 2014); or trivial (the axis
   normals), or given.
3. **Corrected embedding** (Coeurjolly & Lachaud 2022): every quad is projected, on its own, onto the plane
   through the origin orthogonal to its u_f, ``x̃ = x − (u_f · x) u_f``; a quad's area is scaled by |u_f · n_f| (to
   the area of the smooth surface it stands for) and lengths shrink accordingly.
4. **Operators** (:mod:`._degoes`): de Goes et al. 2020 per-face gradient, flat, sharp, projection and inner
   product (λ = 1) on the corrected quads; Laplacian ``L = Σ_f Dᵀ M_f D`` (PSD), 1-form divergence, lumped
   mass ``m_v = Σ_f |a_f| / 4``.
5. **Frames and transport**: vertex normals n_v = normalized mean of the incident u_f (§8.5), an arbitrary
   tangent basis per vertex and per face; r_vf the unit complex number of the smallest rotation n_v → n_f
   expressed in the two bases.
6. **Connection Laplacian**, Option A (DGtal's, after de Goes et al. 2020): per face, the covariant gradient of the
   transported vertex vectors plus the λ-weighted projection term. Because ``U_f D = G_f`` it reduces to the
   scalar face Laplacian conjugated by the transports, ``L∇_ij = Σ_f conj(r_if) (Dᵀ M_f D)_ij r_jf``: a complex
   Hermitian PSD matrix, equal to L on a flat plane with aligned frames. Option B (§8.3/§8.4 style, for
   cross-checking): the off-diagonal entries of L (quad diagonals included) times the vertex-to-vertex
   transport.
7. **Sources**: a segment s of a curve (an edge or a quad diagonal) with length ℓ_s, unit tangent t̂_s and
   n_s the mean corrected normal of the quads containing it contributes ``(ℓ_s / 2) t̂_s × n_s`` (the tangent
   turned clockwise: left of the curve negative, gsdf's convention) to X⁰ at both its end vertices, projected
   onto their tangent bases (§8.5). Points and unsigned curves (their vertices): per quad around the source
   vertex the outward flux −|a_f|∇ψ_v of its hat function, shared by the other corners (App. A.1).
8. **Steps**: (m + t L∇) X = X⁰ with ``t = t_coef · h²``, h the mean edge length; per quad
   ``Y_f = normalize((I − n_f n_fᵀ) Σ_{v∈f} X_v)``; ``b = Σ_f Dᵀ M_f V_f Y_f``; ``L φ = b`` with the level-set
   constraints of §7.1 (if Y = ∇φ then b = L φ exactly on planar faces).

Example
-------
>>> import numpy as np
>>> from gsdf.heat.voxel._domain import VoxelSurfaceSignedHeatSolver
>>> x = np.indices((24, 24, 24)) - 11.5
>>> solver = VoxelSurfaceSignedHeatSolver((x ** 2).sum(0) < 10 ** 2)          # a digital ball
>>> from gsdf.contour import region_boundary_curves
>>> cap = solver.face_centres[:, 2] < 12.0                                    # the lower half
>>> phi = solver.compute_distance(region_boundary_curves(solver.faces, cap))
>>> bool(phi[np.argmin(solver.vertices[:, 2])] < -10)                        # the south pole: −πR/2
True
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf import _checks
from gsdf.heat._core import SignedHeatCore
from gsdf.heat.voxel._degoes import face_operators
from gsdf.heat.voxel._digital import digital_surface, integral_invariant_normals
from gsdf.heat._domain import VertexSurfaceDomain, tangent_frames
from gsdf.heat.polygon._domain import connection_laplacian, frame_transport

CONNECTIONS = ("A", "B")


# --------------------------------------------------------------------------------------------- validation
def as_occupancy(occupancy) -> np.ndarray:
    """Validate a binary volume: a 3-D bool array (0/1 integers accepted) with both occupied and empty voxels
    (:func:`gsdf._checks.as_occupancy`, which checks its size first)."""
    A = _checks.as_occupancy(occupancy, "occupancy")
    if not A.any():
        raise ValueError(f"occupancy: the volume is empty (no occupied voxel, shape {A.shape}): no surface")
    if A.all():
        raise ValueError(f"occupancy: the volume is full (every voxel of shape {A.shape} occupied); pad it with "
                         "empty voxels (np.pad(occupancy, 1)) to use the box as the surface")
    return A


def as_spacing(spacing) -> np.ndarray:
    """Validate a voxel size: a positive finite scalar or 3-vector; returns (3,) float64."""
    s = _checks.as_values(spacing, "spacing", finite=False)
    if s.ndim == 0:
        s = np.full(3, float(s))
    if s.shape != (3,):
        raise ValueError(f"spacing: expected a scalar or 3 values, got shape {s.shape}")
    if not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise ValueError(f"spacing: must be finite and positive, got {s.tolist()}")
    return s


# --------------------------------------------------------------------------------------------- the domain
class VoxelSurfaceDomain(VertexSurfaceDomain):
    """Operators and sources of the signed heat method on the digital surface of a binary volume (module docs).

    Parameters
    ----------
    occupancy : (nx, ny, nz) bool
        Occupied voxels; voxel (i, j, k) is the box ``[i, i+1]·s_x × [j, j+1]·s_y × [k, k+1]·s_z``.
    spacing : float or (3,) float
        Voxel size.
    normal_radius : float >= 0
        Radius of the integral-invariant ball in voxels (times the smallest spacing); 0 gives the trivial
        normals.
    normals : None, "trivial", or (m, 3) float
        Override the corrected normals (e.g. analytic ones in tests); rows are normalized and must point out
        (positive dot product with the quad's axis normal).
    connection : {"A", "B"}
        Connection Laplacian: "A" the de Goes/DGtal operator (default), "B" the scalar Laplacian with rotated
        off-diagonals (cross-check).
    t_coef : float
        Diffusion time ``t = t_coef · h²``, h the mean edge length.

    Attributes
    ----------
    vertices : (n, 3); faces : (m, 4) outward quads; face_centres : (m, 3); normals : (m, 3) corrected u_f;
    L : (n, n) PSD Laplacian; Mv : (n,) lumped mass (``mass()``); Lconn : (n, n) complex connection Laplacian;
    vertex_normals (= N), e1, e2 : (n, 3) vertex frames; h : mean edge length; t : diffusion time;
    face_ops : the per-face operators (:class:`~gsdf.heat.voxel._degoes.FaceOperators`).

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.heat._core import SignedHeatCore
    >>> x = np.indices((16, 16, 16)) - 7.5
    >>> d = VoxelSurfaceDomain((x ** 2).sum(0) < 6 ** 2)
    >>> phi = SignedHeatCore(d).compute_distance([], points=[0])
    >>> phi.shape == (d.n,) and bool(phi.min() == 0)
    True
    """

    def __init__(self, occupancy, spacing=1.0, normal_radius: float = 3.0, normals=None, connection: str = "A",
                 t_coef: float = 1.0):
        t_coef = _checks.positive(t_coef, "t_coef", most=_checks.T_COEF_MAX)
        occ = as_occupancy(occupancy)
        s = as_spacing(spacing)
        self.connection = _checks.choice(connection, "connection", CONNECTIONS)
        r = _checks.nonnegative(normal_radius, "normal_radius")
        self.occupancy, self.spacing, self.normal_radius = occ, s, r
        S = digital_surface(occ, s)
        self.surface = S
        self.vertices, self.faces, self.face_centres = S.vertices, S.faces, S.centres
        self.n, self.m = len(S.vertices), len(S.faces)
        self.normals = self._normals(normals, occ, s, r)
        L, M, Lconn = self._assemble()
        super().__init__(self.vertices, L, M, Lconn, self.vertex_normals, self.e1, self.e2, t_coef * self.h ** 2)

    # ---------------------------------------------------------------- normals and operators
    def _normals(self, normals, occ, s, r) -> np.ndarray:
        S = self.surface
        if normals is None:
            if r == 0:
                return S.trivial_normals.copy()
            return integral_invariant_normals(occ, s, S, r * float(s.min()))
        if isinstance(normals, str):
            if normals != "trivial":
                raise ValueError(f"normals: expected None, 'trivial' or an (m, 3) array, got {normals!r}")
            return S.trivial_normals.copy()
        u = _checks.as_normals(normals, self.m, "normals")
        nrm = np.linalg.norm(u, axis=1)
        if np.any(nrm == 0):
            raise ValueError(f"normals: row {int(np.flatnonzero(nrm == 0)[0])} is zero")
        u = u / nrm[:, None]
        dots = np.einsum("ij,ij->i", u, S.trivial_normals)
        if np.any(dots <= 0):
            raise ValueError(f"normals: row {int(np.flatnonzero(dots <= 0)[0])} does not point out of the volume "
                             "(non-positive dot product with the quad's axis normal)")
        return u

    def _assemble(self):
        V, F, u = self.vertices, self.faces, self.normals
        n, m = self.n, self.m
        X = V[F]                                                   # (m, 4, 3)
        Xt = X - np.einsum("mkj,mj->mk", X, u)[:, :, None] * u[:, None, :]   # corrected embedding (§3(b))
        ops = face_operators(Xt)
        self.face_ops = ops
        rows = np.broadcast_to(F[:, :, None], (m, 4, 4)).ravel()
        cols = np.broadcast_to(F[:, None, :], (m, 4, 4)).ravel()
        L = sp.csr_matrix((ops.laplacian.ravel(), (rows, cols)), shape=(n, n))
        L = (0.5 * (L + L.T)).tocsr()
        M = np.bincount(F.ravel(), weights=np.repeat(ops.area / 4.0, 4), minlength=n)
        # vertex normals: normalized mean of the incident corrected normals (§8.5)
        Nv = np.zeros((n, 3))
        for a in range(3):
            Nv[:, a] = np.bincount(F.ravel(), weights=np.repeat(u[:, a], 4), minlength=n)
        nrm = np.linalg.norm(Nv, axis=1)
        Nv = np.where(nrm[:, None] > 0, Nv / np.where(nrm > 0, nrm, 1.0)[:, None], [0.0, 0.0, 1.0])
        self.vertex_normals = Nv
        self.e1, self.e2 = tangent_frames(Nv)
        # face frames: the corrected quad's normal and its first (projected) edge
        nf = ops.normal
        f1 = Xt[:, 1] - Xt[:, 0]
        f1 -= nf * np.einsum("ij,ij->i", f1, nf)[:, None]
        f1 /= np.linalg.norm(f1, axis=1, keepdims=True)
        self.face_e1, self.face_e2 = f1, np.cross(nf, f1)
        E = np.stack([F.ravel(), np.roll(F, -1, axis=1).ravel()], 1)
        self.h = float(np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1).mean())
        Lconn = self.connection_laplacian_a() if self.connection == "A" else connection_laplacian(L, Nv, self.e1,
                                                                                                  self.e2)
        return L, M, Lconn

    def vertex_face_transport(self) -> np.ndarray:
        """r_vf (m, 4) complex: a tangent vector z in the frame of corner vertex v of face f is ``r_vf z`` in the
        face frame after the smallest rotation n_v → n_f."""
        F = self.faces
        n = self.n
        N = np.concatenate([self.vertex_normals, self.face_ops.normal])
        e1 = np.concatenate([self.e1, self.face_e1])
        e2 = np.concatenate([self.e2, self.face_e2])
        fi = np.repeat(n + np.arange(self.m), 4)
        return frame_transport(N, e1, e2, fi, F.ravel()).reshape(self.m, 4)

    def connection_laplacian_a(self) -> sp.csr_matrix:
        """Option A: ``L∇_ij = Σ_f conj(r_if) (Dᵀ M_f D)_ij r_jf`` (module docs, item 6), complex Hermitian PSD."""
        F, m, n = self.faces, self.m, self.n
        r = self.vertex_face_transport()
        vals = np.conj(r)[:, :, None] * self.face_ops.laplacian * r[:, None, :]
        rows = np.broadcast_to(F[:, :, None], (m, 4, 4)).ravel()
        cols = np.broadcast_to(F[:, None, :], (m, 4, 4)).ravel()
        A = sp.csr_matrix((vals.ravel(), (rows, cols)), shape=(n, n))
        return (0.5 * (A + A.conj().T)).tocsr()

    # ---------------------------------------------------------------- steps II and III (protocol)
    def gather(self, X) -> np.ndarray:
        """Step II before normalization: per quad ``(I − n_f n_fᵀ) Σ_{v∈f} X_v`` (m, 3) from the complex vertex
        vectors X (n,) (§8.5; the core normalizes)."""
        nf = self.face_ops.normal
        Y = self.to_3d(X)[self.faces].sum(axis=1)
        return Y - nf * np.einsum("ij,ij->i", Y, nf)[:, None]

    def divergence(self, Y: np.ndarray) -> np.ndarray:
        """``Σ_f Dᵀ M_f V_f Y_f`` (n,) for face vectors Y (m, 3) (the integrated divergence, gsdf's sign: it equals
        L φ for Y = ∇φ of a linear φ)."""
        ops = self.face_ops
        w = np.einsum("mkj,mj->mk", ops.flat, Y)                   # the 1-form V_f Y_f on the quad's edges
        bf = np.einsum("mkl,ml->mk", ops.divergence, w)
        return np.bincount(self.faces.ravel(), weights=bf.ravel(), minlength=self.n)

    def gradient(self, phi: np.ndarray) -> np.ndarray:
        """Per-quad gradient (m, 3) of vertex values φ (n,) on the corrected quads."""
        return np.einsum("mik,mk->mi", self.face_ops.gradient, np.asarray(phi, np.float64)[self.faces])

    # ---------------------------------------------------------------- sources
    def _segment_keys(self):
        """Sorted keys of every quad's edges and diagonals (min·n + max) with their quads."""
        if getattr(self, "_seg", None) is None:
            F, n = self.faces, self.n
            pairs = np.concatenate([np.stack([F[:, k], F[:, (k + 1) % 4]], 1) for k in range(4)]
                                   + [F[:, [0, 2]], F[:, [1, 3]]])
            face = np.tile(np.arange(self.m), 6)
            key = pairs.min(1) * n + pairs.max(1)
            o = np.argsort(key, kind="stable")
            cum = np.concatenate([np.zeros((1, 3)), np.cumsum(self.normals[face[o]], axis=0)])
            self._seg = key[o], face[o], cum
        return self._seg

    def segment_normals(self, a: np.ndarray, b: np.ndarray, name: str = "curves") -> np.ndarray:
        """Mean corrected normal (s, 3) of the quads containing each segment a→b (an edge or a diagonal);
        ValueError naming ``name`` when a segment lies on no quad."""
        keys, _, cum = self._segment_keys()
        k = np.minimum(a, b) * self.n + np.maximum(a, b)
        lo = np.searchsorted(keys, k, side="left")
        hi = np.searchsorted(keys, k, side="right")
        bad = hi == lo
        if bad.any():
            q = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{name}: vertices {int(a[q])} and {int(b[q])} (points {q}, {q + 1}) are not on a common "
                             "quad (curves run along quad edges or across quad diagonals)")
        s = cum[hi] - cum[lo]
        return s / np.linalg.norm(s, axis=1, keepdims=True)

    def check_curve_edges(self, a: np.ndarray, k: int) -> None:
        """Validate that consecutive vertices of curve k share a quad."""
        self.segment_normals(a[:-1], a[1:], f"curves[{k}]")

    def curve_source(self, curves, X0: np.ndarray, normals=None) -> None:
        """Add ``(ℓ_s / 2) t̂_s × n_s`` of every segment to X⁰ at both end vertices, projected onto their tangent
        bases (§8.5; module docs item 7). ``normals`` is not used (the segment normals are the quads')."""
        for g in curves:
            a, b = g[:-1], g[1:]
            T = self.vertices[b] - self.vertices[a]                # = ℓ_s t̂_s
            Ns = 0.5 * np.cross(T, self.segment_normals(a, b))     # (ℓ_s/2) t̂_s × n_s (clockwise: left negative)
            for v in (a, b):
                z = np.einsum("kj,kj->k", Ns, self.e1[v]) + 1j * np.einsum("kj,kj->k", Ns, self.e2[v])
                np.add.at(X0, v, z)


    def point_source(self, ids: np.ndarray, X0: np.ndarray) -> None:
        """Isolated vertex sources (App. A.1 on a vertex discretization): on every quad f around a source v the
        outward flux vector ``−|a_f| ∇_f ψ_v`` of v's hat function ψ_v, shared by the quad's other three corners
        (projected onto their tangent bases). It points away from v on each quad and sums to zero around v on a
        flat umbrella (∮ ψ_v n ds = 0), so no net vector survives in the far field. (The Laplacian-row weights of
        the polygon solver are unbalanced here: corrected quads at digital corners have positive off-diagonal
        entries.)"""
        if len(ids) == 0:
            return
        F, ops = self.faces, self.face_ops
        f, k = np.nonzero(np.isin(F, ids))
        vec = -ops.area[f, None] * ops.gradient[f, :, k] / 3.0
        for o in (1, 2, 3):
            j = F[f, (k + o) % 4]
            z = np.einsum("kj,kj->k", vec, self.e1[j]) + 1j * np.einsum("kj,kj->k", vec, self.e2[j])
            np.add.at(X0, j, z)


# --------------------------------------------------------------------------------------------- the solver
class VoxelSurfaceSignedHeatSolver:
    """Generalized signed geodesic distance on the digital surface of a binary volume (Feng & Crane 2024 §8.5).

    Parameters
    ----------
    occupancy : (nx, ny, nz) bool array
        The voxels inside; the surface is the boundary of their union (quads between occupied and empty
        6-neighbours; the outside of the array counts as empty).
    spacing : float or (3,) float
        Voxel size (world units per voxel along x, y, z). Any scale: the solve runs with the spacing divided by
        a power of two (exact), so φ scales with it from 1e-150 to 1e150; ``vertices``, ``face_centres``, ``t``
        and φ are in world units.
    normal_radius : float >= 0
        Integral-invariant radius of the corrected normals, in voxels (of the smallest spacing); 0 = trivial
        normals. Default 3 (DGtal's). A fixed radius in voxels leaves a normal bias that stops the convergence
        under refinement; for convergence let it grow like ``0.5 · N^(2/3)`` voxels for an object N voxels
        across (r ∝ h^(1/3) in world units, Coeurjolly et al. 2014).
    t_coef : float
        Diffusion time ``t = t_coef · h²``, h the mean edge length (≈ the voxel size).

    Attributes
    ----------
    vertices : (n, 3) float64 surface vertices (pointels; split where the surface is pinched)
    faces : (m, 4) int64 outward quads
    face_centres : (m, 3); normals : (m, 3) corrected normals; domain : the :class:`VoxelSurfaceDomain`

    Examples
    --------
    >>> import numpy as np
    >>> import gsdf
    >>> x = np.indices((20, 20, 20)) - 9.5
    >>> solver = gsdf.VoxelSurfaceSignedHeatSolver((x ** 2).sum(0) < 8 ** 2)
    >>> ring = gsdf.region_boundary_curves(solver.faces, solver.face_centres[:, 2] < 10)
    >>> phi = solver.compute_distance(ring)
    >>> phi.shape == (len(solver.vertices),)
    True
    """

    def __init__(self, occupancy, spacing=1.0, normal_radius: float = 3.0, *, t_coef: float = 1.0):
        # scale invariance: solve with the spacing divided by the power of two 2^e that brings its largest
        # entry into [1, 2) (exact; e = 0 for unit voxels), and scale lengths back by 2^e on output
        sp = as_spacing(spacing)
        self.exponent = e = int(np.frexp(float(sp.max()))[1]) - 1
        # the grid's extent (spacing × voxels) and the diffusion time (∝ spacing²) must be representable
        n_max = max((int(x) for x in np.shape(occupancy)), default=1) + 1
        with np.errstate(over="ignore"):  # the overflow is the answer looked for
            representable = np.isfinite(float(sp.max()) * n_max) and np.isfinite(np.ldexp(4.0 * _checks.T_COEF_MAX,
                                                                                         2 * e))
        if not representable:
            raise ValueError(f"spacing: {float(sp.max()):g} is too large: the grid's extent or the diffusion time "
                             "(proportional to spacing²) overflows; use smaller units")
        self.domain = d = VoxelSurfaceDomain(occupancy, np.ldexp(sp, -e), normal_radius, t_coef=t_coef)
        self.vertices, self.face_centres = np.ldexp(d.vertices, e), np.ldexp(d.face_centres, e)
        self.faces, self.normals = d.faces, d.normals
        self.t = float(np.ldexp(d.t, 2 * e))
        self.core = SignedHeatCore(d)

    def compute_distance(self, curves, *, points=(), curve_signs=None, level_set_constraint: str = "zero",
                         soft_weight=None, progress=None) -> np.ndarray:
        """Generalized signed geodesic distance (n,) at the vertices, negative inside.

        Parameters
        ----------
        curves : list of 1-D int arrays
            Vertex polylines; consecutive vertices share a quad (an edge or a diagonal); closed curves repeat the
            first vertex. A loop counter-clockwise seen from outside the volume encloses the negative region.
        points : sequence of int, default ()
            Vertex indices of point sources (unsigned distance).
        curve_signs : list of bool, optional
            Per curve: True (signed, default) or False (unsigned: its vertices act as point sources).
        level_set_constraint : {"zero", "multiple", "none"}, default "zero"
            φ = 0 on every source vertex, φ constant per connected curve component, or no constraint; φ is
            finally shifted to mean zero along the curves (Alg. 13).
        soft_weight : float, optional
            Replace the hard constraint by the penalty λ Σ (φ(v) − φ(v₀))² (§7.1).
        progress : callable, optional
            ``progress(stage, fraction)`` (:mod:`gsdf.heat._core`).

        Returns
        -------
        phi : (n,) float64
            Signed distance per vertex of the digital surface, model units (the voxel ``spacing``'s units).

        Raises
        ------
        ValueError
            Consecutive curve vertices that share no quad, indices out of range, bad ``curve_signs``, an unknown
            constraint.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> x = np.indices((20, 20, 20)) - 9.5
        >>> solver = gsdf.VoxelSurfaceSignedHeatSolver((x ** 2).sum(0) < 8 ** 2)      # a voxel ball
        >>> loops = gsdf.region_boundary_curves(solver.faces, solver.face_centres[:, 2] < 10)
        >>> phi = solver.compute_distance(loops)
        >>> bool(phi[np.argmin(solver.vertices[:, 2])] < 0 < phi[np.argmax(solver.vertices[:, 2])])
        True
        """
        phi = self.core.compute_distance(curves, points=points, curve_signs=curve_signs,
                                         level_set_constraint=level_set_constraint, soft_weight=soft_weight,
                                         progress=progress)
        return np.ldexp(phi, self.exponent)


__all__ = ["VoxelSurfaceSignedHeatSolver", "VoxelSurfaceDomain", "as_occupancy", "as_spacing"]
