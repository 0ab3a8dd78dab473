"""The signed heat method on polygon meshes (Feng & Crane 2024, §8.3) with the polygon Laplacian of Bunge,
Herholz, Kazhdan & Botsch 2020 ("Polygon Laplacian made simple").

Operators (Bunge et al. §3–4):

* every polygon f with more than three corners gets a virtual vertex ``x_f = Σ_i w_i x_i`` whose affine weights
  w minimize the sum of squared areas of the fan triangles (x_f, x_i, x_{i+1}) (the minimizer x_f is unique; of
  the weights reproducing it the minimum-norm ones are taken, as geometry-central does);
* the polygon is split into that fan; on the refined triangle mesh the cotan stiffness C_fan, the lumped mass and
  the gradient/divergence of piecewise-linear functions are the usual ones (:mod:`.operators`);
* the prolongation P ((n + #virtual) × n) is the identity on original vertices and the weights w on virtual ones;
  ``L = Pᵀ C_fan P`` and ``M = lump(Pᵀ M_fan P)`` (row sums; Bunge et al. §4.2 use the lumped mass), i.e.
  ``M = Pᵀ A_fan`` with A_fan the barycentric areas of the refined mesh, since the rows of P sum to one.

  Triangles are left unrefined: for a triangle the optimal virtual vertex is the centroid, and the prolonged fan
  operators equal the triangle's cotan stiffness and barycentric mass exactly (linear precision), so on a
  triangle mesh L is the cotan Laplacian.

Signed heat method on top (§8.3): tangent planes at the vertices from the area-weighted sum of the fine triangle
normals (an arbitrary basis in each plane); the vertex connection Laplacian multiplies the off-diagonal entries of
L by the rotation between the tangent bases of the two vertices (the smallest rotation aligning their normals,
as in Eq. 9 and Sharp et al. 2019 §6.2.2); X⁰ at a curve vertex accumulates the in-plane curve normals of its
incident edges times half their lengths (the "average edge normal times half the sum of incident edge lengths"
of §8.3, averaged by length); step I solves ``(M + t L∇) X = X⁰``; for step II X is prolonged to the fine
vertices (virtual vertex = Σ w_i X_i as 3D vectors), averaged onto the fine triangles, projected into them and
normalized; step III applies the fine divergence and restricts by Pᵀ (Bunge et al. §4.5, D = -Pᵀ Gᵀ M_T), then
solves ``L φ = b`` with the level-set constraints of §7.1. The diffusion time is ``t = t_coef · ℓ̄²`` with ℓ̄
the mean polygon edge length (geometry-central's choice for polygon meshes).

Curves run along polygon edges (vertex-index polylines). Sign convention as everywhere in gsdf: the left of a
curve (the inside of a counter-clockwise loop seen from the normal side) is negative. potpourri3d's
``PolygonMeshHeatSolver.compute_signed_distance`` has the same sign (unlike its triangle-mesh solver): on a UV
sphere of quads both are within 0.12 % of the exact signed distance to a ring (tests/conformance).

:class:`PolygonDomain` supplies these operators to :class:`gsdf.heat._core.SignedHeatCore` (sources: the
vertex-based ones of :class:`~gsdf.heat._domain.VertexSurfaceDomain`);
:class:`gsdf.PolygonMeshSignedHeatSolver` (:mod:`gsdf.heat.polygon._solver`) is the front-end.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gsdf import _checks
from gsdf.mesh._triangle_ops import TriangleOperators
from gsdf.heat.polygon._kernels import (
    connection_values,
    fine_divergence,
    fine_vectors,
    first_repeat,
    polygon_assembly,
    polygon_csr_pattern,
    polygon_weights,
    refine_polygons,
)
from gsdf.heat._domain import VertexSurfaceDomain, tangent_frames


# --------------------------------------------------------------------------------------------- geometry helpers
def integral(q: np.ndarray) -> bool:
    """Whether ``q`` holds integers only (an integer dtype, or finite floats without a fractional part)."""
    if q.dtype.kind in "iu":
        return True
    return q.dtype.kind == "f" and bool(np.isfinite(q).all()) and bool((q == np.round(q)).all())


def _parse_polygons(polygons, n: int):
    """Validate polygons; return their flat layout ``(start, corners)`` in ascending degree (stable):
    ``corners[start[p]:start[p + 1]]`` are the corners of the p-th polygon in that order (int64)."""
    import itertools

    if isinstance(polygons, (list, tuple)) and polygons and isinstance(polygons[0], np.ndarray) \
            and polygons[0].ndim == 1:
        try:                                                  # a list of equal-length index arrays: one array
            stacked = np.array(polygons)
        except ValueError:                                    # ragged
            stacked = None
        if stacked is not None and stacked.ndim == 2 and stacked.dtype != object:
            polygons = stacked
    ragged = None
    if isinstance(polygons, (list, tuple)) and polygons and all(type(p) is np.ndarray for p in polygons):
        try:
            ragged = np.concatenate(polygons)
        except (ValueError, TypeError):                       # mixed dimensions or dtypes: the general path
            ragged = None
        if ragged is not None and (ragged.ndim != 1 or ragged.dtype == object):
            ragged = None
    if isinstance(polygons, np.ndarray) and polygons.ndim == 2 and polygons.dtype != object:
        arr = polygons
        if not integral(arr):
            raise ValueError(f"polygons: vertex indices must be integers, got dtype {arr.dtype}")
        sizes = np.full(len(arr), arr.shape[1], np.int64)
        flat = arr.astype(np.int64).ravel()
    elif ragged is not None:
        # a ragged list of 1-D index arrays (gsdf.read_mesh(triangulate=False)): one concatenation
        sizes = np.fromiter(map(len, polygons), np.int64, count=len(polygons))
        flat = ragged
        if flat.size and not integral(flat):
            raise ValueError(f"polygons: vertex indices must be integers, got dtype {flat.dtype}")
        flat = flat.astype(np.int64)
    else:
        try:
            polygons = [np.asarray(p).ravel() if isinstance(p, np.ndarray) else p for p in polygons]
            sizes = np.fromiter(map(len, polygons), np.int64, count=len(polygons))
            flat = np.asarray(list(itertools.chain.from_iterable(polygons)))
        except TypeError as exc:
            raise ValueError("polygons: expected a list of vertex-index sequences or an (m, k) int array") from exc
        if flat.size and not integral(flat):
            raise ValueError(f"polygons: vertex indices must be integers, got dtype {flat.dtype}")
        flat = flat.astype(np.int64)
    if len(sizes) == 0:
        raise ValueError("polygons: is empty (0 faces)")
    if (sizes < 3).any():
        k = int(np.flatnonzero(sizes < 3)[0])
        raise ValueError(f"polygons[{k}]: a polygon needs at least 3 vertices, got {int(sizes[k])}")
    start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    bad = (flat < 0) | (flat >= n)
    if bad.any():
        k = int(np.searchsorted(start, np.flatnonzero(bad)[0], side="right") - 1)
        raise ValueError(f"polygons[{k}]: vertex index out of range for {n} vertices")
    # the flat layout in ascending degree (stable): the polygon order of the refinement and the assembly
    order = np.argsort(sizes, kind="stable")
    gsize = sizes[order]
    gstart = np.zeros(len(sizes) + 1, np.int64)
    np.cumsum(gsize, out=gstart[1:])
    corners = flat[np.repeat(start[order] - gstart[:-1], gsize) + np.arange(gstart[-1])]
    k = first_repeat(gstart, corners)
    if k >= 0:
        q = corners[gstart[k]:gstart[k + 1]]
        raise ValueError(f"polygons[{int(order[k])}]: repeats a vertex ({q.tolist()})")
    return gstart, corners


def virtual_vertex_weights(X: np.ndarray) -> np.ndarray:
    """Affine weights (q, s) of the virtual vertices of q polygons with s corners ``X`` (q, s, 3).

    The virtual vertex minimizes Σ_i |(x_i - x) × (x_{i+1} - x)|² (twice the squared fan-triangle areas, Bunge et
    al. 2020 §3): a 3×3 linear least-squares problem per polygon. Its weights are the minimum-norm affine ones
    reproducing it (``Σ w = 1``, ``Σ w_i x_i = x``); degenerate polygons get uniform weights. One numba pass
    over the polygons (:func:`gsdf.heat.polygon._kernels.polygon_weights`).

    Example
    -------
    >>> X = np.array([[[0., 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]]])
    >>> virtual_vertex_weights(X).round(6).tolist()
    [[0.25, 0.25, 0.25, 0.25]]
    """
    X = np.ascontiguousarray(X, dtype=np.float64)
    if X.ndim != 3 or X.shape[2] != 3:
        raise ValueError(f"X: expected shape (q, s, 3), got {X.shape}")
    return polygon_weights(X)


def _refine(V: np.ndarray, start: np.ndarray, corners: np.ndarray):
    """The virtual-vertex refinement of validated polygons in the flat layout of :func:`_parse_polygons`, and
    what the assembly kernel reads: ``(V_refined, F_refined, P, vid, wflat)`` (``vid`` = the virtual vertex of
    each polygon, -1 for triangles; ``wflat`` the weights aligned with ``corners``). One numba pass
    (:func:`~gsdf.heat.polygon._kernels.refine_polygons`)."""
    n = len(V)
    wflat, vid, newV, F, indptr, indices, data = refine_polygons(V, start, corners)
    Vr = np.concatenate([V, newV]) if len(newV) else V.copy()
    idx = np.int32 if len(indices) < 2 ** 31 - 1 else np.int64
    P = sp.csr_matrix((data, indices.astype(idx), indptr.astype(idx)), shape=(n + len(newV), n))
    P.has_sorted_indices = True
    P.has_canonical_format = True
    return Vr, F, P, vid, wflat


def virtual_vertex_refinement(V: np.ndarray, polygons):
    """Refine polygons by virtual-vertex fans (Bunge et al. 2020).

    Returns ``(V_refined, F_refined, P)``: the first ``len(V)`` refined vertices are the input ones, the others the
    virtual vertices of the polygons with more than three corners; triangles are kept as they are. ``P`` is the
    sparse prolongation (len(V_refined), len(V)): identity rows for original vertices, affine weights for virtual
    ones.

    Example
    -------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    >>> Vr, Fr, P = virtual_vertex_refinement(V, [[0, 1, 2, 3]])
    >>> (Vr[4].round(3) + 0.0).tolist(), len(Fr), P.shape
    ([0.5, 0.5, 0.0], 4, (5, 4))
    """
    V = np.ascontiguousarray(V, dtype=np.float64)
    return _refine(V, *_parse_polygons(polygons, len(V)))[:3]


def frame_transport(N, e1, e2, i, j) -> np.ndarray:
    """Unit complex r_ij expressing the basis vector e1_j in the basis of i after the smallest rotation taking
    N_j to N_i (Sharp et al. 2019 §6.2.2; geometry-central ``transportBetween(j, i)``): a tangent vector z_j in
    frame j is ``r_ij z_j`` in frame i; r_ji = conj(r_ij)."""
    a, b, v = N[j], N[i], e1[j]
    c = np.einsum("kj,kj->k", a, b)
    w = np.cross(a, b)
    # R v = v + w × v + w × (w × v) / (1 + c)  (Rodrigues, rotation taking a to b); antiparallel: skip
    den = np.where(1 + c > 1e-12, 1 + c, np.inf)
    wv = np.cross(w, v)
    Rv = v + wv + np.cross(w, wv) / den[:, None]
    z = np.einsum("kj,kj->k", Rv, e1[i]) + 1j * np.einsum("kj,kj->k", Rv, e2[i])
    mag = np.abs(z)
    return np.where(mag > 0, z / np.where(mag > 0, mag, 1.0), 1.0)


def connection_laplacian(L: sp.spmatrix, N, e1, e2, symmetric_pattern: bool = False) -> sp.csr_matrix:
    """Vertex connection Laplacian: off-diagonal entries of the real Laplacian L times the frame rotations
    r_ij (Eq. 9 / §8.3–8.4), the diagonal unchanged; Hermitian by construction (upper part, conjugated).
    On a symmetric pattern one numba pass over the upper entries writes both halves in L's own CSR layout
    (:func:`~gsdf.heat.polygon._kernels.connection_values`). ``symmetric_pattern=True``: the caller
    guarantees a canonical CSR ``L`` with a symmetric pattern (the transpose is not formed to check it)."""
    L = sp.csr_matrix(L)
    L.sum_duplicates()
    L.sort_indices()
    n = L.shape[0]
    if not symmetric_pattern:
        Lt = L.T.tocsr()
        Lt.sort_indices()
    if symmetric_pattern or (np.array_equal(L.indptr, Lt.indptr) and np.array_equal(L.indices, Lt.indices)):
        N, e1, e2 = (np.ascontiguousarray(a, dtype=np.float64) for a in (N, e1, e2))
        vals = connection_values(L.indptr.astype(np.int64), L.indices.astype(np.int64), L.data.astype(np.float64),
                                 N, e1, e2)
        return sp.csr_matrix((vals, L.indices, L.indptr), shape=(n, n))
    L = sp.coo_matrix(L)
    up = L.row < L.col
    i, j, v = L.row[up], L.col[up], L.data[up]
    r = frame_transport(N, e1, e2, i, j)
    d = L.diagonal()
    rows = np.concatenate([i, j, np.arange(n)])
    cols = np.concatenate([j, i, np.arange(n)])
    vals = np.concatenate([v * r, v * np.conj(r), d.astype(np.complex128)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


# --------------------------------------------------------------------------------------------- polygon solver
class PolygonDomain(VertexSurfaceDomain):
    """Polygon mesh (§8.3) with the Bunge et al. 2020 polygon Laplacian (module docs).

    Parameters
    ----------
    V : (n, 3) float; polygons : list of int sequences (or an (m, k) array), any mix of degrees, planar or not;
    t_coef : float, diffusion time ``t = t_coef · (mean polygon edge length)²``.

    Attributes
    ----------
    L : (n, n) PSD polygon Laplacian ``Pᵀ C_fan P``; M : (n,) lumped mass; P : prolongation;
    V_refined, F_refined : the virtual-vertex refinement; N, e1, e2 : vertex tangent frames.

    Example
    -------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    >>> PolygonDomain(V, [[0, 1, 2, 3]]).L.shape
    (4, 4)
    """

    # SuperLU's own minimum-degree ordering, no RCM renumbering first (docs/decisions.md)
    renumber = False
    # Lconn has L's pattern exactly (connection_laplacian): the Dirichlet systems of step III take step I's
    # ordering restricted to their free vertices (no ordering pass of their own, ldl.HINT_AMD_FLOPS)
    heat_on_nodes = True
    # step I's operator ordered by AMD alone, no nested-dissection attempt (docs/decisions.md)
    heat_ordering = "amd"

    def __init__(self, V, polygons, t_coef: float = 1.0):
        V = _checks.as_points(V, "V")
        t_coef = _checks.positive(t_coef, "t_coef", most=_checks.T_COEF_MAX)
        self.n_vertices = n = len(V)
        self.V = V
        start, corners = _parse_polygons(polygons, n)
        self.V_refined, F, self.P, vid, wflat = _refine(V, start, corners)
        nxt = np.arange(1, len(corners) + 1)                             # the next corner of each polygon
        nxt[start[1:] - 1] = start[:-1]
        a, b = corners, corners[nxt]
        keys = np.sort(np.minimum(a, b) * n + np.maximum(a, b))
        self._edge_keys = keys[np.concatenate([[True], keys[1:] != keys[:-1]])]
        ell = np.linalg.norm(V[self._edge_keys % n] - V[self._edge_keys // n], axis=1)   # unique polygon edges
        self.mean_edge = float(ell.mean())
        # one kernel sums L = Pᵀ C_fan P (Bunge et al. 2020 §4), M = lump(Pᵀ M_fan P) = Pᵀ A_fan (rows of P sum
        # to one, §4.2) and the normals per polygon, without forming the refined matrices; fan triangles of zero
        # area (nonconvex / degenerate polygons) carry no stiffness or mass and are dropped
        thresh = 1e-12 * self.mean_edge ** 2
        vals, self.M, An, good, fn, fG = polygon_assembly(self.V_refined, start, corners, vid, wflat, n, thresh)
        if not good.any():
            raise ValueError("polygons: all polygons have zero area")
        if good.all():                                             # the usual case: no copies
            self.F_refined, self._fine_normals, self._fine_G = F, fn, fG
        else:
            self.F_refined, self._fine_normals, self._fine_G = F[good], fn[good], fG[good]
        # (the fine triangles' normals and divergence weights are steps II–III's data)
        self._fine_ops = None
        # per polygon exactly symmetric, and the triplets of (i, j) and (j, i) alike are summed in polygon order:
        # L is exactly symmetric
        if len(vals) >= 2 ** 31:
            raise ValueError(f"polygons: {len(vals)} stiffness entries (Σ degree²), beyond 32-bit sparse indices")
        indptr, indices, slot = polygon_csr_pattern(start, corners, n)
        L = sp.csr_matrix((np.bincount(slot, weights=vals, minlength=len(indices)), indices, indptr), shape=(n, n))
        L.has_sorted_indices = True
        L.has_canonical_format = True
        # vertex normals: area-weighted fine triangle normals (§8.3)
        nrm = np.linalg.norm(An, axis=1)
        An[nrm == 0] = [0, 0, 1.0]
        N = An / np.maximum(nrm, 1e-300)[:, None]
        e1, e2 = tangent_frames(N)
        Lconn = connection_laplacian(L, N, e1, e2, symmetric_pattern=True)   # the blocks emit (i, j) and (j, i)
        super().__init__(V, L, self.M, Lconn, N, e1, e2, t_coef * self.mean_edge ** 2)

    @property
    def fine_ops(self) -> TriangleOperators:
        """Vertex operators of the refined triangle mesh (built on first access; the solves use the kernel's
        normals and divergence weights of the same triangles)."""
        if self._fine_ops is None:
            self._fine_ops = TriangleOperators(self.V_refined, self.F_refined, edges=False)
        return self._fine_ops

    def gather(self, X) -> np.ndarray:
        """§8.3: prolong the vertex vectors to the fine vertices (virtual vertex = Σ w_i X_i as 3D vectors), sum
        them over every fine triangle and project into its plane (normalized by the core); one numba pass
        (:func:`~gsdf.heat.polygon._kernels.fine_vectors`)."""
        P = self.P
        return fine_vectors(np.ascontiguousarray(X, np.complex128), self.e1, self.e2, P.indptr, P.indices, P.data,
                            self.F_refined, self._fine_normals)

    def divergence(self, Y) -> np.ndarray:
        """The fine divergence (b_i = Σ_f |f| ∇λ_i · Y_f) restricted by Pᵀ (Bunge et al. §4.5); one numba pass
        (:func:`~gsdf.heat.polygon._kernels.fine_divergence`)."""
        P = self.P
        return fine_divergence(self._fine_G, np.ascontiguousarray(Y, np.float64), self.F_refined, P.indptr,
                               P.indices, P.data, self.n_vertices)

    def check_curve_edges(self, a, k):
        n = self.n_vertices
        key = np.minimum(a[:-1], a[1:]) * n + np.maximum(a[:-1], a[1:])
        pos = np.clip(np.searchsorted(self._edge_keys, key), 0, len(self._edge_keys) - 1)
        bad = self._edge_keys[pos] != key
        if bad.any():
            q = int(np.flatnonzero(bad)[0])
            raise ValueError(f"curves[{k}]: vertices {a[q]} and {a[q + 1]} (points {q}, {q + 1}) are not joined by "
                             "a polygon edge (curves must run along polygon edges)")


__all__ = ["PolygonDomain", "virtual_vertex_refinement", "virtual_vertex_weights", "connection_laplacian",
           "frame_transport", "tangent_frames"]
