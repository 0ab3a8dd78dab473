"""Input validation shared by every entry point.

Every public function funnels its arguments through these helpers so that bad input (wrong shape, NaN/inf,
empty arrays, indices out of range, strings, booleans or complex numbers where real numbers are expected)
raises a ``ValueError`` that names the argument and the problem in gsdf's words, instead of crashing inside a
numba kernel, leaking numpy's text, or silently dropping an imaginary part. Real numbers: :func:`as_values`
(arrays) and :func:`finite` / :func:`positive` / :func:`nonnegative` (scalars) are the one check; coordinates
:func:`as_points`, indices :func:`as_faces`, switches :func:`flag`. The array helpers refuse a copy that would
not fit in memory (:func:`gsdf._memory.check_bytes`) and, given a per-row cost, a request that would run too
long (:func:`gsdf._memory.check_work`), before their first pass over the data.
"""

from __future__ import annotations

import functools
import inspect

import numpy as np

#: dtype kinds of real numbers (float, signed and unsigned integers).
_REAL_KINDS = "fiu"


def _array(X, name: str) -> np.ndarray:
    """``np.asarray(X)`` with numpy's failures (ragged nesting, odd objects) as gsdf's ValueError."""
    if isinstance(X, (str, bytes)):
        raise ValueError(f"{name}: expected an array of numbers, got a string {X[:40]!r}")
    try:
        return np.asarray(X)
    except (ValueError, TypeError, OverflowError) as exc:
        raise ValueError(f"{name}: expected an array of numbers (not ragged nested lists or objects)") from exc


def _dtype_words(A: np.ndarray) -> str:
    k = A.dtype.kind
    return {"c": "complex numbers", "b": "booleans", "U": "strings", "S": "bytes", "O": "Python objects",
            "M": "dates", "m": "time spans", "V": "records"}.get(k, f"dtype {A.dtype}")


def _copy_guard(A: np.ndarray, name: str, itemsize: int = 8) -> None:
    """Refuse (before making it) a converted copy of ``A`` that would not fit in memory."""
    from gsdf._memory import check_bytes, size_of

    n = size_of(A)
    if n > (1 << 20):  # small arrays: no syscall
        check_bytes(n * (itemsize + 1), f"{name}: an array of {n:,} numbers")


def _work_guard(n_rows: int, seconds_per_row: float, name: str) -> None:
    if seconds_per_row and n_rows > 1000:
        from gsdf._memory import check_work

        check_work(n_rows, seconds_per_row, f"{name}: {n_rows:,} points")


def as_values(x, name: str = "values", shape=None, *, finite: bool = True, allow_empty: bool = False,
              seconds_per_item: float = 0.0) -> np.ndarray:
    """The one check of real numbers given as an array: returns ``x`` as a C-contiguous float64 array.

    Refused with a ValueError naming ``name``: strings, bytes, booleans, complex numbers, Python objects, dates
    and ragged nesting; NaN or infinite entries (unless ``finite=False``); a shape other than ``shape`` (a tuple
    whose ``None`` entries match any length, e.g. ``(n,)`` for one value per vertex); an empty array unless
    ``allow_empty``. A conversion copy larger than the memory available, or more than ``seconds_per_item`` × size
    of estimated work beyond the limit, is refused before it is made.

    Example
    -------
    >>> as_values([1, 2.5], "levels").tolist()
    [1.0, 2.5]
    >>> as_values(np.array([1 + 2j]), "values")
    Traceback (most recent call last):
    ...
    ValueError: values: expected real numbers, got complex numbers
    """
    A = _array(x, name)
    if A.dtype.kind not in _REAL_KINDS:
        raise ValueError(f"{name}: expected real numbers, got {_dtype_words(A)}")
    if shape is not None:
        shape = tuple(shape)
        if A.ndim != len(shape) or any(s is not None and int(s) != a for s, a in zip(shape, A.shape)):
            want = "(" + ", ".join("n" if s is None else str(int(s)) for s in shape) + ("," if len(shape) == 1
                                                                                         else "") + ")"
            raise ValueError(f"{name}: expected shape {want}, got {A.shape}")
    if A.size == 0 and not allow_empty:
        raise ValueError(f"{name}: is empty")
    if seconds_per_item:
        from gsdf._memory import size_of

        _work_guard(size_of(A), seconds_per_item, name)
    if A.dtype != np.float64 or not A.flags.c_contiguous:
        _copy_guard(A, name)
    A = np.asarray(A, dtype=np.float64, order="C")  # (ascontiguousarray would make a scalar 1-d)
    if finite and not np.isfinite(A).all():
        bad = int(np.argmax(~np.isfinite(A.ravel())))
        raise ValueError(f"{name}: contains NaN or infinite values (first at flat index {bad})")
    return A


def as_occupancy(x, name: str = "occupancy") -> np.ndarray:
    """Validate a voxel grid: a 3-D boolean array (0/1 numbers accepted) with no empty axis; returns it as a
    C-contiguous bool array. Its size is checked first (the callers' padded copies and masks: a few bytes per
    voxel, :func:`gsdf._memory.check_bytes`; one pass per voxel, :func:`gsdf._memory.check_work`), so that a
    10^12-voxel grid is refused at once."""
    A = _array(x, name)
    if A.ndim != 3:
        raise ValueError(f"{name}: expected a 3-D boolean array, got {A.ndim} dimensions (shape {A.shape})")
    if min(A.shape) < 1:
        raise ValueError(f"{name}: has an empty axis, shape {A.shape}")
    from gsdf._memory import SECONDS_PER_CELL, check_bytes, check_work, size_of

    n = size_of(A)
    what = f"{name}: a {A.shape[0]}x{A.shape[1]}x{A.shape[2]} voxel grid ({n:,} voxels)"
    check_bytes(4 * n, what)
    check_work(n, SECONDS_PER_CELL, what)
    if A.dtype != bool:
        if A.dtype.kind not in _REAL_KINDS:
            raise ValueError(f"{name}: expected a boolean array, got {_dtype_words(A)}")
        if not np.isin(A, (0, 1)).all():
            raise ValueError(f"{name}: expected a boolean array (or 0/1 values), got dtype {A.dtype} with other "
                             "values")
        A = A.astype(bool)
    return np.ascontiguousarray(A)


def as_mask(x, n: int, name: str = "mask") -> np.ndarray:
    """Validate a selection: a boolean array of shape (n,) (0/1 numbers accepted); returns it as bool.
    Strings, floats other than 0 and 1, and other shapes are refused (``"no"`` would otherwise select)."""
    A = _array(x, name)
    if A.shape != (n,):
        raise ValueError(f"{name}: expected {n} booleans (shape ({n},)), got shape {A.shape}")
    if A.dtype != bool:
        if A.dtype.kind not in _REAL_KINDS:
            raise ValueError(f"{name}: expected booleans, got {_dtype_words(A)}")
        if not np.isin(A, (0, 1)).all():
            raise ValueError(f"{name}: expected booleans (or 0/1 values), got dtype {A.dtype} with other values")
        A = A.astype(bool)
    return A


def flag(x, name: str) -> bool:
    """Validate a switch: ``True``/``False`` (or numpy's bool); strings such as ``"no"``, numbers and None are
    refused (``"no"`` is truthy: accepting it would do the opposite of what was asked)."""
    if not isinstance(x, (bool, np.bool_)):
        raise ValueError(f"{name}: expected True or False, got {x!r}")
    return bool(x)


def as_points(X, name: str = "points", dim: int | None = 3, allow_empty: bool = False,
              seconds_per_row: float = 0.0) -> np.ndarray:
    """Return ``X`` as a C-contiguous float64 array of shape (n, dim), or raise ValueError.

    ``dim=None`` accepts 2 or 3 columns. ``seconds_per_row`` > 0: the caller's single-thread cost of one row
    (e.g. :data:`gsdf._memory.SECONDS_PER_QUERY` for query points), checked by :func:`gsdf._memory.check_work`
    before the first pass over ``X``.
    """
    A = _array(X, name)
    if A.dtype.kind not in _REAL_KINDS + "b":
        raise ValueError(f"{name}: expected numeric coordinates, got {_dtype_words(A)}")
    if A.ndim == 1 and dim is not None and A.shape[0] == dim:
        A = A.reshape(1, dim)
    if A.ndim != 2:
        want = f"(n, {dim})" if dim is not None else "(n, 2) or (n, 3)"
        raise ValueError(f"{name}: expected shape {want}, got {A.shape}")
    if dim is None:
        if A.shape[1] not in (2, 3):
            raise ValueError(f"{name}: expected 2 or 3 columns, got shape {A.shape}")
    elif A.shape[1] != dim:
        raise ValueError(f"{name}: expected shape (n, {dim}), got {A.shape}")
    if A.shape[0] == 0 and not allow_empty:
        raise ValueError(f"{name}: is empty (0 rows)")
    _work_guard(A.shape[0], seconds_per_row, name)
    if A.dtype != np.float64 or not A.flags.c_contiguous:
        _copy_guard(A, name)
    A = np.ascontiguousarray(A, dtype=np.float64)
    if not np.isfinite(A).all():
        bad = int(np.argmax(~np.isfinite(A).all(axis=1)))
        raise ValueError(f"{name}: contains NaN or infinite coordinates (first at row {bad})")
    return A


def as_faces(F, n_vertices: int, name: str = "F", corners: int | None = 3, allow_empty: bool = False) -> np.ndarray:
    """Return ``F`` as a C-contiguous int64 (m, corners) index array, checking the index range."""
    A = _array(F, name)
    if A.dtype.kind not in _REAL_KINDS:
        raise ValueError(f"{name}: expected integer indices, got {_dtype_words(A)}")
    if A.ndim == 1 and corners is not None and A.shape[0] == corners:
        A = A.reshape(1, corners)
    if A.ndim != 2 or (corners is not None and A.shape[1] != corners):
        raise ValueError(f"{name}: expected shape (m, {corners}), got {A.shape}")
    if A.shape[0] == 0:
        if allow_empty:
            return np.zeros((0, A.shape[1]), dtype=np.int64)
        raise ValueError(f"{name}: is empty (0 faces)")
    if np.issubdtype(A.dtype, np.floating):
        if not np.isfinite(A).all() or not np.all(A == np.round(A)):
            raise ValueError(f"{name}: face indices must be integers, got non-integral floats")
    if A.dtype != np.int64 or not A.flags.c_contiguous:
        _copy_guard(A, name)
    A = np.ascontiguousarray(A, dtype=np.int64)
    lo, hi = int(A.min()), int(A.max())
    if lo < 0:
        raise ValueError(f"{name}: negative vertex index {lo}")
    if hi >= n_vertices:
        raise ValueError(f"{name}: vertex index {hi} out of range for {n_vertices} vertices")
    return A


def as_mesh(V, F, allow_empty_faces: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Validate a triangle mesh/soup ``(V, F)``."""
    V = as_points(V, "V")
    F = as_faces(F, V.shape[0], "F", allow_empty=allow_empty_faces)
    return V, F


def as_normals(N, n: int, name: str = "N", dim: int = 3) -> np.ndarray:
    """Validate normals: shape (n, dim), finite, not all zero. Zero rows are allowed (they contribute nothing)."""
    A = as_points(N, name, dim=dim)
    if A.shape[0] != n:
        raise ValueError(f"{name}: has {A.shape[0]} rows but there are {n} points")
    norms = np.linalg.norm(A, axis=1)
    if not np.any(norms > 0):
        raise ValueError(f"{name}: all normals are zero")
    return A


def as_weights(a, n: int, name: str = "areas") -> np.ndarray:
    """Validate nonnegative per-element weights of length n."""
    A = as_values(a, name, (n,))
    if (A < 0).any():
        raise ValueError(f"{name}: contains negative values")
    if not (A > 0).any():
        raise ValueError(f"{name}: all values are zero")
    return A


def _real(x, name: str) -> float:
    if isinstance(x, (bool, np.bool_, str, bytes, complex, np.complexfloating)) or np.ndim(x) != 0 \
            or getattr(getattr(x, "dtype", None), "kind", "f") not in _REAL_KINDS:
        raise ValueError(f"{name}: expected a real number, got {x!r}")
    try:
        return float(x)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"{name}: expected a number, got {x!r}") from exc


def positive(x, name: str, most: float = np.inf) -> float:
    """Validate a finite positive scalar (at most ``most``); bools, strings and arrays are refused."""
    v = _real(x, name)
    if not np.isfinite(v) or v <= 0 or v > most:
        rng = "" if most == np.inf else f" <= {most:g}"
        raise ValueError(f"{name}: must be a finite positive number{rng}, got {x!r}")
    return v


def nonnegative(x, name: str, most: float = np.inf) -> float:
    """Validate a finite scalar >= 0 (at most ``most``)."""
    v = _real(x, name)
    if not np.isfinite(v) or v < 0 or v > most:
        rng = "" if most == np.inf else f" and <= {most:g}"
        raise ValueError(f"{name}: must be a finite number >= 0{rng}, got {x!r}")
    return v


def finite(x, name: str) -> float:
    """Validate a finite real scalar."""
    v = _real(x, name)
    if not np.isfinite(v):
        raise ValueError(f"{name}: must be a finite number, got {x!r}")
    return v


#: Largest diffusion-time coefficient of the heat methods (t = t_coef · h², h a mesh or grid spacing): beyond it
#: the heat spreads over thousands of spacings — far past any domain gsdf meshes or grids — and the field loses
#: every feature (at 1e308, t overflows).
T_COEF_MAX = 1e6

#: Largest integer option accepted (beyond 2**53 floats cannot hold it, and numba kernels take int64).
MAX_INT = 2 ** 53


def integer(x, name: str, lo: int = 1, hi: int = MAX_INT) -> int:
    """Validate an integer (not a bool, no fractional part) in ``[lo, hi]``."""
    if isinstance(x, (bool, np.bool_, str, bytes)) or np.ndim(x) != 0:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {x!r}")
    try:
        v = int(x)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {x!r}") from exc
    if v != x or v < lo:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {x!r}")
    if v > hi:
        raise ValueError(f"{name}: expected an integer <= {hi}, got {x!r}")
    return v


def neighbours(k, n: int, name: str = "k", lo: int = 1, default: int = 0) -> int:
    """Validate a neighbour count ``k`` for a cloud of ``n`` points: an integer >= ``lo`` and at most ``n - 1``
    (a point has no more neighbours). Up to ``default`` (the function's default k) is accepted on smaller
    clouds, which then use all ``n - 1`` other points (the callers' documented clamp); beyond both it is refused.
    Returns ``k`` unchanged."""
    hi = max(n - 1, int(default), lo)
    if not isinstance(k, (bool, np.bool_)) and np.ndim(k) == 0 and isinstance(k, (int, np.integer)) and k > hi:
        raise ValueError(f"{name}: {k} neighbours asked for, but the cloud has {n} points (at most {n - 1} "
                         "neighbours each)")
    return integer(k, name, lo, hi=hi)


def choice(x, name: str, options) -> str:
    """Validate one of a set of (hashable, usually string) options."""
    if not isinstance(x, (str, int)) or isinstance(x, bool) or x not in options:
        raise ValueError(f"{name}: must be one of {sorted(options)}, got {x!r}")
    return x


def query_shaped(dim: int = 3):
    """Decorator for a function or method whose argument ``Q`` is a set of query points.

    Besides the (q, dim) array the function takes, ``Q`` may have any shape (..., dim): the function sees the
    points as (q, dim) rows, and every result whose first axis runs over the queries comes back shaped
    (...) + its trailing shape (numpy's convention; Open3D's raycasting scene does the same). An empty set of
    queries ((0, dim), or any shape with a zero) gives empty results of the right dtypes and trailing shapes,
    as numpy functions do: the function is run on one dummy point and its results are cut to no row.
    """

    def deco(fn):
        names = list(inspect.signature(fn).parameters)
        pos = names.index("Q")

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            given = len(args) > pos
            if not given and "Q" not in kwargs:
                return fn(*args, **kwargs)
            Q = args[pos] if given else kwargs["Q"]
            try:
                A = np.asarray(Q)
            except Exception:  # ragged input: let the function refuse it with its own message
                return fn(*args, **kwargs)
            if A.ndim < 2 or A.shape[-1] != dim or A.dtype == object or (A.ndim == 2 and A.shape[0] > 0):
                return fn(*args, **kwargs)  # (q, dim) with q > 0, or a single point: unchanged
            lead = A.shape[:-1]
            flat = A.reshape(-1, dim)
            n = flat.shape[0]
            if n == 0:
                flat = np.zeros((1, dim))
            if given:
                args = args[:pos] + (flat,) + args[pos + 1:]
            else:
                kwargs = dict(kwargs, Q=flat)
            return _shape_results(fn(*args, **kwargs), lead, n)

        return wrapper

    return deco


def _shape_results(out, lead, n):
    if isinstance(out, tuple):
        return tuple(_shape_results(o, lead, n) for o in out)
    if isinstance(out, np.ndarray) and out.ndim >= 1 and out.shape[0] == max(n, 1):
        return out[:n].reshape(lead + out.shape[1:])
    return out


def progress_callback(progress, name: str = "progress"):
    """The one progress signature of gsdf: ``progress(stage: str, fraction: float)``, fraction in [0, 1].

    Returns ``progress`` itself, or a no-op for None; a ValueError naming the argument when it is not callable.
    """
    if progress is None:
        return _no_progress
    if not callable(progress):
        raise ValueError(f"{name}: expected a callable progress(stage, fraction) or None, got {type(progress).__name__}")
    return progress


def _no_progress(stage: str, fraction: float) -> None:
    return None


#: Bytes of memory a reader may need per byte of the file it reads (text tokens -> arrays, with copies).
READ_FACTOR = 8


def readable_file(path, what: str = "file") -> str:
    """Check an input path before opening it; returns it as ``str``.

    A missing path is a ``FileNotFoundError`` (errno ENOENT, as ``open`` gives); everything else is a
    ``ValueError`` naming the path: not a path at all, a directory, anything but a regular file (a FIFO would
    block the reader forever, ``/dev/zero`` never ends), a file the user may not read, or a file whose size ×
    :data:`READ_FACTOR` exceeds the memory available (:func:`gsdf._memory.check_bytes`).
    """
    import errno
    import os
    import stat

    if isinstance(path, (bool, int, float)) or path is None:
        raise ValueError(f"{what}: expected a file name, got {path!r}")
    try:
        p = os.fspath(path)
    except TypeError:
        raise ValueError(f"{what}: expected a file name, got {type(path).__name__}") from None
    if isinstance(p, bytes):
        p = os.fsdecode(p)
    if not p:
        raise ValueError(f"{what}: expected a file name, got an empty string")
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), p) from None
    except NotADirectoryError:
        raise ValueError(f"{p}: a parent of this path is a file, not a folder") from None
    except OSError as exc:
        raise ValueError(f"{p}: cannot read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ValueError(f"{p}: is a directory, not a file")
    if not stat.S_ISREG(st.st_mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else "a device" if stat.S_ISCHR(st.st_mode)
                or stat.S_ISBLK(st.st_mode) else "a socket" if stat.S_ISSOCK(st.st_mode) else "not a regular file")
        raise ValueError(f"{p}: is {kind}; gsdf reads regular files only")
    if not os.access(p, os.R_OK):
        raise ValueError(f"{p}: cannot read (permission denied)")
    if st.st_size > (1 << 24):
        from gsdf._memory import check_bytes, human

        check_bytes(READ_FACTOR * st.st_size, f"{p}: reading a file of {human(st.st_size)}")
    return p


def numpy_file(path, what: str = "file") -> str:
    """Check a ``.npy`` or ``.npz`` file before ``np.load`` reads it; returns its path as ``str``.

    Besides :func:`readable_file`, the header of each array is compared with the data the file holds: a shape
    with a negative size, or one whose data is larger or smaller than what follows the header (a ``.npz``
    member: than the member), is a ValueError naming the file and the shape — a truncated or damaged file or a
    corrupt header, which numpy would otherwise answer by allocating the declared size or reading shifted data. A file that is neither ``.npy`` nor
    ``.npz`` data, or an array of Python objects (which gsdf never loads), is refused too. Headers numpy itself
    cannot parse are left to ``np.load`` and its caller.
    """
    import os
    import zipfile

    p = readable_file(path, what)
    with open(p, "rb") as fh:
        magic = fh.read(6)
        if magic == b"\x93NUMPY":
            fh.seek(0)
            _npy_fits(fh, os.path.getsize(p), p, "")
            return p
    if magic[:4] != b"PK\x03\x04":
        raise ValueError(f"{p}: not a numpy file (neither .npy nor .npz data)")
    try:
        z = zipfile.ZipFile(p)
    except (zipfile.BadZipFile, OSError, ValueError, EOFError):
        return p
    with z:
        for info in z.infolist():
            if not info.filename.endswith(".npy"):
                continue
            try:
                member = z.open(info)
            except Exception:  # noqa: BLE001, S112 - encrypted, unknown compression...: np.load reports it
                continue
            with member:
                _npy_fits(member, info.file_size, p, f"array {info.filename[:-4]!r}: ")
    return p


def _npy_fits(fh, total: int, p: str, label: str) -> None:
    """Raise when the .npy header read from ``fh`` declares more data than the ``total`` bytes hold."""
    from numpy.lib import format as npformat

    try:
        version = npformat.read_magic(fh)
        read = {(1, 0): npformat.read_array_header_1_0, (2, 0): npformat.read_array_header_2_0}.get(version)
        if read is None:
            return
        shape, _, dtype = read(fh)
        offset = fh.tell()
    except Exception:  # noqa: BLE001 - a header numpy cannot parse: np.load says so
        return
    if dtype.hasobject:
        raise ValueError(f"{p}: {label}holds Python objects (pickled data); gsdf reads arrays of numbers only")
    if any(int(s) < 0 for s in shape):
        raise ValueError(f"{p}: {label}the header declares a negative size in shape {tuple(shape)}")
    count = 1
    for s in shape:
        count *= int(s)
    need, have = count * dtype.itemsize, max(int(total) - offset, 0)
    if need > have:
        from gsdf._memory import human

        raise ValueError(f"{p}: {label}the header declares shape {tuple(shape)} ({human(need)} of data) but the "
                         f"file holds {human(have)}; it is truncated or its header is corrupt")
    if need < have:  # numpy writes the data and nothing after it: a byte inserted, or two files joined
        raise ValueError(f"{p}: {label}the header declares shape {tuple(shape)} ({need:,} bytes of data) but "
                         f"{have - need:,} more bytes follow; the file is damaged")
