"""Entry point of the ``gsdf`` command: a click group with one subcommand per module."""

from __future__ import annotations

import click

from .. import __version__
from .boolean import boolean
from .demo import demo
from .heat import heat
from .heat_surface import heat_surface
from .render import render
from .sdf import sdf
from .slice import slice_cmd
from .surface import surface
from .tori import tori
from .voxelize import voxelize
from .winding import winding


def _threads_option(ctx, param, value):
    """``--threads N`` (else ``GSDF_NUM_THREADS``): validated here, so bad values are usage errors."""
    from .. import threads

    try:
        if value is not None:
            return threads.parse_num_threads(value, name="--threads")
        return threads._from_env()
    except ValueError as exc:
        raise click.BadParameter(str(exc), ctx=ctx, param=param) from None


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="gsdf")
@click.option("--threads", type=str, default=None, callback=_threads_option, metavar="N",
              help="Threads for numba kernels and BLAS (one setting for both; default: GSDF_NUM_THREADS, "
                   "else all cores).")
def main(threads):
    """gsdf: generalized winding numbers and signed distance for broken geometry.

    Meshes: OBJ, OFF, PLY, STL. Point clouds: XYZ/PWN (3 or 6 columns), PLY, OBJ v/vn, PC, NPY.
    Start with `gsdf demo`.
    """
    if threads is not None:
        from .. import threads as _threads

        _threads.set_num_threads(threads)


for command in (demo, winding, sdf, voxelize, surface, boolean, slice_cmd, heat, heat_surface, tori, render):
    main.add_command(command)
main.add_command(__import__("gsdf.cli.batch", fromlist=["batch"]).batch)  # gsdf batch (issue 16)

if __name__ == "__main__":  # pragma: no cover
    main()
