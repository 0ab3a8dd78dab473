"""Front-ends of the volumetric signed heat method (Feng & Crane 2024, §8.1–8.2): build the grid or tet
domain (:mod:`gsdf.heat.grid._domain`, :mod:`gsdf.heat.tet._domain`), run :class:`gsdf.heat._core.SignedHeatCore`,
wrap the values in a :class:`~gsdf.GridField` / :class:`~gsdf.TetField` with timings in ``field.meta``."""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial import cKDTree

from gsdf._memory import SECONDS_PER_QUERY, check_bytes, check_work
from gsdf._normalize import Frame
from gsdf.field import GridField, TetField
from gsdf._checks import positive, progress_callback
from gsdf.heat._core import SignedHeatCore
from gsdf.heat.grid._domain import GridDomain
from gsdf.heat.tet._domain import TetDomain
from gsdf.heat._sources import Sources
from gsdf.heat.volume._sources import source_components
from gsdf.heat.tet._mesh import BYTES_PER_TET_VERTEX, delaunay_mesh, input_points, tet_quality, tetgen_mesh

__all__ = ["solve_grid", "solve_tet", "BYTES_PER_NODE"]

_IDENTITY = Frame(np.zeros(3), 0, True)

BYTES_PER_NODE = 400  # positions, X, Y, d*, DCT work arrays (≈ 250 B/node measured); the constrained CG more
TET_LEVELS = 2        # lattice levels of the graded tet mesh (spacing ≤ 2h), gsdf.heat.tet._mesh.delaunay_mesh
TET_GRADING = 2.0     # spacing ratio between consecutive lattice levels
TET_MIN_QUALITY = 0.02  # tets of lower quality (6√2 |T| / l_rms³) are left out of the operators
TET_SURFACE_SPACING = 1.0  # Steiner points on the input every h (× this) for the "zero" rows on tets


def solve_grid(src: Sources, bbox_min, bbox_max, shape, t_coef: float = 1.0, t=None, mode: str = "zero", lam=None,
               theta: float = 1.5, max_memory=None, progress=None, frame=None) -> GridField:
    """Run Steps I–III on the grid ``shape`` spanning ``[bbox_min, bbox_max]``; returns a :class:`GridField`.

    ``t`` defaults to ``t_coef · h²``, h the largest grid spacing (the seed's t = h², §10). ``mode`` is the
    level-set constraint, ``lam`` the soft weight or None (hard), both as :class:`GridDomain` imposes them;
    ``theta`` the Yukawa tree tolerance; ``progress(stage, fraction)``; ``frame``: the
    :class:`gsdf._normalize.Frame` the inputs are in (the field is returned in world units).
    """
    report = progress_callback(progress)
    lo, hi = np.asarray(bbox_min, float), np.asarray(bbox_max, float)
    shape = tuple(int(s) for s in shape)
    n = int(np.prod(shape))
    check_bytes(n * BYTES_PER_NODE, f"signed_heat_volume: a grid of {n:,} nodes {shape}", max_memory)
    check_work(n, SECONDS_PER_QUERY, f"signed_heat_volume: a grid of {n:,} nodes {shape}")
    h = float(((hi - lo) / (np.array(shape) - 1)).max())
    t = positive(float(t_coef) * h * h if t is None else t, "t (= t_coef h^2)")
    domain = GridDomain(lo, hi, shape, t, theta=theta, progress=report)
    core = SignedHeatCore(domain)
    S = domain.prepare(src, source_components(src) if mode == "multiple" else None)
    timings = {}
    t0 = time.perf_counter()
    report("heat (step I)", 0.0)
    X = core.diffuse(S)
    timings["step1"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    report("poisson (step III)", 0.0)
    b = domain.divergence(core.unit_field(X))
    del X
    phi, shift = core.poisson_step(S, b, mode, lam)
    if shift:
        phi = core.shift(S, phi)
    report("poisson (step III)", 1.0)
    timings["step3"] = time.perf_counter() - t0
    fr = frame if frame is not None else _IDENTITY
    field = GridField(fr.length(phi.reshape(shape)), fr.point(lo), fr.point(hi))
    info = core.poisson.info if (mode != "none" and lam is None) else {}
    field.meta = {"method": "signed heat (grid)", "t": float(fr.area(t)), "theta": theta, "eps": domain.eps,
                  "timings": timings, "level_set_constraint": mode, "soft_weight": lam, "n_sources": len(src.B),
                  "step1": domain.step1_used, **info}
    return field


def solve_tet(src: Sources, X, faces, lo, hi, shape, t_coef: float = 1.0, t=None, mode: str = "zero", lam=None,
              theta: float = 1.5, mesher: str = "delaunay", max_memory=None, progress=None, frame=None) -> TetField:
    """Steps I–III on a tet mesh of the box graded toward the input; returns a :class:`TetField`.

    ``t`` defaults to ``t_coef · h²``, h the grid spacing the resolution gives (the lattice spacing near the input).
    ``faces`` are the input triangles (indices into ``X``) for meshes, None for clouds. ``lam`` replaces the hard
    constraint by the penalty λ Σ (φ(z_i) − φ(z_0))² over the input points. ``mesher``: "delaunay" or "tetgen"
    (:mod:`gsdf.heat.tet._mesh`). ``progress(stage, fraction)``; ``frame``: the :class:`gsdf._normalize.Frame`
    the inputs are in (the field is returned in world units).
    """
    report = progress_callback(progress)
    timings = {}
    t0 = time.perf_counter()
    h = float((hi - lo).max()) / (max(shape) - 1)
    kind = "mesh" if faces is not None else "points"
    # TetGen conforms to the input triangles, so φ = 0 on their vertices is φ = 0 on the whole input
    ss = np.inf if mesher == "tetgen" else TET_SURFACE_SPACING
    Z, comp = input_points(kind, np.asarray(X, float), faces, h, ss)
    nZ = len(Z)
    est = (nZ + 2 * int(np.prod(np.asarray(shape)) ** (2 / 3) * 8)) * BYTES_PER_TET_VERTEX
    check_bytes(est, "signed_heat_volume: the tet mesh", max_memory)
    report("tet mesh", 0.0)
    if mesher == "tetgen":
        Fz = None
        if faces is not None:  # faces of the deduplicated vertices: match by position
            kd = cKDTree(Z)
            Fz = kd.query(np.asarray(X, float)[faces].reshape(-1, 3))[1].reshape(-1, 3)
        P, T, D = tetgen_mesh(Z, Fz, lo, hi, h)
    else:
        P, T, D = delaunay_mesh(Z, lo, hi, h, levels=TET_LEVELS, grading=TET_GRADING)
    nV = len(P)
    check_bytes(nV * BYTES_PER_TET_VERTEX, f"signed_heat_volume: the tet mesh of {nV:,} vertices", max_memory)
    check_work(nV, SECONDS_PER_QUERY, f"signed_heat_volume: the tet mesh of {nV:,} vertices")
    keep = tet_quality(P, T) >= TET_MIN_QUALITY
    timings["mesh"] = time.perf_counter() - t0
    report("tet mesh", 1.0)

    t0 = time.perf_counter()
    tt = positive(float(t_coef) * h * h if t is None else t, "t (= t_coef h^2)")
    domain = TetDomain(P, T, D, keep, nZ, comp, tt, theta=theta)
    core = SignedHeatCore(domain)
    S = domain.prepare(src, shift=(mode != "zero" or lam is not None))     # hard "zero" is not shifted
    report("heat (step I)", 0.0)
    Y = core.unit_field(core.diffuse(S))
    report("heat (step I)", 1.0)
    timings["step1"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    report("poisson (step III)", 0.0)
    phi, shift = core.poisson_step(S, domain.divergence(Y), mode, lam)
    if shift:
        phi = core.shift(S, phi)
    used = domain.used
    if (~used).any():  # vertices in no kept tet: interpolate from the rest
        phi[~used] = _eval(P, T[keep], None, phi, P[~used], None, exclude=~used)
    report("poisson (step III)", 1.0)
    timings["step3"] = time.perf_counter() - t0
    fr = frame if frame is not None else _IDENTITY
    field = TetField(P, T, phi, D) if fr.identity else FramedTetField(fr, P, T, phi, D)
    field.meta = {"method": "signed heat (tet)", "t": float(fr.area(tt)), "h": float(fr.length(h)), "timings": timings,
                  "n_vertices": nV, "n_tets": len(T), "n_input_points": nZ, "n_dropped_tets": int((~keep).sum()),
                  "level_set_constraint": mode, "soft_weight": lam, "step1": "yukawa", "mesher": mesher,
                  "n_components": int(comp.max()) + 1}
    return field


class FramedTetField(TetField):
    """A :class:`~gsdf.TetField` in input units whose evaluation and isosurfaces run in the input's frame.

    ``vertices`` / ``values`` are in input units; queries are mapped into the frame (exact, power-of-two
    scale), located there with the frame-unit Delaunay locator, and the distance mapped back, so that
    evaluating at 1e±150 neither overflows nor underflows.
    """

    def __init__(self, frame, P, T, phi, delaunay=None):
        super().__init__(frame.point(P), T, frame.length(phi))
        self.frame = frame
        self._inner = TetField(P, T, phi, delaunay)

    def __call__(self, Q) -> np.ndarray:
        from gsdf._checks import as_points

        Q = as_points(Q, "Q", allow_empty=True)
        return self.frame.length(self._inner(self.frame.queries(Q, "Q")))

    def isosurface(self, level: float = 0.0, report: bool = False):
        out = self._inner.isosurface(float(self.frame.inverse_length(float(level))), report=report)
        return (self.frame.point(out[0]),) + tuple(out[1:])


def _eval(P, T, D, phi, Q, field=None, exclude=None):
    if field is not None:
        return field(Q)
    if exclude is not None:  # nearest used vertices, inverse-distance weighted
        idx = np.flatnonzero(~exclude)
        d, nb = cKDTree(P[idx]).query(Q, k=4)
        w = 1.0 / np.maximum(d, 1e-300)
        return (w * phi[idx][nb]).sum(axis=1) / w.sum(axis=1)
    return TetField(P, T, phi)(Q)
