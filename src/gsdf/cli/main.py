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
from .swn import swn
from .tori import tori
from .voxelize import voxelize
from .winding import winding


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="gsdf")
def main():
    """gsdf: generalized winding numbers and signed distance for broken geometry.

    Meshes: OBJ, OFF, PLY, STL. Point clouds: XYZ/PWN (3 or 6 columns), PLY, OBJ v/vn, PC, NPY.
    Start with `gsdf demo`.
    """


for command in (demo, winding, sdf, voxelize, surface, boolean, slice_cmd, heat, heat_surface, tori, render, swn):
    main.add_command(command)

if __name__ == "__main__":  # pragma: no cover
    main()
