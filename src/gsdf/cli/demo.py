"""``gsdf demo``: the main job on the bundled examples, printing where every output went."""

from __future__ import annotations

import os
import time

import click
import numpy as np

from gsdf.cli._common import Geometry, bbox_of, output_file, report_errors
from gsdf.cli._options import common_options, no_clobber_option, output_dir_option, resolution_option


@click.command("demo", short_help="Run gsdf on the bundled examples.",
               help="""Run gsdf on the bundled examples and say where the outputs went.

Inputs: a broken triangle soup (intersecting sphere + torus with holes, duplicated and degenerate faces)
and an oriented, noisy point cloud of a torus. Outputs: winding numbers, a signed distance grid, the
extracted surfaces, a PNG slice, SVG print slices.

\b
Example:
  gsdf demo -o demo-out
""")
@output_dir_option("Folder for the outputs.", default="gsdf-demo-output")
@resolution_option(64)
@common_options
@no_clobber_option
@report_errors
def demo(output_dir, resolution, quiet):
    from gsdf import data
    from gsdf.contour import extract_isosurface, slice_contours, write_svg
    from gsdf.io import read_mesh, read_points, write_mesh
    from gsdf.render._png import field_to_rgb, write_field_slice_png, write_png
    from gsdf.winding import winding_number
    from gsdf.winding._point_areas import point_areas
    from gsdf.cli.sdf import signed_distance_grid

    from gsdf.cli._background import BackgroundWarmup

    def save(name, writer):
        with output_file(os.path.join(output_dir, name)) as tmp:
            writer(tmp)

    if os.path.exists(output_dir) and not os.path.isdir(output_dir):
        raise ValueError(f"{output_dir}: exists and is not a folder")
    # cold cache, >= 2 threads: a second process compiles the cloud half's kernels, then the distance kernels,
    # while this one compiles the fast winding numbers of triangles; so the soup's signed distance grid (which
    # needs the distance kernels) is computed last (the outputs and what is printed are the same in any order)
    background = BackgroundWarmup(["demo-cloud", "distance"])
    written = {}
    t0 = time.perf_counter()

    # --- the triangle soup -----------------------------------------------------------------------------
    V, F = read_mesh(data.path("broken_soup.obj"))
    soup = Geometry(V, F=F, path=data.path("broken_soup.obj"))
    click.echo(f"[soup]  {soup.describe()}")
    fwn = soup.winding()
    lo, hi = bbox_of(V, 0.05)
    rng = np.random.default_rng(0)
    Q = rng.uniform(lo, hi, (2000, 3))
    w_fast, w_exact = fwn(Q), winding_number(V, F, Q, method="direct")  # 2000 x 2715 solid angles: ~0.05 s
    save("soup_winding_samples.npz", lambda p: np.savez(p, queries=Q, winding_fast=w_fast, winding_exact=w_exact))
    written["samples"] = ("winding numbers at 2000 random points (fast and exact)", "soup_winding_samples.npz")
    click.echo(f"        fast vs exact winding number on 2000 points: RMS {np.sqrt(np.mean((w_fast - w_exact)**2)):.2e},"
               f" inside/outside agree on {np.mean((w_fast > 0.5) == (w_exact > 0.5)) * 100:.2f} %")

    Vs, Fs = extract_isosurface(fwn, lo, hi, resolution=resolution, level=0.5, bisection_steps=10)
    save("soup_surface.ply", lambda p: write_mesh(p, Vs, Fs))
    written["surface"] = (f"watertight surface of the soup (w = 1/2), {len(Fs)} triangles", "soup_surface.ply")

    zs = list(np.linspace(lo[2], hi[2], 12)[1:-1])
    contours = slice_contours(fwn, zs, lo, hi, resolution=192)
    save("soup_slices.svg", lambda p: write_svg(p, contours, z_values=zs, layout="stack"))
    written["slices"] = (f"{len(zs)} closed print slices ({sum(map(len, contours))} contours)", "soup_slices.svg")

    # --- the point cloud -------------------------------------------------------------------------------
    # cold cache: the background process is compiling (or has compiled) this half's kernels; wait for it
    # rather than compile the same kernels here a second time
    background.wait_for("demo-cloud")
    P, N = read_points(data.path("torus_cloud.xyz"))
    cloud = Geometry(P, N=N, path=data.path("torus_cloud.xyz"))
    click.echo(f"[cloud] {cloud.describe()}")
    A = point_areas(P, N)
    click.echo(f"        point areas sum to {A.sum():.4f} (torus area 4π²Rr = {4 * np.pi**2 * 0.4:.4f})")
    from gsdf.winding import FastWindingNumberPoints

    fwp = FastWindingNumberPoints(P, N, areas=A)
    plo, phi = bbox_of(P, 0.05)
    Vc, Fc = extract_isosurface(fwp, plo, phi, resolution=resolution, level=0.5, bisection_steps=10)
    save("cloud_surface.ply", lambda p: write_mesh(p, Vc, Fc))
    written["cloud"] = (f"point-set surface of the cloud (w = 1/2), {len(Fc)} triangles", "cloud_surface.ply")
    # winding number on the z = 0 plane
    n = 256
    xs = np.linspace(plo[0], phi[0], n)
    ys = np.linspace(plo[1], phi[1], n)
    X, Y = np.meshgrid(xs, ys, indexing="xy")
    W = fwp(np.column_stack([X.ravel(), Y.ravel(), np.zeros(n * n)])).reshape(n, n)
    save("cloud_winding_slice.png", lambda p: write_png(p, field_to_rgb(np.flipud(-(W - 0.5)), zero_level=0.0)))
    written["cloud_png"] = ("PNG of the cloud's winding number on z = 0 (1/2 contour in black)",
                            "cloud_winding_slice.png")

    # --- the soup's signed distance (its distance kernels were compiled last in the background) ----------
    background.close()
    field = signed_distance_grid(soup, resolution, 0.05)
    save("soup_sdf.npz", field.save)
    written["sdf"] = (f"signed distance grid {field.shape} (negative inside)", "soup_sdf.npz")
    save("soup_sdf_slice.png", lambda p: write_field_slice_png(p, field))
    written["sdf_png"] = ("PNG of the middle z slice of the signed distance, zero contour in black", "soup_sdf_slice.png")

    click.echo(f"\nDone in {time.perf_counter() - t0:.1f} s. Outputs in {os.path.abspath(output_dir)}:")
    for key in ("samples", "sdf", "sdf_png", "surface", "slices", "cloud", "cloud_png"):
        what, name = written[key]
        click.echo(f"  {name:28s} {what}")
