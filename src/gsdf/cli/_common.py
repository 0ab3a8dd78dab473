"""Shared helpers of the subcommands: loading inputs, progress bars, clean error reporting, safe outputs.

Output policy (the same for every subcommand; see :mod:`gsdf.io._safe_write`):

* the outputs of a command are **one set**: all of them appear, or none. Each file is written to a temporary
  name in its target folder; only when the whole command has succeeded are the temporaries renamed onto their
  names (:class:`Outputs`). On any failure — a bad option found late, a level outside the field's range, a full
  disk, Ctrl-C — the temporaries and the folders the command created are removed and existing files are left
  as they were;
* every output name is checked before any work is done: an output that is one of the command's inputs (same
  file after resolving symlinks / hard links) is refused, and so are two outputs with one name (``--mesh-output
  x.vtk -o x.vtk``);
* an existing output that is not an input is **overwritten**, as ``-o`` does in most command-line tools; pass
  ``--no-clobber`` to refuse instead;
* the requested name is never changed: an extension the output cannot have is refused with the list of the ones
  it can; missing parent folders are created (and removed again on failure).

Subcommands get this by decorating with :data:`gsdf.cli._options.no_clobber_option` and :func:`report_errors`
(which runs the command inside :func:`outputs`, refuses any ``OUTPUT_PARAMS`` option naming an input and turns
library errors — MemoryError included — into one-line messages), by calling :func:`check_output` on every output
name before the work starts, and by writing each file inside ``with output_file(path) as tmp:``. Inputs are the
values of the command's ``click.Path`` parameters, so outputs must be declared as plain strings.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import os
import tempfile
import warnings

import click
import numpy as np

from gsdf._memory import check_environment
from gsdf.io._geometry import Geometry, load_geometry  # noqa: F401  (the CLI commands import them from here)
from gsdf.io._safe_write import _FILE_MODE, check_output_path, extension_of, same_file

def progress_bar(total: int, desc: str, enabled: bool = True):
    """A tqdm bar of ``total`` units and the library's ``progress(stage, fraction)`` callback that moves it."""
    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit="pt", unit_scale=True, disable=not enabled, leave=False)

    def update(stage, fraction):
        bar.update(round(fraction * total) - bar.n)

    return bar, update


class LazyWinding:
    """The fast winding number of a loaded input, its tree built on the first evaluation: a contouring call's
    size guard (which reads ``_seconds_per_point``, the cost of a tree query) refuses a too large grid before any
    tree is built."""

    def __init__(self, geo, beta=None):
        from gsdf._memory import SECONDS_PER_QUERY

        self._geo, self._beta, self._fn = geo, beta, None
        self._seconds_per_point = SECONDS_PER_QUERY

    def __call__(self, Q):
        if self._fn is None:
            self._fn = self._geo.winding(self._beta)
        return self._fn(Q)


def counting(func, desc: str, enabled: bool = True):
    """Wrap a field ``func(Q)`` so that a progress bar counts the evaluated points (total unknown up front)."""
    from tqdm import tqdm

    bar = tqdm(desc=desc, unit="pt", unit_scale=True, disable=not enabled, leave=False)

    def wrapped(Q):
        out = func(Q)
        bar.update(len(Q))
        return out

    if hasattr(func, "_seconds_per_point"):  # the cost of one evaluation, for the size guard
        wrapped._seconds_per_point = func._seconds_per_point
    return bar, wrapped


#: Names of the subcommands' parameters that hold output file names (checked before the work starts).
OUTPUT_PARAMS = ("output", "mesh_output", "png")

_OUTPUTS: contextvars.ContextVar = contextvars.ContextVar("gsdf_outputs", default=None)


class Outputs:
    """The output files of one command, committed as one set (see the module docstring).

    :meth:`declare` checks a name up front (policy of :func:`gsdf.io._safe_write.check_output_path`, plus: no
    two outputs with one name); :meth:`file` yields a temporary path in the target folder to write to;
    :meth:`commit` renames every temporary onto its name (an existing file is kept as a hard-linked backup until
    all renames succeeded, and put back if one fails); :meth:`abort` removes the temporaries and the folders the
    set created.
    """

    def __init__(self, inputs=(), overwrite: bool = True):
        self.inputs = [i for i in inputs if i is not None]
        self.overwrite = overwrite
        self._names: list = []      # (path, what) declared
        self._pending: dict = {}    # final path -> temporary path
        self._created: list = []    # folders created for the outputs, deepest first
        self._notes: list = []      # messages about the outputs, printed once they are committed

    def declare(self, path, extensions=None, what: str = "-o", again: bool = False) -> str:
        """Check ``path`` and add it to the set; a name already declared by another option is refused (by the
        same option, or ``again``: accepted)."""
        p = check_output_path(path, inputs=self.inputs, extensions=extensions, overwrite=self.overwrite,
                              make_parents=True, what=what)
        for q, w in self._names:
            if same_file(p, q):
                if w != what and not again:
                    raise ValueError(f"{p}: named by both {w} and {what}; give each output its own name")
                return p
        self._names.append((p, what))
        return p

    def _make_parents(self, folder: str) -> None:
        new = []
        probe = folder
        while not os.path.exists(probe):
            new.append(probe)
            probe = os.path.dirname(probe)
        os.makedirs(folder, exist_ok=True)
        self._created = new + self._created

    @contextlib.contextmanager
    def file(self, path, extensions=None, what: str = "output"):
        p = self.declare(path, extensions, what, again=True)
        parent = os.path.dirname(os.path.abspath(p))
        base = os.path.basename(p)
        try:
            self._make_parents(parent)
            # the temporary keeps the extension (lower case): writers choose their format by it
            fd, tmp = tempfile.mkstemp(prefix=f".{base}.", suffix=f".tmp{extension_of(base)}", dir=parent)
            os.close(fd)
        except OSError as exc:
            raise ValueError(f"{p}: cannot write ({exc.strerror or exc})") from exc
        try:
            yield tmp
            strays = [q for q in os.listdir(parent) if q.startswith(os.path.basename(tmp)) and
                      q != os.path.basename(tmp)]
            if strays:  # the writer changed the name it was given: never publish a different (or empty) file
                for q in strays:
                    _remove(os.path.join(parent, q))
                raise ValueError(f"{p}: the writer wrote {strays[0]} instead of the name it was given")
            if not os.path.exists(tmp):
                raise ValueError(f"{p}: the writer produced no file")
            os.chmod(tmp, _FILE_MODE)
        except OSError as exc:
            _remove(tmp)
            raise ValueError(f"{p}: cannot write ({exc.strerror or exc})") from exc
        except BaseException:
            _remove(tmp)
            raise
        old = self._pending.pop(os.path.abspath(p), None)
        if old is not None:
            _remove(old)
        self._pending[os.path.abspath(p)] = tmp

    def commit(self) -> None:
        done, backups = [], {}
        try:
            for final, tmp in self._pending.items():
                if os.path.lexists(final):
                    if not self.overwrite:  # appeared while we were computing
                        raise ValueError(f"{final}: already exists (refusing to overwrite)")
                    backup = tmp + ".old"
                    with contextlib.suppress(OSError):
                        os.link(final, backup)
                        backups[final] = backup
                os.replace(tmp, final)
                done.append(final)
        except BaseException as exc:
            for final in done:  # put the set back as it was
                if final in backups:
                    with contextlib.suppress(OSError):
                        os.replace(backups.pop(final), final)
                else:
                    _remove(final)
            self.abort()
            for b in backups.values():
                _remove(b)
            if isinstance(exc, OSError):
                raise ValueError(f"cannot write the outputs ({exc.strerror or exc}); nothing was written") from exc
            raise
        for b in backups.values():
            _remove(b)
        self._pending = {}
        for msg in self._notes:
            click.echo(msg)
        self._notes = []

    def abort(self) -> None:
        for tmp in self._pending.values():
            _remove(tmp)
        self._pending = {}
        self._notes = []
        for d in self._created:
            try:
                os.rmdir(d)
            except OSError:
                break
        self._created = []


def _remove(path: str) -> None:
    with contextlib.suppress(OSError):
        os.remove(path)


@contextlib.contextmanager
def outputs(inputs=(), overwrite: bool = True):
    """Run a command's body with one output set (:class:`Outputs`): :func:`check_output` and :func:`output_file`
    inside the block use it; the files are committed together when the block succeeds, removed when it fails.
    :func:`report_errors` opens it for every subcommand.

    Example
    -------
    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> try:
    ...     with outputs():
    ...         with output_file(os.path.join(d, "a.txt")) as tmp:
    ...             _ = open(tmp, "w").write("a")
    ...         raise ValueError("a later step fails")
    ... except ValueError:
    ...     pass
    >>> os.listdir(d)
    []
    """
    out = Outputs(inputs, overwrite)
    token = _OUTPUTS.set(out)
    try:
        yield out
    except BaseException:
        out.abort()
        raise
    else:
        out.commit()
    finally:
        _OUTPUTS.reset(token)


def announce(message: str) -> None:
    """Print a message about an output (``... -> path``) once the command's outputs are committed (at once
    outside a command): a command that fails later never claims a file it did not leave."""
    out = _OUTPUTS.get()
    if out is None:
        click.echo(message)
    else:
        out._notes.append(message)


def _current() -> Outputs:
    out = _OUTPUTS.get()
    return out if out is not None else Outputs()


def _input_paths(ctx) -> list:
    """The values of every ``click.Path`` parameter of the running command: its input files."""
    if ctx is None:
        return []
    out = []
    for param in ctx.command.params:
        if isinstance(param.type, click.Path) and ctx.params.get(param.name):
            v = ctx.params[param.name]
            out.extend(v if isinstance(v, (tuple, list)) else [v])
    return out


def _one_line(exc) -> str:
    msg = str(exc)
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        msg = f"{exc.filename}: {exc.strerror}"
    return " ".join(msg.split()) or type(exc).__name__


@contextlib.contextmanager
def output_file(path, extensions=None, what: str = "output"):
    """Write one output of the running command: yields a temporary path in the target folder (same extension)
    that joins the command's output set (:class:`Outputs`) and is renamed onto ``path`` when the whole command
    has succeeded. Applies the command's policy: never one of its inputs nor a name another output has, existing
    files replaced unless ``--no-clobber``, parent folders created. Outside a command (no :func:`outputs` block)
    the file is committed at the end of the ``with`` block."""
    if _OUTPUTS.get() is None:
        with outputs():
            with _current().file(path, extensions, what) as tmp:
                yield tmp
        return
    with _current().file(path, extensions, what) as tmp:
        yield tmp


def _plain_warnings(show):
    """A ``warnings.showwarning`` that prints gsdf's own warnings as one ``gsdf: warning: ...`` line on stderr and
    passes the others to ``show``."""

    def plain(message, category, filename, lineno, file=None, line=None):
        if category.__module__.startswith("gsdf."):
            click.echo(f"gsdf: warning: {message}", err=True)
        else:
            show(message, category, filename, lineno, file, line)

    return plain


def report_errors(fn):
    """Decorate a subcommand (innermost, below the click options): runs it inside :func:`outputs` (inputs = the
    command's ``click.Path`` parameters; ``--no-clobber`` when the command has :data:`no_clobber_option`), refuses
    up front any parameter of ``OUTPUT_PARAMS`` that names one of the inputs or another output, turns the
    library's ValueError / FileNotFoundError / OSError / MemoryError into a one-line CLI error (exit code 1)
    without a traceback, and prints gsdf's warnings (e.g. an unreliable sign rule) as one ``gsdf: warning: ...``
    line on stderr."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        no_clobber = bool(kwargs.pop("no_clobber", False))
        ctx = click.get_current_context(silent=True)
        try:
            check_environment()
            with outputs(_input_paths(ctx), overwrite=not no_clobber) as out, warnings.catch_warnings():
                warnings.showwarning = _plain_warnings(warnings.showwarning)
                for name in OUTPUT_PARAMS:
                    value = kwargs.get(name)
                    if isinstance(value, str) and value:
                        if any(same_file(value, src) for src in out.inputs):
                            raise ValueError(f"{value}: refusing to overwrite an input of this command; choose "
                                             "another output name")
                        out.declare(value, None, _flag(ctx, name))
                return fn(*args, **kwargs)
        except MemoryError as exc:
            raise click.ClickException(f"out of memory ({_one_line(exc)}); lower the resolution / size, or set "
                                       "GSDF_MEMORY_LIMIT so that gsdf refuses such requests up front") from None
        except (ValueError, OSError) as exc:  # FileNotFoundError is an OSError
            raise click.ClickException(_one_line(exc)) from exc

    return wrapper


def _flag(ctx, name: str) -> str:
    """How the command line spells the option ``name`` (``-o``, ``--png``, ...)."""
    for param in getattr(getattr(ctx, "command", None), "params", ()):
        if param.name == name and getattr(param, "opts", None):
            return param.opts[0]
    return "--" + name.replace("_", "-")


def check_output(path, extensions=None, what: str = "-o"):
    """Check an output name up front (extension, not an input, not another output's name, ``--no-clobber``)
    under the running command's policy, before any expensive work; returns it unchanged. ``None`` passes (an
    optional output not asked for)."""
    if path is None:
        return None
    return _current().declare(path, extensions, what)


def bbox_of(X: np.ndarray, pad: float) -> tuple[np.ndarray, np.ndarray]:
    from gsdf.mesh._geometry import bounding_box

    return bounding_box(X, pad)


def write_picture(png, *items, view=None, axis=None, at=None) -> None:
    """The ``--png`` of a command: :func:`gsdf.render.save_png` of ``items`` (polyscope when it renders here, else
    gsdf's own renderers), written under the command's output policy; ``axis``/``at`` place the slice of a volume
    field. Prints which renderer drew it and where it went."""
    import os

    from gsdf.render import ViewOptions, save_png

    options = ViewOptions(slice_axis=axis, slice_at=at)
    with output_file(png, (".png",), what="--png") as tmp:
        used = save_png(tmp, *items, view=view, options=options)
    announce(f"picture ({used}) -> {os.path.abspath(png)}")


def check_slice(png, axis, at) -> None:
    """``--axis``/``--at`` shape the ``--png`` picture: refused without it."""
    if png is None and (axis is not None or at is not None):
        raise click.UsageError("--axis and --at place the slice of the --png picture; give --png FILE too")
