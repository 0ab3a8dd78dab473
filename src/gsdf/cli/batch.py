"""``gsdf batch``: SDF samples / occupancy / SDF grids / surfaces for a whole dataset (library: gsdf.batch)."""

from __future__ import annotations

import sys

import click

from gsdf.cli._common import report_errors
from gsdf.cli._options import (
    BISECTION,
    COUNT,
    FLOATS,
    PAD,
    SURFACE_FORMAT,
    beta_option,
    common_options,
    explicit_threads,
    normals_option,
    output_dir_option,
    resolution_option,
)

#: Exit status of a run in which some items failed (1: the run itself failed; 2: a usage error; 130: Ctrl-C).
FAILED_EXIT = 3

#: The task options of the command line -> the library's option name, per task (None: the same name).
#: ``--n-points`` is the number of query points of either sampling task; ``--resolution`` is the grid of
#: sdf-grid / surface and the signed heat grid of sdf-samples (--sign heat).
_TASK_KEYS = {
    "n_points": {"sdf-samples": "n_samples", "occupancy": "n_points"},
    "resolution": {"sdf-samples": "heat_resolution", "sdf-grid": "resolution", "surface": "resolution"},
}


def _library_options(task: str, options: dict) -> dict:
    """The given CLI task options as the library's options of ``task`` (UsageError for one that does not apply)."""
    from gsdf.batch._tasks import task_defaults

    allowed = task_defaults(task)
    out = {}
    for name, value in options.items():
        if value is None or (name == "estimate_normals" and value is False):
            continue
        key = _TASK_KEYS.get(name, name)
        key = key.get(task) if isinstance(key, dict) else key
        if key not in allowed:
            raise click.UsageError(f"--{name.replace('_', '-')} does not apply to --task {task}")
        out[key] = value
    return out


@click.command("batch", short_help="Dataset jobs: SDF samples, occupancy, SDF grids, surfaces.",
               help="""Run one TASK on every mesh / cloud of INPUTS; one .npz per item in the output folder, plus
manifest.jsonl there.

INPUTS is a folder (searched recursively), a quoted glob ("data/**/*.off"), a list file (one path per line),
or a CSV / JSON manifest with a 'path' column / field and per-item task options. Outputs mirror the inputs'
folder layout. A rerun skips items whose output exists and whose input hash and options match; failing items
are recorded in the manifest and the run goes on; the exit status is then 3 (--allow-failures: 0); Ctrl-C stops
cleanly. The output folder may not be, or lie inside, the folder of the inputs. The manifest records each input
mesh's topology (open, non-manifold, oriented, components).

\b
Tasks and their arrays (float32 unless --dtype float64; all carry center (3,), scale):
  sdf-samples  points (n,3), sdf (n,) negative inside   [--n-points --sign winding|heat --seed ...]
  occupancy    points (n,3), occupancy (n,) bool, winding (n,)   [--n-points --seed ...]
  sdf-grid     sdf (R,R,R), bbox_min, bbox_max, spacing   [--resolution --method fast|heat|pat]
  surface      vertices (nv,3), faces (nf,3) int64   [--resolution --method winding|heat --bisection]
               (--surface-format ply|obj|off|stl: also the mesh file next to the .npz)

\b
Executors (choose one): --workers N local processes (default 1), --dask-local N (a Dask LocalCluster),
--scheduler tcp://host:8786 (an existing Dask cluster: dask-jobqueue, Kubernetes, ...; needs the dask extra).
--threads N: threads of each item (default: the cores divided by the workers).

\b
Examples:
  gsdf batch meshes/ --task sdf-samples -o samples/ --workers 2 --normalize sphere
  gsdf batch "thingi/**/*.stl" --task sdf-grid --resolution 128 -o grids/ --scheduler tcp://10.0.0.5:8786
  gsdf batch scans/ --task surface --surface-format stl -o watertight/
""")
@click.argument("inputs")
@click.option("--task", required=True, type=click.Choice(["sdf-samples", "occupancy", "sdf-grid", "surface"]))
@output_dir_option("Output folder (created).", required=True)
@click.option("--workers", type=COUNT, default=None, help="Local worker processes [default: 1].")
@click.option("--dask-local", type=COUNT, default=None, help="Start a Dask LocalCluster of N workers.")
@click.option("--scheduler", default=None, help="Address of a running Dask scheduler (tcp://host:port).")
@click.option("--scheduler-timeout", type=click.FloatRange(0.1), default=10.0, show_default=True,
              help="Seconds to wait for the scheduler.")
@click.option("--normalize", type=click.Choice(["none", "sphere", "cube"]), default=None,
              help="Output frame: input coordinates (none, default), unit sphere or [-1,1]^3 cube.")
@click.option("--n-points", type=COUNT, default=None,
              help="sdf-samples / occupancy: query points per item [250000 / 100000].")
@click.option("--sign", type=click.Choice(["winding", "heat"]), default=None,
              help="sdf-samples: sign by the fast winding number (default) or the signed heat method.")
@click.option("--method", default=None, help="sdf-grid: fast|heat|pat [fast]; surface: winding|heat [winding].")
@resolution_option(None, help="Grid nodes per side: the output grid of sdf-grid / surface [128], the signed heat "
                              "grid of sdf-samples --sign heat [64].")
@click.option("--bisection", type=BISECTION, default=None, help="surface: bisection steps per vertex [10].")
@click.option("--surface-format", type=SURFACE_FORMAT, default=None,
              help="surface: also write each mesh as ITEM.ply / .obj / .off / .stl next to its .npz.")
@click.option("--margin", type=PAD, default=None,
              help="The sampling cube / grid is centred on the input's box with half-side (1 + MARGIN) frame "
                   "scales [0.05; occupancy 0.1].")
@click.option("--uniform-fraction", type=click.FloatRange(0, 1), default=None,
              help="sdf-samples / occupancy: fraction of uniform (not near-surface) points [0.1 / 1.0].")
@click.option("--sigmas", type=FLOATS, default=None, help="Near-surface offset scales, comma-separated "
              "[0.05,0.0158].")
@click.option("--seed", type=click.IntRange(0), default=None, help="Random seed [0] (combined with the input).")
@click.option("--dtype", type=click.Choice(["float32", "float64"]), default=None, help="Float arrays [float32].")
@beta_option
@normals_option
@click.option("--resume/--no-resume", default=True, show_default=True,
              help="Skip items whose output and input hash are up to date.")
@click.option("--retry-failed", is_flag=True, help="Run items that failed before again.")
@click.option("--max-retries", type=click.IntRange(0), default=2, show_default=True,
              help="Resubmissions of an item whose worker died.")
@click.option("--allow-failures", is_flag=True,
              help="Exit 0 even when items failed (default: exit 3 when any item failed; the manifest says why).")
@common_options
@report_errors
def batch(inputs, task, output_dir, workers, dask_local, scheduler, scheduler_timeout, resume, retry_failed,
          max_retries, allow_failures, quiet, **task_options):
    from gsdf.batch import BatchInterrupted, BatchOptions, run_batch

    chosen = [f"--{n}" for n, v in (("workers", workers), ("dask-local", dask_local), ("scheduler", scheduler))
              if v is not None]
    if len(chosen) > 1:
        raise click.UsageError(f"conflicting options: {' and '.join(chosen)} (choose one executor)")
    if scheduler is not None and not scheduler.strip():
        raise click.BadParameter("expected an address like tcp://host:8786, got an empty string",
                                 param_hint="--scheduler")
    given = _library_options(task, task_options)
    bar = None
    counts = {"done": 0, "failed": 0, "skipped": 0}

    def progress(stage, fraction):
        nonlocal bar
        if quiet:
            return
        counts[stage] = counts.get(stage, 0) + 1
        if bar is None:
            from tqdm import tqdm

            bar = tqdm(total=round(sum(counts.values()) / fraction), desc=task, unit="item", dynamic_ncols=True)
        bar.update(1)
        bar.set_postfix(done=counts["done"], failed=counts["failed"], skipped=counts["skipped"], refresh=False)

    if scheduler is not None:
        executor = scheduler
    elif dask_local is not None:
        executor, workers = "dask", dask_local
    else:
        executor = "local"
    try:
        result = run_batch(inputs, task, output_dir, given, workers=workers, executor=executor, progress=progress,
                           batch_options=BatchOptions(resume=resume, retry_failed=retry_failed,
                                                      max_retries=max_retries, threads=explicit_threads(),
                                                      scheduler_timeout=scheduler_timeout))
    except BatchInterrupted as exc:
        if bar is not None:
            bar.close()
        click.echo(exc.result.summary())
        click.echo("interrupted: in-flight items recorded as cancelled; rerun the same command to resume", err=True)
        sys.exit(130)
    if bar is not None:
        bar.close()
    click.echo(result.summary())
    failed = result.counts.get("failed", 0)
    if failed and not allow_failures:
        click.echo(f"Error: {failed} of {len(result.records)} item(s) failed (see {result.manifest}; "
                   "--allow-failures to exit 0 anyway)", err=True)
        sys.exit(FAILED_EXIT)
