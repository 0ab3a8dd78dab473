"""Dataset batches: SDF samples, occupancy, SDF grids and surfaces for thousands of (broken) meshes and clouds.

Modules (one job each):

- :mod:`~gsdf.batch._tasks` — the per-item tasks, plain functions of one input (``sdf_samples``, ``occupancy``,
  ``sdf_grid``, ``surface``), their options and array names;
- :mod:`~gsdf.batch._inputs` — INPUTS (folder, glob, manifest file, list) to items with mirrored output paths;
- :mod:`~gsdf.batch._manifest` — the JSON-lines manifest and the content hashes that make runs resumable;
- :mod:`~gsdf.batch._worker` — one item on a worker: threads, hash, read, compute, atomic ``.npz`` write;
- :mod:`~gsdf.batch._executors` — local processes or a Dask cluster behind one submit / wait interface;
- :mod:`~gsdf.batch._run` — the driver :func:`run_batch`: resume, retries, Ctrl-C, the manifest.

Example
-------
>>> from gsdf.batch import run_batch, sdf_samples
>>> out = sdf_samples("bunny.off", n_samples=250_000)                         # doctest: +SKIP
>>> r = run_batch("meshes/", "sdf-samples", "out/", workers=2)                 # doctest: +SKIP
>>> r = run_batch("meshes/", "sdf-grid", "grids/", {"resolution": 128},
...               executor="tcp://scheduler:8786")                              # doctest: +SKIP
"""

from gsdf.batch._executors import DaskExecutor, LocalExecutor
from gsdf.batch._inputs import Item, collect_inputs
from gsdf.batch._manifest import file_sha256, read_manifest
from gsdf.batch._run import BatchInterrupted, BatchOptions, BatchResult, run_batch
from gsdf.batch._tasks import (
    TASKS,
    Geometry,
    OccupancyOptions,
    SdfSamplesOptions,
    check_options,
    load_geometry,
    occupancy,
    run_task,
    sdf_grid,
    sdf_samples,
    surface,
)
from gsdf.batch._worker import process_item, write_npz_atomic

__all__ = ["run_batch", "BatchOptions", "BatchResult", "BatchInterrupted", "collect_inputs", "Item",
           "read_manifest", "file_sha256", "TASKS", "Geometry", "load_geometry", "check_options", "run_task",
           "sdf_samples", "SdfSamplesOptions", "occupancy", "OccupancyOptions", "sdf_grid", "surface",
           "process_item", "write_npz_atomic", "LocalExecutor", "DaskExecutor"]
