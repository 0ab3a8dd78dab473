"""Fields: values on a domain, evaluation anywhere, and isosurfaces — what every volumetric method returns."""

from __future__ import annotations

import numpy as np

from gsdf._checks import _array, as_faces, as_points, as_values, finite, query_shaped
from gsdf._memory import SECONDS_PER_NODE
from gsdf.contour._tets import locate_in_tets, marching_tetrahedra
from gsdf.grid import Grid


class Field:
    """The result protocol every gsdf method returns: values on a domain, evaluated anywhere, contoured, saved.

    * ``field(Q)`` — values at query points ``Q`` (q, 3) → (q,);
    * ``field.isosurface(level)`` → ``(V, F)`` for volume fields (:class:`GridField`, :class:`TetField`),
      ``field.isolines(level)`` → list of (k, 3) polylines for fields on surfaces (:class:`SurfaceField`);
    * ``field.save(path)`` — format by extension, one of ``type(field).SAVE_EXTENSIONS``; any other extension is a
      ``ValueError`` listing those (the requested name is never changed). The file is written atomically
      (:mod:`gsdf.io._safe_write`).

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> f = gsdf.GridField(np.zeros((2, 2, 2)), [0, 0, 0], [1, 1, 1])   # every result type is a Field
    >>> isinstance(f, gsdf.Field), f([[0.5, 0.5, 0.5]]).shape
    (True, (1,))
    """

    #: Extensions :meth:`save` can write (lower case, with the dot).
    SAVE_EXTENSIONS: tuple = ()

    def __call__(self, Q) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def isosurface(self, level: float = 0.0):  # pragma: no cover - interface
        """The level set ``field = level`` as a triangle mesh ``(V, F)`` (volume fields; see the subclasses).

        Parameters
        ----------
        level : float, default 0.0
            The value whose level set is extracted, in the field's units.

        Returns
        -------
        V : (n, 3) float64
        F : (m, 3) int64

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> x = np.linspace(-1, 1, 9)
        >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
        >>> V, F = gsdf.GridField(X, [-1] * 3, [1] * 3).isosurface(0.25)      # the plane x = 1/4
        >>> bool(np.allclose(V[:, 0], 0.25))
        True
        """
        raise NotImplementedError

    def save(self, path) -> None:
        """Write the field to ``path``; the format follows the extension (see ``SAVE_EXTENSIONS``).

        Parameters
        ----------
        path : str or os.PathLike
            The file to write, replaced atomically if it exists. Its extension picks the format: one of the
            class's ``SAVE_EXTENSIONS`` (``.npz`` keeps the domain and reads back with :func:`gsdf.load_field`;
            ``.npy`` holds the values alone; ``.vtk``, ``.vti``, ``.vtu``, ``.ply`` open in ParaView).

        Raises
        ------
        ValueError
            For an extension outside ``SAVE_EXTENSIONS`` (the message lists them), a directory, a parent that is
            not a folder, or a failed write.

        Examples
        --------
        >>> import numpy as np, os, tempfile, gsdf
        >>> f = gsdf.GridField(np.zeros((2, 2, 2)), [0, 0, 0], [1, 1, 1])
        >>> p = os.path.join(tempfile.mkdtemp(), "f.vti")
        >>> f.save(p)
        >>> gsdf.load_field(p).shape
        (2, 2, 2)
        """
        from gsdf.io._safe_write import atomic_output, extension_of

        with atomic_output(path, extensions=self.SAVE_EXTENSIONS) as tmp:
            self._write(tmp, extension_of(path))

    def _write(self, path: str, ext: str) -> None:  # pragma: no cover - interface
        raise NotImplementedError


class GridField(Field):
    """Values on the nodes of a regular grid spanning ``[bbox_min, bbox_max]``.

    Parameters
    ----------
    values : (nx, ny, nz) float array
        Node values (at least 2 per axis, finite); node ``(i, j, k)`` sits at ``bbox_min + (i, j, k) * spacing``
        with ``spacing = (bbox_max - bbox_min) / (shape - 1)``.
    bbox_min, bbox_max : (3,) float
        Corners of the grid, model units; ``bbox_max > bbox_min`` on every axis.

    Attributes
    ----------
    values, bbox_min, bbox_max
        As given (float64).
    shape : (int, int, int)
        Nodes per axis.
    spacing : (3,) float64
        Distance between neighbouring nodes along each axis.
    grid : gsdf.Grid
        The grid of the nodes.
    meta : dict
        What the method that made the field records about it (e.g. its parameters); not saved.

    Raises
    ------
    ValueError
        Not a 3D array with at least 2 nodes per axis, NaN or infinite values, an empty or inverted box.

    Notes
    -----
    Calling the field, ``field(Q)``, interpolates it trilinearly at the points ``Q`` (q, 3) and returns (q,)
    values; points outside the box take the value at the nearest point of the box.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.field import GridField
    >>> x = np.linspace(-1, 1, 33)
    >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    >>> f = GridField(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, [-1, -1, -1], [1, 1, 1])
    >>> round(float(f([[0.5, 0.0, 0.0]])[0]), 6)
    0.0
    """

    def __init__(self, values, bbox_min, bbox_max):
        values = as_values(values, "values", finite=False, allow_empty=True)
        if values.ndim != 3 or min(values.shape) < 2:
            raise ValueError(f"values: expected a 3D grid with at least 2 nodes per axis, got shape {values.shape}")
        if not np.isfinite(values).all():
            raise ValueError("values: contains NaN or infinite entries")
        lo = as_points(bbox_min, "bbox_min")[0]
        hi = as_points(bbox_max, "bbox_max")[0]
        if np.any(hi <= lo):
            raise ValueError(f"bbox_max {hi} must exceed bbox_min {lo} on every axis")
        self.values = np.ascontiguousarray(values)
        self.bbox_min = lo
        self.bbox_max = hi
        self.meta: dict = {}

    @property
    def shape(self) -> tuple[int, int, int]:
        """Nodes per axis ``(nx, ny, nz)``."""
        return tuple(self.values.shape)

    @property
    def grid(self) -> Grid:
        """The :class:`gsdf.Grid` of the nodes."""
        return Grid((self.bbox_min, self.bbox_max), self.values.shape)

    @property
    def spacing(self) -> np.ndarray:
        """Distance between neighbouring nodes along each axis, (3,) float64."""
        return (self.bbox_max - self.bbox_min) / (np.array(self.values.shape) - 1)

    def grid_points(self) -> np.ndarray:
        """Node positions in the C order of ``values`` (x slowest).

        Returns
        -------
        (nx * ny * nz, 3) float64

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> gsdf.GridField(np.zeros((2, 3, 2)), [0, 0, 0], [1, 2, 1]).grid_points()[:3].tolist()
        [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
        """
        return self.grid.points()

    @query_shaped()
    def __call__(self, Q) -> np.ndarray:
        """Trilinear interpolation at query points ``Q`` (q, 3); points outside are clamped to the box."""
        Q = as_points(Q, "Q", allow_empty=True, seconds_per_row=SECONDS_PER_NODE)
        n = np.array(self.values.shape)
        t = (Q - self.bbox_min) / self.spacing
        t = np.clip(t, 0.0, n - 1.0)
        i0 = np.minimum(np.floor(t).astype(np.int64), n - 2)
        f = t - i0
        v = self.values
        out = np.zeros(Q.shape[0])
        for dx in (0, 1):
            wx = f[:, 0] if dx else 1.0 - f[:, 0]
            for dy in (0, 1):
                wy = f[:, 1] if dy else 1.0 - f[:, 1]
                for dz in (0, 1):
                    wz = f[:, 2] if dz else 1.0 - f[:, 2]
                    out += wx * wy * wz * v[i0[:, 0] + dx, i0[:, 1] + dy, i0[:, 2] + dz]
        return out

    def isosurface(self, level: float = 0.0, close: bool = False, report: bool = False):
        """The level set ``field = level`` by marching cubes (scikit-image), in world coordinates.

        With ``close=True`` a level set that reaches the box is capped on the box faces (the grid is padded
        with one layer of nodes above the level and the cap vertices are projected back onto the box); the
        result is welded (cap and surface share their seam vertices). Where the level set touches itself at a
        grid node (a pinch), that vertex is split per fan, so the mesh stays vertex-manifold and the report says
        it is not welded.

        Parameters
        ----------
        level : float, default 0.0
            The value whose level set is extracted (0: the surface of a signed distance; an offset distance for
            an offset surface), strictly between the field's minimum and maximum.
        close : bool, default False
            Cap the surface where it leaves the box, so that it is closed.
        report : bool, default False
            Also return the mesh's checks: a dict with ``closed``, ``edge_manifold``, ``vertex_manifold`` and
            ``welded``.

        Returns
        -------
        V : (n, 3) float64
            Vertices, model units.
        F : (m, 3) int64
            Triangles, oriented towards increasing values (outward for a signed distance).
        report : dict
            Only with ``report=True``.

        Raises
        ------
        ValueError
            ``level`` is not finite or outside the range of the field (no surface); ``close`` or ``report`` is
            not a bool.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> x = np.linspace(-1, 1, 17)
        >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
        >>> f = gsdf.GridField(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, [-1] * 3, [1] * 3)
        >>> V, F = f.isosurface(0.0)
        >>> bool(np.abs(np.linalg.norm(V, axis=1) - 0.5).max() < 0.02)
        True
        >>> V, F, rep = f.isosurface(1.0, close=True, report=True)         # cut by the box, capped
        >>> rep["closed"]
        True
        """
        from skimage.measure import marching_cubes

        from gsdf._checks import finite
        from gsdf.mesh._topology import manifold_report, split_nonmanifold_vertices, weld

        level = finite(level, "level")
        for name, flag in (("close", close), ("report", report)):
            if not isinstance(flag, (bool, np.bool_)):
                raise ValueError(f"{name}: expected True or False, got {flag!r}")
        vmin, vmax = float(self.values.min()), float(self.values.max())
        if not (vmin < level < vmax):
            raise ValueError(f"level {level} is outside the field's range [{vmin:.6g}, {vmax:.6g}]: no surface")
        # scikit-image works in float32: hand it values relative to the level scaled to [-1, 1] and a unit
        # spacing, so fields and boxes of any magnitude (1e-150 or 1e150) keep their sign pattern
        rel = self.values * 0.5 - level * 0.5
        rel = rel / float(np.abs(rel).max())
        h = self.spacing
        if close:
            rel = np.pad(rel, 1, mode="constant", constant_values=1.0)
        verts, faces, _, _ = marching_cubes(rel, level=0.0)
        verts = np.asarray(verts, dtype=np.float64)
        F = faces.astype(np.int64)
        if not close:
            V = self.bbox_min + verts * h
            return (V, F, manifold_report(V, F)) if report else (V, F)
        V = np.clip((verts - 1.0) * h + self.bbox_min, self.bbox_min, self.bbox_max)
        V, F = weld(V, F)
        rep = manifold_report(V, F)
        if not rep["vertex_manifold"]:
            V, F = split_nonmanifold_vertices(V, F)
            rep = manifold_report(V, F)
        return (V, F, rep) if report else (V, F)

    def isosurfaces(self, levels, close: bool = False):
        """Several level sets at once (e.g. offsets ±1 %, ±3 %), as :meth:`isosurface` of each.

        Parameters
        ----------
        levels : float or sequence of float
            The values, each strictly inside the field's range.
        close : bool, default False
            Cap each surface where it leaves the box.

        Returns
        -------
        list of (V, F)
            One mesh per level, in order.

        Raises
        ------
        ValueError
            A level outside the field's range.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> x = np.linspace(-1, 1, 17)
        >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
        >>> f = gsdf.GridField(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, [-1] * 3, [1] * 3)
        >>> len(f.isosurfaces([-0.1, 0.0, 0.1]))
        3
        """
        return [self.isosurface(float(v), close=close) for v in np.atleast_1d(as_values(levels, "levels"))]

    SAVE_EXTENSIONS = (".npz", ".npy", ".vtk", ".vti", ".vtu")

    def _write(self, path: str, ext: str) -> None:
        """``.npz``: ``values``, ``bbox_min``, ``bbox_max`` (reload with :meth:`load`); ``.npy``: the values array
        alone (nx, ny, nz) — the box is not stored; ``.vtk``: legacy binary STRUCTURED_POINTS; ``.vti``: VTK XML
        ImageData (base64 binary); ``.vtu``: hexahedra with point data ``values`` (meshio). All VTK forms open in
        ParaView with the field as point data ``values``."""
        if ext == ".vtk":
            _write_vtk_structured_points(path, self.values, self.bbox_min, self.spacing)
        elif ext == ".vti":
            _write_vti(path, self.values, self.bbox_min, self.spacing)
        elif ext == ".vtu":
            import meshio

            P = self.grid_points()
            nx, ny, nz = self.shape
            idx = np.arange(nx * ny * nz).reshape(self.shape)
            c = idx[:-1, :-1, :-1].ravel()
            sx, sy = ny * nz, nz
            hexes = np.column_stack([c, c + sx, c + sx + sy, c + sy, c + 1, c + sx + 1, c + sx + sy + 1, c + sy + 1])
            meshio.write(path, meshio.Mesh(P, [("hexahedron", hexes)], point_data={"values": self.values.ravel()}),
                         file_format="vtu")
        elif ext == ".npy":
            np.save(path, self.values)
        else:
            np.savez_compressed(path, values=self.values, bbox_min=self.bbox_min, bbox_max=self.bbox_max,
                                kind="grid")

    @classmethod
    def load(cls, path) -> "GridField":
        """Read a grid field written by :meth:`save` to ``.npz`` (:func:`gsdf.load_field` reads every format).

        Parameters
        ----------
        path : str or os.PathLike
            A ``.npz`` file with the arrays ``values``, ``bbox_min`` and ``bbox_max``.

        Returns
        -------
        GridField

        Raises
        ------
        FileNotFoundError
            No such file.
        ValueError
            Not a gsdf grid field ``.npz`` (the message names the missing arrays or the damage).

        Examples
        --------
        >>> import numpy as np, os, tempfile, gsdf
        >>> p = os.path.join(tempfile.mkdtemp(), "g.npz")
        >>> gsdf.GridField(np.ones((2, 2, 2)), [0, 0, 0], [1, 1, 1]).save(p)
        >>> gsdf.GridField.load(p).shape
        (2, 2, 2)
        """
        d = _load_npz(path, ("values", "bbox_min", "bbox_max"), "grid field", "grid")
        return _build(path, cls, d["values"], d["bbox_min"], d["bbox_max"])


def load_field(path) -> Field:
    """Read a field written by ``field.save(path)``: a :class:`GridField`, :class:`TetField` or
    :class:`SurfaceField`.

    ``.npz``: chosen by the arrays the file holds. ``.vti``, ``.vtk``, ``.vtu``: the point data ``values`` (else
    the only point data array) on a regular grid (VTK image data, or hexahedra whose points form a grid) →
    GridField, on tetrahedra → TetField, on triangles → SurfaceField. ``.ply``: the vertex property ``values``
    (else the only one) → SurfaceField. (``.npy`` holds the values without their domain: not readable here.)

    Parameters
    ----------
    path : str or os.PathLike
        A ``.npz``, ``.vti``, ``.vtk``, ``.vtu`` or ``.ply`` file.

    Returns
    -------
    GridField, TetField or SurfaceField

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        A ``.npy`` file, a directory, or a file that holds no gsdf field (the message says what was found).

    Examples
    --------
    >>> import numpy as np, os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "f.npz")
    >>> GridField(np.zeros((2, 2, 2)), [0, 0, 0], [1, 1, 1]).save(p)
    >>> type(load_field(p)).__name__
    'GridField'
    """
    import os

    from gsdf._checks import readable_file

    p = readable_file(path, "path")
    ext = os.path.splitext(p)[1].lower()
    if ext in (".vti", ".vtk", ".vtu", ".ply"):
        return _load_vti(p) if ext == ".vti" else _load_mesh_field(p, ext)
    if ext == ".npy":
        raise ValueError(f"{p}: a .npy file holds the values without their grid or mesh; save the field as .npz "
                         "(or .vti/.vtk/.vtu) to read it back")
    d = _load_npz(path, (), "field")
    keys = set(d["__files__"])
    if {"values", "bbox_min", "bbox_max"} <= keys:
        return GridField.load(path)
    if {"vertices", "tets", "values"} <= keys:
        return TetField.load(path)
    if {"vertices", "faces", "values"} <= keys:
        return SurfaceField.load(path)
    raise ValueError(f"{path}: not a gsdf field file (arrays {sorted(keys)}; a grid has values/bbox_min/bbox_max, "
                     "a tet field vertices/tets/values, a surface field vertices/faces/values)")


def _pick_values(p: str, data: dict) -> np.ndarray:
    """The point data array ``values``, else the only scalar one."""
    scalars = {k: np.asarray(v).reshape(len(v), -1) for k, v in data.items()}
    scalars = {k: v[:, 0] for k, v in scalars.items() if v.shape[1] == 1}
    if "values" in scalars:
        return scalars["values"].astype(np.float64)
    if len(scalars) == 1:
        return next(iter(scalars.values())).astype(np.float64)
    raise ValueError(f"{p}: expected point data 'values' (or one scalar array), found {sorted(data) or 'none'}")


def _load_mesh_field(p: str, ext: str) -> Field:
    """A field from the cells of a VTK/VTU file (meshio) or the vertices of a PLY file."""
    if ext == ".ply":
        from gsdf.io import read_mesh, read_vertex_data

        V, F = read_mesh(p)
        return SurfaceField(V, F, _pick_values(p, read_vertex_data(p)))
    from gsdf.io._external import _read_meshio_raw

    m = _read_meshio_raw(p, ext)
    P = np.asarray(m.points, dtype=np.float64)
    vals = _pick_values(p, m.point_data)
    cells = {c.type: np.asarray(c.data) for c in m.cells}
    if "tetra" in cells:
        return TetField(P, cells["tetra"], vals)
    if "triangle" in cells:
        return SurfaceField(P, cells["triangle"], vals)
    if "hexahedron" in cells or "voxel" in cells:
        axes = [np.unique(P[:, a]) for a in range(3)]
        shape = tuple(len(x) for x in axes)
        if int(np.prod(shape)) == len(P):
            idx = [np.searchsorted(axes[a], P[:, a]) for a in range(3)]
            grid = np.full(shape, np.nan)
            grid[idx[0], idx[1], idx[2]] = vals
            if np.isfinite(grid).all():
                return GridField(grid, [x[0] for x in axes], [x[-1] for x in axes])
        raise ValueError(f"{p}: the hexahedra's points do not form a regular grid")
    raise ValueError(f"{p}: no tetra, triangle or hexahedron cells to hold a field (cells: {sorted(cells)})")


def _is_number(t: str) -> bool:
    try:
        float(t)
    except ValueError:
        return False
    return True


def _vti_numbers(p: str, img, name: str, default, kind, count: int) -> list:
    """The ``count`` numbers of attribute ``name`` of the ImageData element (``default`` when absent)."""
    text = img.get(name, default)
    if text is None:
        raise ValueError(f"{p}: not a VTK ImageData (.vti) file (no {name})")
    toks = text.split()
    try:
        vals = [kind(t) for t in toks]
    except ValueError:
        raise ValueError(f"{p}: ImageData {name}: expected {count} numbers, got {text[:60]!r}") from None
    if len(vals) != count:
        raise ValueError(f"{p}: ImageData {name}: expected {count} numbers, got {len(vals)}")
    return vals


def _load_vti(p: str) -> GridField:
    """VTK XML ImageData with one point data array (inline ``binary`` base64 with a UInt32/UInt64 byte-count
    header, uncompressed, or ``ascii``), as :meth:`GridField.save` writes it."""
    import base64
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(p).getroot()
    except ET.ParseError as exc:
        raise ValueError(f"{p}: not a VTK ImageData (.vti) file ({exc})") from exc
    img = root.find("ImageData")
    if img is None:
        raise ValueError(f"{p}: not a VTK ImageData (.vti) file (no ImageData element)")
    ext = _vti_numbers(p, img, "WholeExtent", None, int, 6)
    origin = np.array(_vti_numbers(p, img, "Origin", "0 0 0", float, 3))
    spacing = np.array(_vti_numbers(p, img, "Spacing", "1 1 1", float, 3))
    arrays = img.findall("Piece/PointData/DataArray")
    if root.get("compressor"):
        raise ValueError(f"{p}: compressed .vti data is not supported (write it uncompressed)")
    named = [a for a in arrays if a.get("Name") == "values"] or arrays
    if len(named) != 1 or named[0].get("NumberOfComponents", "1") != "1":
        raise ValueError(f"{p}: expected one scalar point data array 'values'")
    a = named[0]
    dtype = np.dtype({"Float64": "f8", "Float32": "f4", "Int32": "i4", "Int64": "i8", "UInt8": "u1"}
                     .get(a.get("type"), "f8"))
    dtype = dtype.newbyteorder("<" if root.get("byte_order", "LittleEndian") == "LittleEndian" else ">")
    shape = (ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1)
    n = int(np.prod(shape))
    text = (a.text or "").strip()
    if a.get("format") == "ascii":
        try:
            v = np.array(text.split(), dtype=np.float64)
        except ValueError:
            bad = next(t for t in text.split() if not _is_number(t))
            raise ValueError(f"{p}: .vti data: non-numeric value {bad[:40]!r}") from None
    elif a.get("format") == "binary":
        try:
            raw = base64.b64decode(text)
        except ValueError:  # binascii.Error
            raise ValueError(f"{p}: .vti data: not valid base64 text") from None
        head = 8 if root.get("header_type", "UInt32") == "UInt64" else 4
        v = np.frombuffer(raw[head:head + n * dtype.itemsize], dtype=dtype).astype(np.float64)
    else:
        raise ValueError(f"{p}: .vti data in '{a.get('format')}' format is not supported (ascii or binary)")
    if v.size != n:
        raise ValueError(f"{p}: expected {n} values for the extent {ext}, got {v.size}")
    values = v.reshape(shape[::-1]).transpose(2, 1, 0)               # VTK: x fastest
    lo = origin + spacing * np.array(ext[0::2])
    return GridField(values, lo, lo + spacing * (np.array(shape) - 1))


def _load_npz(path, keys, what: str, kind: str | None = None) -> dict:
    """The arrays ``keys`` of a gsdf ``.npz`` file; FileNotFoundError if missing, else ValueError naming the file.
    With ``kind``: the file's ``kind`` entry, when it has one, must be that string (what ``save`` writes)."""
    from gsdf._checks import numpy_file

    p = numpy_file(path, "path")
    try:
        with np.load(p, allow_pickle=False) as d:
            missing = [k for k in keys if k not in d]
            if missing:
                raise ValueError(f"missing arrays {', '.join(missing)}")
            out = {"__files__": list(d.files), **{k: d[k] for k in keys}}
            stored = d["kind"] if kind is not None and "kind" in d.files else None
    except Exception as exc:  # numpy/zipfile raise ValueError, EOFError, BadZipFile, zlib.error, TokenError,
        # NotImplementedError ... for broken headers, archives and compressed data: all mean a malformed file
        raise ValueError(f"{p}: not a gsdf {what} .npz file ({exc})") from exc
    if stored is not None and not (stored.dtype.kind == "U" and stored.shape == () and str(stored) == kind):
        raise ValueError(f"{p}: not a gsdf {what} .npz file (its 'kind' is {stored.tolist()!r}, expected {kind!r})")
    return out


def _build(path, cls, *arrays):
    """``cls(*arrays)`` of arrays read from ``path``; a refusal names the file."""
    try:
        return cls(*arrays)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def _write_vtk_structured_points(path, values, origin, spacing) -> None:
    """Legacy VTK STRUCTURED_POINTS, binary big-endian float64; x varies fastest as VTK expects."""
    nx, ny, nz = values.shape
    header = (f"# vtk DataFile Version 3.0\ngsdf field\nBINARY\nDATASET STRUCTURED_POINTS\n"
              f"DIMENSIONS {nx} {ny} {nz}\nORIGIN {' '.join(repr(float(v)) for v in origin)}\n"
              f"SPACING {' '.join(repr(float(v)) for v in spacing)}\nPOINT_DATA {nx * ny * nz}\n"
              f"SCALARS values double 1\nLOOKUP_TABLE default\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(values.transpose(2, 1, 0)).astype(">f8").tobytes())
        f.write(b"\n")


def _write_vti(path, values, origin, spacing) -> None:
    """VTK XML ImageData with the values as inline base64 binary point data (UInt64 byte-count header).

    VTK orders points with x fastest, so the (nx, ny, nz) C-order array is written transposed.
    """
    import base64

    nx, ny, nz = values.shape
    data = np.ascontiguousarray(values.transpose(2, 1, 0)).astype("<f8").tobytes()
    payload = base64.b64encode(np.array([len(data)], "<u8").tobytes() + data).decode("ascii")
    ext = f"0 {nx - 1} 0 {ny - 1} 0 {nz - 1}"
    text = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
        f'  <ImageData WholeExtent="{ext}" Origin="{" ".join(repr(float(v)) for v in origin)}" '
        f'Spacing="{" ".join(repr(float(v)) for v in spacing)}">\n'
        f'    <Piece Extent="{ext}">\n'
        '      <PointData Scalars="values">\n'
        f'        <DataArray type="Float64" Name="values" NumberOfComponents="1" format="binary">{payload}'
        '</DataArray>\n'
        '      </PointData>\n'
        '    </Piece>\n'
        '  </ImageData>\n'
        '</VTKFile>\n')
    with open(path, "w", encoding="ascii") as f:
        f.write(text)


class TetField(Field):
    """Values on the vertices of a tetrahedral mesh: barycentric evaluation and marching tetrahedra.

    Parameters
    ----------
    vertices : (n, 3) float
        Vertex positions, model units.
    tets : (m, 4) int
        Tetrahedra as vertex indices (m > 0).
    values : (n,) float
        One finite value per vertex, interpolated linearly over each tet.
    delaunay : scipy.spatial.Delaunay, optional
        Point locator whose simplices are ``tets`` (what :func:`gsdf.signed_heat_volume` with ``domain="tet"``
        builds). Without it, points are located among ``tets`` themselves (any tet mesh, e.g. TetGen's): the
        tets whose centroids are nearest to the query are tested by their barycentric coordinates.

    Attributes
    ----------
    vertices, tets, values
        As given (float64, int64, float64).
    bbox_min, bbox_max : (3,) float64
        Corners of the vertices' bounding box.
    meta : dict
        What the method that made the field records about it; not saved.

    Raises
    ------
    ValueError
        Bad shapes, indices out of range, NaN or infinite values, a ``delaunay`` that is not a
        ``scipy.spatial.Delaunay`` of as many simplices and points as ``tets`` and ``vertices``.

    Notes
    -----
    Calling the field, ``field(Q)``, interpolates it at the points ``Q`` (q, 3) and returns (q,) values; points
    outside the mesh take the value of the nearest vertex.

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.field import TetField
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
    >>> f = TetField(V, [[0, 1, 2, 3]], V[:, 0])
    >>> float(f([[0.25, 0.25, 0.25]])[0])
    0.25
    """

    def __init__(self, vertices, tets, values, delaunay=None):
        self.vertices = as_points(vertices, "vertices")
        self.tets = as_faces(tets, len(self.vertices), "tets", corners=4)
        self.values = as_values(values, "values", (len(self.vertices),))
        if delaunay is not None:
            from scipy.spatial import Delaunay

            if not isinstance(delaunay, Delaunay):
                raise ValueError(f"delaunay: expected a scipy.spatial.Delaunay or None, got "
                                 f"{type(delaunay).__name__}")
            if delaunay.simplices.shape != self.tets.shape or len(delaunay.points) != len(self.vertices):
                raise ValueError(f"delaunay: its {len(delaunay.simplices)} simplices over {len(delaunay.points)} "
                                 f"points are not the {len(self.tets)} tets over {len(self.vertices)} vertices")
        self._delaunay = delaunay
        self.meta: dict = {}

    @property
    def bbox_min(self):
        """Low corner of the vertices' bounding box, (3,) float64."""
        return self.vertices.min(axis=0)

    @property
    def bbox_max(self):
        """High corner of the vertices' bounding box, (3,) float64."""
        return self.vertices.max(axis=0)

    @query_shaped()
    def __call__(self, Q) -> np.ndarray:
        """Barycentric (piecewise linear) interpolation at ``Q`` (q, 3); outside the mesh: nearest vertex."""
        Q = as_points(Q, "Q", allow_empty=True, seconds_per_row=SECONDS_PER_NODE)
        out = np.empty(len(Q))
        if self._delaunay is not None:
            D = self._delaunay
            s = D.find_simplex(Q)
            inside = s >= 0
            if inside.any():
                Tr = D.transform[s[inside]]
                b = np.einsum("qij,qj->qi", Tr[:, :3], Q[inside] - Tr[:, 3])
                bary = np.column_stack([b, 1.0 - b.sum(axis=1)])
                out[inside] = (bary * self.values[D.simplices[s[inside]]]).sum(axis=1)
        else:
            s, bary = locate_in_tets(self.vertices, self.tets, Q)
            inside = s >= 0
            out[inside] = (bary[inside] * self.values[self.tets[s[inside]]]).sum(axis=1)
        if (~inside).any():
            from scipy.spatial import cKDTree

            out[~inside] = self.values[cKDTree(self.vertices).query(Q[~inside])[1]]
        return out

    def isosurface(self, level: float = 0.0, report: bool = False):
        """The level set ``field = level`` by marching tetrahedra (:func:`gsdf.marching_tetrahedra`).

        Parameters
        ----------
        level : float, default 0.0
            The value whose level set is extracted, in the field's units.
        report : bool, default False
            Also return the mesh's checks (``closed``, ``edge_manifold``, ``vertex_manifold``, ``welded``).

        Returns
        -------
        V : (n, 3) float64
            Vertices, welded.
        F : (m, 3) int64
            Triangles oriented so that normals point toward increasing values (outward for a signed distance).
        report : dict
            Only with ``report=True``.

        Raises
        ------
        ValueError
            ``level`` is not a finite number.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
        >>> Vs, Fs = gsdf.TetField(V, [[0, 1, 2, 3]], V[:, 0]).isosurface(0.5)
        >>> Vs[:, 0].round(6).tolist(), Fs.shape
        ([0.5, 0.5, 0.5], (1, 3))
        """
        return marching_tetrahedra(self.vertices, self.tets, self.values, level, report=report)

    def isosurfaces(self, levels):
        """Several level sets at once, as :meth:`isosurface` of each.

        Parameters
        ----------
        levels : float or sequence of float
            The values.

        Returns
        -------
        list of (V, F)
            One mesh per level, in order.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
        >>> [len(F) for _, F in gsdf.TetField(V, [[0, 1, 2, 3]], V[:, 0]).isosurfaces([0.25, 0.5])]
        [1, 1]
        """
        return [self.isosurface(float(v)) for v in np.atleast_1d(as_values(levels, "levels"))]

    SAVE_EXTENSIONS = (".npz", ".npy", ".vtk", ".vtu")

    def _write(self, path: str, ext: str) -> None:
        """``.npz``: vertices, tets, values (reload with :meth:`load`); ``.npy``: the values (n,) alone;
        ``.vtk`` (legacy) / ``.vtu`` (XML): tetra cells with point data ``values`` (meshio). A tet field is not an
        image, so ``.vti`` is refused."""
        if ext in (".vtu", ".vtk"):
            import meshio

            meshio.write(path, meshio.Mesh(self.vertices, [("tetra", self.tets)], point_data={"values": self.values}),
                         file_format=ext[1:])
        elif ext == ".npy":
            np.save(path, self.values)
        else:
            np.savez_compressed(path, vertices=self.vertices, tets=self.tets, values=self.values, kind="tet")

    @classmethod
    def load(cls, path) -> "TetField":
        """Read a tet field written by :meth:`save` to ``.npz`` (:func:`gsdf.load_field` reads every format).

        Parameters
        ----------
        path : str or os.PathLike
            A ``.npz`` file with the arrays ``vertices``, ``tets`` and ``values``.

        Returns
        -------
        TetField

        Raises
        ------
        FileNotFoundError
            No such file.
        ValueError
            Not a gsdf tet field ``.npz``.

        Examples
        --------
        >>> import numpy as np, os, tempfile, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
        >>> p = os.path.join(tempfile.mkdtemp(), "t.npz")
        >>> gsdf.TetField(V, [[0, 1, 2, 3]], V[:, 0]).save(p)
        >>> gsdf.TetField.load(p).tets.tolist()
        [[0, 1, 2, 3]]
        """
        d = _load_npz(path, ("vertices", "tets", "values"), "tet field", "tet")
        return _build(path, cls, d["vertices"], d["tets"], d["values"])


class SurfaceField(Field):
    """Values on the vertices of a triangle mesh: evaluation at (closest) surface points and isolines.

    What the surface methods (the signed heat method on meshes, surface winding numbers) can return.

    Parameters
    ----------
    vertices : (n, 3) float
        Vertex positions, model units.
    faces : (m, 3) int
        Triangles as vertex indices.
    values : (n,) float
        One finite value per vertex, interpolated linearly over each triangle.

    Attributes
    ----------
    vertices, faces, values
        As given (float64, int64, float64).
    meta : dict
        What the method that made the field records about it; not saved.

    Raises
    ------
    ValueError
        Bad shapes, indices out of range, not one finite number per vertex.

    Notes
    -----
    Calling the field, ``field(Q)``, returns the (q,) values at the points of the surface closest to ``Q``
    (q, 3).

    Examples
    --------
    >>> import numpy as np
    >>> from gsdf.field import SurfaceField
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.]])
    >>> f = SurfaceField(V, [[0, 1, 2], [0, 2, 3]], V[:, 0])
    >>> float(f([[0.25, 0.5, 1.0]])[0])
    0.25
    >>> [np.round(p, 3).tolist() for p in f.isolines(0.5)]
    [[[0.5, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 1.0, 0.0]]]
    """

    SAVE_EXTENSIONS = (".npz", ".npy", ".ply", ".vtk", ".vtu")

    def __init__(self, vertices, faces, values):
        from gsdf._checks import as_mesh

        self.vertices, self.faces = as_mesh(vertices, faces)
        self.values = as_values(values, "values", (len(self.vertices),))
        self._distance = None
        self.meta: dict = {}

    def at(self, face, bary) -> np.ndarray:
        """Values at surface points given by their face and barycentric coordinates.

        Parameters
        ----------
        face : (q,) int
            Face index of each point.
        bary : (q, 3) float
            Barycentric coordinates of each point in its face (weights of the face's three corners).

        Returns
        -------
        (q,) float64

        Raises
        ------
        ValueError
            Face indices out of range, shapes that do not match, NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.]])
        >>> f = gsdf.SurfaceField(V, [[0, 1, 2], [0, 2, 3]], V[:, 0])
        >>> f.at([0], [[0.5, 0.5, 0.0]]).tolist()
        [0.5]
        """
        face = _array(face, "face")
        if face.size == 0:  # [] is a float array: no face of any dtype is fine
            face = np.zeros(0, dtype=np.int64)
        if face.dtype.kind not in "iu" or face.ndim != 1:
            raise ValueError(f"face: expected a 1-d integer array, got {face.dtype} {face.shape}")
        if len(face) and (face.min() < 0 or face.max() >= len(self.faces)):
            raise ValueError(f"face: indices must be in [0, {len(self.faces)})")
        if len(face) == 0 and np.size(bary) == 0:
            return np.zeros(0)
        bary = as_values(bary, "bary", (len(face), 3))
        return (bary * self.values[self.faces[face]]).sum(axis=1)

    @query_shaped()
    def __call__(self, Q) -> np.ndarray:
        """Values at the points of the surface closest to ``Q`` (q, 3) (on the surface: at ``Q`` itself)."""
        Q = as_points(Q, "Q", allow_empty=True, seconds_per_row=SECONDS_PER_NODE)
        if len(Q) == 0:
            return np.zeros(0)
        if self._distance is None:
            from gsdf.distance._triangles import TriangleDistance

            self._distance = TriangleDistance(self.vertices, self.faces)
        _, face, _, bary = self._distance.query_barycentric(Q)
        return (bary * self.values[self.faces[face]]).sum(axis=1)

    def isosurface(self, level: float = 0.0):
        """A field on a surface has level curves, not level surfaces: use :meth:`isolines`.

        Parameters
        ----------
        level : float, default 0.0
            Ignored.

        Raises
        ------
        ValueError
            Always.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.]])
        >>> gsdf.SurfaceField(V, [[0, 1, 2]], V[:, 0]).isolines(0.5)[0].shape      # not isosurface
        (2, 3)
        """
        raise ValueError("a SurfaceField has level curves, not level surfaces: use isolines(level)")

    def isolines(self, level: float = 0.0) -> list:
        """The curves where the piecewise-linear field equals ``level`` (marching triangles).

        Each triangle whose corners lie on both sides (above: ``value > level``) contributes one segment between
        the crossing points of its two crossed edges; crossing points are shared per mesh edge and segments are
        chained into polylines. Polylines are oriented with the region below ``level`` on their left, seen from
        the face normals (so the zero isoline of a signed distance runs counter-clockwise around the negative
        region, as the curves of the surface signed heat method do).

        Parameters
        ----------
        level : float, default 0.0
            The value whose level curves are traced, in the field's units.

        Returns
        -------
        list of (k, 3) float arrays
            One per curve; a closed curve repeats its first point at the end. Empty when ``level`` is not
            crossed.

        Raises
        ------
        ValueError
            ``level`` is not a finite number.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.]])
        >>> f = gsdf.SurfaceField(V, [[0, 1, 2], [0, 2, 3]], V[:, 0])
        >>> [len(c) for c in f.isolines(0.5)]
        [3]
        """
        level = finite(level, "level")
        F = self.faces
        s = self.values - level
        pos = s[F] > 0
        npos = pos.sum(axis=1)
        cut = (npos == 1) | (npos == 2)
        if not cut.any():
            return []
        Fc, Pc = F[cut], pos[cut]
        lone_pos = npos[cut] == 1
        lone = np.where(lone_pos, np.argmax(Pc, axis=1), np.argmax(~Pc, axis=1))
        r = np.arange(len(Fc))
        a, b, c = Fc[r, lone], Fc[r, (lone + 1) % 3], Fc[r, (lone + 2) % 3]
        # p1 on edge (a, b), p2 on edge (c, a): p1 -> p2 has the lone corner a on its left
        e1 = np.sort(np.column_stack([a, b]), axis=1)
        e2 = np.sort(np.column_stack([c, a]), axis=1)
        start = np.where(lone_pos[:, None], e2, e1)  # below-level side on the left
        end = np.where(lone_pos[:, None], e1, e2)
        uniq, inv = np.unique(np.vstack([start, end]), axis=0, return_inverse=True)
        inv = inv.ravel()
        u, v = inv[: len(Fc)], inv[len(Fc):]
        sa, sb = s[uniq[:, 0]], s[uniq[:, 1]]
        t = sa / (sa - sb)
        X = self.vertices[uniq[:, 0]] + t[:, None] * (self.vertices[uniq[:, 1]] - self.vertices[uniq[:, 0]])
        return [X[chain] for chain in _chain_segments(u, v, len(uniq))]

    def _write(self, path: str, ext: str) -> None:
        """``.npz``: vertices, faces, values (reload with :meth:`load`); ``.npy``: the values (n,) alone; ``.ply``:
        the mesh with vertex property ``values``; ``.vtk``/``.vtu``: triangles with point data ``values``."""
        if ext == ".ply":
            from gsdf.io._mesh import write_mesh

            write_mesh(path, self.vertices, self.faces, vertex_data={"values": self.values})
        elif ext in (".vtk", ".vtu"):
            import meshio

            meshio.write(path, meshio.Mesh(self.vertices, [("triangle", self.faces)],
                                           point_data={"values": self.values}), file_format=ext[1:])
        elif ext == ".npy":
            np.save(path, self.values)
        else:
            np.savez_compressed(path, vertices=self.vertices, faces=self.faces, values=self.values, kind="surface")

    @classmethod
    def load(cls, path) -> "SurfaceField":
        """Read a surface field written by :meth:`save` to ``.npz`` (:func:`gsdf.load_field` reads every format).

        Parameters
        ----------
        path : str or os.PathLike
            A ``.npz`` file with the arrays ``vertices``, ``faces`` and ``values``.

        Returns
        -------
        SurfaceField

        Raises
        ------
        FileNotFoundError
            No such file.
        ValueError
            Not a gsdf surface field ``.npz``.

        Examples
        --------
        >>> import numpy as np, os, tempfile, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.]])
        >>> p = os.path.join(tempfile.mkdtemp(), "s.npz")
        >>> gsdf.SurfaceField(V, [[0, 1, 2]], V[:, 0]).save(p)
        >>> gsdf.SurfaceField.load(p).values.tolist()
        [0.0, 1.0, 1.0]
        """
        d = _load_npz(path, ("vertices", "faces", "values"), "surface field", "surface")
        return _build(path, cls, d["vertices"], d["faces"], d["values"])


def _chain_segments(u: np.ndarray, v: np.ndarray, n: int) -> list:
    """Chain directed segments ``u[i] -> v[i]`` over ``n`` nodes into node sequences (open chains first from
    their start, then cycles, closed by repeating the first node). A node with several outgoing segments
    (non-manifold input) starts extra chains, so every segment is used exactly once."""
    order = np.argsort(u, kind="stable")
    first = np.searchsorted(u[order], np.arange(n + 1))
    used = np.zeros(len(u), bool)
    indeg = np.bincount(v, minlength=n)
    outdeg = np.bincount(u, minlength=n)
    nxt_ptr = first[:-1].copy()

    def take(node):
        while nxt_ptr[node] < first[node + 1]:
            seg = order[nxt_ptr[node]]
            nxt_ptr[node] += 1
            if not used[seg]:
                used[seg] = True
                return seg
        return -1

    chains = []
    starts = list(np.flatnonzero(outdeg > indeg)) + list(range(n))
    for s0 in starts:
        while True:
            seg = take(s0)
            if seg < 0:
                break
            chain = [s0, int(v[seg])]
            while True:
                seg = take(chain[-1])
                if seg < 0:
                    break
                chain.append(int(v[seg]))
            chains.append(np.array(chain, dtype=np.int64))
    return chains
