"""Front-end of the signed heat method on polygon meshes (Feng & Crane 2024, §8.3): operators in
:mod:`gsdf.heat.polygon._domain`, steps I–III in :mod:`gsdf.heat._core`."""

from __future__ import annotations

import numpy as np

from gsdf import _checks
from gsdf._normalize import Frame
from gsdf.heat._core import SignedHeatCore
from gsdf.heat.polygon._domain import (
    PolygonDomain,
    connection_laplacian,
    integral,
    tangent_frames,
    virtual_vertex_refinement,
    virtual_vertex_weights,
)

__all__ = ["PolygonMeshSignedHeatSolver", "virtual_vertex_refinement", "virtual_vertex_weights",
           "connection_laplacian", "tangent_frames"]


class PolygonMeshSignedHeatSolver:
    """Signed heat method on a polygon mesh (§8.3) with the Bunge et al. 2020 polygon Laplacian.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions, model units.
    polygons : list of int sequences or (m, k) int array
        Faces as vertex indices, any mix of degrees (triangles, quads, ...), planar or not, consistently
        oriented; a polygon that repeats a vertex is dropped with a warning.
    t_coef : float, default 1.0
        Diffusion time ``t = t_coef · (mean polygon edge length)²``; larger smooths over gaps.

    Attributes
    ----------
    L : (n, n) sparse float64
        The positive semidefinite polygon Laplacian ``Pᵀ C_fan P``.
    M : (n,) float64
        Lumped masses (square model units).
    P : sparse float64
        Prolongation from the vertices to the virtual-vertex refinement.
    V_refined, F_refined
        The virtual-vertex refinement (a triangle mesh).
    N, e1, e2 : (n, 3) float64
        Vertex tangent frames.
    t : float
        The diffusion time, square model units.
    domain, core
        The :class:`~gsdf.heat.polygon._domain.PolygonDomain` and its :class:`~gsdf.heat._core.SignedHeatCore`
        (factorizations kept between calls).

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, indices out of range, degenerate polygons, ``t_coef <= 0``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> x = np.linspace(-1, 1, 9)
    >>> V = np.array([[a, b, 0.0] for a in x for b in x])
    >>> i = np.arange(81).reshape(9, 9)
    >>> quads = np.stack([i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel(), i[:-1, 1:].ravel()], 1)
    >>> loop = np.concatenate([i[2:6, 2], i[6, 2:6], i[6:2:-1, 6], i[2, 6:1:-1]])   # counter-clockwise
    >>> phi = gsdf.PolygonMeshSignedHeatSolver(V, quads).compute_distance([loop])
    >>> bool(phi[40] < 0)                                          # the centre is inside
    True
    """

    def __init__(self, V, polygons, t_coef: float = 1.0):
        # scale invariance: solved in the geometry's frame (centred, power-of-two scale: exact), distances
        # mapped back on output (gsdf._normalize); the attributes below are in input units
        V = _checks.as_points(V, "V")
        self.frame = Frame.of(V)
        self.V_world = V
        polygons = _without_repeats(polygons)
        self.domain = d = PolygonDomain(self.frame.geometry(V), polygons, t_coef=t_coef)
        self.core = SignedHeatCore(d)
        fr = self.frame  # attributes in input units (L, Lconn, P, frames are scale-free); fine_ops: frame units
        self.n_vertices, self.V, self.P = d.n_vertices, V, d.P
        self.V_refined, self.F_refined = fr.point(d.V_refined), d.F_refined
        self.L, self.M, self.Lconn, self.t = d.L, fr.area(d.M), d.Lconn, float(fr.area(d.t))
        self.N, self.e1, self.e2, self.mean_edge = d.N, d.e1, d.e2, float(fr.length(d.mean_edge))

    @property
    def fine_ops(self):
        """Vertex operators of the refined triangle mesh (frame units; built on first access)."""
        return self.domain.fine_ops

    def compute_distance(self, curves, *, points=(), curve_signs=None, level_set_constraint="zero",
                         soft_weight=None, progress=None):
        """Generalized signed distance at the vertices (signed heat method, §8.3).

        Parameters
        ----------
        curves : list of gsdf.Curve or 1-D int arrays
            Vertex polylines along polygon edges (closed: first = last); a counter-clockwise loop (seen from the
            normal side) encloses the negative region.
        points : sequence of int, default ()
            Vertex indices of isolated point sources (unsigned).
        curve_signs : list of bool, optional
            Per curve True (signed, default) or False (unsigned: its vertices act as point sources).
        level_set_constraint : {"zero", "multiple", "none"}, default "zero"
            φ = 0 on all source vertices, φ constant along every connected curve component, or none; then φ is
            shifted to mean zero along the curves (Alg. 13).
        soft_weight : float, optional
            Replaces the hard constraint by the penalty λ Σ (φ(v) - φ(v0))² (§7.1).
        progress : callable, optional
            ``progress(stage, fraction)`` during the solves.

        Returns
        -------
        (n,) float64
            Signed distance per vertex, model units; negative inside counter-clockwise loops.

        Raises
        ------
        ValueError
            Curves not along polygon edges, indices out of range, bad ``curve_signs``, an unknown constraint.

        Examples
        --------
        >>> phi = solver.compute_distance([loop], level_set_constraint="none")     # doctest: +SKIP
        """
        phi = self.core.compute_distance(curves, points=points, curve_signs=curve_signs,
                                         level_set_constraint=level_set_constraint, soft_weight=soft_weight,
                                         progress=progress)
        return self.frame.length(phi)


def _without_repeats(polygons):
    """The polygons without those that repeat a vertex (a warning says how many); anything not a list of integer
    index sequences (strings, NaN, fractions, objects) is passed on unchanged for the domain to validate and
    refuse."""
    import warnings

    try:
        polys = [np.asarray(q).ravel() for q in polygons]
        if not all(integral(q) for q in polys):
            return polygons
        rep = [len(np.unique(q)) < len(q) for q in polys]
    except (TypeError, ValueError):
        return polygons
    if not any(rep):
        return polygons
    keep = [q for q, r in zip(polys, rep) if not r]
    warnings.warn(f"polygons: {sum(rep)} polygons repeat a vertex (first: polygon {rep.index(True)}); they are "
                  "dropped", stacklevel=3)
    return keep

