"""Reading and writing point clouds, optionally with normals.

Formats: ``.xyz`` / ``.pwn`` (3 or 6 whitespace-separated columns), ``.ply`` (vertex ``x y z``
and optional ``nx ny nz``), ``.obj`` and ``.pc`` (``v`` and ``vn`` lines), ``.off`` (vertices
only, normals from ``NOFF``; read only), ``.npy`` / ``.npz``.  Text files are parsed with the
vectorized tokenizer of :mod:`gsdf.io._mesh` (a million points take a second or two;
writing text is slower, prefer binary PLY or NPY for large outputs).
"""

from __future__ import annotations

import io
import warnings

import numpy as np

from gsdf._checks import as_points, flag, numpy_file
from gsdf.io._safe_write import atomic_output
from gsdf.io._mesh import (
    _check_file,
    _extension,
    _format_rows,
    _parse_obj,
    _parse_off,
    _read_bytes,
    _read_ply,
    _Table,
    _write_ply,
    _write_text,
)

__all__ = ["read_points", "write_points"]

POINTS_READ_FORMATS = (".xyz", ".pwn", ".ply", ".obj", ".pc", ".off", ".npy", ".npz")
POINTS_WRITE_FORMATS = (".xyz", ".pwn", ".ply", ".obj", ".pc", ".npy", ".npz")


def _read_columns(p: str, data: bytes):
    """3 or 6 numeric columns per line; an optional first line holding only the point count."""
    try:  # fast path: a single np.loadtxt call on a regular file
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "input contained no data"
            A = np.loadtxt(io.BytesIO(data), comments="#", ndmin=2, encoding="latin1")
        if len(A) and A.shape[1] in (3, 6):
            return A[:, :3], (A[:, 3:] if A.shape[1] == 6 else None)
    except ValueError:
        pass
    return _read_columns_checked(p, data)


def _read_columns_checked(p: str, data: bytes):
    """Line-by-line validated parse (count line, precise error messages)."""
    tab = _Table(p, data)
    if not len(tab):
        raise ValueError(f"{p}: file is empty (no data lines)")
    declared, r0 = None, 0
    if tab.counts[0] == 1:
        try:
            declared, r0 = int(tab.row_tokens(0)[0]), 1
        except ValueError:
            raise tab.error(0, "expected 3 (x y z) or 6 (x y z nx ny nz) values, got 1") from None
    if r0 == len(tab):
        raise ValueError(f"{p}: contains no points")
    ncol = int(tab.counts[r0])
    if ncol not in (3, 6):
        raise tab.error(r0, f"expected 3 (x y z) or 6 (x y z nx ny nz) values, got {ncol}")
    bad = np.flatnonzero(tab.counts[r0:] != ncol)
    if bad.size:
        r = r0 + bad[0]
        raise tab.error(r, f"expected {ncol} values like line {tab.lines[r0]}, got {tab.counts[r]}")
    A = tab.columns(np.arange(r0, len(tab)), 0, ncol, "point")
    if declared is not None and declared != len(A):
        raise tab.error(0, f"point count {declared} does not match the {len(A)} point lines")
    return A[:, :3], (A[:, 3:] if ncol == 6 else None)


def _read_obj_points(p: str, data: bytes):
    P, _, _, tab = _parse_obj(p, data, with_faces=False)
    rows = tab.keyword_rows(b"vn")
    N = tab.columns(rows, 1, 3, "'vn' line") if len(rows) == len(P) and len(P) else None
    return P, N


def _read_numpy(p: str, ext: str):
    _check_file(p)
    numpy_file(p)
    try:
        if ext == ".npy":
            A, N = np.load(p, allow_pickle=False), None
        else:
            with np.load(p, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
            pk = next((k for k in ("P", "points") if k in arrays), None)
            if pk is None and len(arrays) == 1 and next(iter(arrays)) not in ("N", "normals"):
                pk = next(iter(arrays))          # np.savez(path, P) names its array arr_0; lone normals are no cloud
            if pk is None:
                raise ValueError(f"{p}: expected arrays named 'P'/'N' or 'points'/'normals', found {sorted(arrays)}")
            A = arrays[pk]
            N = next((arrays[k] for k in ("N", "normals") if k in arrays), None)
    except Exception as exc:  # numpy/zipfile raise ValueError, EOFError, BadZipFile, zlib.error, TokenError,
        # NotImplementedError ... for broken headers, archives and compressed data: all mean a malformed file
        if isinstance(exc, FileNotFoundError) or str(exc).startswith(p):
            raise
        raise ValueError(f"{p}: cannot read numpy file ({exc})") from exc
    A = np.asarray(A)
    if A.ndim == 2 and A.shape[1] == 6 and N is None:
        return A[:, :3], A[:, 3:]
    if A.ndim != 2 or A.shape[1] != 3:
        raise ValueError(f"{p}: expected an array of shape (n, 3) or (n, 6), got {A.shape}")
    return A, N


def read_points(path):
    """Read a point cloud and its normals, if the file has them.

    Parameters
    ----------
    path : str or os.PathLike
        ``.xyz``/``.pwn`` (3 or 6 columns per line; a first line holding only the point count is
        tolerated), ``.ply`` (``x y z`` and optional ``nx ny nz``), ``.obj``/``.pc`` (``v`` and
        ``vn`` lines; normals are used only when there are as many as vertices), ``.off``
        (vertices; normals for ``NOFF``), ``.npy`` ((n, 3) or (n, 6) array) or ``.npz``
        (arrays ``P``/``N`` or ``points``/``normals``).

    Returns
    -------
    P : (n, 3) float64 ndarray
        Point positions.
    N : (n, 3) float64 ndarray or None
        Normals (not normalized), or None when the file has none.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        Message starting with the path, for an unsupported extension, an empty file, a
        malformed line (with its line number), NaN/inf values or zero points.

    Examples
    --------
    >>> P, N = read_points("kitten.xyz")          # doctest: +SKIP
    >>> P.shape, None if N is None else N.shape   # doctest: +SKIP
    ((20000, 3), (20000, 3))
    """
    p, ext = _extension(path, POINTS_READ_FORMATS, "point cloud")
    if ext in (".xyz", ".pwn"):
        P, N = _read_columns(p, _read_bytes(p))
    elif ext in (".obj", ".pc"):
        P, N = _read_obj_points(p, _read_bytes(p))
    elif ext == ".off":
        P, N, _, _ = _parse_off(p, _read_bytes(p), with_faces=False)
    elif ext == ".ply":
        P, N, _, _ = _read_ply(p)
    else:
        P, N = _read_numpy(p, ext)
    if len(P) == 0:
        raise ValueError(f"{p}: contains no points")
    P = as_points(P, f"{p}: points")
    if N is not None:
        N = as_points(N, f"{p}: normals")
        if len(N) != len(P):
            raise ValueError(f"{p}: has {len(P)} points but {len(N)} normals")
    return P, N


def write_points(path, P, N=None, *, binary: bool = True) -> None:
    """Write a point cloud, with normals if given.

    Parameters
    ----------
    path : str or os.PathLike
        ``.xyz``/``.pwn`` (3 or 6 columns), ``.ply`` (doubles; ``nx ny nz`` when N is given),
        ``.obj``/``.pc`` (``v`` and ``vn`` lines), ``.npy`` ((n, 3) or (n, 6)) or ``.npz``
        (arrays ``P`` and ``N``).
    P : (n, 3) array_like of float
        Point positions.
    N : (n, 3) array_like of float, optional
        Normals.
    binary : bool, default True
        PLY only: binary little-endian (default) or ASCII.

    Examples
    --------
    >>> P = np.random.rand(100, 3)
    >>> write_points("cloud.xyz", P, P - 0.5)     # doctest: +SKIP
    """
    p, ext = _extension(path, POINTS_WRITE_FORMATS, "point cloud")
    binary = flag(binary, "binary")
    P = as_points(P, "P")
    if N is not None:
        N = as_points(N, "N")
        if len(N) != len(P):
            raise ValueError(f"N: has {len(N)} rows but there are {len(P)} points")
    with atomic_output(p, extensions=POINTS_WRITE_FORMATS) as tmp:
        if ext in (".xyz", ".pwn"):
            _write_text(tmp, _format_rows(P if N is None else np.hstack([P, N])))
        elif ext in (".obj", ".pc"):
            _write_text(tmp, _format_rows(P, "v ") + ("" if N is None else _format_rows(N, "vn ")))
        elif ext == ".ply":
            fields = dict(zip("xyz", P.T))
            if N is not None:
                fields.update(zip(("nx", "ny", "nz"), N.T))
            _write_ply(tmp, fields, None, binary=binary)
        elif ext == ".npy":
            with open(tmp, "wb") as fh:
                np.save(fh, P if N is None else np.hstack([P, N]))
        else:
            with open(tmp, "wb") as fh:
                np.savez(fh, P=P) if N is None else np.savez(fh, P=P, N=N)
