"""The signed heat method on triangle meshes (Feng & Crane 2024, §3–7, Alg. 1–4)."""

from __future__ import annotations

import hashlib

import numpy as np
import scipy.sparse as sp

from ... import _checks
from ...linalg import BlockHermitianFactorization, Factorization, HermitianFactorization, cached_factorization, saddle_matrix
from .operators import TriangleMeshOperators
from .sources import build_sources

LEVEL_SETS = ("zero", "multiple", "none")
CONNECTIONS = ("auto", "complex", "real")


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
    F : (m, 3) int array
        Triangle mesh of any topology: boundary, several components, nonmanifold edges/vertices (operators are
        per-face sums, §9.4). Nonorientable meshes (and faces whose orientation disagrees with a neighbour's)
        are handled exactly: transport across such an edge is a reflection, so the connection Laplacian is then
        assembled as a real 2|E|×2|E| block matrix (see ``connection``); give the curve normals
        (``curve_normals=`` of :meth:`compute_distance`) there, since face normals flip across the seam.
        Faces with repeated vertices or zero area raise ValueError (remove them first).
    t_coef : float
        Diffusion time ``t = t_coef · h²`` with h the mean spacing of edge midpoints (§6) of the input mesh.
    intrinsic_delaunay : bool
        Build the operators on an intrinsic Delaunay triangulation of the input (§9.4, Fig. 22): Lawson edge
        flips on edge lengths only (:mod:`gsdf.heat.surface.intrinsic`), operators from per-face planar
        layouts; output stays per input vertex. This helps on meshes with obtuse slivers. Curve segments along
        input edges (vertex polylines, surface points on one edge) keep those edges unflippable (the
        triangulation is re-flipped, and refactorized, for a curve set whose edges were flipped away; cached per
        edge set). Segments inside input faces and point sources inside faces need no fixed edges: they are
        carried through the flips (the logged flips are redone with the points in the planar layout of every
        flipped quad) and the segments are re-split along the intrinsic edges by tracing, so that Eq. 11 is
        applied per intrinsic face. Unsigned curves must be closed vertex polylines; ``curve_normals`` is not
        available; ``compute_distance_l1`` raises NotImplementedError. On a mesh that is already Delaunay no
        edge flips and the results equal those on the input triangulation.
    connection : {"auto", "complex", "real"}
        Form of the connection Laplacian of step I. ``"auto"``: complex |E|×|E| (Eq. 9) when all faces are
        consistently oriented, else the real 2|E|×2|E| block form that also represents the reflections across
        orientation flips. ``"real"`` forces the block form (same result on orientable meshes, ~2× slower);
        ``"complex"`` forces Eq. 9 (wrong transport across orientation flips; for comparisons only).

    Components of the mesh without sources get an arbitrary (near-constant) value; unreferenced vertices
    get 0 before the final shift.

    Example
    -------
    >>> import numpy as np
    >>> from gsdf.heat import SurfaceSignedHeatSolver
    >>> from gsdf.heat.surface.meshes import grid_mesh
    >>> from gsdf.heat.surface.curves import level_set_curves
    >>> V, F = grid_mesh(32)                                   # the square [-1, 1]², normals +z
    >>> circle = level_set_curves(V, F, np.linalg.norm(V, axis=1) - 0.5)   # counter-clockwise
    >>> phi = SurfaceSignedHeatSolver(V, F).compute_distance(circle)
    >>> round(float(phi[np.argmin(np.linalg.norm(V, axis=1))]), 1)          # the centre: 0.5 inside
    -0.5
    """

    def __init__(self, V, F, t_coef: float = 1.0, intrinsic_delaunay: bool = False, connection: str = "auto"):
        V, F = _checks.as_mesh(V, F)
        self.connection = _checks.choice(connection, "connection", CONNECTIONS)
        self.t_coef = _checks.positive(t_coef, "t_coef")
        rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
        if rep.any():
            raise ValueError(f"F: face {int(np.flatnonzero(rep)[0])} repeats a vertex ({int(rep.sum())} "
                             "degenerate faces); remove degenerate triangles first")
        dbl = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
        L = np.linalg.norm(V[F[:, 1]] - V[F[:, 0]], axis=1).mean()
        bad = dbl <= 1e-12 * L * L
        if bad.any():
            raise ValueError(f"F: face {int(np.flatnonzero(bad)[0])} has zero area ({int(bad.sum())} degenerate "
                             "faces); remove degenerate triangles first")
        self.V, self.F = V, F
        self.intrinsic_delaunay = bool(intrinsic_delaunay)
        self.input_ops = TriangleMeshOperators(V, F)
        self.t = self.t_coef * self.input_ops.h ** 2
        self._states: dict = {}
        self._state_key = None
        if not self.intrinsic_delaunay:
            self._set_ops(self.input_ops)
        # with intrinsic_delaunay the triangulation is built on first use: by the first solve (with its curve
        # edges kept unflippable), or without fixed edges when an operator is accessed before any solve

    def __getattr__(self, name):
        d = self.__dict__
        if name in SurfaceSignedHeatSolver._STATE and d.get("intrinsic_delaunay") and d.get("_state_key") is None:
            self._use_state(self._key(np.zeros((0, 2), np.int64)), None)
            return getattr(self, name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    _STATE = ("ops", "C", "_Mv", "_eps", "_vec", "_poisson", "_cache")

    def _set_ops(self, ops):
        self.ops = ops
        self.C = self.ops.cotan_laplacian().tocsc()
        Mv = self.ops.vertex_mass()
        self._Mv = np.where(Mv > 0, Mv, Mv.mean())               # unreferenced vertices: keep the system regular
        # tiny mass regularization fixes the constant of every mesh component (C is only semidefinite)
        self._eps = 1e-10 * float(self.C.diagonal().mean()) / float(self._Mv.mean())
        self._vec = None
        self._poisson = None
        self._cache: dict = {}

    def _use_state(self, key, fixed_pairs):
        """Switch to the intrinsic triangulation with the original edges ``fixed_pairs`` unflippable (built and
        cached on first use, with its own factorizations)."""
        if key == self._state_key:
            return
        if self._state_key is not None:
            self._states[self._state_key] = tuple(getattr(self, a) for a in self._STATE)
        if key in self._states:
            for a, v in zip(self._STATE, self._states[key]):
                setattr(self, a, v)
        else:
            from .intrinsic import intrinsic_delaunay, layout

            Fi, L, nflips, log = intrinsic_delaunay(self.V, self.F, fixed_pairs, return_log=True)
            ops = TriangleMeshOperators(self.V, Fi, P=layout(L))
            ops.n_flips, ops.flip_log, ops.L_slots = nflips, log, L
            self._set_ops(ops)
            if len(self._states) >= 4:
                self._states.pop(next(iter(self._states)))
        self._state_key = key

    # ------------------------------------------------------------------ steps
    @property
    def vector_heat_factorization(self):
        """The factorization of ``M + t L∇`` (Eq. 12), built on first use (complex, or the real 2×2 block form
        on inconsistently oriented meshes)."""
        if self._vec is None:
            if self.connection == "real" or (self.connection == "auto" and not self.ops.consistent):
                M = self.ops.cr_mass().diagonal()
                A = sp.diags(np.repeat(M, 2)) + self.t * self.ops.cr_connection_laplacian_real()
                self._vec = BlockHermitianFactorization(A)
            else:
                A = self.ops.cr_mass() + self.t * self.ops.cr_connection_laplacian()
                self._vec = HermitianFactorization(A)
        return self._vec

    def _poisson_fact(self) -> Factorization:
        if self._poisson is None:
            self._poisson = Factorization((self.C + sp.diags(self._eps * self._Mv)).tocsc())
        return self._poisson

    def diffuse(self, sources) -> np.ndarray:
        """Step I: X = (M + tL∇)⁻¹ X0, complex per edge (Alg. 2)."""
        return self.vector_heat_factorization.solve(sources.X0)

    def unit_field(self, X: np.ndarray) -> np.ndarray:
        """Step II: face-averaged, normalized vectors Y (m, 3) (§6, Alg. 3); zero where X vanishes."""
        Y = self.ops.edge_to_face_vectors(X)
        nrm = np.linalg.norm(Y, axis=1)
        out = np.zeros_like(Y)
        # no relative threshold: far from the sources |X| decays like exp(-d/√t) (1e-20 is common) yet its
        # direction is still meaningful (§3.1)
        np.divide(Y, nrm[:, None], out=out, where=nrm[:, None] > 0)
        return out

    # ------------------------------------------------------------------ public
    def compute_distance(self, curves, points=(), curve_signs=None, level_set_constraint: str = "zero",
                         soft_weight=None, curve_normals=None) -> np.ndarray:
        """Generalized signed distance at the vertices, negative inside.

        Parameters
        ----------
        curves : list
            Each curve either an int array of vertex indices (a polyline along edges) or a list of surface
            points ``(face_index, barycentric (3,))`` (``(vertex, ())`` also means a vertex). A curve oriented
            counter-clockwise (seen from the side the face normals point to) encloses the negative region.
        points : sequence
            Isolated point sources (App. A.1): vertex indices or ``(face, barycentric)`` tuples (split over the
            face's vertices). Distance to points is unsigned.
        curve_signs : list of bool, optional
            Per curve: True = oriented (signed, default), False = unoriented (unsigned distance, App. A.2; must
            run along edges).
        level_set_constraint : {"zero", "multiple", "none"}
            ``"zero"``: φ = 0 on all sources (saddle system Eq. 14; vertex sources are eliminated directly);
            ``"multiple"``: φ constant along every connected curve component (curves sharing a vertex are one
            component); ``"none"``: no constraint. In every case φ is finally shifted to mean zero along the
            curves (Alg. 13), or to minimum zero when there are only points.
        soft_weight : float, optional
            Replace the hard constraint of ``"zero"`` / ``"multiple"`` by the penalty λ Σ (φ(p_i) - φ(p_0))²
            over the nodes (§7.1): solves ``(C + λAᵀA)φ = b``. Ignored with ``"none"``.
        curve_normals : list, optional
            Explicit surface normals for the signed curves (one entry per curve: None = face normals, a (3,)
            vector, or one (3,) per curve point), used instead of the face normals in N = T × n (Eq. 11) — the
            way to orient curves on nonorientable domains (§9.4), where face normals flip across the seam.
            Negating them negates φ. Not available with ``intrinsic_delaunay=True``.

        Notes
        -----
        Sign convention: potpourri3d / the paper turn curve tangents counter-clockwise to get normals, which
        makes the left side positive; gsdf makes it negative (so a counter-clockwise loop has a negative
        inside, like a winding number of 1). Values for signed curves are therefore the negative of
        potpourri3d's, for points and unsigned curves equal. Point sources at vertices follow Eq. 19; points
        inside faces are split over the face's vertices by their barycentric weights (potpourri3d rejects them).
        Curve nodes that are surface points cost a saddle factorization per distinct curve set (cached).

        Returns
        -------
        phi : (n,) float64

        Example
        -------
        >>> from gsdf.heat.surface.meshes import grid_mesh
        >>> V, F = grid_mesh(4)
        >>> solver = SurfaceSignedHeatSolver(V, F)
        >>> solver.compute_distance([np.array([6, 7, 12, 6])], level_set_constraint="none").shape
        (25,)
        """
        mode = _checks.choice(level_set_constraint, "level_set_constraint", LEVEL_SETS)
        lam = None
        if soft_weight is not None:
            lam = _checks.positive(soft_weight, "soft_weight")
        if self.intrinsic_delaunay:
            if curve_normals is not None:
                raise ValueError("curve_normals: not available with intrinsic_delaunay=True")
            curves, points = self._to_intrinsic(curves, points, curve_signs)
        S = build_sources(self.ops, curves, points, curve_signs, curve_normals)
        return self._solve_sources(S, mode, lam)

    def _to_intrinsic(self, curves, points, curve_signs):
        """Re-express the sources on an intrinsic Delaunay triangulation (§9.4): vertex polylines and curve
        segments along input edges stay on those edges (kept unflippable); segments inside input faces are
        carried through the flips (their midpoints and directions, :func:`~gsdf.heat.surface.intrinsic.
        locate_points`) and re-split along the intrinsic edges by tracing (:func:`~gsdf.heat.surface.intrinsic.
        trace_paths`); point sources inside faces are carried through the flips. Switches to the triangulation
        that keeps the needed edges and returns (curves, points) for :func:`build_sources` on it."""
        from .intrinsic import face_coords, locate_points, trace_paths
        from .sources import _bary_curve_segments, _faces_of_node, _parse_curve, _to_face

        ops0 = self.input_ops
        F0, V0 = ops0.F, ops0.V
        if curves is None:
            curves = []
        if isinstance(curves, np.ndarray) and curves.ndim == 1 and np.issubdtype(curves.dtype, np.integer):
            curves = [curves]
        curves = list(curves)
        signs = [True] * len(curves) if curve_signs is None else [bool(x) for x in curve_signs]
        specs, pairs = [], []
        mids_f, mids_b, mids_v = [], [], []                  # face-segment midpoints to carry through the flips
        for k, c in enumerate(curves):
            parsed = _parse_curve(c, ops0, k)
            vs = None
            if parsed[0] == "v":
                vs = parsed[1]
            elif ((parsed[2] > 0).sum(1) == 1).all():          # surface points that are all vertices
                vs = F0[parsed[1], np.argmax(parsed[2], axis=1)]
            if vs is not None:
                keep = np.concatenate([[True], vs[1:] != vs[:-1]])
                vs = vs[keep]
                e = ops0.edge_lookup(vs[:-1], vs[1:])
                if np.any(e < 0):
                    q = int(np.flatnonzero(e < 0)[0])
                    raise ValueError(f"curves[{k}]: vertices {vs[q]} and {vs[q + 1]} (points {q}, {q + 1}) are not "
                                     "joined by a mesh edge (give the curve as (face, barycentric) points)")
                if k < len(signs) and not signs[k] and vs[0] != vs[-1]:
                    raise ValueError(f"curves[{k}]: open unsigned curves are not supported with "
                                     "intrinsic_delaunay=True (close the curve or use the input triangulation)")
                specs.append(("v", vs))
                pairs.append(np.stack([vs[:-1], vs[1:]], 1))
                continue
            if k < len(signs) and not signs[k]:
                raise ValueError(f"curves[{k}]: unsigned curves must run along mesh edges (give vertex indices)")
            nf, nb, *_ = _bary_curve_segments(ops0, parsed[1], parsed[2], f"curves[{k}]", return_faces=True)
            segs = []
            for q in range(len(nf) - 1):
                fa, ba, fb, bb = nf[q], nb[q], nf[q + 1], nb[q + 1]
                va, vb = set(F0[fa, ba > 0].tolist()), set(F0[fb, bb > 0].tolist())
                both = va | vb
                if len(both) <= 2:                             # on one input edge (or one vertex)
                    if len(both) == 2 and ops0.edge_lookup(*sorted(both)) >= 0:
                        pairs.append(np.array([sorted(both)]))
                        segs.append(("e", (fa, ba), (fb, bb)))
                        continue
                    if len(both) == 1:
                        continue                               # zero length
                g = min(_faces_of_node(ops0, fa, ba) & _faces_of_node(ops0, fb, bb))
                wa, wb = _to_face(F0, fa, ba, g), _to_face(F0, fb, bb, g)
                if np.abs(wa - wb).max() == 0:
                    continue
                mids_f.append(g)
                mids_b.append(0.5 * (wa + wb))
                mids_v.append(0.5 * (wb - wa) @ V0[F0[g]])
                segs.append(("f", len(mids_f) - 1))
            if not segs:
                raise ValueError(f"curves[{k}]: the curve has zero length")
            specs.append(("b", segs))
        # point sources: vertices stay, points inside faces / on edges are carried through the flips
        pts_v, pts_track = [], []
        if points is not None:
            items = list(np.asarray(points).reshape(-1)) if isinstance(points, np.ndarray) else list(points)
            for q, it in enumerate(items):
                if np.isscalar(it):
                    v = int(it)
                    if v != it or not 0 <= v < ops0.n_vertices:
                        raise ValueError(f"points[{q}]: vertex index {it!r} out of range for {ops0.n_vertices} "
                                         "vertices")
                    pts_v.append(v)
                    continue
                _, f, bq = _parse_curve([it, it], ops0, 0)
                if (bq[0] > 0).sum() == 1:
                    pts_v.append(int(F0[f[0], np.argmax(bq[0])]))
                else:
                    pts_track.append((int(f[0]), bq[0]))
        P = np.concatenate(pairs) if pairs else np.zeros((0, 2), np.int64)
        P = np.unique(np.sort(P, axis=1), axis=0)
        if self._state_key is None:
            self._use_state(self._key(P), P)
        else:
            # are all curve edges (same vertex pair, same length) present in the current triangulation?
            e = self.ops.edge_lookup(P[:, 0], P[:, 1])
            ok = np.all(e >= 0) and np.allclose(self.ops.edge_len[e],
                                                ops0.edge_len[ops0.edge_lookup(P[:, 0], P[:, 1])], rtol=1e-9, atol=0)
            if not ok:
                self._use_state(self._key(P), P)
        ops = self.ops
        # carry midpoints (with half-segment vectors) and point sources through the flips
        nm = len(mids_f)
        tf = np.array(mids_f + [f for f, _ in pts_track], np.int64)
        tb = np.array(mids_b + [b for _, b in pts_track]).reshape(-1, 3)
        tv = np.zeros((len(tf), 2))
        if nm:
            tv[:nm] = face_coords(V0, F0, tf[:nm], np.array(mids_v))
        if len(tf):
            tf, tb, tv = locate_points(V0, F0, ops.flip_log, tf, tb, tv)
        paths = []
        if nm:
            paths = trace_paths(ops.F, ops.L_slots, np.concatenate([tf[:nm], tf[:nm]]),
                                np.concatenate([tb[:nm], tb[:nm]]), np.concatenate([tv[:nm], -tv[:nm]]))

        def on_edge(node):
            """An input node on an input edge / vertex as an intrinsic (face, barycentric)."""
            f, b = node
            vs = F0[f, b > 0]
            ws = b[b > 0]
            if len(vs) == 2:
                e = int(ops.edge_lookup(vs[0], vs[1]))
            else:                                              # a vertex: any intrinsic face around it
                vf = ops.vertex_faces()
                g = int(vf.indices[vf.indptr[vs[0]]])
                out = np.zeros(3)
                out[vf.data[vf.indptr[vs[0]]] - 1] = 1.0
                return g, out
            g = int(ops.edge_ref_slot[e] // 3)
            out = np.zeros(3)
            for v, w in zip(vs, ws):
                out[np.flatnonzero(ops.F[g] == v)[0]] += w
            return g, out

        out = []
        for spec in specs:
            if spec[0] == "v":
                out.append(spec[1])
                continue
            nodes = []
            for sg in spec[1]:
                if sg[0] == "e":
                    chain = [on_edge(sg[1]), on_edge(sg[2])]
                else:
                    i = sg[1]
                    bf, bb = paths[nm + i]                      # backward: crossings ..., start point
                    ff, fb = paths[i]                          # forward: crossings ..., end point
                    chain = [(int(f), b) for f, b in zip(bf[::-1], bb[::-1])] + \
                            [(int(f), b) for f, b in zip(ff, fb)]
                nodes.extend(chain if not nodes else chain[1:])
            out.append(nodes)
        pts = pts_v + [(int(f), b) for f, b in zip(tf[nm:], tb[nm:])]
        return out, (pts if pts else None)

    def _solve_sources(self, S, mode, lam):
        """Steps I–III for parsed sources (Alg. 1), with the level-set handling of §7.1."""
        if not np.any(S.X0):
            raise ValueError("curves: the sources have zero total length / weight")
        X = self.diffuse(S)
        Y = self.unit_field(X)
        b = self.ops.divergence(Y)
        if mode == "none":
            phi = self._poisson_fact().solve(b)
        elif lam is not None:
            phi = self._soft(S, b, mode, lam)
        elif mode == "zero":
            phi = self._zero(S, b)
        else:
            phi = self._multiple(S, b)
        return self._shift(S, phi)

    def compute_distance_l1(self, curves, points=(), curve_signs=None) -> np.ndarray:
        """Piecewise-continuous generalized signed distance (§7.2): per-corner values, shape (m, 3).

        For curves that do not bound a region (or are inconsistently oriented) the unit field cannot be
        integrated by a continuous function; this integrates it exactly in every face and puts the
        discontinuities where the weighted L1 jump (Eq. 16) is least — a linear program on |F| unknowns solved
        by HiGHS (seconds for ~10⁴ faces; it grows superlinearly). Shifted so that the length-weighted mean
        along the curves is zero.

        Example
        -------
        >>> corners = solver.compute_distance_l1([open_curve])     # doctest: +SKIP
        >>> phi_face = corners.mean(axis=1)                          # doctest: +SKIP
        """
        from .l1 import integrate_l1

        if self.intrinsic_delaunay:
            raise NotImplementedError("compute_distance_l1 is not available with intrinsic_delaunay=True")
        S = build_sources(self.ops, curves, points, curve_signs)
        Y = self.unit_field(self.diffuse(S))
        Phi = integrate_l1(self.ops, Y)
        # shift: mean over the curve segments of the value in a face containing the segment midpoint
        if S.node_rows:
            ids = np.concatenate([mm[0] for mm in S.seg_mid])
            w = np.concatenate([mm[1] for mm in S.seg_mid])
            L = np.concatenate(S.seg_len)
            vf = self.ops.vertex_faces()
            # value of the face of the first vertex of the midpoint's support: average of its corner values
            v0 = ids[np.arange(len(ids)), np.argmax(w, axis=1)]
            f0 = vf.indices[vf.indptr[v0]]
            vals = Phi[f0].mean(axis=1)
            if L.sum() > 0:
                return Phi - float((vals * L).sum() / L.sum())
        return Phi - float(Phi.min())

    def sharpen(self, phi0: np.ndarray, curves, points=(), iterations: int = 3000) -> np.ndarray:
        """Distance sharpening (§7.3, Eq. 18): the largest |∇φ| ≤ 1 function with the sign pattern of ``phi0``
        that vanishes on the sources, by PDHG warm-started from ``phi0`` (a signed heat result).

        Vertex sources are pinned to 0; for surface points the vertices of their faces keep their values from
        ``phi0`` (exactly zero on the curve after a ``"zero"`` solve). Returns φ (n,).

        Example
        -------
        >>> phi = solver.compute_distance(curves)                  # doctest: +SKIP
        >>> sharp = solver.sharpen(phi, curves)                     # doctest: +SKIP
        """
        from .sharpen import sharpen

        phi0 = np.asarray(phi0, dtype=np.float64)
        if phi0.shape != (self.ops.n_vertices,) or not np.isfinite(phi0).all():
            raise ValueError(f"phi0: expected {self.ops.n_vertices} finite values, got shape {phi0.shape}")
        if self.intrinsic_delaunay:
            curves, points = self._to_intrinsic(curves, points, None)
        S = build_sources(self.ops, curves, points, None)
        ids, w, isv = self._all_nodes(S)
        fixed = np.zeros(self.ops.n_vertices, bool)
        fixed[ids[isv < 0][w[isv < 0] > 0]] = True
        values = phi0.copy()
        fixed[isv[isv >= 0]] = True
        values[isv[isv >= 0]] = 0.0
        return sharpen(self.ops, phi0, fixed, values, iterations=_checks.integer(iterations, "iterations"))[0]

    def split_curve(self, curve) -> list:
        """The nodes of ``curve`` as (face, barycentric) points, split where segments cross edges, so that
        consecutive nodes share a face (the form potpourri3d requires)."""
        from .sources import _bary_curve_segments, _parse_curve

        parsed = _parse_curve(curve, self.input_ops, 0)
        if parsed[0] == "v":
            vs = parsed[1]
            return [(int(v), np.zeros(0)) for v in vs]
        ids, w, _, _, _ = _bary_curve_segments(self.input_ops, parsed[1], parsed[2], "curve", return_faces=True)
        return list(zip(ids, w))

    def split_segments(self, curve) -> list:
        """The segments of ``curve`` as pairs ``[(f, bary_a), (f, bary_b)]`` in one face each (vertex polylines
        and points on edges included): the per-segment form of potpourri3d's curves."""
        from .sources import _bary_in_face, _faces_of_node

        nodes = self.split_curve(curve)
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
            pa, pb = ba @ self.V[self.F[fa]], bb @ self.V[self.F[fb]]
            out.append([(f, _bary_in_face(self.input_ops, pa, f)), (f, _bary_in_face(self.input_ops, pb, f))])
        return out

    # ------------------------------------------------------------------ constraints (§7.1)
    def _all_nodes(self, S):
        rows = list(S.node_rows)
        isv = list(S.node_is_vertex)
        if S.point_rows is not None:
            rows.append(S.point_rows)
            isv.append(S.point_is_vertex)
        ids = np.concatenate([r[0] for r in rows])
        w = np.concatenate([r[1] for r in rows])
        return ids, w, np.concatenate(isv)

    def _interp(self, ids, w):
        k = len(ids)
        return sp.csr_matrix((w.ravel(), (np.repeat(np.arange(k), ids.shape[1]), ids.ravel())),
                             shape=(k, self.ops.n_vertices))

    @staticmethod
    def _key(*arrays):
        h = hashlib.sha1()
        for a in arrays:
            a = np.ascontiguousarray(a)
            h.update(str(a.shape).encode())
            h.update(a.tobytes())
        return h.hexdigest()

    def _cached(self, key, build):
        return cached_factorization(self._cache, key, build)

    def _zero(self, S, b):
        ids, w, isv = self._all_nodes(S)
        n = self.ops.n_vertices
        if np.all(isv >= 0):
            # all sources at vertices: eliminate them (Dirichlet φ = 0), as geometry-central does
            fixed = np.zeros(n, bool)
            fixed[isv] = True
            free = np.flatnonzero(~fixed)
            key = self._key(np.array([0]), np.flatnonzero(fixed))

            def build():
                Cf = self.C[free][:, free] + sp.diags(self._eps * self._Mv[free])
                return Factorization(Cf.tocsc())

            fact = self._cached(key, build)
            phi = np.zeros(n)
            phi[free] = fact.solve(b[free])
            return phi
        # general points: φ(p) = 0 at every node (equivalent to Eq. 14 followed by the exact shift to zero)
        A = self._interp(ids, w)
        A = _unique_rows(A)
        return self._saddle_solve(A, b, tag=1)

    def _multiple(self, S, b):
        A = self._difference_rows(S)
        if A.shape[0] == 0:
            return self._poisson_fact().solve(b)
        return self._saddle_solve(A, b, tag=2)

    def _saddle_solve(self, A, b, tag):
        n = self.ops.n_vertices
        A = A.tocsr()
        key = self._key(np.array([tag]), A.indptr, A.indices, A.data)
        delta = 1e-12 * float(self.C.diagonal().mean())

        def build():
            C = self.C + sp.diags(self._eps * self._Mv)
            return Factorization(saddle_matrix(C, A, delta))

        fact = self._cached(key, build)
        rhs = np.concatenate([b, np.zeros(A.shape[0])])
        return fact.solve(rhs)[:n]

    def _difference_rows(self, S, single=False):
        """Rows φ(p_i) - φ(p_0) = 0 per connected curve component (all nodes together when ``single``)."""
        groups = _curve_components(S, self.ops.n_vertices) if not single else np.zeros(len(S.node_rows), int)
        mats = []
        for g in np.unique(groups):
            sel = np.flatnonzero(groups == g)
            ids = np.concatenate([S.node_rows[c][0] for c in sel])
            w = np.concatenate([S.node_rows[c][1] for c in sel])
            if single and S.point_rows is not None:
                ids = np.concatenate([ids, S.point_rows[0]])
                w = np.concatenate([w, S.point_rows[1]])
            P = _unique_rows(self._interp(ids, w))
            if P.shape[0] > 1:
                mats.append(P[1:] - sp.csr_matrix(np.ones((P.shape[0] - 1, 1))) @ P[:1])
        if not mats:
            return sp.csr_matrix((0, self.ops.n_vertices))
        return sp.vstack(mats).tocsr()

    def _soft(self, S, b, mode, lam):
        A = self._difference_rows(S, single=(mode != "multiple"))
        key = self._key(np.array([3]), np.array([lam]), A.indptr, A.indices, A.data)

        def build():
            K = self.C + lam * (A.T @ A) + sp.diags(self._eps * self._Mv)
            return Factorization(K.tocsc())

        return self._cached(key, build).solve(b)

    def _shift(self, S, phi):
        """Alg. 13: subtract the length-weighted mean of φ along the curves (min over points if no curves)."""
        if S.node_rows:
            ids = np.concatenate([m[0] for m in S.seg_mid])
            w = np.concatenate([m[1] for m in S.seg_mid])
            L = np.concatenate(S.seg_len)
            vals = (phi[ids] * w).sum(1)
            if L.sum() > 0:
                return phi - float((vals * L).sum() / L.sum())
        return phi - float(phi.min())


def _unique_rows(A):
    """Drop duplicate rows of a sparse matrix (repeated nodes would make the saddle system singular)."""
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
    return A[np.sort(idx)]


def _curve_components(S, n):
    """Connected components of curves: curves sharing a vertex node belong together."""
    from scipy.sparse.csgraph import connected_components

    k = len(S.node_rows)
    r, c = [], []
    for i, isv in enumerate(S.node_is_vertex):
        v = isv[isv >= 0]
        r.append(np.full(len(v), i))
        c.append(v)
    r, c = np.concatenate(r), np.concatenate(c)
    G = sp.csr_matrix((np.ones(len(r)), (r, k + c)), shape=(k + n, k + n))
    lab = connected_components(G, directed=False)[1]
    return lab[:k]
