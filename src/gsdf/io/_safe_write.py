"""Output safety shared by every gsdf writer (library and CLI): checked names, no clobbered inputs, atomic files.

Every writer in gsdf goes through :func:`atomic_output`:

* the requested name is never changed: when ``extensions`` is given, a name whose extension is not one of them
  is a ``ValueError`` that lists the ones the writer can honour (no silent ``f.vdb.npz``);
* an output that resolves to one of the command's ``inputs`` (same real path after symlinks, or the same file
  through a hard link) is refused with a ``ValueError`` before anything is written;
* an existing output is replaced only when ``overwrite=True`` (the library's default, and the CLI's unless
  ``--no-clobber`` is given);
* a directory, a parent that is a file, a missing parent folder (unless ``make_parents``) or an unwritable folder
  is a ``ValueError`` naming the path;
* the data is written to a temporary file *in the target folder* (same file system) and moved onto the final name
  with :func:`os.replace`, so readers never see a half-written file and a failed write leaves the old file intact.

The temporary name keeps the final extension, so writers that choose their format by extension (numpy's
``savez``, meshio, PIL) behave exactly as for the final name.

Example
-------
>>> import os, tempfile, numpy as np
>>> d = tempfile.mkdtemp()
>>> with atomic_output(os.path.join(d, "a.npy"), extensions=(".npy",)) as tmp:
...     np.save(tmp, np.arange(3))
>>> np.load(os.path.join(d, "a.npy")).tolist()
[0, 1, 2]
"""

from __future__ import annotations

import contextlib
import glob
import os
import tempfile

__all__ = ["check_output_path", "atomic_output", "same_file", "extension_of"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


_FILE_MODE = 0o666 & ~_umask()  # what open(path, "w") would have given the file


def extension_of(path) -> str:
    """Lower-case extension of ``path`` including the dot (``""`` when there is none)."""
    return os.path.splitext(os.fspath(path))[1].lower()


def same_file(a, b) -> bool:
    """True when ``a`` and ``b`` name the same file: equal real paths, or (both existing) the same inode."""
    ra, rb = os.path.realpath(a), os.path.realpath(b)
    if os.path.normcase(ra) == os.path.normcase(rb):
        return True
    try:
        return os.path.samefile(ra, rb)
    except OSError:
        return False


def check_output_path(path, *, inputs=(), extensions=None, overwrite: bool = True, make_parents: bool = False,
                      what: str = "output") -> str:
    """Validate an output path before anything is computed or written; return it as ``str``.

    Parameters
    ----------
    path : str or os.PathLike
        The requested output name (never altered).
    inputs : iterable of str or os.PathLike
        Files read by the same call or command; the output may not be any of them.
    extensions : sequence of str, optional
        Lower-case extensions (with the dot) the writer can honour; ``None`` accepts any.
    overwrite : bool, default True
        Replace an existing output (which is not an input). ``False`` refuses it.
    make_parents : bool, default False
        Create missing parent folders (the CLI does); otherwise a missing folder is an error.
    what : str
        How the message names the path (e.g. ``"--png"``).

    Raises
    ------
    ValueError
        Message naming the path and the problem.
    """
    if path is None or isinstance(path, (bool, int, float)):
        raise ValueError(f"{what}: expected a file name, got {path!r}")
    try:
        p = os.fspath(path)
    except TypeError:
        raise ValueError(f"{what}: expected a file name, got {type(path).__name__}") from None
    if isinstance(p, bytes):
        p = os.fsdecode(p)
    if not p or p.endswith(("/", os.sep)):
        raise ValueError(f"{what}: {p!r} is not a file name")
    ext = extension_of(p)
    if extensions is not None and ext not in extensions:
        raise ValueError(f"{p}: cannot write {ext or 'a name without extension'!r} files here; "
                         f"supported extensions: {', '.join(extensions)}")
    for src in inputs:
        if src is not None and same_file(p, src):
            raise ValueError(f"{p}: refusing to overwrite an input of this command ({os.fspath(src)}); "
                             "choose another output name")
    if os.path.isdir(p):
        raise ValueError(f"{p}: is a directory, not a file name")
    if os.path.lexists(p) and not overwrite:
        raise ValueError(f"{p}: already exists (refusing to overwrite; remove it, choose another name, or allow "
                         "overwriting)")
    parent = os.path.dirname(os.path.abspath(p))
    # walk up to the first existing ancestor: it must be a folder (a file there makes the path impossible)
    probe = parent
    while not os.path.exists(probe):
        up = os.path.dirname(probe)
        if up == probe:
            break
        probe = up
    if not os.path.isdir(probe):
        raise ValueError(f"{p}: cannot create the file, {probe} is not a folder")
    if probe != parent and not make_parents:
        raise ValueError(f"{p}: the folder {parent} does not exist")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise ValueError(f"{p}: the folder {probe} is not writable")
    return p


@contextlib.contextmanager
def atomic_output(path, *, inputs=(), extensions=None, overwrite: bool = True, make_parents: bool = False,
                  what: str = "output"):
    """Context manager yielding a temporary path to write to; on success it is moved onto ``path``.

    Checks as :func:`check_output_path`; the temporary file lives in the target folder and has the same
    extension. On an exception the temporary file is removed and the existing ``path`` (if any) is untouched.
    ``OSError`` from the writer (disk full, permission) becomes a ``ValueError`` naming ``path``.

    Example
    -------
    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "note.txt")
    >>> with atomic_output(p) as tmp:
    ...     _ = open(tmp, "w").write("hello")
    >>> open(p).read()
    'hello'
    """
    p = check_output_path(path, inputs=inputs, extensions=extensions, overwrite=overwrite,
                          make_parents=make_parents, what=what)
    parent = os.path.dirname(os.path.abspath(p))
    try:
        if make_parents:
            os.makedirs(parent, exist_ok=True)
        base = os.path.basename(p)
        # lower-case extension: writers such as numpy's savez append ".npz" unless the name ends exactly so
        fd, tmp = tempfile.mkstemp(prefix=f".{base}.", suffix=f".tmp{extension_of(base)}", dir=parent)
        os.close(fd)
    except OSError as exc:
        raise ValueError(f"{p}: cannot write ({exc.strerror or exc})") from exc
    try:
        yield tmp
        strays = [q for q in glob.glob(glob.escape(tmp) + "?*")]
        if strays:  # the writer changed the name it was given: never publish a different (or empty) file
            for q in strays:
                _remove(q)
            raise ValueError(f"{p}: the writer wrote {os.path.basename(strays[0])} instead of the name it was given")
        if not os.path.exists(tmp):
            raise ValueError(f"{p}: the writer produced no file")
        os.chmod(tmp, _FILE_MODE)
        if not overwrite and os.path.lexists(p):  # appeared while we were computing
            raise ValueError(f"{p}: already exists (refusing to overwrite)")
        os.replace(tmp, p)
    except OSError as exc:
        _remove(tmp)
        raise ValueError(f"{p}: cannot write ({exc.strerror or exc})") from exc
    except BaseException:
        _remove(tmp)
        raise


def _remove(tmp: str) -> None:
    with contextlib.suppress(OSError):
        os.remove(tmp)
