"""Regular grids of nodes: :class:`Grid`, with one rule for ``resolution`` and one for padding.

Every function of gsdf that samples something on a grid (``signed_distance_grid``, ``winding_grid``,
``voxelize``, ``extract_isosurface``, ``slice_contours``, ``signed_heat_volume``, the batch tasks, the CLI) builds
its grid here:

* **resolution** — the number of *nodes* along the longest side of the box. The spacing is
  ``h = longest side / (resolution - 1)`` on every axis (cubic cells); a shorter side of length ``e`` gets
  ``ceil(e / h) + 1`` nodes (at least 2), and the box's upper corner moves up to ``lo + (n - 1) h`` so that it
  ends on a node (:meth:`Grid.fit`).
* **pad** — the default box is the bounding box of the input grown by ``pad`` times its diagonal on every side
  (:func:`padded_box`, :meth:`Grid.around`); the default is :data:`PAD`.

A voxel of a grid is the cube of side ``h`` centred on a node (:meth:`Grid.voxel_box`): a voxelization of
``resolution`` voxels along the longest side samples the voxel centres, i.e. the nodes.

Example
-------
>>> import numpy as np
>>> from gsdf.grid import Grid
>>> g = Grid.fit(([0, 0, 0], [2, 1, 0.5]), resolution=5)
>>> g.shape, g.spacing.tolist()
((5, 3, 2), [0.5, 0.5, 0.5])
>>> g.points()[-1].tolist()
[2.0, 1.0, 0.5]
"""

from __future__ import annotations

import math

import numpy as np

from gsdf._checks import as_points, integer, nonnegative, positive

__all__ = ["Grid", "PAD", "padded_box", "grid_points"]

#: The default padding of a box around an input: a fraction of its bounding-box diagonal, on every side.
PAD = 0.1

#: The most nodes a grid may have: one float64 value per node must fit the address space of any 64-bit
#: process (2**57 bytes with 5-level paging). What fits but cannot be allocated now is refused by each function
#: that allocates (``gsdf._memory``), so a large grid stays usable for sampling a few of its nodes.
MAX_NODES = 1 << 54


def _corner(x, name: str) -> np.ndarray:
    P = as_points(x, name)
    if P.shape != (1, 3):
        raise ValueError(f"{name}: expected 3 numbers, got shape {np.shape(x)}")
    return P[0]


def _box(box, name: str = "box") -> tuple[np.ndarray, np.ndarray]:
    """``box`` as two (3,) float64 corners, validated (``hi >= lo`` on every axis)."""
    try:
        lo, hi = box
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected two corners (bbox_min, bbox_max), got {box!r}") from None
    lo, hi = _corner(lo, f"{name} (bbox_min)"), _corner(hi, f"{name} (bbox_max)")
    if np.any(hi < lo):
        raise ValueError(f"{name}: bbox_max {hi} must not be below bbox_min {lo} on any axis")
    return lo, hi


def padded_box(X, pad: float = PAD) -> tuple[np.ndarray, np.ndarray]:
    """The bounding box of points ``X`` (n, 3) grown by ``pad`` times its diagonal on every side.

    A single point (zero diagonal) is grown by ``pad`` in absolute units.

    Examples
    --------
    >>> lo, hi = padded_box([[0, 0, 0], [3, 4, 0]], pad=0.1)
    >>> lo.tolist(), hi.tolist()
    ([-0.5, -0.5, -0.5], [3.5, 4.5, 0.5])
    """
    X = as_points(X, "X")
    pad = nonnegative(pad, "pad", most=1e6)
    lo, hi = X.min(axis=0), X.max(axis=0)
    d = diagonal(lo, hi) or 1.0
    return lo - pad * d, hi + pad * d


def diagonal(lo, hi) -> float:
    """``|hi - lo|`` without underflow or overflow of the squares (scaled by the largest component first): the
    diagonal of a box at 1e-300 or 1e300 is exact, where ``np.linalg.norm`` gives 0 or inf."""
    half = 0.5 * np.asarray(hi, dtype=np.float64) - 0.5 * np.asarray(lo, dtype=np.float64)  # no overflow
    m = float(np.abs(half).max())
    if m == 0.0 or not np.isfinite(m):
        return 2.0 * m
    return 2.0 * m * float(np.linalg.norm(half / m))


class Grid:
    """The nodes of a regular 3D grid: ``shape[d]`` evenly spaced nodes from ``box[0][d]`` to ``box[1][d]``.

    Node ``(i, j, k)`` sits at ``bbox_min + (i, j, k) * spacing``; :meth:`points` lists the nodes in C order
    (``k`` fastest), the order of a ``values`` array of shape ``shape``.

    Parameters
    ----------
    box : pair of (3,) float
        ``(bbox_min, bbox_max)``: the first and the last node, model units.
    shape : three ints >= 2
        Nodes per axis.

    Attributes
    ----------
    bbox_min, bbox_max : (3,) float64
        The first and the last node.
    shape : (int, int, int)
        Nodes per axis.
    box, spacing, size
        ``(bbox_min, bbox_max)``; the distance between neighbouring nodes per axis, (3,); the number of nodes.

    Raises
    ------
    ValueError
        A box that is empty or inverted on some axis, fewer than 2 nodes on an axis, or more than
        :data:`MAX_NODES` (2⁵⁴) nodes in all.

    Build one from a resolution with :meth:`fit` (a given box) or :meth:`around` (the padded bounding box of
    an input). Every grid-making function of gsdf takes one as its ``resolution``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> g = gsdf.Grid.around([[0, 0, 0], [3, 4, 0]], resolution=11)     # the box padded by 0.1 of its diagonal
    >>> g.shape, g.spacing.tolist(), g.bbox_min.tolist()
    ((9, 11, 3), [0.5, 0.5, 0.5], [-0.5, -0.5, -0.5])
    >>> gsdf.Grid(([0, 0, 0], [1, 1, 1]), (2, 2, 2)).points().shape
    (8, 3)
    """

    __slots__ = ("bbox_min", "bbox_max", "shape")

    def __init__(self, box, shape):
        lo, hi = _box(box)
        s = np.asarray(shape)
        if s.shape != (3,):
            raise ValueError(f"shape: expected three node counts, got {shape!r}")
        shape = tuple(integer(v, "shape", lo=2) for v in s.tolist())
        if np.any(hi <= lo):
            raise ValueError(f"box: bbox_max {hi} must exceed bbox_min {lo} on every axis")
        n = math.prod(shape)
        if n > MAX_NODES:
            raise ValueError(f"shape: a {'x'.join(str(v) for v in shape)} grid has {n:.3g} nodes, more than a grid "
                             f"can have ({MAX_NODES:.3g}: one float64 per node must fit a 64-bit address space); "
                             "lower the resolution")
        self.bbox_min = lo
        self.bbox_max = hi
        self.shape = shape

    @classmethod
    def fit(cls, box, resolution: int) -> "Grid":
        """A grid of cubic cells over ``box``, ``resolution`` nodes along its longest side.

        The lower corner is kept; the upper corner moves up (by less than one cell) to the last node.

        Parameters
        ----------
        box : pair of (3,) float
            ``(bbox_min, bbox_max)``, model units; ``bbox_max > bbox_min`` on every axis.
        resolution : int
            Nodes along the longest side (>= 2); the other sides get as many as cells of the same size need.

        Returns
        -------
        Grid

        Raises
        ------
        ValueError
            An empty or inverted box, ``resolution < 2``, more than :data:`MAX_NODES` nodes.

        Examples
        --------
        >>> import gsdf
        >>> gsdf.Grid.fit(([0, 0, 0], [2, 1, 0.5]), 5).shape
        (5, 3, 2)
        """
        lo, hi = _box(box)
        r = integer(resolution, "resolution", lo=2)
        ext = hi - lo
        h = positive(ext.max(), "box size") / (r - 1)
        shape = tuple(int(max(2, np.ceil(e / h - 1e-9) + 1)) for e in ext)
        return cls((lo, lo + (np.array(shape) - 1) * h), shape)

    @classmethod
    def around(cls, X, resolution: int, pad: float = PAD) -> "Grid":
        """:meth:`fit` on the bounding box of the points ``X`` grown by ``pad`` times its diagonal.

        Parameters
        ----------
        X : (n, 3) float
            Points (vertices of a mesh, a cloud) that the grid surrounds.
        resolution : int
            Nodes along the longest side of the padded box (>= 2).
        pad : float, default 0.1
            Growth of the box on every side, as a fraction of the points' bounding-box diagonal (>= 0).

        Returns
        -------
        Grid

        Raises
        ------
        ValueError
            Empty or non-finite ``X``, ``resolution < 2``, a negative ``pad``, more than :data:`MAX_NODES`
            nodes.

        Examples
        --------
        >>> import gsdf
        >>> gsdf.Grid.around([[0, 0, 0], [1, 1, 1]], 12, pad=0.0).shape
        (12, 12, 12)
        """
        return cls.fit(padded_box(X, pad), resolution)

    @property
    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """``(bbox_min, bbox_max)``."""
        return self.bbox_min, self.bbox_max

    @property
    def spacing(self) -> np.ndarray:
        """Distance between neighbouring nodes along each axis, (3,)."""
        return (self.bbox_max - self.bbox_min) / (np.array(self.shape) - 1)

    @property
    def size(self) -> int:
        """Number of nodes."""
        return math.prod(int(s) for s in self.shape)

    def axes(self) -> list:
        """The node coordinates along each axis.

        Returns
        -------
        list of three 1-D float64 arrays
            ``np.linspace(bbox_min[d], bbox_max[d], shape[d])`` for d = 0, 1, 2.

        Examples
        --------
        >>> import gsdf
        >>> gsdf.Grid(([0, 0, 0], [1, 1, 1]), (3, 2, 2)).axes()[0].tolist()
        [0.0, 0.5, 1.0]
        """
        return [np.linspace(self.bbox_min[d], self.bbox_max[d], self.shape[d]) for d in range(3)]

    def _flat_index(self, flat_index) -> np.ndarray:
        """``flat_index`` as int64 node numbers, each an integer in [0, number of nodes)."""
        from gsdf._checks import as_values

        A = np.atleast_1d(as_values(flat_index, "flat_index", allow_empty=True))
        if A.ndim != 1:
            raise ValueError(f"flat_index: expected shape (k,), got {A.shape}")
        if not (A == np.round(A)).all():
            raise ValueError("flat_index: expected integer node numbers, got fractions")
        n = 1
        for s in self.shape:
            n *= int(s)
        if A.size and (A.min() < 0 or A.max() >= n):
            raise ValueError(f"flat_index: node number out of range for {n:,} nodes")
        return A.astype(np.int64)

    def points(self, flat_index=None) -> np.ndarray:
        """Node positions in C order (the last axis fastest), or only some of them.

        Parameters
        ----------
        flat_index : (k,) int, optional
            Indices of nodes in that order (to evaluate a large grid in chunks). Default: every node.

        Returns
        -------
        (size, 3) or (k, 3) float64

        Raises
        ------
        ValueError
            All nodes of a grid too large for the available memory (the message says how large).

        Examples
        --------
        >>> import gsdf
        >>> g = gsdf.Grid(([0, 0, 0], [1, 1, 1]), (2, 2, 2))
        >>> g.points([0, 7]).tolist()
        [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
        """
        ax = self.axes()
        if flat_index is not None:
            I = np.unravel_index(self._flat_index(flat_index), self.shape)
            return np.column_stack([ax[d][I[d]] for d in range(3)])
        from gsdf._memory import check_bytes, grid_bytes

        # the node positions (24 B) and, in every caller, at least one float per node and its meshgrid copies
        check_bytes(grid_bytes(self.shape, 56),
                    f"a {'x'.join(str(s) for s in self.shape)} grid of nodes (lower the resolution)")
        X, Y, Z = np.meshgrid(*ax, indexing="ij")
        return np.column_stack((X.ravel(), Y.ravel(), Z.ravel()))

    def voxel_box(self) -> tuple[np.ndarray, np.ndarray]:
        """Corners of the voxels: the cells of side ``spacing`` centred on the nodes.

        Returns
        -------
        (3,) float64, (3,) float64
            The low and the high corner, half a spacing outside the first and the last node.

        Examples
        --------
        >>> import gsdf
        >>> [c.tolist() for c in gsdf.Grid(([0, 0, 0], [1, 1, 1]), (3, 3, 3)).voxel_box()]
        [[-0.25, -0.25, -0.25], [1.25, 1.25, 1.25]]
        """
        h = self.spacing
        return self.bbox_min - 0.5 * h, self.bbox_max + 0.5 * h

    def __eq__(self, other) -> bool:
        return (isinstance(other, Grid) and self.shape == other.shape
                and np.array_equal(self.bbox_min, other.bbox_min) and np.array_equal(self.bbox_max, other.bbox_max))

    __hash__ = None

    def __repr__(self) -> str:
        return f"Grid(({self.bbox_min.tolist()}, {self.bbox_max.tolist()}), {self.shape})"


def as_grid(resolution, *, X=None, box=None, name: str = "resolution") -> Grid:
    """The grid a function samples: ``resolution`` itself when it is a :class:`Grid`, else ``Grid.fit(box,
    resolution)`` when a box is given, else ``Grid.around(X, resolution)``."""
    if isinstance(resolution, Grid):
        if box is not None:
            raise ValueError(f"{name}: a Grid already has its box; do not also pass bbox_min / bbox_max")
        return resolution
    if isinstance(resolution, (bool, np.bool_)) or np.ndim(resolution) != 0:
        raise ValueError(f"{name}: expected an integer >= 2 (nodes along the longest side) or a gsdf.Grid, "
                         f"got {resolution!r}")
    r = integer(resolution, name, lo=2)
    if box is not None:
        return Grid.fit(box, r)
    return Grid.around(X, r)


def grid_points(bbox_min, bbox_max, shape) -> np.ndarray:
    """``Grid((bbox_min, bbox_max), shape).points()``."""
    return Grid((bbox_min, bbox_max), shape).points()
