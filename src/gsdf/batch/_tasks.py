"""The per-item tasks of a batch: plain functions of one input (a path or a loaded :class:`Geometry`).

Each task returns a dict of numpy arrays, exactly what ``gsdf batch`` writes to the item's ``.npz``:

=================  ============================================================================================
task               arrays (``F`` = the ``dtype`` option, float32 by default)
=================  ============================================================================================
``sdf-samples``    ``points`` (n, 3) F, ``sdf`` (n,) F (negative inside)
``occupancy``      ``points`` (n, 3) F, ``occupancy`` (n,) bool (inside), ``winding`` (n,) F
``sdf-grid``       ``sdf`` (R, R, R) F (negative inside), node (i, j, k) at ``bbox_min + (i, j, k) * spacing``;
                   ``bbox_min``, ``bbox_max`` (3,) float64, ``spacing`` (3,) float64
``surface``        ``vertices`` (nv, 3) F, ``faces`` (nf, 3) int64 (outward oriented); with the option
                   ``surface_format`` ("ply", "obj", "off", "stl") :func:`gsdf.run_batch` also writes the mesh
                   next to the item's ``.npz``
every task         ``center`` (3,) float64 and ``scale`` () float64: stored coordinates are
                   ``(x_input - center) / scale`` and stored distances ``d_input / scale`` (identity for
                   ``normalize="none"``)
=================  ============================================================================================

Normalisation frames (``normalize``): ``"sphere"`` maps the input into the unit ball (centre of the bounding
box, scale = the largest vertex distance from it), ``"cube"`` into [-1, 1]³ (scale = half the longest box side),
``"none"`` keeps the input's coordinates. Every task works in one cube, fixed in the frame: centred on the
bounding box, half-side ``1 + margin`` frame scales — so every item of a dataset normalized the same way shares
the same box, as learning pipelines expect (DeepSDF, Occupancy Networks). Uniform samples are drawn in it, and the
grids of ``sdf-grid`` and ``surface`` are its :class:`gsdf.Grid` of ``resolution`` nodes per side. Near-surface
offsets are fractions of the frame scale. With ``normalize="none"`` the samples use the sphere frame's scale and
the grids the cube frame's (half the longest side, the tightest cube). So the same input gives the same samples
for every ``normalize``, up to the stored transform.

Signs come from the generalized winding number at 1/2 (Barill et al. 2018 §4; robust to holes, flips and
soups) or from the signed heat method's zero level set (Feng & Crane 2024 §8.2). Random sampling is seeded
from ``seed`` and the input's content (its vertex/face arrays), so results do not depend on which worker or
machine ran the item.
"""

from __future__ import annotations

import dataclasses
import hashlib
import inspect
import os

import numpy as np

from gsdf._checks import _real, choice, flag, integer, nonnegative, positive
from gsdf._memory import SECONDS_PER_QUERY, check_bytes, check_work
from gsdf.grid import Grid
from gsdf.io._geometry import Geometry, load_geometry

NORMALIZE = ("none", "sphere", "cube")
DTYPES = {"float32": np.float32, "float64": np.float64}


def _geometry(source, estimate_normals=False) -> Geometry:
    if isinstance(source, Geometry):
        return source
    if isinstance(source, (str, os.PathLike)):
        return load_geometry(source, estimate_normals)
    raise ValueError(f"source: expected a path or a gsdf.batch.Geometry, got {type(source).__name__}")


def frame(X, normalize: str = "none"):
    """Centre and scale of the normalisation frame of positions ``X`` (n, 3).

    Returns ``(center (3,), scale, stored_center (3,), stored_scale)``: the frame used for sampling, and the
    transform applied to stored outputs (identity for ``"none"``).
    """
    normalize = choice(normalize, "normalize", NORMALIZE)
    lo, hi = X.min(axis=0), X.max(axis=0)
    c = 0.5 * (lo + hi)
    if normalize == "cube":
        s = 0.5 * float((hi - lo).max())
    else:
        s = float(np.sqrt(((X - c) ** 2).sum(axis=1).max()))
    if not s > 0:
        raise ValueError("the input is degenerate: all its points coincide (no extent to normalise)")
    if normalize == "none":
        return c, s, np.zeros(3), 1.0
    return c, s, c, s


def _rng(geo: Geometry, seed: int, salt: str) -> np.random.Generator:
    key = hashlib.sha256(geo.digest() + salt.encode()).digest()
    return np.random.default_rng([int(seed), int.from_bytes(key[:8], "little")])


def surface_points(geo: Geometry, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` random points on the input: area-weighted on triangles, or drawn from the cloud's points."""
    if not geo.is_mesh:
        return geo.X[rng.integers(0, len(geo.X), n)]
    from gsdf.mesh._geometry import face_areas

    A = face_areas(geo.X, geo.F)
    total = float(A.sum())
    if not total > 0 or not np.isfinite(total):
        raise ValueError("the mesh is degenerate: its triangles have zero total area (nothing to sample)")
    cdf = np.cumsum(A) / total
    f = np.minimum(np.searchsorted(cdf, rng.random(n), side="right"), len(A) - 1)
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)  # uniform on the triangle: (1 - √r1, √r1 (1 - r2), √r1 r2)
    T = geo.X[geo.F[f]]
    return ((1 - s)[:, None] * T[:, 0] + (s * (1 - r2))[:, None] * T[:, 1] + (s * r2)[:, None] * T[:, 2])


def _unsigned(geo: Geometry, Q) -> np.ndarray:
    from gsdf.distance import TriangleDistance, point_cloud_distance

    if geo.is_mesh:
        return TriangleDistance(geo.X, geo.F).query(Q)[0]
    return point_cloud_distance(geo.X, Q)


def _heat(geo: Geometry, resolution, lo, hi):
    """The signed heat method's grid distance (Feng & Crane 2024 §8.2): ``resolution`` an int or three node
    counts, in the box ``[lo, hi]``."""
    from gsdf.heat.volume import signed_heat_volume

    if geo.is_mesh:
        return signed_heat_volume(mesh=(geo.X, geo.F), resolution=resolution, bbox_min=lo, bbox_max=hi)
    return signed_heat_volume(points=(geo.X, geo.N), resolution=resolution, bbox_min=lo, bbox_max=hi)


def cube(X, normalize: str, margin: float, grid: bool = False):
    """The cube a task works in: centre (the bounding box's) and half-side ``(1 + margin)`` frame scales
    (:func:`frame`; for ``normalize="none"`` a grid uses the cube frame, half the longest side)."""
    c, s, _, _ = frame(X, "cube" if grid and normalize == "none" else normalize)
    return c, (1.0 + float(margin)) * s


def _stored(out: dict, c0, s0, dtype) -> dict:
    out["center"] = np.asarray(c0, np.float64)
    out["scale"] = np.float64(s0)
    return out


def _sample_queries(geo, n, uniform_fraction, sigmas, s, centre, half, rng):
    """DeepSDF-style queries: surface points offset by N(0, σ²) at each scale σ·s, plus uniform ones in the
    cube centre ± half. Counts: ``round(n·uniform_fraction)`` uniform, the rest split evenly over the scales."""
    n_uniform = int(round(n * uniform_fraction))
    n_near = n - n_uniform
    parts = []
    if n_near and sigmas:
        counts = [n_near // len(sigmas) + (i < n_near % len(sigmas)) for i in range(len(sigmas))]
        S = surface_points(geo, n_near, rng)
        start = 0
        for k, sigma in zip(counts, sigmas):
            parts.append(S[start:start + k] + rng.normal(0.0, sigma * s, (k, 3)))
            start += k
    elif n_near:
        n_uniform = n
    parts.append(centre + half * rng.uniform(-1.0, 1.0, (n_uniform, 3)))
    return np.concatenate(parts)


@dataclasses.dataclass(frozen=True)
class SdfSamplesOptions:
    """The sampling and input options of :func:`sdf_samples` (the same names as ``gsdf batch`` flags).

    Attributes
    ----------
    uniform_fraction : float in [0, 1], default 0.1
        Share of the samples drawn uniformly in the task's cube (the rest: near the surface).
    sigmas : sequence of float, default (0.05, 0.0158)
        Near-surface offset scales, fractions of the frame scale: DeepSDF's variances 0.0025 and 0.00025 in the
        unit sphere.
    margin : float in [0, 1e6], default 0.05
        The task's cube has half-side ``1 + margin`` frame scales (the module docstring).
    heat_resolution : int, default 64
        With ``sign="heat"``: nodes along the longest side of the signed heat method's grid.
    beta : float, optional
        Fast winding number accuracy (default 2 for meshes, 2.3 for clouds).
    estimate_normals : bool, default False
        For a cloud without normals: PCA normals oriented away from the centroid.

    Examples
    --------
    >>> from gsdf import SdfSamplesOptions
    >>> SdfSamplesOptions(sigmas=(0.01,)).uniform_fraction
    0.1
    >>> out = sdf_samples("bunny.off", options=SdfSamplesOptions(uniform_fraction=0.5))   # doctest: +SKIP
    """

    uniform_fraction: float = 0.1
    sigmas: tuple = (0.05, 0.0158)
    margin: float = 0.05
    heat_resolution: int = 64
    beta: float | None = None
    estimate_normals: bool = False

    def __post_init__(self):
        _check_fields(self)


@dataclasses.dataclass(frozen=True)
class OccupancyOptions:
    """The sampling and input options of :func:`occupancy` (the same names as ``gsdf batch`` flags).

    Attributes
    ----------
    uniform_fraction : float in [0, 1], default 1.0
        Share of the points drawn uniformly in the task's cube (the rest: near the surface).
    sigmas : sequence of float, default (0.01,)
        Near-surface offset scales, fractions of the frame scale.
    margin : float in [0, 1e6], default 0.1
        The task's cube has half-side ``1 + margin`` frame scales (the module docstring).
    beta : float, optional
        Fast winding number accuracy (default 2 for meshes, 2.3 for clouds).
    estimate_normals : bool, default False
        For a cloud without normals: PCA normals oriented away from the centroid.

    Examples
    --------
    >>> out = occupancy("scan.xyz", options=OccupancyOptions(estimate_normals=True))   # doctest: +SKIP
    """

    uniform_fraction: float = 1.0
    sigmas: tuple = (0.01,)
    margin: float = 0.1
    beta: float | None = None
    estimate_normals: bool = False

    def __post_init__(self):
        _check_fields(self)


def _check_fields(opts) -> None:
    """A ValueError naming the attribute of an options dataclass, at construction (the checks of the flags)."""
    for f in dataclasses.fields(opts):
        v = getattr(opts, f.name)
        if isinstance(f.default, bool):
            flag(v, f.name)  # a switch given in Python: True or False, not the words of a CSV cell
        elif v is not None or f.name != "beta":
            _CHECKS[f.name](v, f.name)


def _task_options(task, values: dict) -> dict:
    """The flat, validated options of a task called from the library: its keyword values and the fields of its
    options dataclass (``options=None``: the defaults)."""
    flat = {k: v for k, v in values.items() if k not in ("source", "options")}
    opts = values.get("options")
    cls = OPTIONS_CLASSES.get(task)
    if cls is not None:
        if opts is None:
            opts = cls()
        if not isinstance(opts, cls):
            raise ValueError(f"options: expected a gsdf.batch.{cls.__name__}, got {type(opts).__name__}")
        flat.update(dataclasses.asdict(opts))
    return check_options(task, flat, python=True)


def sdf_samples(source, n_samples: int = 250_000, sign: str = "winding", normalize: str = "none", seed: int = 0,
                dtype: str = "float32", options: SdfSamplesOptions | None = None) -> dict:
    """DeepSDF-style signed distance samples of one mesh, soup or oriented cloud.

    ``n_samples`` queries: ``(1 - uniform_fraction)`` of them are surface points (area-weighted) moved by
    Gaussian offsets, split evenly over the scales ``sigmas`` (× the frame scale), the rest uniform in the task's
    cube (the module docstring). ``|sdf|`` is the exact distance to the triangles (nearest point of a cloud); the
    sign is negative where the fast winding number exceeds 1/2 (``sign="winding"``, Barill et al. 2018 §4), or
    where the signed heat method's distance (a grid of ``heat_resolution`` nodes along its longest side) is
    negative (``sign="heat"``, Feng & Crane 2024 §8.2).

    Parameters
    ----------
    source : str, os.PathLike or Geometry
        The input.
    n_samples : int
        Number of samples n.
    sign : {"winding", "heat"}
    normalize : {"none", "sphere", "cube"}
        Output frame (see the module docstring); the transform is stored as ``center``, ``scale``.
    seed : int
        Random seed (combined with the input's content).
    dtype : {"float32", "float64"}
    options : SdfSamplesOptions, optional
        The sampling distribution and input options.

    Returns
    -------
    dict
        ``points`` (n, 3), ``sdf`` (n,) in ``dtype``; ``center`` (3,), ``scale``.

    Examples
    --------
    >>> out = sdf_samples("bunny.off", n_samples=10000, normalize="sphere")     # doctest: +SKIP
    >>> out["points"].shape, out["sdf"].dtype                                     # doctest: +SKIP
    ((10000, 3), dtype('float32'))
    """
    o = _task_options("sdf-samples", locals())
    check_samples_size(o["n_samples"], "n_samples")
    geo = _geometry(source, o["estimate_normals"])
    c, s, c0, s0 = frame(geo.X, o["normalize"])
    centre, half = cube(geo.X, o["normalize"], o["margin"])
    rng = _rng(geo, o["seed"], "sdf-samples")
    Q = _sample_queries(geo, o["n_samples"], o["uniform_fraction"], o["sigmas"], s, centre, half, rng)
    d = _unsigned(geo, Q)
    if o["sign"] == "winding":
        inside = geo.winding(o["beta"])(Q) > 0.5
    else:
        m = 1.1 * half  # the heat grid holds every query, the tails of the Gaussian offsets included
        m = max(m, float(np.abs(Q - centre).max()) * 1.001)
        inside = _heat(geo, o["heat_resolution"], centre - m, centre + m)(Q) < 0
    dt = DTYPES[o["dtype"]]
    return _stored({"points": ((Q - c0) / s0).astype(dt), "sdf": (np.where(inside, -d, d) / s0).astype(dt)},
                   c0, s0, dt)


def occupancy(source, n_points: int = 100_000, normalize: str = "none", seed: int = 0, dtype: str = "float32",
              options: OccupancyOptions | None = None) -> dict:
    """Occupancy-Networks-style inside/outside labels of points, from the generalized winding number.

    By default all ``n_points`` are uniform in the task's cube (the module docstring); ``uniform_fraction < 1``
    moves the rest near the surface (offsets ``sigmas``). A point is inside where the fast winding number
    exceeds 1/2 (Barill et al. 2018 §4).

    Returns
    -------
    dict
        ``points`` (n, 3) and ``winding`` (n,) in ``dtype``, ``occupancy`` (n,) bool; ``center``, ``scale``.

    Examples
    --------
    >>> out = occupancy("soup.obj", n_points=50000)       # doctest: +SKIP
    >>> out["occupancy"].mean()                            # doctest: +SKIP
    0.21
    """
    o = _task_options("occupancy", locals())
    check_samples_size(o["n_points"], "n_points")
    geo = _geometry(source, o["estimate_normals"])
    c, s, c0, s0 = frame(geo.X, o["normalize"])
    centre, half = cube(geo.X, o["normalize"], o["margin"])
    rng = _rng(geo, o["seed"], "occupancy")
    Q = _sample_queries(geo, o["n_points"], o["uniform_fraction"], o["sigmas"], s, centre, half, rng)
    w = geo.winding(o["beta"])(Q)
    dt = DTYPES[o["dtype"]]
    return _stored({"points": ((Q - c0) / s0).astype(dt), "occupancy": w > 0.5, "winding": w.astype(dt)},
                   c0, s0, dt)


GRID_BYTES_PER_NODE = 96  # node positions (24), distance + winding + sign (24), outputs and temporaries
SAMPLE_BYTES = 160        # a sample's position (24), offsets and choices (48), distance, winding, sign (24), outputs


def check_grid_size(resolution: int) -> None:
    """Refuse a dense R³ grid whose working memory (``GRID_BYTES_PER_NODE`` × R³, :func:`gsdf._memory.check_bytes`)
    or work (R³ queries, :func:`gsdf._memory.check_work`) is beyond the limits, before the input is read or
    anything allocated: a clear per-item error, not an out-of-memory kill."""
    n = int(resolution) ** 3
    what = f"resolution: a {resolution}^3 grid ({n:,} nodes)"
    check_bytes(GRID_BYTES_PER_NODE * n, what)
    check_work(n, SECONDS_PER_QUERY, what)


def check_samples_size(n: int, name: str) -> None:
    """Refuse ``n`` samples whose memory (``SAMPLE_BYTES`` each) or work (a distance and a winding number query
    each) is beyond the limits, before the input is read."""
    what = f"{name}: {n:,} samples"
    check_bytes(SAMPLE_BYTES * n, what)
    check_work(n, 2 * SECONDS_PER_QUERY, what)


def task_grid(X, resolution: int, normalize: str = "none", margin: float = 0.05) -> Grid:
    """The grid of ``sdf-grid`` and ``surface``: :meth:`gsdf.Grid.fit` of the task's cube (:func:`cube`),
    ``resolution`` nodes per side."""
    centre, half = cube(X, normalize, margin, grid=True)
    return Grid.fit((centre - half, centre + half), resolution)


def sdf_grid(source, resolution: int = 128, method: str = "fast", normalize: str = "none", margin: float = 0.05,
             beta=None, dtype: str = "float32", estimate_normals: bool = False) -> dict:
    """Signed distance on a dense cubic grid of ``resolution``³ nodes around one input; negative inside.

    The grid is :func:`task_grid`: the task's cube (half-side ``1 + margin`` frame scales, the module
    docstring), ``resolution`` nodes per side. Methods: ``"fast"`` — :func:`gsdf.signed_distance_grid`
    (exact distance to the triangles or nearest point of a cloud, signed by the fast winding number at 1/2);
    ``"heat"`` — the signed heat method on the same grid (Feng & Crane 2024 §8.2; a generalized signed
    distance, smooth across holes); ``"pat"`` — Points as Tori (oriented clouds only; Feng 2026 ch. 5).

    Returns
    -------
    dict
        ``sdf`` (R, R, R) in ``dtype`` (C order, x slowest); ``bbox_min``, ``bbox_max``, ``spacing`` (3,);
        ``center``, ``scale``. All in the stored frame.

    Examples
    --------
    >>> out = sdf_grid("bunny.off", resolution=64)        # doctest: +SKIP
    >>> out["sdf"].shape                                    # doctest: +SKIP
    (64, 64, 64)
    """
    o = check_options("sdf-grid", locals_without_source(locals()), python=True)
    check_grid_size(o["resolution"])
    geo = _geometry(source, o["estimate_normals"])
    if o["method"] == "pat" and geo.is_mesh:
        raise ValueError('method "pat" (Points as Tori) needs an oriented point cloud, not a mesh; '
                         'use "fast" or "heat"')
    c, s, c0, s0 = frame(geo.X, o["normalize"])
    grid = task_grid(geo.X, o["resolution"], o["normalize"], o["margin"])
    if o["method"] == "heat":
        values = _heat(geo, grid.shape, *grid.box).values
    elif o["method"] == "pat":
        from gsdf.tori import PointsAsTori

        values = PointsAsTori(geo.X, geo.N).signed_distance(grid.points())
    else:
        from gsdf.ops import signed_distance_grid

        kw = dict(V=geo.X, F=geo.F) if geo.is_mesh else dict(V=None, points=(geo.X, geo.N))
        values = signed_distance_grid(resolution=grid, beta=o["beta"], **kw).values
    dt = DTYPES[o["dtype"]]
    lo0, hi0 = (grid.bbox_min - c0) / s0, (grid.bbox_max - c0) / s0
    return _stored({"sdf": (np.asarray(values).reshape(grid.shape) / s0).astype(dt), "bbox_min": lo0,
                    "bbox_max": hi0, "spacing": (hi0 - lo0) / (np.array(grid.shape) - 1)}, c0, s0, dt)


def surface(source, resolution: int = 128, method: str = "winding", normalize: str = "none", margin: float = 0.05,
            bisection: int = 10, beta=None, dtype: str = "float32", estimate_normals: bool = False) -> dict:
    """A watertight surface of one input: the winding number's 1/2 level set, or the signed heat zero set.

    ``method="winding"``: marching cubes on the fast winding number sampled on :func:`task_grid`, vertices moved
    onto the level set by ``bisection`` steps along their grid edges (Barill et al. 2018 Fig. 9).
    ``method="heat"``: the zero level set of the signed heat method's distance on that grid (Feng & Crane 2024
    §8.2).

    Returns
    -------
    dict
        ``vertices`` (nv, 3) in ``dtype``, ``faces`` (nf, 3) int64 (outward oriented); ``center``, ``scale``.

    Examples
    --------
    >>> out = surface("soup.obj", resolution=96)           # doctest: +SKIP
    >>> out["faces"].shape[1]                               # doctest: +SKIP
    3
    """
    o = check_options("surface", locals_without_source(locals()), python=True)
    check_grid_size(o["resolution"])
    geo = _geometry(source, o["estimate_normals"])
    c, s, c0, s0 = frame(geo.X, o["normalize"])
    grid = task_grid(geo.X, o["resolution"], o["normalize"], o["margin"])
    if o["method"] == "heat":
        V, F = _heat(geo, grid.shape, *grid.box).isosurface(0.0)
    else:
        from gsdf.contour import extract_isosurface

        V, F = extract_isosurface(geo.winding(o["beta"]), resolution=grid, level=0.5, bisection_steps=o["bisection"])
    dt = DTYPES[o["dtype"]]
    return _stored({"vertices": ((V - c0) / s0).astype(dt), "faces": np.asarray(F, np.int64)}, c0, s0, dt)


def input_topology(geo: Geometry):
    """What the manifest records about an input mesh: ``open`` (some edge has one face), ``non_manifold`` (an edge
    in more than two faces, or faces around a vertex in several fans), ``oriented`` (neighbouring faces agree),
    ``components`` (face-connected pieces), ``degenerate_faces``; None for a point cloud
    (:func:`gsdf.mesh_topology`)."""
    if not geo.is_mesh:
        return None
    from gsdf.mesh._topology import mesh_topology

    t = mesh_topology(geo.X, geo.F)
    return {"open": not t["closed"], "non_manifold": not (t["edge_manifold"] and t["vertex_manifold"]),
            "oriented": bool(t["oriented"]), "components": int(t["components"]),
            "degenerate_faces": int(t["degenerate_faces"])}


# ------------------------------------------------------------------------------------------------------------
# option validation: one table for the library calls, the CLI and per-item manifest options
# ------------------------------------------------------------------------------------------------------------

TASKS = {"sdf-samples": sdf_samples, "occupancy": occupancy, "sdf-grid": sdf_grid, "surface": surface}
OPTIONS_CLASSES = {"sdf-samples": SdfSamplesOptions, "occupancy": OccupancyOptions}
#: Options of what is written besides the ``.npz`` (not of the computation): ``surface_format`` ("ply", "obj",
#: "off", "stl" or None) writes the surface task's mesh also as ``<item>.<format>`` next to its ``.npz``.
WRITE_OPTIONS = {"surface": {"surface_format": None}}
SURFACE_FORMATS = ("ply", "obj", "off", "stl")
TASK_ALIASES = {"sdf_samples": "sdf-samples", "sdf_grid": "sdf-grid"}


def locals_without_source(values: dict) -> dict:
    return {k: v for k, v in values.items() if k != "source"}


def _float(x, name) -> float:
    if isinstance(x, (bool, np.bool_)):
        raise ValueError(f"{name}: expected a number, got the bool {x!r}")
    if not isinstance(x, str):  # a CSV cell is parsed; anything else is the one real-number check
        return _real(x, name)
    try:
        return float(x)
    except ValueError:
        raise ValueError(f"{name}: expected a number, got {x!r}") from None


def _unit(x, name):
    x = _float(x, name)
    if not 0.0 <= x <= 1.0:
        raise ValueError(f"{name}: must lie in [0, 1], got {x}")
    return x


#: Largest ``margin`` and ``sigmas`` (frame scales): a cube or an offset a million times the input's size says
#: nothing of its shape, and near 1e308 the cube's side overflows (NaN samples).
SPREAD_MAX = 1e6


def _nonneg(x, name):
    return nonnegative(_float(x, name), name, most=SPREAD_MAX)


def _sigmas(x, name):
    if isinstance(x, str):
        x = [t for t in x.split(",") if t.strip()]
    if np.ndim(x) != 1:
        raise ValueError(f"{name}: expected a list of positive numbers, got {x!r}")
    return tuple(positive(_float(v, name), name, most=SPREAD_MAX) for v in x)


def _flag(x, name):
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, str) and x.strip().lower() in ("true", "1", "yes", "false", "0", "no"):
        return x.strip().lower() in ("true", "1", "yes")
    raise ValueError(f"{name}: expected true or false, got {x!r}")


def _int(lo):
    def check(x, name):
        if isinstance(x, str):
            try:
                x = int(x)
            except ValueError:
                raise ValueError(f"{name}: expected an integer, got {x!r}") from None
        return integer(x, name, lo=lo)
    return check


def _grid_side(lo):
    """A grid's nodes per side: an integer >= ``lo`` whose cube a grid can have (:data:`gsdf.grid.MAX_NODES`),
    whether or not this item uses it (``heat_resolution`` only with ``sign="heat"``)."""
    def check(x, name):
        from gsdf.grid import MAX_NODES

        r = _int(lo)(x, name)
        if r ** 3 > MAX_NODES:
            raise ValueError(f"{name}: {r:,} nodes per side make a grid of {float(r) ** 3:.3g} nodes, more than a "
                             f"grid can have ({MAX_NODES:.3g})")
        return r
    return check


def _optional_positive(x, name):
    from gsdf.winding._fast import BETA_MAX

    return None if x is None or x == "" else positive(_float(x, name), name, most=BETA_MAX)


_CHECKS = {
    "n_samples": _int(1), "n_points": _int(1), "resolution": _grid_side(2), "bisection": _int(0),
    "heat_resolution": _grid_side(8), "seed": _int(0),
    "sign": lambda x, n: choice(x, n, {"winding", "heat"}),
    "normalize": lambda x, n: choice(x, n, set(NORMALIZE)),
    "dtype": lambda x, n: choice(x, n, set(DTYPES)),
    "uniform_fraction": _unit, "margin": _nonneg, "sigmas": _sigmas, "beta": _optional_positive,
    "estimate_normals": _flag,
}
_METHODS = {"sdf-grid": {"fast", "heat", "pat"}, "surface": {"winding", "heat"}}


def task_name(task) -> str:
    """The canonical name of a task (``"sdf-samples"``, ...), or ValueError listing the tasks."""
    name = TASK_ALIASES.get(task, task)
    if name not in TASKS:
        raise ValueError(f"task: unknown task {task!r}; expected one of {', '.join(TASKS)}")
    return name


def task_defaults(task) -> dict:
    """The options of a task and their defaults (its keywords and the fields of its options dataclass)."""
    task = task_name(task)
    sig = inspect.signature(TASKS[task])
    out = {k: p.default for k, p in sig.parameters.items() if k not in ("source", "options")}
    if task in OPTIONS_CLASSES:
        out.update(dataclasses.asdict(OPTIONS_CLASSES[task]()))
    out.update(WRITE_OPTIONS.get(task, {}))
    return out


def check_options(task, options: dict, where: str = "", python: bool = False) -> dict:
    """Validate the options of ``task``: every key must be one of its parameters; returns them with defaults
    filled in and values converted (strings from CSV manifests are parsed). Raises ValueError naming the option.
    ``python``: the options come from a Python call, where a switch must be True or False (not ``"yes"``).
    """
    task = task_name(task)
    defaults = task_defaults(task)
    prefix = f"{where}: " if where else ""
    unknown = sorted(set(options) - set(defaults))
    if unknown:
        raise ValueError(f"{prefix}option {unknown[0]!r} does not apply to task {task!r} "
                         f"(its options: {', '.join(defaults)})")
    out = dict(defaults)
    out.update(options)
    for k, v in out.items():
        if k == "method":
            out[k] = choice(v, f"{prefix}method", _METHODS[task])
        elif k == "surface_format":
            out[k] = None if v in (None, "", "none") else choice(str(v).lower().lstrip("."), f"{prefix}{k}",
                                                                  SURFACE_FORMATS)
        elif python and isinstance(defaults[k], bool):
            out[k] = flag(v, f"{prefix}{k}")
        elif v is not None or k != "beta":
            out[k] = _CHECKS[k](v, f"{prefix}{k}")
    if "uniform_fraction" in out and out["uniform_fraction"] < 1 and not out["sigmas"]:
        raise ValueError(f"{prefix}sigmas: empty, but uniform_fraction < 1 asks for near-surface samples")
    for k in ("n_samples", "n_points"):    # sizes that do not depend on the input: refused before any item runs
        if k in out:
            check_samples_size(out[k], f"{prefix}{k}")
    return out


def run_task(task, source, options: dict) -> dict:
    """Run ``task`` on ``source`` with the flat ``options`` (names as in :func:`task_defaults`):
    ``run_task("sdf-grid", path, {"resolution": 64})``."""
    task = task_name(task)
    fn = TASKS[task]
    options = {k: v for k, v in options.items() if k not in WRITE_OPTIONS.get(task, {})}
    keywords = set(inspect.signature(fn).parameters) - {"source", "options"}
    kw = {k: v for k, v in options.items() if k in keywords}
    rest = {k: v for k, v in options.items() if k not in keywords}
    if task in OPTIONS_CLASSES:
        fields = {f.name for f in dataclasses.fields(OPTIONS_CLASSES[task])}
        unknown = sorted(set(rest) - fields)
        if unknown:
            raise ValueError(f"option {unknown[0]!r} does not apply to task {task!r} "
                             f"(its options: {', '.join(task_defaults(task))})")
        return fn(source, options=OPTIONS_CLASSES[task](**rest), **kw)
    if rest:
        raise ValueError(f"option {sorted(rest)[0]!r} does not apply to task {task!r} "
                         f"(its options: {', '.join(task_defaults(task))})")
    return fn(source, **kw)
