"""Voxelization by thresholding the (fast) generalized winding number at voxel centers.

Barill et al. 2018, *Fast Winding Numbers for Soups and Clouds*, §4 "Voxelization" (Fig. 11): a voxel is
*inside* when the winding number of the input at the voxel center is at least 1/2. Because the winding
number degrades gracefully on open boundaries, self-intersections and inconsistent components, this works
on triangle soups and oriented point clouds, not only on closed meshes (Fig. 4). The fast (tree) evaluation
with ``beta = 2`` (triangles) / ``beta = 2.3`` (points) gives the same voxelization as the exact sum in
practice (§4, "Even a small value of beta = 2 produces the identical voxelization").

The voxel centers are the nodes of a :class:`gsdf.Grid` (``resolution`` voxels = nodes along the longest side);
a voxel is the cube of side ``spacing`` centred on its node (:meth:`gsdf.Grid.voxel_box`).
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import as_mesh, as_normals, as_occupancy, as_points, as_weights, flag, positive, progress_callback
from gsdf._memory import SECONDS_PER_QUERY, check_bytes, check_work, grid_bytes
from gsdf.mesh._topology import manifold_report, split_nonmanifold_vertices

__all__ = [
    "winding_grid",
    "voxelize",
    "save_voxels",
    "load_voxels",
    "voxels_to_mesh",
]

#: Voxel centers evaluated per winding-number call (bounds memory; progress is reported per chunk).
CHUNK = 1 << 20


def _bbox(bbox_min, bbox_max) -> tuple[np.ndarray, np.ndarray]:
    lo = as_points(bbox_min, "bbox_min")
    hi = as_points(bbox_max, "bbox_max")
    if lo.shape[0] != 1 or hi.shape[0] != 1:
        raise ValueError(f"bbox_min/bbox_max: expected 3 numbers each, got shapes {lo.shape} and {hi.shape}")
    lo, hi = lo[0], hi[0]
    if np.any(hi <= lo):
        raise ValueError(f"bbox_max {hi} must exceed bbox_min {lo} on every axis")
    return lo, hi


# ----------------------------------------------------------------------------------------------------------
# winding evaluation on the grid
# ----------------------------------------------------------------------------------------------------------


def _winding_object(mesh, points, beta):
    """Validate the input and build the reusable fast winding-number evaluator; also return its points."""
    if (mesh is None) == (points is None):
        raise ValueError("give exactly one of mesh=(V, F) or points=(P, N) / (P, N, areas)")
    kw = {} if beta is None else {"beta": positive(beta, "beta")}
    if mesh is not None:
        if not isinstance(mesh, (tuple, list)) or len(mesh) != 2:
            raise ValueError("mesh: expected a pair (V, F)")
        V, F = as_mesh(*mesh)
        from gsdf.winding import FastWindingNumber  # lazy: gsdf.winding owns the numba kernels

        return FastWindingNumber(V, F, **kw), V[np.unique(F)]  # box of the referenced vertices only
    if not isinstance(points, (tuple, list)) or len(points) not in (2, 3):
        raise ValueError("points: expected a tuple (P, N) or (P, N, areas)")
    P = as_points(points[0], "P")
    if points[1] is None:
        raise ValueError("N: the winding number of a point cloud needs oriented normals (got None)")
    N = as_normals(points[1], P.shape[0], "N")
    areas = None
    if len(points) == 3 and points[2] is not None:
        areas = as_weights(points[2], P.shape[0], "areas")
    from gsdf.winding import FastWindingNumberPoints

    return FastWindingNumberPoints(P, N, areas=areas, **kw), P


def winding_grid(mesh=None, points=None, resolution=100, beta=None, progress=None):
    """Fast generalized winding number of a mesh/soup or an oriented point cloud on the nodes of a grid.

    This is :func:`voxelize` without the final threshold (Barill et al. 2018, §4 "Voxelization"): the nodes are
    the voxel centers.

    Parameters
    ----------
    mesh : tuple (V, F), optional
        Triangle mesh or soup, ``V`` (n, 3) float, ``F`` (m, 3) int. Evaluated with
        :class:`gsdf.winding.FastWindingNumber`.
    points : tuple (P, N) or (P, N, areas), optional
        Oriented point cloud, evaluated with :class:`gsdf.winding.FastWindingNumberPoints` (``areas=None``:
        estimated). Give exactly one of ``mesh`` and ``points``.
    resolution : int or gsdf.Grid, default 100
        Nodes (voxels) along the longest side of the input's bounding box grown by :data:`gsdf.grid.PAD` × its
        diagonal (:meth:`gsdf.Grid.around`; a mesh's box is that of its referenced vertices); or the
        :class:`gsdf.Grid` to sample.
    beta : float, optional
        Accuracy parameter of the tree approximation (§3.4); ``None`` uses the evaluator's default
        (2.0 for triangles, 2.3 for points).
    progress : callable ``progress(stage, fraction)``, optional
        Called after each chunk of nodes with ``stage="winding numbers"`` and the fraction done.

    Returns
    -------
    gsdf.GridField
        The winding numbers on the grid's nodes (``.values`` (nx, ny, nz), ``.bbox_min``, ``.bbox_max``).

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.ops import winding_grid
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> winding_grid(mesh=(V, F), resolution=8).shape
    (8, 8, 8)
    """
    from gsdf.field import GridField
    from gsdf.grid import as_grid

    wn, X = _winding_object(mesh, points, beta)
    progress = progress_callback(progress)
    grid = as_grid(resolution, X=X)
    shape = grid.shape
    # the grid (8 B/node, +1 B for voxelize's occupancy) plus one chunk of centres, indices and values
    what = f"winding grid: {shape[0]}x{shape[1]}x{shape[2]} voxels"
    check_bytes(grid_bytes(shape, 9) + 64 * min(CHUNK, grid_bytes(shape, 1)), what)
    check_work(grid_bytes(shape, 1), SECONDS_PER_QUERY, what)
    total = grid.size
    W = np.empty(total, dtype=np.float64)
    for s in range(0, total, CHUNK):
        e = min(total, s + CHUNK)
        W[s:e] = np.asarray(wn(grid.points(np.arange(s, e, dtype=np.int64))), dtype=np.float64).reshape(-1)
        progress("winding numbers", e / total)
    return GridField(W.reshape(shape), *grid.box)


def voxelize(mesh=None, points=None, resolution=100, beta=None, progress=None):
    """Voxelize a mesh, triangle soup or oriented point cloud: inside where the winding number >= 1/2.

    Barill et al. 2018, §4 "Voxelization" and Fig. 11: the occupancy of each cubic voxel is decided by the fast
    generalized winding number at its center, which is robust to holes, self-intersections, duplicated and
    inconsistently connected geometry (Fig. 4), and works on point clouds (§3.2).

    Parameters
    ----------
    mesh, points, resolution, beta, progress
        As in :func:`winding_grid` (``resolution``: voxels along the longest side, or the :class:`gsdf.Grid`
        of the voxel centers).

    Returns
    -------
    occupancy : (nx, ny, nz) bool
        True for voxels whose center has winding number >= 1/2.
    bbox_min, bbox_max : (3,) float64
        Corners of the voxels (:meth:`gsdf.Grid.voxel_box`; voxel size ``(bbox_max - bbox_min) /
        occupancy.shape``, equal on all axes).

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf import Grid
    >>> from gsdf.ops import voxelize
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> occ, lo, hi = voxelize(mesh=(V, F), resolution=Grid.around(V, 16, pad=0.0))
    >>> bool(occ[1, 1, 1]), bool(occ[-1, -1, -1])
    (True, False)
    """
    W = winding_grid(mesh=mesh, points=points, resolution=resolution, beta=beta, progress=progress)
    return (W.values >= 0.5, *W.grid.voxel_box())


# ----------------------------------------------------------------------------------------------------------
# output
# ----------------------------------------------------------------------------------------------------------


def _occupancy(occ) -> np.ndarray:
    return as_occupancy(occ, "occ")


def save_voxels(path, occ, bbox_min, bbox_max) -> None:
    """Write a voxelization to a compressed ``.npz`` file (atomically; another extension is a ValueError).

    Keys: ``occupancy`` (nx, ny, nz) bool, ``bbox_min``, ``bbox_max`` (3,) float64 (grid corners),
    ``voxel_size`` (3,) float64 and ``kind = "voxels"``. Read back with :func:`load_voxels`.

    Parameters
    ----------
    path : str or os.PathLike
        The file; it must end in ``.npz``.
    occ : (nx, ny, nz) bool or 0/1 array
        Occupancy of the cells (e.g. from :func:`gsdf.voxelize`).
    bbox_min, bbox_max : (3,) float
        Outer corners of the grid of cells, model units.

    Raises
    ------
    ValueError
        Another extension, a non-boolean ``occ``, a bad box, a failed write.

    Examples
    --------
    >>> import numpy as np, tempfile, os, gsdf
    >>> from gsdf.ops import load_voxels
    >>> p = os.path.join(tempfile.mkdtemp(), "v.npz")
    >>> gsdf.save_voxels(p, np.ones((2, 2, 2), bool), [0, 0, 0], [1, 1, 1])
    >>> int(load_voxels(p)[0].sum())
    8
    """
    from gsdf.io._safe_write import atomic_output, check_output_path

    check_output_path(path, extensions=(".npz",))
    A = _occupancy(occ)
    lo, hi = _bbox(bbox_min, bbox_max)
    with atomic_output(path, extensions=(".npz",)) as tmp:
        np.savez_compressed(tmp, occupancy=A, bbox_min=lo, bbox_max=hi, voxel_size=(hi - lo) / np.array(A.shape),
                            kind="voxels")


def load_voxels(path):
    """Read a file written by :func:`save_voxels`; returns ``(occupancy, bbox_min, bbox_max)``."""
    from gsdf._checks import numpy_file

    path = numpy_file(path, "path")
    try:
        with np.load(path, allow_pickle=False) as d:
            return _occupancy(d["occupancy"]), *_bbox(d["bbox_min"], d["bbox_max"])
    except (OSError, KeyError, ValueError) as exc:
        raise ValueError(f"{path}: not a gsdf voxel file ({exc})") from exc


def voxels_to_mesh(occ, bbox_min, bbox_max, report: bool = False):
    """Boundary of the occupied voxels as a triangle mesh (two triangles per exposed cell face).

    Every face between an occupied and an empty cell (or the outside of the grid) becomes a quad split in
    two triangles, oriented with the normal pointing out of the occupied region. Grid nodes are shared, so
    the result is closed and welded — except where occupied cells touch only along an edge or at a corner,
    which no welded surface can represent manifoldly. There the rule is: *cells that share only an edge or a
    corner are separate*; the faces of each cell at such an edge are paired with each other, and a grid node
    gets one copy per fan of faces around it. Isolated edge and corner contacts then become closed,
    edge- and vertex-manifold surfaces with coincident (unwelded) vertex copies at those nodes. An edge
    contact whose two cells are also connected around the edge's end nodes (through other occupied cells)
    cannot be cut by copying vertices: such edges stay non-manifold (four faces). ``report=True`` returns
    what the mesh is (:func:`gsdf.mesh._topology.manifold_report`: closed, edge_manifold, vertex_manifold,
    welded and the counts of non-manifold edges and vertices).

    Parameters
    ----------
    occ : (nx, ny, nz) bool
        Occupancy, e.g. from :func:`voxelize`.
    bbox_min, bbox_max : (3,) float
        Grid corners.
    report : bool, default False
        Also return what the mesh is (closed, manifold, welded, and the counts of non-manifold elements).

    Returns
    -------
    V : (n, 3) float64
        Used grid nodes.
    F : (m, 3) int64
        Outward-oriented triangles; ``(0, 3)`` arrays when nothing is occupied.
    report : dict
        Only with ``report=True``: closed / edge-manifold / vertex-manifold / welded and counts.

    Raises
    ------
    ValueError
        A non-boolean ``occ``, a bad box, a grid too large for the memory.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.ops import voxels_to_mesh
    >>> V, F = voxels_to_mesh(np.ones((1, 1, 1), bool), [0, 0, 0], [1, 1, 1])
    >>> V.shape, F.shape
    ((8, 3), (12, 3))
    """
    A = _occupancy(occ)
    lo, hi = _bbox(bbox_min, bbox_max)
    report = flag(report, "report")
    # padded copy and masks (~4 B/cell), plus ~300 B per exposed cell face (at most 6 per occupied cell:
    # indices, quads, triangles, the unique of the node ids)
    check_bytes(grid_bytes(np.array(A.shape) + 2, 4) + 300 * 6 * int(np.count_nonzero(A)),
                f"voxels_to_mesh: a {A.shape[0]}x{A.shape[1]}x{A.shape[2]} occupancy grid")
    shape = np.array(A.shape, dtype=np.int64)
    h = (hi - lo) / shape
    nn = shape + 1  # nodes per axis
    strides = np.array([nn[1] * nn[2], nn[2], 1], dtype=np.int64)
    P = np.pad(A, 1, constant_values=False)
    tris = []
    cells = []  # flat index of the occupied cell each triangle bounds (pairs faces at non-manifold edges)
    for d in range(3):
        e1, e2 = (d + 1) % 3, (d + 2) % 3
        sl_lo = [slice(1, -1)] * 3
        sl_hi = [slice(1, -1)] * 3
        sl_lo[d] = slice(0, -1)
        sl_hi[d] = slice(1, None)
        a, b = P[tuple(sl_lo)], P[tuple(sl_hi)]  # cells on the low / high side of node plane i (0..n_d)
        for sign, mask in ((+1, b & ~a), (-1, a & ~b)):
            # sign=+1: occupied cell is on the high side -> outward normal is -e_d; and vice versa
            idx = np.argwhere(mask)  # (k, 3) with idx[:, d] = node plane, others = cell index
            if idx.shape[0] == 0:
                continue
            base = idx @ strides
            u, v = strides[e1], strides[e2]
            q = np.column_stack((base, base + u, base + u + v, base + v))  # normal +e_d (e1 x e2 = e_d)
            if sign > 0:
                q = q[:, ::-1]
            tris.append(q[:, [0, 1, 2]])
            tris.append(q[:, [0, 2, 3]])
            cell = idx.copy()
            cell[:, d] -= sign < 0  # sign=+1: the occupied cell is on the high side of node plane i
            cid = np.ravel_multi_index(cell.T, A.shape)
            cells += [cid, cid]
    if not tris:
        empty = (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
        return (*empty, manifold_report(*empty)) if report else empty
    F = np.concatenate(tris)
    C = np.concatenate(cells)
    used, F = np.unique(F, return_inverse=True)
    F = F.reshape(-1, 3).astype(np.int64)
    ijk = np.column_stack(np.unravel_index(used, tuple(nn))).astype(np.float64)
    V = lo + ijk * h
    rep = manifold_report(V, F)
    if not (rep["edge_manifold"] and rep["vertex_manifold"]):
        tri_cell = C

        def same_cell(hs):
            """At an edge with 4 faces (two cells touching along it) pair the two faces of each cell."""
            cs = tri_cell[hs // 3]
            o = np.argsort(cs, kind="stable")
            hs, cs = hs[o], cs[o]
            return [(hs[i], hs[i + 1]) for i in range(0, len(hs) - 1, 2) if cs[i] == cs[i + 1]]

        V, F = split_nonmanifold_vertices(V, F, pair_ok=same_cell)
        rep = manifold_report(V, F)
    return (V, F, rep) if report else (V, F)
