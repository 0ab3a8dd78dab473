"""The signed heat method in volumes (Feng & Crane 2024, §8.1–8.2): regular grids and tetrahedral meshes."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from gsdf._checks import T_COEF_MAX, as_mesh, as_points, choice, integer, nonnegative, positive
from gsdf._normalize import Frame
from gsdf.grid import PAD, Grid
from gsdf._checks import progress_callback
from gsdf.heat._core import LEVEL_SETS
from gsdf.heat._yukawa import YukawaTree
from gsdf.heat.volume._sources import Sources, _cloud_sources, _mesh_sources, check_cloud, mesh_sources, point_sources

__all__ = ["signed_heat_volume", "VolumeHeatOptions", "YukawaTree", "mesh_sources", "point_sources", "Sources",
           "volume_grid_box", "input_spacing"]

MAX_RESOLUTION = 4096


@dataclass
class VolumeHeatOptions:
    """Options of :func:`signed_heat_volume` beyond the input, the domain, its box and the diffusion time.

    Attributes
    ----------
    level_set_constraint : {"zero", "multiple", "none"}
        The level-set constraint of Step III (§7.1). ``"zero"`` (default): the zero level set goes through the
        input — on grids the per-cell rows (the area-weighted mean of the trilinear rows of the cell's sources),
        on tets φ = 0 on every input vertex and Steiner point. ``"multiple"``: φ constant on each connected
        component of the input (faces sharing vertices; clouds: the near-neighbour graph). ``"none"``: only the
        final shift (the area-weighted mean of φ over the sources is 0).
    soft_weight : float, None or "auto"
        A number c replaces the hard constraint by a penalty: on grids c Σ_f a_f φ(b_f)² / h⁴ (CG, about the
        cost of the unconstrained solve), on tets c Σ (φ(z_i) − φ(z_0))² over the input points; then the shift.
        None: the hard constraint (on grids an augmented Lagrangian: a factorization up to 50k nodes, CG above).
        ``"auto"`` (default): c = 10 for ``"zero"`` on grids, the hard constraint otherwise.
    t_scale : {"grid", "input"}
        The h of t = t_coef · h²: the grid spacing (default; on tets the lattice spacing near the input), or the
        input's own spacing (:func:`input_spacing`: mean edge length, or mean neighbour distance of a cloud).
    theta : float >= 0
        Cluster error tolerance of the tree-accelerated Yukawa sum of Step I (:class:`YukawaTree`); 0 sums
        every source directly.
    mesher : {"delaunay", "tetgen"}
        Tets only: the Delaunay tetrahedralization of the input points and a graded lattice (default), or the
        conforming constrained Delaunay mesh of the optional ``tetgen`` package (AGPL, ``pip install tetgen``).
    max_memory : int, optional
        Byte limit of the solve (default: :func:`gsdf._memory.available_bytes`); larger grids or tet meshes are
        refused before any work.
    progress : callable, optional
        ``progress(stage, fraction)``, ``fraction`` in [0, 1]; stages "heat (step I)", "poisson (step III)" and
        on tets "tet mesh".

    Examples
    --------
    >>> from gsdf.heat.volume import VolumeHeatOptions
    >>> VolumeHeatOptions(level_set_constraint="none").soft_weight
    'auto'
    """

    level_set_constraint: str = "zero"
    soft_weight: float | str | None = "auto"
    t_scale: str = "grid"
    theta: float = 1.5
    mesher: str = "delaunay"
    max_memory: int | None = None
    progress: Callable[[str, float], None] | None = None

    def __post_init__(self):  # a ValueError naming the attribute, at construction ("auto" is resolved per domain)
        self._checked("grid")

    def _checked(self, domain: str) -> dict:
        """The options validated for ``domain`` (ValueError naming the option): a dict with ``mode`` and ``lam``
        (the soft weight, or None for the hard constraint) in place of the two constraint fields."""
        mode = choice(self.level_set_constraint, "level_set_constraint", set(LEVEL_SETS))
        lam = self.soft_weight
        if isinstance(lam, str) and lam == "auto":
            lam = 10.0 if domain == "grid" and mode == "zero" else None
        lam = None if lam is None else positive(lam, "soft_weight")
        max_memory = None if self.max_memory is None else integer(self.max_memory, "max_memory")
        return dict(mode=mode, lam=lam, t_scale=choice(self.t_scale, "t_scale", {"grid", "input"}),
                    theta=nonnegative(self.theta, "theta"),
                    mesher=choice(self.mesher, "mesher", {"delaunay", "tetgen"}),
                    max_memory=max_memory, progress=progress_callback(self.progress))


def _input_positions(mesh, points):
    """(sources, positions, faces, frame): the input validated once and mapped into its frame
    (:mod:`gsdf._normalize`: centred, power-of-two scale, so the mapping is exact and results are
    scale-covariant)."""
    if (mesh is None) == (points is None):
        raise ValueError("pass exactly one of mesh=(V, F) or points=(P, N)")
    if mesh is not None:
        try:
            V, F = mesh
        except (TypeError, ValueError) as exc:
            raise ValueError("mesh: expected a pair (V, F)") from exc
        V, F = as_mesh(V, F)
        frame = Frame.of_mesh(V, F) if len(F) else Frame.of(V)
        V = frame.geometry(V, "V")
        return _mesh_sources(V, F), V, F, frame
    try:
        P, N = points
    except (TypeError, ValueError) as exc:
        raise ValueError("points: expected a pair (P, N); N are the normals") from exc
    P, N = check_cloud(P, N)
    frame = Frame.of(P)
    P = frame.geometry(P, "P")
    return _cloud_sources(P, N), P, None, frame


def input_spacing(X, F=None) -> float:
    """The input's own length scale: mean edge length of the triangles ``F`` over ``X``, or for a cloud the mean
    distance from each point to its 6 nearest neighbours (about the mean edge of its tufted cover, §8.4). This is
    the ``h`` of t = t_coef · h² that signedheat3d uses on grids (``meanEdgeLength``)."""
    X = np.asarray(X, float)
    if F is not None and len(F):
        E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
        L = np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1)
        L = L[L > 0]
        if len(L):
            return float(L.mean())
    from scipy.spatial import cKDTree

    k = min(7, len(X))
    if k < 2:
        raise ValueError('t_scale="input" needs at least 2 distinct input points')
    d = cKDTree(X).query(X, k)[0][:, 1:]
    d = d[d > 0]
    if not len(d):
        raise ValueError('t_scale="input": all input points coincide')
    return float(d.mean())


def volume_grid_box(X, resolution, bbox_min=None, bbox_max=None, pad: float = PAD):
    """The grid box and node counts used by :func:`signed_heat_volume`.

    With an int ``resolution``, :meth:`gsdf.Grid.fit` of the box (``resolution`` nodes along the longest side,
    cubic cells); with three ints the box is used exactly. Missing box corners default to the input's box
    padded by ``pad`` × its diagonal. Raises ValueError when the box does not contain the input ``X``.

    Returns ``(bbox_min, bbox_max, shape)``.
    """
    X = as_points(X, "input")
    lo = None if bbox_min is None else as_points(bbox_min, "bbox_min")[0]
    hi = None if bbox_max is None else as_points(bbox_max, "bbox_max")[0]
    return _grid_box(X, resolution, lo, hi, pad)


def _grid_box(X, resolution, lo=None, hi=None, pad: float = PAD, frame=None):
    """:func:`volume_grid_box` of validated positions ``X`` and corners ``lo``, ``hi`` ((3,) or None); with the
    ``frame`` they are in, its errors name the boxes in the caller's units."""
    def user(a):
        return a if frame is None else frame.point(np.asarray(a, dtype=np.float64)[None])[0]

    xlo, xhi = X.min(axis=0), X.max(axis=0)
    diag = float(np.linalg.norm(xhi - xlo))
    if diag == 0:
        diag = 1.0
    lo = xlo - pad * diag if lo is None else lo
    hi = xhi + pad * diag if hi is None else hi
    if np.any(hi <= lo):
        raise ValueError(f"bbox_max {user(hi)} must exceed bbox_min {user(lo)} on every axis")
    tol = 1e-9 * max(diag, float(np.abs(hi - lo).max()))
    if np.any(xlo < lo - tol) or np.any(xhi > hi + tol):
        raise ValueError(f"the bounding box [{user(lo)}, {user(hi)}] does not contain the input (input box "
                         f"[{user(xlo)}, {user(xhi)}])")
    if np.ndim(resolution) == 0:
        r = integer(resolution, "resolution", lo=2)
        if r > MAX_RESOLUTION:
            raise ValueError(f"resolution: {r} is absurdly large (at most {MAX_RESOLUTION})")
        grid = Grid.fit((lo, hi), r)
        return grid.bbox_min, grid.bbox_max, grid.shape
    res = np.asarray(resolution).ravel()
    if res.shape != (3,):
        raise ValueError(f"resolution: expected an int or three ints, got {resolution!r}")
    shape = tuple(integer(v, "resolution", lo=2) for v in res.tolist())
    if max(shape) > MAX_RESOLUTION:
        raise ValueError(f"resolution: {shape} is absurdly large (at most {MAX_RESOLUTION} per axis)")
    return lo, hi, tuple(int(s) for s in shape)


def signed_heat_volume(mesh=None, points=None, domain: str = "grid", resolution=64, bbox_min=None, bbox_max=None,
                       t_coef: float = 1.0, *, options: VolumeHeatOptions | None = None):
    """Generalized signed distance in a volume by the signed heat method (Feng & Crane 2024, §8).

    Step I is the Yukawa potential of the input's vector sources (the closed form of the short-time heat flow
    in R³, summed by :class:`YukawaTree`, or on grids one screened solve on the grid,
    :mod:`gsdf.heat.grid._screened`), Step II normalizes it, Step III solves the Poisson problem with the
    level-set constraint (§7.1) and the shift (Alg. 13).

    Parameters
    ----------
    mesh : (V, F), optional
        Triangle mesh or soup (V (n, 3) float, F (m, 3) int): holes, flips and self-intersections are fine.
    points : (P, N), optional
        Oriented point cloud; normals need not be unit length. Point areas are estimated (§3.1 of Barill 2018).
    domain : {"grid", "tet"}, default "grid"
        Regular grid (§8.2) or tetrahedral mesh (§8.1: Delaunay of the input points and a lattice graded toward
        them, h = the grid spacing near the input, :mod:`gsdf.heat.tet._mesh`).
    resolution : int or (3,) ints, default 64
        Grid nodes along the longest side (cubic cells), or exact node counts per axis. The error falls about
        linearly with the spacing; time and memory grow with the number of nodes.
    bbox_min, bbox_max : (3,) float, optional
        Box of the domain; defaults to the input's box padded by 10 % of its diagonal. Must contain the input.
    t_coef : float, default 1.0
        Diffusion time t = t_coef · h² (§10 of the seed: t = h²), h set by ``options.t_scale``: smaller follows
        the input more closely, larger smooths over holes and noise (see the guide page "Choosing a method").
    options : VolumeHeatOptions, optional
        Level-set constraint, soft penalty, the scale of t, the Yukawa tree tolerance, the tet mesher, a memory
        limit and a progress callback (:class:`VolumeHeatOptions`).

    Returns
    -------
    GridField or TetField
        Signed distance on the grid nodes (tet vertices), negative inside; ``field(Q)``, ``field.isosurface(level)``;
        ``field.meta`` holds t, the timings of the steps and the constraint used.

    Raises
    ------
    ValueError
        Neither or both of ``mesh`` and ``points``, bad arrays, a box that does not contain the input, a bad
        resolution or option, a grid too large for the memory limit.

    Notes
    -----
    Everything runs in the input's frame (centred, power-of-two scale: exact), so φ of ``s·V`` is ``s·φ`` from
    1e-150 to 1e150; the returned field, ``t`` and ``meta`` are in input units.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> i = np.arange(2000) + 0.5
    >>> phi, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
    >>> P = np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])
    >>> f = gsdf.signed_heat_volume(points=(P, P), resolution=32)
    >>> d = f([[0, 0, 0], [1.1, 0, 0]])
    >>> bool(d[0] < -0.8 and abs(d[1] - 0.1) < 0.05)
    True
    >>> g = gsdf.signed_heat_volume(points=(P, P), resolution=16,
    ...                             options=gsdf.VolumeHeatOptions(level_set_constraint="none"))
    """
    from gsdf.threads import blas_region

    domain = choice(domain, "domain", {"grid", "tet"})
    t_coef = positive(t_coef, "t_coef", most=T_COEF_MAX)
    if options is None:
        options = VolumeHeatOptions()
    elif not isinstance(options, VolumeHeatOptions):
        raise ValueError(f"options: expected a gsdf.VolumeHeatOptions, got {type(options).__name__}")
    opt = options._checked(domain)
    # BLAS on one thread (or the explicit gsdf.threads setting) for the whole run: the CG loops of Step III
    # call BLAS dot / norm on 10⁴–10⁶-vectors, where threads cost more than they save
    with blas_region():
        return _signed_heat_volume(mesh, points, domain, resolution, bbox_min, bbox_max, t_coef, opt)


def _signed_heat_volume(mesh, points, domain, resolution, bbox_min, bbox_max, t_coef, opt):
    """The body of :func:`signed_heat_volume` (options checked, BLAS already limited)."""
    from gsdf.heat.volume._solve import solve_grid, solve_tet

    src, X, F, frame = _input_positions(mesh, points)
    # world-unit options into the frame (exact: power-of-two scale)
    if bbox_min is not None:
        bbox_min = frame.queries(as_points(bbox_min, "bbox_min"), "bbox_min")[0]
    if bbox_max is not None:
        bbox_max = frame.queries(as_points(bbox_max, "bbox_max"), "bbox_max")[0]
    lo, hi, shape = _grid_box(X, resolution, bbox_min, bbox_max, frame=frame)
    t = positive(t_coef * input_spacing(X, F) ** 2, "t") if opt["t_scale"] == "input" else None
    common = dict(t_coef=t_coef, t=t, mode=opt["mode"], lam=opt["lam"], theta=opt["theta"],
                  max_memory=opt["max_memory"], progress=opt["progress"], frame=frame)
    if domain == "tet":
        return solve_tet(src, X, F, lo, hi, shape, mesher=opt["mesher"], **common)
    return solve_grid(src, lo, hi, shape, **common)
