"""``gsdf heat``: generalized signed distance in a volume by the signed heat method (Feng & Crane 2024, §8)."""

from __future__ import annotations

import os

import click

from gsdf.cli._common import (
    announce,
    check_output,
    check_slice,
    load_geometry,
    output_file,
    report_errors,
    write_picture,
)
from gsdf.cli._options import (
    SURFACE_FORMAT,
    common_options,
    level_set_option,
    no_clobber_option,
    normals_option,
    offsets_option,
    output_option,
    png_option,
    resolution_option,
    slice_options,
    soft_weight_option,
    t_coef_option,
    view_option,
)


def _stage_progress(enabled: bool):
    """A ``progress(stage, fraction)`` callback (gsdf.heat._core) drawing one tqdm bar (percent) per stage."""
    from tqdm import tqdm

    state = {"stage": None, "bar": None}

    def update(stage, fraction):
        if stage != state["stage"]:
            if state["bar"] is not None:
                state["bar"].close()
            state["stage"] = stage
            state["bar"] = tqdm(total=100, desc=stage, unit="%", disable=not enabled, leave=False)
        bar = state["bar"]
        bar.update(max(0, int(round(100 * fraction)) - bar.n))

    def close():
        if state["bar"] is not None:
            state["bar"].close()

    return update, close


@click.command("heat", short_help="Signed distance in a volume (grid or tets).",
               help="""Signed distance of INPUT (mesh, soup or oriented cloud) in a volume by the
signed heat method: negative inside, robust to holes, flips and noise.

Writes the field to OUTPUT (.npz, .npy, .vtk, .vtu; .vti for grids) and, with --offsets, one surface per offset
next to it (OUTPUT stem + _offset_<value>.ply, or --surface-format). Offsets are distances, or fractions of the
input's bounding-box diagonal with --relative. --png draws a slice of the field with isolines and the zero level
set (--axis, --at: which slice).

\b
Example:
  gsdf heat bunny.off --resolution 128 --offsets 0,0.01,-0.01 --relative -o bunny_heat.npz
  gsdf heat scan.xyz -o scan_heat.npz --png scan_heat.png --axis z
""")
@click.argument("input", type=click.Path(dir_okay=False))
@output_option("Output field: .npz, .npy, .vtk, .vtu, or .vti (grid only).")
@resolution_option(64, help="Grid nodes along the longest side of the box (§8.2); with --tet, the spacing of the "
                            "tet mesh near the input.")
@click.option("--tet", is_flag=True, help="Tetrahedral domain instead of a grid (§8.1).")
@offsets_option("Comma-separated levels to contour, e.g. 0,0.01,-0.01.")
@click.option("--relative", is_flag=True, help="Offsets are fractions of the bounding-box diagonal.")
@t_coef_option
@click.option("--t-scale", type=click.Choice(["grid", "input"]), default="grid", show_default=True,
              help="h of t = t_coef·h²: the grid spacing (robust to flipped/noisy normals) or the input's mean "
                   "edge length / point spacing (more accurate on clean input with holes).")
@level_set_option
@soft_weight_option("Default: 10 on grids, exact on tets.")
@click.option("--surface-format", type=SURFACE_FORMAT, default="ply",
              show_default=True, help="Format of the --offsets surfaces.")
@png_option("Also write a PNG: a slice of the field with isolines, and the zero level set.")
@slice_options
@view_option()
@normals_option
@common_options
@no_clobber_option
@report_errors
def heat(input, output, resolution, tet, offsets, relative, t_coef, t_scale, level_set, soft_weight, surface_format,
         png, axis, at, view, estimate_normals, quiet):

    from gsdf.heat.volume import VolumeHeatOptions, signed_heat_volume

    from gsdf.field import GridField, TetField

    check_output(output, TetField.SAVE_EXTENSIONS if tet else GridField.SAVE_EXTENSIONS)
    levels = offsets
    stem = os.path.splitext(output)[0]
    surface_paths = [f"{stem}_offset_{v:g}.{surface_format}" for v in levels or []]
    for path in surface_paths:
        check_output(path, None, "--offsets")
    check_output(png, (".png",), "--png")
    check_slice(png, axis, at)
    geo = load_geometry(input, estimate_normals)
    kw = dict(mesh=(geo.X, geo.F)) if geo.is_mesh else dict(points=(geo.X, geo.N))
    if soft_weight is None and not tet:
        soft_weight = 10.0
    if level_set == "none":
        soft_weight = None
    update, close = _stage_progress(not quiet)
    try:
        options = VolumeHeatOptions(level_set_constraint=level_set, soft_weight=soft_weight, t_scale=t_scale,
                                    progress=update)
        field = signed_heat_volume(domain="tet" if tet else "grid", resolution=resolution, t_coef=t_coef,
                                   options=options, **kw)
    finally:
        close()
    with output_file(output) as tmp:
        field.save(tmp)
    where = f"a {len(field.vertices)}-node tet mesh" if tet else f"{field.shape} grid nodes"
    announce(f"{geo.describe()}\nsigned heat field on {where} -> {os.path.abspath(output)}")
    if levels:
        from gsdf.io import write_mesh

        X = geo.X
        from gsdf.grid import diagonal

        scale = diagonal(X.min(axis=0), X.max(axis=0)) if relative else 1.0
        for v, path in zip(levels, surface_paths):
            Vs, Fs = field.isosurface(v * scale, close=True) if hasattr(field, "spacing") \
                else field.isosurface(v * scale)
            with output_file(path, what="--offsets") as tmp:
                write_mesh(tmp, Vs, Fs)
            announce(f"level {v * scale:.6g}: {len(Fs)} triangles -> {os.path.abspath(path)}")
    if png:
        write_picture(png, ("signed distance [model units]", field), view=view, axis=axis, at=at)
