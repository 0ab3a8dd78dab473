"""``gsdf warmup``: compile every numba kernel once (on tiny inputs), in parallel processes.

gsdf's kernels are compiled on first use and cached on disk (:mod:`gsdf._jit`). A cold first command
therefore spends most of its time compiling. ``gsdf warmup`` runs each subcommand once on tiny inputs (the
bundled examples, a small generated sphere) so that every kernel those commands use is compiled with the
argument types they use; the jobs are independent and run in ``--workers`` processes side by side (numba
compiles on one thread per process, so on 2 cores two jobs take about half the time).

Each job is a list of real ``gsdf`` command lines: :data:`JOBS`. :func:`warm` is the library entry point.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time

import click

from gsdf.cli._common import report_errors
from gsdf.cli._options import COUNT, common_options

# name -> what it compiles; the command lines are built by _job_commands (they need the temp files)
JOBS = {
    "soup": "fast winding numbers of triangles, exact (direct + hierarchical), distance, sdf, isosurface, slices",
    "cloud": "point areas, fast winding numbers of points, point-set surface, voxelize",
    "boolean": "mesh booleans",
    "heat-surface": "the signed heat method on a surface",
    "heat": "the signed heat method in a volume (grid)",
    "tori": "Points as Tori (jet), sphere-traced rendering",
}


# jobs that other commands start in the background (not part of a full warm-up: a subset of "cloud")
_PARTIAL = {"demo-cloud": "the point-cloud half of gsdf demo",
            "distance": "the unsigned-distance kernels (gsdf sdf of a mesh)"}


def _surface_command():
    from gsdf.cli.surface import surface  # the command itself, not the group (gsdf.cli.main imports this module)

    return surface


# the commands the background jobs of _PARTIAL run in this process
_PARTIAL_COMMANDS = {"surface": _surface_command}


def _write_inputs(d: str) -> dict:
    """Tiny inputs in ``d``: the bundled soup and cloud, a manifold sphere with a curve, query points."""
    import numpy as np

    from gsdf import data
    from gsdf.data._shapes import sphere_mesh
    from gsdf.io import write_mesh
    from gsdf.io._curves import write_curves

    V, F = sphere_mesh(2)
    sphere = os.path.join(d, "sphere.obj")
    write_mesh(sphere, V, F)
    # a closed curve along the equator (vertex loop of the closest-to-equator vertices, in angular order)
    ring = np.flatnonzero(np.abs(V[:, 2]) < 0.2)
    ring = ring[np.argsort(np.arctan2(V[ring, 1], V[ring, 0]))]
    curves = os.path.join(d, "curve.txt")
    write_curves(curves, [list(map(int, ring)) + [int(ring[0])]])
    queries = os.path.join(d, "q.npy")
    np.save(queries, np.random.default_rng(0).uniform(-1.2, 1.2, (300, 3)))
    return {"soup": data.path("broken_soup.obj"), "cloud": data.path("torus_cloud.xyz"), "sphere": sphere,
            "curves": curves, "queries": queries, "dir": d}


def _job_commands(name: str, f: dict) -> list[list[str]]:
    o = lambda n: os.path.join(f["dir"], f"{name}-{n}")  # noqa: E731
    if name == "soup":
        return [["winding", f["soup"], f["queries"], "-o", o("w.npy"), "-q"],
                ["winding", f["soup"], f["queries"], "--exact", "-o", o("we.npy"), "-q"],
                ["sdf", f["soup"], "-o", o("s.npz"), "--resolution", "12", "--mesh-output", o("s.ply"), "-q"],
                ["sdf", f["soup"], "-o", o("sp.npz"), "--resolution", "8", "--sign", "pseudonormal", "-q"],
                ["slice", f["soup"], "-o", o("s.svg"), "--layers", "2", "--resolution", "16"]]
    if name == "demo-cloud":
        # the cloud at a resolution whose 28³ grid takes the parallel walk, as the demo's 64³ one does
        return [["surface", f["cloud"], "-o", o("c.ply"), "--resolution", "28"]]
    if name == "distance":
        return [["@distance", f["soup"]]]
    if name == "cloud":
        return [["surface", f["cloud"], "-o", o("c.ply"), "--resolution", "12"],
                ["voxelize", f["cloud"], "-o", o("v.npz"), "--resolution", "8", "-q"],
                ["sdf", f["cloud"], "-o", o("c.npz"), "--resolution", "8", "-q"]]
    if name == "boolean":
        return [["boolean", f["sphere"], f["soup"], "--op", "difference", "-o", o("b.ply")]]
    if name == "heat-surface":
        return [["heat-surface", f["sphere"], "--curves", f["curves"], "-o", o("h.ply")]]
    if name == "heat":
        return [["heat", f["soup"], "--resolution", "10", "-o", o("h.npz")]]
    if name == "tori":
        return [["tori", f["cloud"], "-o", o("t.npz")],
                ["tori", f["cloud"], "-o", o("t.ply"), "--resolution", "8"],
                ["render", o("t.npz"), "-o", o("t.png"), "--size", "8"]]
    raise ValueError(f"unknown warm-up job {name!r}; known: {', '.join(JOBS)}")


def _warm_distance(mesh_path: str) -> None:
    """Compile the unsigned-distance kernels (tree build, packing, nearest-triangle search) on a mesh."""
    import numpy as np

    from gsdf.distance._triangles import TriangleDistance
    from gsdf.io import read_mesh

    V, F = read_mesh(mesh_path)
    TriangleDistance(V, F).query(np.random.default_rng(0).uniform(V.min(0), V.max(0), (500, 3)))


def _run_job(name: str) -> tuple[str, float, str]:
    """Run one job's commands, each as ``python -m gsdf.cli.main ...`` in a child process (the kernels they
    compile land in the on-disk cache; the background jobs of :data:`_PARTIAL` run in this process);
    returns (name, seconds, error or '')."""
    import subprocess

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="gsdf-warmup-") as d:
        f = _write_inputs(d)
        for args in _job_commands(name, f):
            if args[0] == "@distance":  # no command computes distances alone: in this process
                _warm_distance(args[1])
                continue
            if name in _PARTIAL:  # a command's background job: in this process, one interpreter start less
                from click.testing import CliRunner

                res = CliRunner().invoke(_PARTIAL_COMMANDS[args[0]](), args[1:])
                if res.exit_code != 0:
                    err = (res.output or repr(res.exception)).strip().splitlines()[-1:] or [f"exit {res.exit_code}"]
                    return name, time.perf_counter() - t0, f"gsdf {' '.join(args[:1])}: {err[0]}"
                continue
            res = subprocess.run([sys.executable, "-m", "gsdf.cli.main", *args], capture_output=True, text=True,
                                 stdin=subprocess.DEVNULL)
            if res.returncode != 0:
                err = (res.stderr or res.stdout).strip().splitlines()[-1:] or [f"exit {res.returncode}"]
                return name, time.perf_counter() - t0, f"gsdf {' '.join(args[:1])}: {err[0]}"
    return name, time.perf_counter() - t0, ""


def warm(jobs=None, processes=None, echo=None) -> list[tuple[str, float, str]]:
    """Compile the kernels of ``jobs`` (default all of :data:`JOBS`) in ``processes`` parallel processes.

    Parameters
    ----------
    jobs : list of str, optional
        Names from :data:`JOBS`.
    processes : int, optional
        Parallel worker processes (default: the thread setting of :mod:`gsdf.threads`, at most len(jobs)).
    echo : callable, optional
        Called with one line per finished job.

    Returns
    -------
    list of (job, seconds, error)
        ``error`` is '' for a job that ran.

    Example
    -------
    >>> from gsdf.cli.warmup import warm
    >>> warm(["soup"], processes=1)                      # doctest: +SKIP
    [('soup', 9.8, '')]
    """
    from concurrent.futures import ProcessPoolExecutor, as_completed
    import multiprocessing

    from gsdf._memory import check_bytes
    from gsdf.batch._run import WORKER_BYTES
    from gsdf.threads import get_num_threads

    if processes is not None:  # the same rule as gsdf batch: a count the machine cannot start is refused at once
        check_bytes(int(processes) * WORKER_BYTES, f"workers: {int(processes):,} worker processes")

    names = list(JOBS) if jobs is None else list(jobs)
    for n in names:
        if n not in JOBS and n not in _PARTIAL:
            raise ValueError(f"jobs: unknown warm-up job {n!r}; known: {', '.join(JOBS)}")
    processes = min(len(names), processes or get_num_threads()) or 1
    results = []
    if processes == 1:
        for n in names:
            results.append(_run_job(n))
            if echo:
                echo(_line(results[-1]))
        return results
    # spawn, not fork: forking after numba/OpenMP started threads can deadlock the child
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=processes, mp_context=ctx) as pool:
        futures = [pool.submit(_run_job, n) for n in names]
        for fut in as_completed(futures):
            results.append(fut.result())
            if echo:
                echo(_line(results[-1]))
    return results


def _line(result) -> str:
    name, seconds, error = result
    return f"  {name:<13} {seconds:6.1f} s  " + (f"FAILED: {error}" if error else {**JOBS, **_PARTIAL}[name])


@click.command("warmup", short_help="Compile all kernels now, in parallel.",
               help="""Compile all of gsdf's kernels now (once per install), in parallel.

Every command compiles the kernels it needs on first use and caches them; this runs each command once on
tiny inputs so that later first runs start at full speed. Jobs run in parallel processes (--workers, default:
the --threads setting, i.e. all cores).

\b
Example:
  gsdf warmup
  gsdf warmup --only soup,cloud --workers 2
""")
@click.option("--only", default=None, help=f"Comma-separated jobs (default all): {', '.join(JOBS)}.")
@click.option("--workers", type=COUNT, default=None,
              help="Parallel worker processes (default: the thread setting).")
@common_options
@report_errors
def warmup(only, workers, quiet):
    names = None if only is None else [t.strip() for t in only.split(",") if t.strip()]
    if names == []:
        raise ValueError(f"--only: expected comma-separated job names ({', '.join(JOBS)}), got {only!r}")
    t0 = time.perf_counter()
    if not quiet:
        click.echo(f"compiling gsdf's kernels ({', '.join(names or JOBS)}) ...")
    results = warm(names, workers, echo=None if quiet else click.echo)
    failed = [r for r in results if r[2]]
    click.echo(f"done in {time.perf_counter() - t0:.1f} s" + (f", {len(failed)} job(s) failed" if failed else ""))
    if failed:
        raise click.ClickException("warm-up failed: " + "; ".join(f"{n}: {e}" for n, _, e in failed))


if __name__ == "__main__":  # pragma: no cover
    warmup(sys.argv[1:])
