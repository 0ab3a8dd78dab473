"""Intrinsic Delaunay triangulations as a signed-heat domain (Feng & Crane 2024, §9.4, Fig. 22).

The domain owns everything intrinsic: Lawson edge flips on edge lengths only
(:func:`gsdf.heat.intrinsic._kernels.intrinsic_delaunay`), operators from per-face planar layouts, and the
transfer of sources onto the flipped triangulation — curve segments along input edges keep those edges
unflippable (the triangulation is re-flipped, and its factorizations rebuilt, for a curve set whose edges were
flipped away; a few triangulations are cached, each with its own factorizations in the core, keyed by
``state_key``), segments inside input faces and point sources inside faces are carried through the logged
flips (:func:`~gsdf.heat.intrinsic._kernels.locate_points`) and re-split along intrinsic edges by tracing
(:func:`~gsdf.heat.intrinsic._kernels.trace_paths`). Output stays per input vertex. The solver
(:class:`gsdf.SurfaceSignedHeatSolver` with ``intrinsic_delaunay=True``) knows none of this.

Example
-------
>>> from gsdf.data._shapes import grid_mesh
>>> d = IntrinsicDomain(*grid_mesh(4))
>>> d.ops.n_flips >= 0
True
"""

from __future__ import annotations

import numpy as np

from gsdf.heat._core import hash_key
from gsdf.heat.intrinsic._kernels import face_coords, intrinsic_delaunay, layout, locate_points, trace_paths
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.heat._domain import HeatDomain
from gsdf.heat.triangle._domain import TriangleDomain
from gsdf.heat.triangle._sources import (
    _bary_curve_segments,
    _faces_of_node,
    _to_face,
    assemble,
    parse_curves,
    parse_points,
    surface_points,
)

__all__ = ["IntrinsicDomain"]


class IntrinsicDomain(HeatDomain):
    """A triangle mesh through its intrinsic Delaunay triangulation (module docs).

    Parameters
    ----------
    V, F : the input mesh (validated); t : diffusion time (default h² of the input); connection : as for
    :class:`~gsdf.heat.triangle._domain.TriangleDomain`; input_ops : prebuilt operators of the input mesh.
    """

    difference_order = "first"
    MAX_STATES = 4

    def __init__(self, V, F, t: float | None = None, connection: str = "auto", input_ops=None):
        self.V, self.F = V, F
        self.input_ops = input_ops if input_ops is not None else TriangleMeshOperators(V, F)
        self.n_nodes = self.input_ops.n_vertices
        self.t = float(self.input_ops.h ** 2 if t is None else t)
        self.connection = connection
        self._states: dict = {}
        self.state_key = None
        self._tri = None

    # ---- the current triangulation
    def _use_state(self, key, fixed_pairs):
        """Switch to the intrinsic triangulation with the original edges ``fixed_pairs`` unflippable (built and
        cached on first use)."""
        if key == self.state_key:
            return
        if key not in self._states:
            Fi, L, nflips, log = intrinsic_delaunay(self.V, self.F, fixed_pairs, return_log=True)
            ops = TriangleMeshOperators(self.V, Fi, P=layout(L))
            ops.point_weight = self.input_ops.point_weight
            ops.n_flips, ops.flip_log, ops.L_slots = nflips, log, L
            if len(self._states) >= self.MAX_STATES:
                self._states.pop(next(iter(self._states)))
            self._states[key] = TriangleDomain(ops=ops, t=self.t, connection=self.connection)
        self._tri = self._states[key]
        self.state_key = key

    @property
    def tri(self) -> TriangleDomain:
        """The current intrinsic triangulation (without fixed edges when nothing was solved yet)."""
        if self._tri is None:
            self._use_state(hash_key(np.zeros((0, 2), np.int64)), None)
        return self._tri

    @property
    def ops(self):
        return self.tri.ops

    @property
    def heat_form(self):
        return self.tri.heat_form

    def vector_heat_matrix(self):
        return self.tri.vector_heat_matrix()

    def gather(self, X):
        return self.tri.gather(X)

    def divergence(self, Y):
        return self.tri.divergence(Y)

    def laplacian(self):
        return self.tri.laplacian()

    def mass(self):
        return self.tri.mass()

    @property
    def C(self):
        return self.tri.C

    # ---- sources
    def assemble_sources(self, curves, points, curve_normals=None):
        if curve_normals is not None:
            raise ValueError("curve_normals: not available with intrinsic_delaunay=True")
        pts = parse_points(self.input_ops, points)
        parts, pts = self.transfer(parse_curves(self.input_ops, curves), pts)
        return assemble(self.ops, parts, pts)

    def transfer(self, parts, points):
        """Re-express the sources on an intrinsic Delaunay triangulation (§9.4): vertex polylines and curve
        segments along input edges stay on those edges (kept unflippable); segments inside input faces are
        carried through the flips (their midpoints and directions, :func:`~gsdf.heat.intrinsic._kernels.
        locate_points`) and re-split along the intrinsic edges by tracing (:func:`~gsdf.heat.intrinsic._kernels.
        trace_paths`); point sources inside faces are carried through the flips. ``parts`` and ``points`` are
        parsed on the input mesh (:func:`~gsdf.heat.triangle._sources.parse_curves`, ``parse_points``).
        Switches to the triangulation that keeps the needed edges and returns (parts, points) parsed on it, for
        :func:`~gsdf.heat.triangle._sources.assemble`."""

        ops0 = self.input_ops
        F0, V0 = ops0.F, ops0.V
        specs, pairs = [], []
        mids_f, mids_b, mids_v = [], [], []                  # face-segment midpoints to carry through the flips
        for part in parts:
            vs = part.vertices
            if vs is None and ((part.bary > 0).sum(1) == 1).all():   # surface points that are all vertices
                vs = F0[part.faces, np.argmax(part.bary, axis=1)]
            if vs is not None:
                keep = np.concatenate([[True], vs[1:] != vs[:-1]])
                vs = vs[keep]
                if len(vs) < 2:
                    raise ValueError(f"{part.name}: a curve needs at least 2 points, got {len(vs)}")
                e = ops0.edge_lookup(vs[:-1], vs[1:])
                if np.any(e < 0):
                    q = int(np.flatnonzero(e < 0)[0])
                    raise ValueError(f"{part.name}: vertices {vs[q]} and {vs[q + 1]} (points {q}, {q + 1}) are not "
                                     "joined by a mesh edge (give the curve as (face, barycentric) points)")
                if not part.signed and vs[0] != vs[-1]:
                    raise ValueError(f"{part.name}: open unsigned curves are not supported with "
                                     "intrinsic_delaunay=True (close the curve or use the input triangulation)")
                specs.append((part, vs))
                pairs.append(np.stack([vs[:-1], vs[1:]], 1))
                continue
            if not part.signed:
                raise ValueError(f"{part.name}: unsigned curves must run along mesh edges (give vertex indices)")
            nf, nb, *_ = _bary_curve_segments(ops0, part.faces, part.bary, part.name, return_faces=True)
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
                raise ValueError(f"{part.name}: the curve has zero length")
            specs.append((part, segs))
        # point sources: vertices stay, points inside faces / on edges are carried through the flips
        pts_v, pts_track = [], []
        if points is not None:
            for ids, w, f in zip(points.ids, points.w, points.faces):
                if (w > 0).sum() == 1:
                    pts_v.append(int(ids[np.argmax(w)]))
                else:
                    pts_track.append((int(f), w))
        P = np.concatenate(pairs) if pairs else np.zeros((0, 2), np.int64)
        P = np.unique(np.sort(P, axis=1), axis=0)
        if self.state_key is None:
            self._use_state(hash_key(P), P)
        else:
            # are all curve edges (same vertex pair, same length) present in the current triangulation?
            e = self.ops.edge_lookup(P[:, 0], P[:, 1])
            ok = np.all(e >= 0) and np.allclose(self.ops.edge_len[e],
                                                ops0.edge_len[ops0.edge_lookup(P[:, 0], P[:, 1])], rtol=1e-9, atol=0)
            if not ok:
                self._use_state(hash_key(P), P)
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
        for part, spec in specs:
            if isinstance(spec, np.ndarray):
                out.append(part._replace(vertices=spec, faces=None, bary=None))
                continue
            nodes = []
            for sg in spec:
                if sg[0] == "e":
                    chain = [on_edge(sg[1]), on_edge(sg[2])]
                else:
                    i = sg[1]
                    bf, bb = paths[nm + i]                      # backward: crossings ..., start point
                    ff, fb = paths[i]                          # forward: crossings ..., end point
                    chain = [(int(f), b) for f, b in zip(bf[::-1], bb[::-1])] + \
                            [(int(f), b) for f, b in zip(ff, fb)]
                nodes.extend(chain if not nodes else chain[1:])
            faces, bary = surface_points(ops, [(f, np.asarray(b, np.float64).ravel()) for f, b in nodes], part.name)
            out.append(part._replace(faces=faces, bary=bary))
        pts = pts_v + [(int(f), np.asarray(b, np.float64).ravel()) for f, b in zip(tf[nm:], tb[nm:])]
        return out, parse_points(ops, pts)
