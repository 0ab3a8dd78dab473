"""Entry point of the ``gsdf`` command: a click group with one subcommand per module."""

from __future__ import annotations

import click

from gsdf import __version__
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


def _threads_option(ctx, param, value):
    """``--threads N`` (else ``GSDF_NUM_THREADS``): validated here, so bad values are usage errors."""
    from gsdf import threads

    try:
        if value is not None:
            return threads.parse_num_threads(value, name="--threads")
        return threads._from_env()
    except ValueError as exc:
        raise click.BadParameter(str(exc), ctx=ctx, param=param) from None


class _Main(click.Group):
    """The gsdf group: a numba compilation failure becomes one message naming the kernel (exit 1)."""

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
@click.option("--threads", type=str, default=None, callback=_threads_option, metavar="N",
              help="Threads for numba kernels and BLAS (one setting for both; default: GSDF_NUM_THREADS, "
                   "else all cores for numba and one for BLAS).")
def main(threads):
    """gsdf: generalized winding numbers and signed distance for broken geometry.

    Meshes: OBJ, OFF, PLY, STL; also GLB/GLTF/3MF (trimesh) and VTK, VTU, MSH, MESH, INP, BDF, NAS, SU2
    (meshio) as inputs, VTK/VTU as outputs. Point clouds: XYZ/PWN (3 or 6 columns), PLY, OBJ v/vn, PC, NPY.
    Start with `gsdf demo`.

    Outputs, in every subcommand: written under exactly the name given (an extension the output cannot have is
    refused, listing the ones it can), atomically (temporary file + rename), never onto an input of the
    command; an existing output file is replaced unless --no-clobber is given.
    """
    from gsdf._jit import install_compile_notice

    install_compile_notice()  # one line on stderr when a kernel compiles (first use after install)
    from gsdf import threads as _threads

    if threads is not None:
        _threads.set_num_threads(threads)
    else:
        _threads.apply_cli_default()  # BLAS on one thread (measured: its idle threads spin, see gsdf.threads)


for command in (batch, demo, winding, sdf, voxelize, surface, boolean, slice_cmd, heat, heat_surface, tori, render, swn, reconstruct,
                warmup, view):
    main.add_command(command)


if __name__ == "__main__":  # pragma: no cover
    main()
