"""Entry point of the ``gsdf`` command: a click group with one subcommand per module."""

from __future__ import annotations

import click

from gsdf import __version__
from gsdf.cli._options import THREADS, THREADS_KEY
from gsdf.cli.batch import batch
from gsdf.cli.boolean import boolean
from gsdf.cli.demo import demo
from gsdf.cli.heat import heat
from gsdf.cli.heat_surface import heat_surface
from gsdf.cli.reconstruct import reconstruct
from gsdf.cli.render import render
from gsdf.cli.sdf import sdf
from gsdf.cli.slice import slice_cmd
from gsdf.cli.surface import surface
from gsdf.cli.swn import swn
from gsdf.cli.tori import tori
from gsdf.cli.view import view
from gsdf.cli.voxelize import voxelize
from gsdf.cli.warmup import warmup
from gsdf.cli.winding import winding


#: ``gsdf --help`` lists the subcommands under these headings, in this order (every subcommand once).
SECTIONS = (
    ("Inside/outside", ("winding", "voxelize", "surface", "boolean")),
    ("Distance", ("sdf",)),
    ("Signed heat method", ("heat", "heat-surface")),
    ("Curves on surfaces", ("swn",)),
    ("Point clouds", ("tori", "render", "reconstruct")),
    ("Viewing", ("view",)),
    ("Printing", ("slice",)),
    ("Datasets", ("batch",)),
    ("Setup", ("demo", "warmup")),
)


def _threads_option(ctx, param, value):
    """``--threads N`` (else ``GSDF_NUM_THREADS``): validated here, so bad values are usage errors."""
    from gsdf import threads

    if value is not None:
        ctx.meta[THREADS_KEY] = value
        return value
    try:
        return threads._from_env()
    except ValueError as exc:
        raise click.BadParameter(str(exc), ctx=ctx, param=param) from None


class _Main(click.Group):
    """The gsdf group: subcommands listed by task (:data:`SECTIONS`); a numba compilation failure becomes one
    message naming the kernel (exit 1)."""

    def list_commands(self, ctx):
        listed = [name for _, names in SECTIONS for name in names if name in self.commands]
        return listed + sorted(set(self.commands) - set(listed))

    def format_commands(self, ctx, formatter):
        limit = formatter.width - 6 - max((len(n) for n in self.commands), default=0)
        placed = set()
        sections = []
        for title, names in SECTIONS:
            rows = [(n, self.commands[n].get_short_help_str(limit)) for n in names
                    if n in self.commands and not self.commands[n].hidden]
            placed.update(names)
            if rows:
                sections.append((title, rows))
        rest = [(n, self.commands[n].get_short_help_str(limit)) for n in sorted(self.commands)
                if n not in placed and not self.commands[n].hidden]
        if rest:
            sections.append(("Other commands", rest))
        for title, rows in sections:
            with formatter.section(title):
                formatter.write_dl(rows)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except (click.exceptions.ClickException, click.exceptions.Exit, click.exceptions.Abort):
            raise
        except Exception as exc:
            from gsdf._jit import compile_error_message

            message = compile_error_message(exc)
            if message is None:
                raise
            raise click.ClickException(message) from exc


@click.group(cls=_Main, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="gsdf")
@click.option("--threads", type=THREADS, default=None, callback=_threads_option,
              help="Threads for numba kernels and BLAS (one setting for both; default: GSDF_NUM_THREADS, "
                   "else all cores for numba and one for BLAS). Every command also takes --threads.")
def main(threads):
    """gsdf: generalized winding numbers and signed distance for broken geometry.

    Meshes: OBJ, OFF, PLY, STL; also GLB/GLTF/3MF (trimesh) and VTK, VTU, MSH, MESH, INP, BDF, NAS, SU2
    (meshio) as inputs, VTK/VTU as outputs. Point clouds: XYZ/PWN (3 or 6 columns), PLY, OBJ v/vn, PC, NPY.
    Start with `gsdf demo`.

    Options, in every subcommand: -o/--output FILE for the output file (-o/--output-dir DIR for a folder),
    --resolution N for grids, --pad F (a fraction of the bounding-box diagonal) for boxes, -q/--quiet,
    --threads N. Outputs are written under exactly the name given (an extension the output cannot have is
    refused, listing the ones it can), atomically (temporary file + rename), never onto an input of the
    command; an existing output file is replaced unless --no-clobber is given.
    """
    from gsdf._jit import install_compile_notice

    install_compile_notice()  # one line on stderr when a kernel compiles (first use after install)
    from gsdf import threads as _threads

    if threads is not None:
        _threads.set_num_threads(threads)
    else:
        _threads.apply_cli_default()  # BLAS on one thread unless asked (see gsdf.threads)


for command in (batch, demo, winding, sdf, voxelize, surface, boolean, slice_cmd, heat, heat_surface, tori, render,
                swn, reconstruct, warmup, view):
    main.add_command(command)


if __name__ == "__main__":  # pragma: no cover
    main()
