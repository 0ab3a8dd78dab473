"""Shared helpers of the subcommands: loading inputs, progress bars, clean error reporting, safe outputs.

Output policy (the same for every subcommand; see :mod:`gsdf.io._safe_write`):

* an output that is one of the command's inputs (same file after resolving symlinks / hard links) is always
  refused, before any work is done;
* an existing output that is not an input is **overwritten**, as ``-o`` does in most command-line tools; pass
  ``--no-clobber`` to refuse instead;
* the requested name is never changed: an extension the output cannot have is refused with the list of the ones
  it can;
* every file is written to a temporary name in the target folder and renamed when complete; missing parent
  folders are created.

Subcommands get this by decorating with :data:`gsdf.cli._options.no_clobber_option` and :func:`report_errors`
(which sets the policy, refuses any ``OUTPUT_PARAMS`` option naming an input and turns library errors into
one-line messages),
by calling :func:`check_output` on every output name before the work starts, and by writing each file inside
``with output_file(path) as tmp:``. Inputs are the values of the command's ``click.Path``
parameters, so outputs must be declared as plain strings.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import warnings

import click
import numpy as np

from gsdf.io._geometry import Geometry, load_geometry  # noqa: F401  (the CLI commands import them from here)
from gsdf.io._safe_write import atomic_output, check_output_path, same_file

def progress_bar(total: int, desc: str, enabled: bool = True):
    """A tqdm bar of ``total`` units and the library's ``progress(stage, fraction)`` callback that moves it."""
    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit="pt", unit_scale=True, disable=not enabled, leave=False)

    def update(stage, fraction):
        bar.update(round(fraction * total) - bar.n)

    return bar, update


def counting(func, desc: str, enabled: bool = True):
    """Wrap a field ``func(Q)`` so that a progress bar counts the evaluated points (total unknown up front)."""
    from tqdm import tqdm

    bar = tqdm(desc=desc, unit="pt", unit_scale=True, disable=not enabled, leave=False)

    def wrapped(Q):
        out = func(Q)
        bar.update(len(Q))
        return out

    return bar, wrapped


#: Names of the subcommands' parameters that hold output file names (checked before the work starts).
OUTPUT_PARAMS = ("output", "mesh_output", "png")

_POLICY: contextvars.ContextVar = contextvars.ContextVar("gsdf_output_policy", default=None)


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
    """Write one output of the running command safely: yields a temporary path in the target folder (same
    extension) that is renamed onto ``path`` when the block succeeds. Applies the command's policy: never one of
    its inputs, existing files replaced unless ``--no-clobber``, parent folders created."""
    policy = _POLICY.get() or {"inputs": [], "overwrite": True}
    with atomic_output(path, inputs=policy["inputs"], extensions=extensions, overwrite=policy["overwrite"],
                       make_parents=True, what=what) as tmp:
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
    """Decorate a subcommand (innermost, below the click options): sets the output policy (inputs = the
    command's ``click.Path`` parameters; ``--no-clobber`` when the command has :data:`no_clobber_option`), refuses
    up front any parameter of ``OUTPUT_PARAMS`` that names one of the inputs, turns the library's
    ValueError / FileNotFoundError / OSError into a one-line CLI error (exit code 1) without a traceback, and
    prints gsdf's warnings (e.g. an unreliable sign rule) as one ``gsdf: warning: ...`` line on stderr."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        no_clobber = bool(kwargs.pop("no_clobber", False))
        ctx = click.get_current_context(silent=True)
        policy = {"inputs": _input_paths(ctx), "overwrite": not no_clobber}
        token = _POLICY.set(policy)
        try:
            with warnings.catch_warnings():
                warnings.showwarning = _plain_warnings(warnings.showwarning)
                for name in OUTPUT_PARAMS:
                    value = kwargs.get(name)
                    if isinstance(value, str) and value and any(same_file(value, src) for src in policy["inputs"]):
                        raise ValueError(f"{value}: refusing to overwrite an input of this command; choose another "
                                         "output name")
                return fn(*args, **kwargs)
        except (ValueError, OSError) as exc:  # FileNotFoundError is an OSError
            raise click.ClickException(_one_line(exc)) from exc
        finally:
            _POLICY.reset(token)

    return wrapper


def check_output(path, extensions=None, what: str = "-o"):
    """Check an output name up front (extension, not an input, ``--no-clobber``) under the running command's
    policy, before any expensive work; returns it unchanged. ``None`` passes (an optional output not asked for)."""
    if path is None:
        return None
    policy = _POLICY.get() or {"inputs": [], "overwrite": True}
    return check_output_path(path, inputs=policy["inputs"], extensions=extensions, overwrite=policy["overwrite"],
                             make_parents=True, what=what)


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
    click.echo(f"picture ({used}) -> {os.path.abspath(png)}")


def check_slice(png, axis, at) -> None:
    """``--axis``/``--at`` shape the ``--png`` picture: refused without it."""
    if png is None and (axis is not None or at is not None):
        raise click.UsageError("--axis and --at place the slice of the --png picture; give --png FILE too")
