"""The signed heat method in volumes (Feng & Crane 2024, §8.1–8.2): regular grids and tetrahedral meshes."""

from __future__ import annotations

import numpy as np

from gsdf._checks import as_mesh, as_points, choice, integer, positive
from gsdf._normalize import Frame
from gsdf.grid import PAD, Grid
from gsdf.heat.volume._memory import check_memory
from gsdf.heat.volume._sources import Sources, mesh_sources, point_sources
from gsdf.heat._yukawa import YukawaTree

__all__ = ["signed_heat_volume", "YukawaTree", "mesh_sources", "point_sources", "Sources", "volume_grid_box", "input_spacing"]

MAX_RESOLUTION = 4096


def _input_positions(mesh, points):
    """(sources, positions, faces, frame): everything in the input's frame (gsdf._normalize: centred,
    power-of-two scale, so the mapping is exact and results are scale-covariant)."""
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
        return mesh_sources(V, F), V, F, frame
    try:
        P, N = points
    except (TypeError, ValueError) as exc:
        raise ValueError("points: expected a pair (P, N); N are the normals") from exc
    P = as_points(P, "P")
    frame = Frame.of(P)
    P = frame.geometry(P, "P")
    return point_sources(P, N), P, None, frame


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
    xlo, xhi = X.min(axis=0), X.max(axis=0)
    diag = float(np.linalg.norm(xhi - xlo))
    if diag == 0:
        diag = 1.0
    lo = xlo - pad * diag if bbox_min is None else as_points(bbox_min, "bbox_min")[0]
    hi = xhi + pad * diag if bbox_max is None else as_points(bbox_max, "bbox_max")[0]
    if np.any(hi <= lo):
        raise ValueError(f"bbox_max {hi} must exceed bbox_min {lo} on every axis")
    tol = 1e-9 * max(diag, float(np.abs(hi - lo).max()))
    if np.any(xlo < lo - tol) or np.any(xhi > hi + tol):
        raise ValueError(f"the bounding box [{lo}, {hi}] does not contain the input (input box [{xlo}, {xhi}])")
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
                       t_coef: float = 1.0, level_set_constraint: str = "zero", soft_weight="auto",
                       theta: float = 1.5, max_memory=None, progress=None, t_scale: str = "grid", **kwargs):
    """Generalized signed distance in a volume by the signed heat method (Feng & Crane 2024, §8).

    Parameters
    ----------
    mesh : (V, F), optional
        Triangle mesh or soup (V (n, 3) float, F (m, 3) int): holes, flips and self-intersections are fine.
    points : (P, N), optional
        Oriented point cloud; normals need not be unit length. Point areas are estimated (§3.1 of Barill 2018).
    domain : {"grid", "tet"}
        Regular grid (§8.2; step I by one screened solve on the grid, or by the Yukawa tree walk —
        option ``step1`` "auto" / "yukawa" / "heat", :mod:`gsdf.heat.grid._screened`) or tetrahedral mesh (§8.1: Delaunay of the input
        points and an octree-like lattice graded toward them, h = the grid spacing near the input; see
        :mod:`gsdf.heat.tet._mesh` for its options ``step1``, ``mesher``, ``levels``, …).
    resolution : int or (3,) ints
        Grid nodes along the longest side (cubic cells), or exact node counts per axis.
    bbox_min, bbox_max : (3,) float, optional
        Box of the domain; defaults to the input's box padded by 10 % of its diagonal. Must contain the input.
        (Everything runs in the input's frame — centred, power-of-two scale, exact — so φ of ``s·V`` is ``s·φ``
        from 1e-150 to 1e150; the returned field, ``t`` and ``meta`` are in input units.)
    t_coef : float
        Diffusion time t = t_coef · h² (§10 of the seed: t = h² is accurate), h set by ``t_scale``.
    t_scale : {"grid", "input"}
        "grid" (default): h is the grid spacing (near the input, on tets). "input": h is the input's own
        spacing (:func:`input_spacing`: mean edge length, or mean neighbour distance of a cloud), as signedheat3d
        does. Step I is a convolution, so t is free of the grid: a shorter t follows the input more closely —
        "input" is markedly more accurate on clean meshes and scans with holes (every real input of
        bench/RESULTS.md) — while the longer default averages more sources and is more robust to flipped or
        noisy normals (the Points-as-Tori corruption landscape).
    level_set_constraint : {"zero", "multiple", "none"}
        "zero" (default; measured more accurate than "none" on every benchmark input, bench/RESULTS.md): the
        zero level set goes through the input, exactly — on grids the per-cell rows (the area-weighted mean of
        the trilinear rows of the cell's sources) by an augmented Lagrangian (a factorization up to 50k nodes,
        CG above: slow above ~40³; pass ``soft_weight`` for the fast penalty), on tets φ = 0 on every input
        vertex (and Steiner point). "multiple": φ constant on each connected component of the input (faces
        sharing vertices; clouds: near-neighbour graph). "none": φ shifted so its area-weighted mean over the
        sources is 0.
    soft_weight : float, None or "auto"
        "auto" (default): for "zero" on grids the penalty below with c = 10 — the hard grid constraint costs
        minutes at 64³ and was less accurate than the penalty in both cases measured (a holed sphere at 20³: mean error
        0.0058 vs 0.0042; the broken bunny at 32³: 0.0170 vs 0.0153) — and the hard constraint on tets.
        None: the hard constraint on both. A number c: replace the hard constraint by a penalty, on grids
        c Σ_f a_f φ(b_f)² / h⁴, CG-solved in about the time of the unconstrained solve; on tets
        λ Σ (φ(z_i) − φ(z_0))² over the input points. Then the same shift as "none". The older spelling
        ``constraint="soft"`` (with ``constraint_weight=10``) / ``constraint="exact"`` is still accepted on grids.
    theta : float
        Cluster error tolerance of the tree-accelerated Yukawa sum (see :class:`YukawaTree`).
    max_memory : int, optional
        Byte limit of the solve (default 80 % of available memory); larger grids are refused before any work.
    progress : callable, optional
        ``progress(stage, fraction)`` (:mod:`gsdf.heat._core`; the older ``(stage, done, total)`` also works).

    Returns
    -------
    GridField or TetField
        Signed distance on the grid nodes (tet vertices), negative inside; ``field(Q)``, ``field.isosurface(level)``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> from gsdf.heat.volume import signed_heat_volume
    >>> i = np.arange(2000) + 0.5
    >>> phi, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
    >>> P = np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])
    >>> f = signed_heat_volume(points=(P, P), resolution=32)
    >>> d = f([[0, 0, 0], [1.1, 0, 0]])
    >>> bool(d[0] < -0.8 and abs(d[1] - 0.1) < 0.05)
    True
    """
    from gsdf.threads import blas_region

    # BLAS on one thread (or the explicit gsdf.threads setting) for the whole run: the CG loops of step III
    # call BLAS dot / norm on 10⁴–10⁶-vectors, where OpenBLAS's threads cost more than they save (32³ grid:
    # 12 ms per dot with 2 threads on a shared machine vs 20 µs with one; bench/bench_heat_volume_speed.py).
    with blas_region():
        return _signed_heat_volume(mesh, points, domain, resolution, bbox_min, bbox_max, t_coef,
                                   level_set_constraint, soft_weight, theta, max_memory, progress, t_scale, kwargs)


def _signed_heat_volume(mesh, points, domain, resolution, bbox_min, bbox_max, t_coef, level_set_constraint,
                        soft_weight, theta, max_memory, progress, t_scale, kwargs):
    """The body of :func:`signed_heat_volume` (BLAS already limited)."""
    domain = choice(domain, "domain", {"grid", "tet"})
    t_coef = positive(t_coef, "t_coef")
    level_set_constraint = choice(level_set_constraint, "level_set_constraint", {"none", "zero", "multiple"})
    t_scale = choice(t_scale, "t_scale", {"grid", "input"})
    import inspect

    from gsdf.heat.volume._solve import solve_grid, solve_tet

    # options of the domain's solver (documented there); anything else is refused by name, not as a TypeError
    own = {"src", "X", "lo", "hi", "shape", "bbox_min", "bbox_max", "frame", "faces", "t_coef", "level_set_constraint",
           "soft_weight", "max_memory", "progress", "theta"}
    allowed = set(inspect.signature(solve_tet if domain == "tet" else solve_grid).parameters) - own
    unknown = sorted(set(kwargs) - allowed)
    if unknown:
        raise ValueError(f"signed_heat_volume: unknown option(s) {', '.join(unknown)} for domain={domain!r}; "
                         f"known: {', '.join(sorted(allowed))}")
    if isinstance(soft_weight, str) and soft_weight == "auto":
        soft_weight = (10.0 if domain == "grid" and level_set_constraint == "zero" and "constraint" not in kwargs
                       else None)
    src, X, F, frame = _input_positions(mesh, points)
    # world-unit options into the frame (exact: power-of-two scale)
    if bbox_min is not None:
        bbox_min = frame.queries(as_points(bbox_min, "bbox_min"), "bbox_min")[0]
    if bbox_max is not None:
        bbox_max = frame.queries(as_points(bbox_max, "bbox_max"), "bbox_max")[0]
    if "t" in kwargs and kwargs["t"] is not None:
        kwargs["t"] = frame.inverse_area(positive(kwargs["t"], "t"))
    lo, hi, shape = volume_grid_box(X, resolution, bbox_min, bbox_max)
    if t_scale == "input" and kwargs.get("t") is None:
        kwargs["t"] = t_coef * input_spacing(X, F) ** 2
    if domain == "tet":
        from gsdf.heat.volume._solve import solve_tet

        return solve_tet(src, X, lo, hi, shape, t_coef=t_coef, level_set_constraint=level_set_constraint,
                         soft_weight=soft_weight, max_memory=max_memory, progress=progress, theta=theta, faces=F,
                         frame=frame, **kwargs)
    from gsdf.heat.volume._solve import solve_grid

    check_memory(int(np.prod(shape)), max_memory)
    return solve_grid(src, lo, hi, shape, t_coef=t_coef, level_set_constraint=level_set_constraint,
                      soft_weight=soft_weight, theta=theta, progress=progress, frame=frame, **kwargs)
