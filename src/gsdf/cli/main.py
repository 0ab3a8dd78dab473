"""Entry point of the ``gsdf`` command: a click group with one subcommand per module."""

from __future__ import annotations

import click

from .. import __version__
from .boolean import boolean
from .demo import demo
from .heat import heat
from .heat_surface import heat_surface
from .reconstruct import reconstruct
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

    Meshes: OBJ, OFF, PLY, STL; also GLB/GLTF/3MF (trimesh) and VTK, VTU, MSH, MESH, INP, BDF, NAS, SU2
    (meshio) as inputs, VTK/VTU as outputs. Point clouds: XYZ/PWN (3 or 6 columns), PLY, OBJ v/vn, PC, NPY.
    Start with `gsdf demo`.

    Outputs, in every subcommand: written under exactly the name given (an extension the output cannot have is
    refused, listing the ones it can), atomically (temporary file + rename), never onto an input of the
    command; an existing output file is replaced unless --no-clobber is given.
    """


for command in (demo, winding, sdf, voxelize, surface, boolean, slice_cmd, heat, heat_surface, tori, render, swn, reconstruct):
    main.add_command(command)
main.add_command(__import__("gsdf.cli.batch", fromlist=["batch"]).batch)  # gsdf batch (issue 16)

if __name__ == "__main__":  # pragma: no cover
    main()
