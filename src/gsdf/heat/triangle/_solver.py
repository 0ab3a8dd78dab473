"""Front-end of the signed heat method on triangle meshes (Feng & Crane 2024, §3–7, Alg. 1–4).

Operators and sources: :mod:`gsdf.heat.triangle._domain` (or :mod:`gsdf.heat.intrinsic._domain` with
``intrinsic_delaunay=True``); steps I–III, constraints and shift: :mod:`gsdf.heat._core`. What stays here is the
public class, L1 integration (§7.2), sharpening (§7.3) and curve splitting helpers.
"""

from __future__ import annotations

import warnings

import numpy as np

from gsdf import _checks
from gsdf._normalize import Frame
from gsdf.heat._core import SignedHeatCore
from gsdf.heat.intrinsic._domain import IntrinsicDomain
from gsdf.heat.triangle._domain import TriangleDomain
from gsdf.curves import Curve, as_curves, as_point_sources
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.heat.triangle._sources import assemble, parse_curves, parse_points



class SurfaceSignedHeatSolver:
    """Generalized signed distance to (broken) curves on a triangle mesh by the signed heat method.

    The operators (CR mass and connection Laplacian, Eqs. 6–9; cotan Laplacian, Eq. 10) are assembled once;
    the vector heat operator ``M + tL∇`` (Eq. 12) and the Poisson operator are factorized on first use and kept,
    so further calls cost only solves. Constrained Poisson systems (level-set constraints, §7.1) depend on the
    curves; their factorizations are cached per constraint set (a repeated call with the same curves and the
    same constraint type costs only solves).

    Parameters
    ----------
    V : (n, 3) float array
        Vertex positions, model units.
    F : (m, 3) int array
        Triangle mesh of any topology: boundary, several components, nonmanifold edges/vertices (operators are
        per-face sums, §9.4). Nonorientable meshes (and faces whose orientation disagrees with a neighbour's)
        are handled exactly: transport across such an edge is a reflection, so the connection Laplacian of step I
        is then assembled as a real block matrix of size ``2|E| × 2|E|`` that represents the reflections (the
        complex ``|E| × |E|`` form of Eq. 9 when all faces agree); give the curve normals (``curve_normals=`` of
        :meth:`compute_distance`) there, since face normals flip across the seam.
        Faces that repeat a vertex have no area and are dropped with a warning (``F`` of the solver lists the
        faces kept; face indices given in curves and point sources still refer to the input ``F``); other faces
        of zero area raise ValueError (remove them first).
    t_coef : float, default 1.0
        Diffusion time ``t = t_coef · h²`` with h the mean spacing of edge midpoints (§6) of the input mesh;
        smaller follows the curves more closely, larger smooths over gaps and noise.
    intrinsic_delaunay : bool, default False
        Build the operators on an intrinsic Delaunay triangulation of the input (§9.4, Fig. 22): Lawson edge
        flips on edge lengths only (:mod:`gsdf.heat.intrinsic._kernels`), operators from per-face planar
        layouts; output stays per input vertex. This helps on meshes with obtuse slivers. Curve segments along
        input edges (vertex polylines, surface points on one edge) keep those edges unflippable (the
        triangulation is re-flipped, and refactorized, for a curve set whose edges were flipped away; cached per
        edge set). Segments inside input faces and point sources inside faces need no fixed edges: they are
        carried through the flips (the logged flips are redone with the points in the planar layout of every
        flipped quad) and the segments are re-split along the intrinsic edges by tracing, so that Eq. 11 is
        applied per intrinsic face. Unsigned curves must be closed vertex polylines; ``curve_normals`` is not
        available; ``compute_distance_l1`` raises NotImplementedError. On a mesh that is already Delaunay no
        edge flips and the results equal those on the input triangulation.

    Notes
    -----
    Scale: the mesh is mapped once into its frame (:class:`gsdf._normalize.Frame`: centred, power-of-two
    scale) and solved there, so results are scale-covariant (φ of ``s·V`` is ``s·φ``) from 1e-150 to 1e150;
    ``ops`` and ``C`` are in frame units (``frame.length`` / ``frame.area`` map lengths and areas back);
    ``V`` (the input, also ``V_world``) and ``t`` are in input units.

    Components of the mesh without sources get an arbitrary (near-constant) value; unreferenced vertices
    get 0 before the final shift.

    Attributes
    ----------
    V, F
        The input mesh (``V`` in model units; also ``V_world``).
    t : float
        The diffusion time, square model units.
    frame : gsdf._normalize.Frame
        The centred, power-of-two-scaled frame the solver works in.
    ops, C
        The operators of the triangulation in use and its cotan Laplacian (frame units).

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, indices out of range, degenerate faces, ``t_coef <= 0``.

    Examples
    --------
    >>> import numpy as np, trimesh, gsdf
    >>> s = trimesh.creation.icosphere(subdivisions=3)
    >>> V, F = np.asarray(s.vertices), np.asarray(s.faces)
    >>> equator = gsdf.level_set_curves(V, F, V[:, 2], 0.0)      # z < 0 on its left
    >>> solver = gsdf.SurfaceSignedHeatSolver(V, F)               # factorize once ...
    >>> phi = solver.compute_distance(equator)                    # ... solve per curve set
    >>> round(float(phi[np.argmin(V[:, 2])]), 1), round(float(phi[np.argmax(V[:, 2])]), 1)   # poles: ±π/2
    (-1.6, 1.6)
    """

    def __init__(self, V, F, t_coef: float = 1.0, intrinsic_delaunay: bool = False):
        V, F = _checks.as_mesh(V, F)
        # scale invariance: everything runs in the geometry's frame (centre, power-of-two scale, exact);
        # distances are mapped back on output (gsdf._normalize)
        self.frame = Frame.of_mesh(V, F) if len(F) else Frame.of(V)
        self.V_world, V = V, self.frame.geometry(V)
        self.t_coef = _checks.positive(t_coef, "t_coef", most=_checks.T_COEF_MAX)
        rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
        self._kept = None  # input face -> kept face (-1: dropped), when faces were dropped
        if rep.any():
            warnings.warn(f"F: {int(rep.sum())} faces repeat a vertex (first: face {int(np.flatnonzero(rep)[0])}); "
                          "they have no area and are dropped", stacklevel=2)
            self._kept = np.full(len(F), -1, np.int64)
            self._kept[~rep] = np.arange(int((~rep).sum()))
            self._input_face = np.flatnonzero(~rep)
            F = F[~rep]
            if not len(F):
                raise ValueError("F: every face repeats a vertex")
        dbl = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
        L = np.linalg.norm(V[F[:, 1]] - V[F[:, 0]], axis=1).mean()
        bad = dbl <= 1e-12 * L * L
        if bad.any():
            raise ValueError(f"F: face {int(np.flatnonzero(bad)[0])} has zero area ({int(bad.sum())} degenerate "
                             "faces); remove degenerate triangles first")
        self.V, self.F = self.V_world, F
        self.intrinsic_delaunay = _checks.flag(intrinsic_delaunay, "intrinsic_delaunay")
        self.input_ops = TriangleMeshOperators(V, F)
        # a vertex point source weighs one input unit against the curves (its old meaning at every scale)
        self.input_ops.point_weight = float(self.frame.inverse_length(1.0))
        self.t = self.t_coef * self.input_ops.h ** 2
        if self.intrinsic_delaunay:
            # the triangulation is built on first use: by the first solve (with its curve edges kept
            # unflippable), or without fixed edges when an operator is accessed before any solve
            self.domain = IntrinsicDomain(V, F, t=self.t, input_ops=self.input_ops)
        else:
            self.domain = TriangleDomain(t=self.t, ops=self.input_ops)
        self.core = SignedHeatCore(self.domain)
        self.t = float(self.frame.area(self.t))  # reported in input units (the domain keeps the frame's)

    @property
    def ops(self) -> TriangleMeshOperators:
        """Operators of the triangulation in use (the input one, or the current intrinsic one)."""
        return self.domain.ops

    @property
    def C(self):
        """The cotan Laplacian (Eq. 10) of the triangulation in use."""
        return self.domain.laplacian()

    @property
    def _cache(self) -> dict:
        return self.core.poisson._cache

    # ------------------------------------------------------------------ steps
    @property
    def vector_heat_factorization(self):
        """The factorization of ``M + t L∇`` (Eq. 12), built on first use (complex, or the real 2×2 block form
        on inconsistently oriented meshes)."""
        return self.core.vector_heat_factorization

    def diffuse(self, sources) -> np.ndarray:
        """Step I of the method: the curves' normals diffused, X = (M + tL∇)⁻¹ X0 (Alg. 2).

        Parameters
        ----------
        sources : gsdf.heat._core.Sources
            The assembled sources of a curve set (``solver.core.sources(curves, points, curve_signs)``); its
            ``X0`` is the right-hand side of Eq. 12.

        Returns
        -------
        (nE,) complex128
            The diffused vector field, one complex number per edge (nE edges; on inconsistently oriented meshes
            solved in the real block form and returned as complex numbers).

        Examples
        --------
        >>> S = solver.core.sources([curve], (), None)               # doctest: +SKIP
        >>> Y = solver.unit_field(solver.diffuse(S))                 # doctest: +SKIP
        """
        from gsdf.heat._sources import Sources

        if not isinstance(sources, Sources):
            raise ValueError(f"sources: expected the assembled sources of solver.core.sources(curves, points, "
                             f"curve_signs), got {type(sources).__name__}")
        return self.vector_heat_factorization.solve(sources.X0)

    def unit_field(self, X: np.ndarray) -> np.ndarray:
        """Step II of the method: the diffused field averaged per face and normalized (§6, Alg. 3).

        Parameters
        ----------
        X : (nE,) complex array
            The output of :meth:`diffuse`: one finite complex number per edge (real numbers are taken as
            complex).

        Returns
        -------
        (m, 3) float64
            Unit vectors per face, zero where the diffused field vanishes.

        Raises
        ------
        ValueError
            ``X`` not one finite number per edge.

        Examples
        --------
        >>> Y = solver.unit_field(solver.diffuse(S))                 # doctest: +SKIP
        """
        nE = self.core.domain.ops.n_edges
        A = _checks._array(X, "X")
        if A.dtype.kind not in "iufc":
            raise ValueError(f"X: expected the complex edge vectors of diffuse(), got {_checks._dtype_words(A)}")
        if A.shape != (nE,):
            raise ValueError(f"X: expected one value per edge, shape ({nE},) (the output of diffuse()), got "
                             f"shape {A.shape}")
        if not np.isfinite(A).all():
            raise ValueError("X: contains NaN or infinite values")
        return self.core.unit_field(A.astype(np.complex128, copy=False))

    def _kept_faces(self, curves, points, curve_signs):
        """Curves and point sources with their face indices mapped to the faces kept (when faces that repeat a
        vertex were dropped); ``curve_signs`` folded into the curves then."""
        if self._kept is None:
            return curves, points, curve_signs

        def face(f, name):
            if not 0 <= f < len(self._kept):
                return f  # out of range: the domain's own message
            g = int(self._kept[f])
            if g < 0:
                raise ValueError(f"{name}: face {f} repeats a vertex and was dropped")
            return g

        out = []
        for k, c in enumerate(as_curves(curves, curve_signs)):
            if c.kind == "points":
                nodes = [(face(f, f"curves[{k}]") if len(b) else f, b) for f, b in c.nodes]
                c = Curve(nodes, signed=c.signed)
            out.append(c)
        pts = [p if not isinstance(p, tuple) or not len(p[1]) else (face(p[0], "points"), p[1])
               for p in as_point_sources(points)]
        return out, pts, None

    # ------------------------------------------------------------------ public
    def compute_distance(self, curves, *, points=(), curve_signs=None, level_set_constraint: str = "zero",
                         soft_weight=None, curve_normals=None, progress=None) -> np.ndarray:
        """Generalized signed distance at the vertices, negative inside.

        Steps I–III of the signed heat method (Feng & Crane 2024, Alg. 1): the curves' normals are diffused for
        the time ``t`` (Eq. 12), normalized per face, and φ is the function whose gradient best matches that
        unit field (the Poisson problem of Eq. 13), with the level-set constraint of §7.1.

        Parameters
        ----------
        curves : list
            Each curve a :class:`gsdf.Curve`, an int array of vertex indices (a polyline along edges), an (k, 2)
            edge set inside a :class:`gsdf.Curve`, or a list of surface points ``(face_index, barycentric
            (3,))`` (``(vertex, ())`` also means a vertex). A curve oriented counter-clockwise (seen from the
            side the face normals point to) encloses the negative region. Curves may have gaps (broken curves):
            the diffused normals still separate an inside from an outside. Keyword-only from here on.
        points : sequence, default ()
            Isolated point sources (App. A.1): vertex indices or ``(face, barycentric)`` tuples (split over the
            face's vertices). Distance to points is unsigned.
        curve_signs : list of bool, optional
            Per curve: True = oriented (signed, default), False = unoriented (unsigned distance, App. A.2; must
            run along edges). Bools only; must agree with ``Curve.signed``.
        level_set_constraint : {"zero", "multiple", "none"}, default "zero"
            ``"zero"``: φ = 0 on all sources (saddle system Eq. 14; vertex sources are eliminated directly);
            ``"multiple"``: φ constant along every connected curve component (curves sharing a vertex are one
            component); ``"none"``: no constraint (use it for broken curves: the constraint pins φ = 0 on the
            given pieces only). In every case φ is finally shifted to mean zero along the curves (Alg. 13), or to
            minimum zero when there are only points.
        soft_weight : float, optional
            Replace the hard constraint of ``"zero"`` / ``"multiple"`` by the penalty λ Σ (φ(p_i) - φ(p_0))²
            over the nodes (§7.1): solves ``(C + λAᵀA)φ = b``; larger λ holds the constraint more tightly.
            Default: the hard constraint. Ignored with ``"none"``.
        curve_normals : list, optional
            Explicit surface normals for the signed curves (one entry per curve: None = face normals, a (3,)
            vector, or one (3,) per curve point), used instead of the face normals in N = T × n (Eq. 11) — the
            way to orient curves on nonorientable domains (§9.4), where face normals flip across the seam.
            Negating them negates φ. Not available with ``intrinsic_delaunay=True``.
        progress : callable, optional
            ``progress(stage, fraction)`` (:mod:`gsdf.heat._core`).

        Notes
        -----
        Sign convention: potpourri3d / the paper turn curve tangents counter-clockwise to get normals, which
        makes the left side positive; gsdf makes it negative (so a counter-clockwise loop has a negative
        inside, like a winding number of 1). What holds in every case is gsdf(C) = potpourri3d(C reversed):
        with signed curves alone that is the negative of potpourri3d's values, with unsigned curves and points
        alone the same values, but with signed curves *and* point sources neither (the point distances do not
        flip: relative L2 0.88 from the negative on potpourri3d's sample) — reverse the curves instead
        (tests/conformance/test_potpourri3d.py). Point sources at vertices follow Eq. 19; points
        inside faces are split over the face's vertices by their barycentric weights (potpourri3d rejects them).
        Curve nodes that are surface points cost a saddle factorization per distinct curve set (cached).

        Returns
        -------
        phi : (n,) float64
            Generalized signed distance per vertex, model units; negative on the left of (inside) the curves.

        Raises
        ------
        ValueError
            A malformed curve (indices out of range, nodes not consecutive along edges, a bad surface point),
            ``curve_signs`` of the wrong length or not bools, an unknown ``level_set_constraint``,
            ``soft_weight <= 0``, no sources at all.

        Examples
        --------
        >>> import numpy as np, trimesh, gsdf
        >>> s = trimesh.creation.icosphere(subdivisions=3)
        >>> V, F = np.asarray(s.vertices), np.asarray(s.faces)
        >>> (equator,) = gsdf.level_set_curves(V, F, V[:, 2], 0.0)    # surface points, z < 0 on the left
        >>> solver = gsdf.SurfaceSignedHeatSolver(V, F)
        >>> phi = solver.compute_distance([equator])
        >>> phi.shape, round(float(phi[np.argmin(V[:, 2])]), 1)       # the south pole: π/2 inside
        ((642,), -1.6)
        >>> half = equator[: len(equator) // 2]                       # a broken curve: half of it
        >>> phi = solver.compute_distance([half], level_set_constraint="none")
        >>> bool(phi[np.argmin(V[:, 2])] < 0 < phi[np.argmax(V[:, 2])])
        True
        """
        curves, points, curve_signs = self._kept_faces(curves, points, curve_signs)
        phi = self.core.compute_distance(curves, points=points, curve_signs=curve_signs,
                                         level_set_constraint=level_set_constraint, soft_weight=soft_weight,
                                         progress=progress, curve_normals=curve_normals)
        return self.frame.length(phi)

    def compute_distance_l1(self, curves, *, points=(), curve_signs=None) -> np.ndarray:
        """Piecewise-continuous generalized signed distance (§7.2): per-corner values, shape (m, 3).

        For curves that do not bound a region (or are inconsistently oriented) the unit field cannot be
        integrated by a continuous function; this integrates it exactly in every face and puts the
        discontinuities where the weighted L1 jump (Eq. 16) is least — a linear program on ``|F|`` unknowns solved
        by HiGHS (seconds for ~10⁴ faces; it grows superlinearly). Shifted so that the length-weighted mean
        along the curves is zero.

        Parameters
        ----------
        curves : list
            As for :meth:`compute_distance`.
        points : sequence, default ()
            Isolated point sources, as for :meth:`compute_distance`.
        curve_signs : list of bool, optional
            As for :meth:`compute_distance`.

        Returns
        -------
        (m, 3) float64
            φ at the three corners of every face, model units.

        Raises
        ------
        ValueError
            Malformed curves or points.
        NotImplementedError
            With ``intrinsic_delaunay=True``.

        Examples
        --------
        >>> corners = solver.compute_distance_l1([open_curve])     # doctest: +SKIP
        >>> phi_face = corners.mean(axis=1)                          # doctest: +SKIP
        """
        from gsdf.heat.triangle._l1 import integrate_l1

        if self.intrinsic_delaunay:
            raise NotImplementedError("compute_distance_l1 is not available with intrinsic_delaunay=True")
        curves, points, curve_signs = self._kept_faces(curves, points, curve_signs)
        S = self.core.sources(curves, points, curve_signs)
        Y = self.unit_field(self.diffuse(S))
        Phi = integrate_l1(self.ops, Y)
        # shift: mean over the curve segments of the value in a face containing the segment midpoint
        if S.node_rows.shape[0]:
            ids, w = S.extra["midpoints"]
            L = S.shift_weights
            vf = self.ops.vertex_faces()
            # value of the face of the first vertex of the midpoint's support: average of its corner values
            v0 = ids[np.arange(len(ids)), np.argmax(w, axis=1)]
            f0 = vf.indices[vf.indptr[v0]]
            vals = Phi[f0].mean(axis=1)
            if L.sum() > 0:
                return self.frame.length(Phi - float((vals * L).sum() / L.sum()))
        return self.frame.length(Phi - float(Phi.min()))

    def sharpen(self, phi0: np.ndarray, curves, *, points=(), iterations: int = 3000) -> np.ndarray:
        """Distance sharpening (§7.3, Eq. 18): the largest function with gradient norm at most 1 and the sign
        pattern of ``phi0`` that vanishes on the sources, by PDHG warm-started from ``phi0``.

        Vertex sources are pinned to 0; for surface points the vertices of their faces keep their values from
        ``phi0`` (exactly zero on the curve after a ``"zero"`` solve).

        Parameters
        ----------
        phi0 : (n,) float
            A signed heat result on this mesh (:meth:`compute_distance`), model units.
        curves : list
            The curves it was computed for (as for :meth:`compute_distance`).
        points : sequence, default ()
            Its point sources.
        iterations : int, default 3000
            PDHG iterations; more get closer to a true distance (slowly).

        Returns
        -------
        (n,) float64
            The sharpened distance, model units.

        Raises
        ------
        ValueError
            ``phi0`` not one finite value per vertex, malformed curves.

        Examples
        --------
        >>> phi = solver.compute_distance(curves)                  # doctest: +SKIP
        >>> sharp = solver.sharpen(phi, curves)                     # doctest: +SKIP
        """
        from gsdf.heat.triangle._sharpen import sharpen

        from gsdf._memory import SECONDS_PER_FACE_STEP, check_work

        phi0 = _checks.as_values(phi0, "phi0", (self.ops.n_vertices,))
        iterations = _checks.integer(iterations, "iterations")
        check_work(iterations * self.ops.n_faces, SECONDS_PER_FACE_STEP,
                   f"sharpen: iterations={iterations:,} on {self.ops.n_faces:,} faces", parallel=False)
        phi0 = self.frame.inverse_length(phi0)
        curves, points, _ = self._kept_faces(curves, points, None)
        ops0 = self.input_ops
        parts = parse_curves(ops0, as_curves(curves))
        pts = parse_points(ops0, as_point_sources(points))
        if self.intrinsic_delaunay:
            parts, pts = self.domain.transfer(parts, pts)
        S = assemble(self.ops, [p._replace(signed=True) for p in parts], pts)   # only the source nodes count
        rows, vertex = S.all_rows()
        inner = rows[np.flatnonzero(vertex < 0)]
        fixed = np.zeros(self.ops.n_vertices, bool)
        fixed[inner.indices[inner.data > 0]] = True
        values = phi0.copy()
        fixed[vertex[vertex >= 0]] = True
        values[vertex[vertex >= 0]] = 0.0
        out = sharpen(self.ops, phi0, fixed, values, iterations=iterations)[0]
        return self.frame.length(out)

    def split_curve(self, curve) -> list:
        """The nodes of ``curve`` as (face, barycentric) points, split where segments cross edges, so that
        consecutive nodes share a face (the form potpourri3d requires).

        Parameters
        ----------
        curve : gsdf.Curve, int array or list of (face, barycentric)
            One curve, as for :meth:`compute_distance`.

        Returns
        -------
        list of (int, ndarray)
            ``(vertex, empty array)`` per node of a vertex polyline, else ``(face, barycentric (3,))``.

        Raises
        ------
        ValueError
            A malformed curve, or an edge set that is not one path.

        Examples
        --------
        >>> nodes = solver.split_curve(equator)                       # doctest: +SKIP
        """
        from gsdf.heat.triangle._sources import _bary_curve_segments

        (curve,), _, _ = self._kept_faces([Curve(curve)], (), None)
        parts = parse_curves(self.input_ops, [curve])
        if len(parts) != 1:
            raise ValueError(f"curve: expected one curve, got an edge set of {len(parts)} paths")
        (part,) = parts
        if part.vertices is not None:
            return [(int(v), np.zeros(0)) for v in part.vertices]
        ids, w, _, _, _ = _bary_curve_segments(self.input_ops, part.faces, part.bary, "curve", return_faces=True)
        return list(zip(self._input_faces(ids), w))

    def _input_faces(self, faces):
        """Kept-face indices back to the input's (identity unless faces were dropped)."""
        return list(faces) if self._kept is None else [int(self._input_face[f]) for f in faces]

    def split_segments(self, curve) -> list:
        """The segments of ``curve`` as pairs ``[(f, bary_a), (f, bary_b)]`` in one face each (vertex polylines
        and points on edges included): the per-segment form of potpourri3d's curves.

        Parameters
        ----------
        curve : gsdf.Curve, int array or list of (face, barycentric)
            One curve, as for :meth:`compute_distance`.

        Returns
        -------
        list of [(int, (3,) float), (int, (3,) float)]
            Both ends of each segment in the same face.

        Raises
        ------
        ValueError
            A malformed curve.

        Examples
        --------
        >>> segments = solver.split_segments(equator)                 # doctest: +SKIP
        """
        from gsdf.heat.triangle._sources import _bary_in_face, _faces_of_node

        nodes = self.split_curve(curve)
        if self._kept is not None and len(nodes[0][1]):
            nodes = [(int(self._kept[f]), b) for f, b in nodes]
        if len(nodes[0][1]) == 0:
            vf = self.input_ops.vertex_faces()
            nodes2 = []
            for v, _ in nodes:
                r = vf.indptr[v]
                b = np.zeros(3)
                b[vf.data[r] - 1] = 1
                nodes2.append((int(vf.indices[r]), b))
            nodes = nodes2
        out = []
        for (fa, ba), (fb, bb) in zip(nodes[:-1], nodes[1:]):
            common = _faces_of_node(self.input_ops, fa, ba) & _faces_of_node(self.input_ops, fb, bb)
            f = min(common)
            Vf = self.input_ops.V
            pa, pb = ba @ Vf[self.F[fa]], bb @ Vf[self.F[fb]]
            g = self._input_faces([f])[0]
            out.append([(g, _bary_in_face(self.input_ops, pa, f)), (g, _bary_in_face(self.input_ops, pb, f))])
        return out
