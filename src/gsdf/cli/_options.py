"""The options the subcommands share: each is defined here once, with one spelling, one type (so one
validation) and one meaning, and every subcommand that has it uses this definition.

Outputs: ``-o/--output FILE`` names the output file of a command, ``-o/--output-dir DIR`` the folder of a
command that writes several files (``--out`` is a hidden alias of ``--output-dir`` for one release); secondary
outputs are ``--png FILE`` and ``--mesh-output FILE``. Grids: ``--resolution N`` (nodes along the longest
side of the box, unless the command's help says voxels), ``--pad F`` (the box grows by ``F`` times the
bounding-box diagonal of the input on every side). Every command takes ``-q/--quiet`` and ``--threads N``.

The value types are module constants (``RESOLUTION``, ``PAD``, ...) so that a test can check that two
commands validate an option with the very same object.
"""

from __future__ import annotations

import functools
import math

import click


class FiniteFloat(click.ParamType):
    """A finite number (``nan`` and ``inf`` are refused)."""

    name = "float"

    def convert(self, value, param, ctx):
        rv = click.FLOAT.convert(value, param, ctx)
        if not math.isfinite(rv):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return rv


class FiniteFloatRange(click.FloatRange):
    """A :class:`click.FloatRange` that also refuses ``nan`` and ``inf``."""

    def convert(self, value, param, ctx):
        return super().convert(FiniteFloat().convert(value, param, ctx), param, ctx)


class FloatList(click.ParamType):
    """Comma-separated finite numbers, e.g. ``0,0.01,-0.01`` -> ``[0.0, 0.01, -0.01]``."""

    name = "x,y,..."

    def convert(self, value, param, ctx):
        if isinstance(value, (list, tuple)):
            return list(value)
        try:
            out = [float(t) for t in str(value).split(",") if t.strip()]
        except ValueError:
            self.fail(f"expected comma-separated numbers, got {value!r}", param, ctx)
        if not out or not all(math.isfinite(v) for v in out):
            self.fail(f"expected comma-separated finite numbers, got {value!r}", param, ctx)
        return out


class Direction(click.ParamType):
    """A 3D direction ``x,y,z``: three finite numbers, not all zero."""

    name = "x,y,z"

    def convert(self, value, param, ctx):
        if isinstance(value, (list, tuple)) and len(value) == 3:
            value = ",".join(str(v) for v in value)
        try:
            d = [float(t) for t in str(value).split(",")]
            if len(d) != 3 or not all(math.isfinite(v) for v in d) or not any(d):
                raise ValueError
        except ValueError:
            self.fail(f"expected x,y,z (finite, not all zero), got {value!r}", param, ctx)
        return d


class ThreadCount(click.ParamType):
    """A positive number of threads (:func:`gsdf.threads.parse_num_threads`)."""

    name = "N"

    def convert(self, value, param, ctx):
        from gsdf.threads import parse_num_threads

        try:
            return parse_num_threads(value, name="--threads")
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


# --- the value types (one object per meaning) --------------------------------------------------------------
RESOLUTION = click.IntRange(2, 8192)                     #: grid resolution of every command
PAD = FiniteFloatRange(min=0, max=1e6)                   #: box padding, fraction of the bounding-box diagonal
POSITIVE = FiniteFloatRange(min=0, min_open=True)        #: --t-coef, --soft-weight, --beta, --time-limit
NONNEGATIVE = FiniteFloatRange(min=0)                    #: --normal-radius
NUMBER = FiniteFloat()                                   #: --level
FLOATS = FloatList()                                     #: --offsets, --heights, --sigmas
class Up(click.ParamType):
    """The up direction of a picture: ``auto``, an axis (``x``, ``-y``, ``z``, ...) or ``x,y,z``."""

    name = "auto|axis|x,y,z"

    def convert(self, value, param, ctx):
        s = str(value).strip().lower()
        if s == "auto" or s.lstrip("+-") in ("x", "y", "z"):
            return s
        return DIRECTION.convert(value, param, ctx)


class Size(click.ParamType):
    """A picture size in pixels: ``N`` (square) or ``WxH``, each 8..8192; returns (width, height)."""

    name = "N|WxH"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        try:
            parts = [int(t) for t in str(value).lower().split("x")]
            w, h = (parts[0], parts[0]) if len(parts) == 1 else parts
            if not (8 <= w <= 8192 and 8 <= h <= 8192):
                raise ValueError
        except ValueError:
            self.fail(f"expected N or WIDTHxHEIGHT (8..8192 each), got {value!r}", param, ctx)
        return w, h


DIRECTION = Direction()                                  #: --view
UP = Up()                                                #: --up
SIZE = Size()                                            #: --size
THREADS = ThreadCount()                                  #: --threads
AXIS = click.Choice(["x", "y", "z"], case_sensitive=False)   #: --axis
SURFACE_FORMAT = click.Choice(["ply", "obj", "off", "stl"])   #: --surface-format
BISECTION = click.IntRange(0, 60)                        #: --bisection
COUNT = click.IntRange(1)                                #: --n-points, --workers, ...
LEVEL_SET = click.Choice(["zero", "multiple", "none"])   #: --level-set

#: The context key under which the explicit ``--threads`` value (group or command) is kept.
THREADS_KEY = "gsdf.threads"


# --- outputs -------------------------------------------------------------------------------------------------
def output_option(help: str, required: bool = True):
    """``-o/--output FILE``: the command's output file."""
    return click.option("-o", "--output", "output", required=required, metavar="FILE", help=help)


def output_dir_option(help: str, default=None, required: bool = False):
    """``-o/--output-dir DIR``: the command's output folder. ``--out`` is accepted as a hidden alias for one
    release (a note on stderr asks for ``--output-dir``)."""

    def decorator(fn):
        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            old = kwargs.pop("out_alias", None)
            if old is not None:
                click.echo("gsdf: --out is deprecated, use -o/--output-dir", err=True)
                if kwargs.get("output_dir") not in (None, old) and kwargs.get("output_dir") != default:
                    raise click.UsageError("give the output folder once (--output-dir; --out is its old name)")
                kwargs["output_dir"] = old
            if kwargs.get("output_dir") is None and required:
                raise click.UsageError("Missing option '-o' / '--output-dir'.")
            return fn(*args, **kwargs)

        wrapper = click.option("--out", "out_alias", default=None, hidden=True, metavar="DIR",
                               help="Old name of --output-dir.")(wrapper)
        return click.option("-o", "--output-dir", "output_dir", default=default, show_default=default is not None,
                            metavar="DIR", help=help + ("  [required]" if required else ""))(wrapper)

    return decorator


def png_option(help: str = "Also write a PNG picture of the result."):
    """``--png FILE``: a picture of the result, besides the output."""
    return click.option("--png", "png", default=None, metavar="FILE", help=help)


def mesh_output_option(help: str):
    """``--mesh-output FILE``: a mesh of the result, besides the output (.ply/.obj/.off/.stl)."""
    return click.option("--mesh-output", "mesh_output", default=None, metavar="FILE", help=help)


#: ``--no-clobber``: every subcommand that writes files has it (see :mod:`gsdf.cli._common`).
no_clobber_option = click.option("--no-clobber", is_flag=True,
                                 help="Refuse to replace existing output files (default: replace them; an input "
                                      "of the command is never replaced).")


# --- grids ---------------------------------------------------------------------------------------------------
def resolution_option(default: int, help: str = "Grid nodes along the longest side of the box."):
    """``--resolution N``: the size of the command's grid."""
    return click.option("--resolution", type=RESOLUTION, default=default, show_default=default is not None,
                        help=help)


def pad_option(default: float):
    """``--pad F``: the box is the input's bounding box grown by ``F`` times its diagonal on every side."""
    return click.option("--pad", type=PAD, default=default, show_default=True,
                        help="Box padding on every side, as a fraction of the input's bounding-box diagonal.")


bisection_option = click.option("--bisection", type=BISECTION, default=10, show_default=True,
                                help="Bisection steps per surface vertex (0: plain marching cubes).")


# --- methods -------------------------------------------------------------------------------------------------
beta_option = click.option("--beta", type=POSITIVE, default=None,
                           help="Accuracy β of the fast winding number (default 2 for meshes, 2.3 for points).")
exact_option = click.option("--exact", is_flag=True,
                            help="Exact winding numbers (direct sum) instead of the fast tree approximation.")
normals_option = click.option("--estimate-normals", is_flag=True,
                              help="For clouds without normals: PCA normals oriented away from the centroid.")
t_coef_option = click.option("--t-coef", type=POSITIVE, default=1.0, show_default=True,
                             help="Diffusion time t = t_coef · h², h the mesh or grid spacing (§5.3).")
level_set_option = click.option("--level-set", type=LEVEL_SET, default="zero", show_default=True,
                                help="Level-set constraint (§7.1): φ = 0 on every source (zero), one constant per "
                                     "connected source component (multiple), or only a shift by the sources' mean "
                                     "(none).")


def soft_weight_option(default_help: str):
    """``--soft-weight W`` (> 0): impose the level-set constraint by a penalty of weight W instead of exactly."""
    return click.option("--soft-weight", type=POSITIVE, default=None,
                        help="Impose the level-set constraint by a penalty of this weight (> 0) instead of "
                             f"exactly. {default_help}")


def view_option(default: str | None = None):
    """``--view x,y,z``: the direction from the centre of the picture towards the camera (default: the 3/4 view
    of ``gsdf view``)."""
    if default is None:
        return click.option("--view", type=DIRECTION, default=None,
                            help="Direction from the centre of the picture towards the camera (x,y,z). Default: "
                                 "the 3/4 view of gsdf view (y up, the broad side facing the camera).")
    return click.option("--view", type=DIRECTION, default=default, show_default=True,
                        help="Direction from the centre of the picture towards the camera (x,y,z).")


def slice_options(fn):
    """``--axis x|y|z`` and ``--at VALUE``: the slice of a volume field that a picture shows."""
    fn = click.option("--at", type=NUMBER, default=None, metavar="VALUE",
                      help="Coordinate of that slice along --axis, in model units (default: the middle of the "
                           "box).")(fn)
    return click.option("--axis", type=AXIS, default=None,
                        help="Axis across the slice of the field that the picture shows (default: the horizontal "
                             "axis facing the camera).")(fn)


def offsets_option(help: str):
    """``--offsets A,B,...``: levels of the distance to contour, one surface each."""
    return click.option("--offsets", type=FLOATS, default=None, help=help)


# --- every command -------------------------------------------------------------------------------------------
quiet_option = click.option("-q", "--quiet", is_flag=True,
                            help="No progress bars or progress messages (results are still printed).")


def _apply_threads(ctx, param, value):
    """``--threads N`` given to a command: the same setting as ``gsdf --threads N`` (this one wins)."""
    if value is not None:
        from gsdf import threads

        threads.set_num_threads(value)
        ctx.meta[THREADS_KEY] = value
    return value


threads_option = click.option("--threads", type=THREADS, default=None, expose_value=False, callback=_apply_threads,
                              help="Threads for numba kernels and BLAS (the same as gsdf --threads; default: "
                                   "GSDF_NUM_THREADS, else all cores for numba and one for BLAS).")


def common_options(fn):
    """``-q/--quiet`` and ``--threads N``, which every subcommand takes."""
    return quiet_option(threads_option(fn))


def explicit_threads(ctx=None):
    """The ``--threads`` value given on the command line (to the group or to the command), else None."""
    ctx = ctx or click.get_current_context(silent=True)
    return None if ctx is None else ctx.meta.get(THREADS_KEY)
