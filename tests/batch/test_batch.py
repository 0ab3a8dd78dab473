"""gsdf.batch / `gsdf batch`: tasks against analytic answers, resume, atomic writes, failures, Ctrl-C, local
processes and a real dask.distributed LocalCluster (bit-identical outputs, a killed worker loses no item)."""

import json
import os
import signal
import time

import numpy as np
import pytest
from click.testing import CliRunner

from gsdf.batch import (
    BatchInterrupted,
    BatchOptions,
    DaskExecutor,
    Geometry,
    LocalExecutor,
    SdfSamplesOptions,
    collect_inputs,
    occupancy,
    read_manifest,
    run_batch,
    sdf_grid,
    sdf_samples,
    surface,
    write_npz_atomic,
)
from gsdf.cli.main import main
from gsdf.io import read_mesh, write_mesh

from tests.shapes import cube, uv_sphere

N = 4000  # samples per item: enough to test, small enough to be fast


def _open_sphere():
    V, F = uv_sphere(12, 24)
    keep = V[F].mean(axis=1)[:, 2] < 0.8  # a hole around the north pole
    return V, F[keep]


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    """Four small meshes in a nested layout (one with a hole, one polygon soup) and one corrupt file."""
    d = tmp_path_factory.mktemp("in")
    (d / "a" / "b").mkdir(parents=True)
    write_mesh(str(d / "sphere.obj"), *uv_sphere(10, 20))
    write_mesh(str(d / "a" / "cube.off"), *cube())
    write_mesh(str(d / "a" / "b" / "open.ply"), *_open_sphere())
    V, F = uv_sphere(8, 16, radius=0.5)
    write_mesh(str(d / "a" / "small.stl"), V + 2.0, F)
    (d / "corrupt.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    return d


GOOD = {"sphere.npz", "a/cube.npz", "a/b/open.npz", "a/small.npz"}


@pytest.fixture(scope="module")
def local1():
    """One spawned local worker process, shared by the tests (starting one costs seconds)."""
    ex = LocalExecutor(1)
    yield ex
    ex.close()


@pytest.fixture(scope="module")
def local_run(dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("local")
    return run_batch(str(dataset), "sdf-samples", str(out), {"n_samples": N}, workers=1), out


def _outputs(out):
    return {os.path.relpath(os.path.join(b, f), out) for b, _, fs in os.walk(out) for f in fs if f.endswith(".npz")}


# ---------------------------------------------------------------------------------------------- tasks


def test_sdf_samples_sphere_analytic():
    V, F = uv_sphere(24, 48, radius=2.0)
    out = sdf_samples(Geometry(V, F=F), n_samples=N, normalize="sphere", seed=3)
    P, d = out["points"], out["sdf"]
    assert P.shape == (N, 3) and d.shape == (N,) and P.dtype == np.float32 and d.dtype == np.float32
    assert out["scale"] == pytest.approx(2.0) and np.allclose(out["center"], 0, atol=1e-12)
    r = np.linalg.norm(P.astype(float), axis=1)
    assert np.abs(d - (r - 1.0)).max() < 0.01  # unit sphere in the stored frame, up to the faceting
    assert 0.3 < np.mean(np.abs(r - 1) < 0.05) < 0.95  # most samples near the surface, some uniform
    # "none" keeps input coordinates: the same samples scaled back
    raw = sdf_samples(Geometry(V, F=F), n_samples=N, seed=3)
    assert np.allclose(raw["points"], 2.0 * P, atol=1e-5) and np.allclose(raw["sdf"], 2.0 * d, atol=1e-5)
    assert raw["scale"] == 1.0


def test_sdf_samples_heat_sign_and_open_mesh():
    V, F = _open_sphere()
    wind = sdf_samples(Geometry(V, F=F), n_samples=N, seed=1)
    r = np.linalg.norm(wind["points"], axis=1)
    # away from the surface, and not inside right under the hole (z > 0.76), where w is near 1/2
    far = (np.abs(r - 1) > 0.1) & ~((r < 1) & (wind["points"][:, 2] > 0.6))
    assert np.all((wind["sdf"][far] < 0) == (r[far] < 1))  # winding sign survives the hole
    heat = sdf_samples(Geometry(V, F=F), n_samples=N, seed=1, sign="heat",
                       options=SdfSamplesOptions(heat_resolution=32))
    assert np.array_equal(heat["points"], wind["points"]) and np.allclose(np.abs(heat["sdf"]), np.abs(wind["sdf"]))
    assert np.all((heat["sdf"][far] < 0) == (r[far] < 1))


def test_occupancy_grid_surface_analytic():
    V, F = cube(0.5)
    g = Geometry(V, F=F)
    occ = occupancy(g, n_points=N, seed=2)
    inside = np.all(np.abs(occ["points"]) < 0.5, axis=1)
    margin = np.abs(np.abs(occ["points"]).max(axis=1) - 0.5) > 1e-3
    assert occ["occupancy"].dtype == bool and np.array_equal(occ["occupancy"][margin], inside[margin])
    grid = sdf_grid(g, resolution=17, margin=0.5)
    X = np.stack(np.meshgrid(*[np.linspace(grid["bbox_min"][i], grid["bbox_max"][i], 17) for i in range(3)],
                             indexing="ij"), -1)
    q = np.abs(X) - 0.5  # exact box SDF
    exact = np.linalg.norm(np.maximum(q, 0), axis=-1) + np.minimum(q.max(axis=-1), 0)
    assert grid["sdf"].shape == (17, 17, 17) and np.abs(grid["sdf"] - exact).max() < 1e-5
    assert np.allclose(grid["spacing"], (grid["bbox_max"] - grid["bbox_min"]) / 16)
    Vs, Fs = uv_sphere(16, 32)
    s = surface(Geometry(Vs, F=Fs), resolution=24)
    assert s["faces"].dtype == np.int64 and len(s["faces"]) > 100
    assert np.abs(np.linalg.norm(s["vertices"], axis=1) - 1).max() < 0.02


def test_sdf_grid_is_signed_distance_grid_on_the_task_grid():
    """sdf-grid "fast" is gsdf.signed_distance_grid on the task's cube (half-side (1 + margin) x half the longest
    side for normalize="none"): the same numbers, and the former distance + winding-sign computation's numbers
    on the same nodes, bit for bit."""
    import gsdf
    from gsdf.batch._tasks import cube as task_cube, task_grid
    from gsdf.distance import TriangleDistance
    from gsdf.grid import Grid
    from gsdf.winding import FastWindingNumber

    V, F = _open_sphere()
    V = V * [1.0, 0.8, 0.6]
    g = Geometry(V, F=F)
    out = sdf_grid(g, resolution=11, dtype="float64")
    grid = task_grid(V, 11)
    c, half = task_cube(V, "none", 0.05, grid=True)
    lo, hi = V.min(0), V.max(0)
    assert np.allclose(c, 0.5 * (lo + hi)) and half == 1.05 * 0.5 * float((hi - lo).max())
    assert grid.shape == (11, 11, 11) and np.array_equal(out["bbox_min"], grid.bbox_min)
    S = gsdf.signed_distance_grid(V, F, resolution=grid)
    assert np.array_equal(out["sdf"], S.values)
    # the former sdf_grid: the cube c +- (1 + pad) * L / 2, nodes np.linspace, |d| and the winding sign
    old_half = 1.05 * 0.5 * float((hi - lo).max())
    Q = np.stack(np.meshgrid(*[np.linspace(c[k] - old_half, c[k] + old_half, 11) for k in range(3)],
                             indexing="ij"), -1).reshape(-1, 3)
    d = TriangleDistance(V, F).query(Q)[0]
    old = np.where(FastWindingNumber(V, F, beta=2.0)(Q) > 0.5, -d, d)
    same = Grid((Q[0], Q[-1]), (11, 11, 11))
    assert np.array_equal(same.points(), Q)
    assert np.array_equal(gsdf.signed_distance_grid(V, F, resolution=same).values.ravel(), old)
    P = V[::3]
    N = P / np.linalg.norm(P, axis=1, keepdims=True)
    cloud = sdf_grid(Geometry(P, N=N), resolution=9, dtype="float64")
    Sc = gsdf.signed_distance_grid(None, points=(P, N), resolution=task_grid(P, 9))
    assert np.array_equal(cloud["sdf"], Sc.values)


def test_task_bad_options():
    V, F = cube()
    g = Geometry(V, F=F)
    with pytest.raises(ValueError, match="n_samples"):
        sdf_samples(g, n_samples=0)
    with pytest.raises(ValueError, match="normalize"):
        sdf_samples(g, normalize="ball")
    with pytest.raises(ValueError, match="pat"):
        sdf_grid(g, method="pat", resolution=8)
    with pytest.raises(ValueError, match="zero total area"):
        sdf_samples(Geometry(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.]]), F=np.array([[0, 1, 2]])), n_samples=10)
    with pytest.raises(ValueError, match="source"):
        sdf_samples(42)
    from gsdf.batch import check_options

    for bad, match in [({"n_samples": True}, "n_samples"), ({"margin": float("nan")}, "margin"),
                       ({"sigmas": "a,b"}, "sigmas: expected a number"), ({"beta": -1}, "beta"),
                       ({"dtype": "int8"}, "dtype"), ({"uniform_fraction": "x"}, "uniform_fraction"),
                       ({"margin": 1e308}, "margin: must be a finite number >= 0 and <= 1e"),
                       ({"sigmas": "1e308"}, "sigmas: must be a finite positive number <= 1e"),
                       ({"beta": 1e308}, "beta: must be a finite positive number <= 1e")]:
        with pytest.raises(ValueError, match=match):
            check_options("sdf-samples", bad)
    with pytest.raises(ValueError, match="method"):
        check_options("surface", {"method": "pat"})
    with pytest.raises(ValueError, match="options"):
        sdf_samples(g, options={"margin": 0.1})
    with pytest.raises(ValueError, match="estimate_normals: expected True or False"):
        SdfSamplesOptions(estimate_normals="yes")
    with pytest.raises(ValueError, match="estimate_normals: expected True or False"):
        sdf_grid(g, resolution=8, estimate_normals="yes")
    assert check_options("sdf-samples", {"estimate_normals": "yes"})["estimate_normals"] is True  # a CSV cell
    from gsdf.batch import run_task

    with pytest.raises(ValueError, match="'bisection' does not apply"):
        run_task("sdf-samples", g, {"bisection": 3})
    with pytest.raises(ValueError, match=r"resolution: a 4000\^3 grid \(64,000,000,000 nodes\): needs about"):
        sdf_grid(g, resolution=4000)


def test_point_cloud_inputs(tmp_path):
    from gsdf.io import write_points

    from tests.shapes import fibonacci_sphere

    P = fibonacci_sphere(1500)
    out = sdf_samples(Geometry(P, N=P), n_samples=N, seed=4)
    r = np.linalg.norm(out["points"], axis=1)
    far = np.abs(r - 1) > 0.1
    assert np.all((out["sdf"][far] < 0) == (r[far] < 1))
    grid = sdf_grid(Geometry(P, N=P), resolution=9, method="pat")
    assert grid["sdf"][4, 4, 4] == pytest.approx(-1.0, abs=0.1)  # the centre node, 1 from the sphere
    write_points(str(tmp_path / "bare.xyz"), P)
    with pytest.raises(ValueError, match="no normals"):
        occupancy(str(tmp_path / "bare.xyz"))
    from gsdf.batch import OccupancyOptions

    occ = occupancy(str(tmp_path / "bare.xyz"), n_points=2000, options=OccupancyOptions(estimate_normals=True))
    rr = np.linalg.norm(occ["points"], axis=1)
    ok = np.abs(rr - 1) > 0.1
    assert np.mean(occ["occupancy"][ok] == (rr[ok] < 1)) > 0.99


# ---------------------------------------------------------------------------------- inputs and manifests


def test_collect_inputs_layout_and_manifests(dataset, tmp_path):
    items = collect_inputs(str(dataset))
    assert {it.output for it in items} == GOOD | {"corrupt.npz"}
    items = collect_inputs(str(dataset / "a" / "**" / "*.ply"))
    assert [it.output for it in items] == ["b/open.npz"]
    csv = tmp_path / "items.csv"
    csv.write_text(f"path,n_samples\n{dataset / 'sphere.obj'},100\n{dataset / 'a' / 'cube.off'},\n")
    items = collect_inputs(str(csv))
    assert [it.options for it in items] == [{"n_samples": "100"}, {}]
    js = tmp_path / "items.json"
    js.write_text(json.dumps([str(dataset / "sphere.obj"), {"path": "in/x.off", "seed": 1}]))
    with pytest.raises(ValueError, match="not a file"):
        collect_inputs(str(js))
    (tmp_path / "bad.csv").write_text("file\nx.obj\n")
    with pytest.raises(ValueError, match="'path' column"):
        collect_inputs(str(tmp_path / "bad.csv"))
    (tmp_path / "bad.json").write_text("[1, 2")
    with pytest.raises(ValueError, match="malformed JSON"):
        collect_inputs(str(tmp_path / "bad.json"))


def test_per_item_options_from_csv(dataset, tmp_path, local1):
    csv = tmp_path / "items.csv"
    csv.write_text(f"path,n_samples,seed\n{dataset / 'sphere.obj'},100,\n{dataset / 'a' / 'cube.off'},250,7\n")
    r = run_batch(str(csv), "sdf-samples", str(tmp_path / "out"), {"n_samples": 50}, executor=local1)
    assert r.counts["done"] == 2
    assert np.load(tmp_path / "out" / "sphere.npz")["sdf"].shape == (100,)
    assert np.load(tmp_path / "out" / "a" / "cube.npz")["points"].shape == (250, 3)
    (tmp_path / "bad.csv").write_text(f"path,n_samples\n{dataset / 'sphere.obj'},many\n")
    with pytest.raises(ValueError, match="n_samples: expected an integer"):
        run_batch(str(tmp_path / "bad.csv"), "sdf-samples", str(tmp_path / "o2"))


# ------------------------------------------------------------------------------ the local run, resume


def test_local_run_manifest_and_failures(local_run, dataset):
    r, out = local_run
    assert r.counts["done"] == 4 and r.counts["failed"] == 1
    assert _outputs(out) == GOOD
    state = read_manifest(out / "manifest.jsonl")
    assert set(state) == GOOD | {"corrupt.npz"}
    bad = state["corrupt.npz"]
    assert bad["status"] == "failed" and "out of range" in bad["error"] and bad["failure"] == "item"
    ok = state["sphere.npz"]
    assert ok["status"] == "done" and ok["counts"]["faces"] > 0 and ok["arrays"]["points"] == [N, 3]
    assert set(ok["seconds"]) == {"read", "compute", "write", "total"} and len(ok["input_sha256"]) == 64
    z = np.load(out / "sphere.npz")
    assert set(z.files) == {"points", "sdf", "center", "scale"}


def test_rerun_recomputes_nothing_and_notices_changes(local_run, dataset, tmp_path, local1):
    r0, out0 = local_run
    out = tmp_path / "out"
    run_batch(str(dataset), "sdf-samples", str(out), {"n_samples": N}, executor=local1)
    mtimes = {p: os.stat(out / p).st_mtime_ns for p in GOOD}
    lines = (out / "manifest.jsonl").read_text().count("\n")
    r = run_batch(str(dataset), "sdf-samples", str(out), {"n_samples": N}, executor=local1)
    assert r.counts["skipped"] == 5 and r.counts["done"] == 0 and r.executor == ""  # nothing submitted
    assert {p: os.stat(out / p).st_mtime_ns for p in GOOD} == mtimes
    assert (out / "manifest.jsonl").read_text().count("\n") == lines
    # other options: everything again; a changed input: only that item
    r = run_batch(str(dataset), "sdf-samples", str(out), {"n_samples": N, "seed": 1}, executor=local1)
    assert r.counts["done"] == 4
    V, F = uv_sphere(6, 12)
    changed = tmp_path / "in"
    import shutil

    shutil.copytree(dataset, changed)
    out2 = tmp_path / "out2"
    run_batch(str(changed), "sdf-samples", str(out2), {"n_samples": N}, executor=local1)
    write_mesh(str(changed / "a" / "cube.off"), V, F)
    r = run_batch(str(changed), "sdf-samples", str(out2), {"n_samples": N}, executor=local1,
                  batch_options=BatchOptions(retry_failed=True))
    ran = {x["output"] for x in r.records if x["status"] in ("done", "failed")}
    assert ran == {"a/cube.npz", "corrupt.npz"}


# -------------------------------------------------------------------------------------- atomic writes


class _Boom:
    """An array that interrupts the writer when numpy converts it (mid-file: earlier arrays are written)."""

    def __array__(self, *args, **kwargs):
        raise KeyboardInterrupt


def test_atomic_write_interrupted_leaves_no_file(tmp_path):
    target = tmp_path / "sub" / "x.npz"
    with pytest.raises(KeyboardInterrupt):
        write_npz_atomic(target, {"a": np.zeros(1000), "b": _Boom()})
    assert not target.exists() and not (tmp_path / "sub").exists()  # nor the folder made for it
    write_npz_atomic(target, {"a": np.arange(3)})
    with pytest.raises(KeyboardInterrupt):
        write_npz_atomic(target, {"a": np.zeros(1000), "b": _Boom()})
    assert np.array_equal(np.load(target)["a"], np.arange(3))  # the old output is intact
    assert os.listdir(tmp_path / "sub") == ["x.npz"]


def test_stale_part_files_never_count(dataset, tmp_path, local1):
    out = tmp_path / "out"
    (out / "a").mkdir(parents=True)
    (out / "a" / ".cube.npz.abc123.part").write_bytes(b"half a zip")  # a worker killed mid-write
    r = run_batch([str(dataset / "a" / "cube.off")], "sdf-samples", str(out), {"n_samples": 100}, executor=local1)
    assert r.counts["done"] == 1 and os.listdir(out / "a") == []  # cube.npz sits at the root of that list
    assert (out / "cube.npz").exists()


# ------------------------------------------------------------------------------------------ Ctrl-C


def test_interrupt_keeps_manifest_consistent(dataset, tmp_path, local1):
    out = tmp_path / "out"

    def stop(stage, fraction):
        if stage in ("done", "failed"):
            raise KeyboardInterrupt

    with pytest.raises(BatchInterrupted) as info:
        run_batch(str(dataset), "sdf-samples", str(out), {"n_samples": N}, workers=1, progress=stop)
    res = info.value.result
    assert res.interrupted and len(res.records) == 5
    state = read_manifest(out / "manifest.jsonl")
    for key, rec in state.items():
        assert rec["status"] in ("done", "failed", "cancelled")
        assert (rec["status"] == "done") == (out / key).exists()
    assert any(r["status"] in ("cancelled", "pending") for r in res.records)
    r = run_batch(str(dataset), "sdf-samples", str(out), {"n_samples": N}, executor=local1)
    assert _outputs(out) == GOOD and r.counts["done"] + r.counts["skipped"] >= 4


# --------------------------------------------------------------------------- worker death, local pool


def test_local_worker_killed_loses_no_item(dataset, tmp_path):
    ex = LocalExecutor(2)
    killed = []

    def kill_one(stage, fraction):
        if not killed and stage != "skipped":
            pid = ex.worker_pids()[0]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    try:
        r = run_batch(str(dataset), "sdf-samples", str(tmp_path / "out"), {"n_samples": 50_000}, executor=ex,
                      progress=kill_one)
    finally:
        ex.close()
    assert killed
    assert all(x["threads"] == max(1, os.cpu_count() // 2) for x in r.records if x["status"] == "done")
    assert {x["output"] for x in r.records} == GOOD | {"corrupt.npz"}
    assert all(x["status"] in ("done", "failed") for x in r.records)
    assert _outputs(tmp_path / "out") == {x["output"] for x in r.records if x["status"] == "done"}


# --------------------------------------------------- faults: the driver killed, full disk, output folders


def _children(pid: int) -> list[int]:
    out = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as fh:
                    stat = fh.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(stat[1]) == pid and stat[0] != "Z":
                out.append(int(d))
    return out


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads the process table from /proc (Linux)")
def test_workers_die_with_a_killed_driver_and_a_rerun_finishes(dataset, tmp_path):
    """kill -9 of the `gsdf batch` process alone: its workers end at once (PR_SET_PDEATHSIG / parent watch)
    instead of finishing items the manifest never records; the next run removes their partial files."""
    import subprocess
    import sys

    inp = tmp_path / "in"
    inp.mkdir()
    for k in range(8):
        write_mesh(str(inp / f"s{k}.obj"), *uv_sphere(30, 60))
    out = tmp_path / "out"
    cmd = [sys.executable, "-c", "from gsdf.cli.main import main; main()", "batch", str(inp), "--task",
           "sdf-grid", "--resolution", "48", "-o", str(out), "-q", "--workers", "2"]
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        t0 = time.time()
        while time.time() - t0 < 300 and not (out / "manifest.jsonl").exists():
            time.sleep(0.1)
        kids = _children(p.pid)
        assert kids, "no worker started"
    finally:
        p.kill()  # SIGKILL of the driver alone (not its process group)
        p.wait()
    t0 = time.time()
    while time.time() - t0 < 10 and any(_alive(k) for k in kids):
        time.sleep(0.1)
    left = [k for k in kids if _alive(k)]
    for k in left:  # do not leave them running if the test fails
        os.kill(k, signal.SIGKILL)
    assert not left, f"{len(left)} worker(s) outlived the driver"
    time.sleep(1.0)  # nothing is written after the workers are gone
    recorded = {r["output"] for r in read_manifest(out / "manifest.jsonl").values() if r["status"] == "done"}
    assert {f for f in os.listdir(out) if f.endswith(".npz")} == recorded
    r = run_batch(str(inp), "sdf-grid", str(out), {"resolution": 48}, workers=2)
    assert r.counts["done"] + r.counts["skipped"] == 8
    assert sorted(os.listdir(out)) == ["manifest.jsonl"] + [f"s{k}.npz" for k in range(8)]  # no .part, no lock


def test_lock_and_created_folder_removed_on_every_exit(dataset, tmp_path, monkeypatch, local1):
    from gsdf.batch import _run

    out = tmp_path / "o" / "deep"
    r = run_batch([str(dataset / "a" / "cube.off")], "occupancy", str(out), {"n_points": 100}, executor=local1)
    assert r.counts["done"] == 1 and not (out / _run.LOCK_NAME).exists()
    monkeypatch.setattr(_run, "_drive", lambda *a, **k: (_ for _ in ()).throw(OSError(28, "No space left on device")))
    with pytest.raises(OSError):
        run_batch([str(dataset / "sphere.obj")], "occupancy", str(out), {"n_points": 100}, executor=local1)
    assert sorted(os.listdir(out)) == ["cube.npz", "manifest.jsonl"]  # the lock is gone, the folder kept
    fresh = tmp_path / "fresh" / "out"
    with pytest.raises(OSError):
        run_batch([str(dataset / "sphere.obj")], "occupancy", str(fresh), {"n_points": 100}, executor=local1)
    assert (fresh / "manifest.jsonl").exists()  # the manifest says what was attempted; no lock
    assert sorted(os.listdir(fresh)) == ["manifest.jsonl"]


def test_unreachable_scheduler_leaves_nothing(dataset, tmp_path):
    pytest.importorskip("distributed")
    with pytest.raises(ValueError, match="cannot reach the Dask scheduler"):
        run_batch(str(dataset), "occupancy", str(tmp_path / "new" / "out"), executor="tcp://127.0.0.1:9",
                  batch_options=BatchOptions(scheduler_timeout=1))
    assert os.listdir(tmp_path) == []  # neither the lock nor the folders this run created


@pytest.mark.parametrize("args", [["--workers", "1000000000"], ["--dask-local", "1000000000"],
                                  ["--scheduler", ""], ["--sigmas", "1e308"], ["--beta", "1e308"]])
def test_refused_executor_or_option_leaves_nothing(dataset, tmp_path, args):
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["batch", str(dataset), "--task", "sdf-samples", "-o", str(out),
                                  "--n-points", "200", "--quiet", *args])
    assert r.exit_code in (1, 2), r.output
    assert ("--scheduler" if args[0] == "--scheduler" else args[0][2:].replace("-", "_")
            if args[0] != "--dask-local" else "workers") in r.output
    assert not out.exists()


def test_two_runs_on_one_folder(dataset, tmp_path, local1):
    from gsdf.batch._run import LOCK_NAME, _Lock

    out = tmp_path / "out"
    out.mkdir()
    held = _Lock(str(out))
    try:
        with pytest.raises(ValueError, match="another gsdf batch is writing to"):
            run_batch(str(dataset), "occupancy", str(out), {"n_points": 100}, executor=local1)
    finally:
        held.release()
    assert os.listdir(out) == []
    stale = open(out / LOCK_NAME, "a")  # a file left by a killed run (no flock on it): taken over
    stale.close()
    r = run_batch([str(dataset / "a" / "cube.off")], "occupancy", str(out), {"n_points": 100}, executor=local1)
    assert r.counts["done"] == 1 and not (out / LOCK_NAME).exists()


def test_output_folder_in_the_inputs_refused(dataset, tmp_path):
    import shutil

    inp = tmp_path / "in"
    shutil.copytree(dataset, inp)
    for out in (inp, inp / "out", inp / "a" / "out"):
        with pytest.raises(ValueError, match="the input folder"):
            run_batch(str(inp), "occupancy", str(out))
    with pytest.raises(ValueError, match="inside the input folder"):
        run_batch(str(inp / "**" / "*.obj"), "occupancy", str(inp / "a" / "o"))
    with pytest.raises(ValueError, match="lies inside the output folder"):
        run_batch([str(inp / "a" / "cube.off")], "occupancy", str(inp / "a"))
    assert not (inp / "out").exists() and not (inp / "a" / "o").exists()
    res = CliRunner().invoke(main, ["batch", str(inp), "--task", "occupancy", "-o", str(inp / "out")])
    assert res.exit_code == 1 and "is inside the input folder" in res.output


def test_outputs_have_the_umask_mode(tmp_path):
    mask = os.umask(0)
    os.umask(mask)
    write_npz_atomic(tmp_path / "x.npz", {"a": np.arange(3)})
    assert (tmp_path / "x.npz").stat().st_mode & 0o777 == 0o666 & ~mask


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="mounting a small tmpfs needs root")
def test_disk_full(dataset, tmp_path):
    """A full disk: every item fails, the exit status says so, no lock and no partial file remain."""
    import subprocess

    full = tmp_path / "full"
    full.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(full)]).returncode:
        pytest.skip("mount -t tmpfs refused (no CAP_SYS_ADMIN in this container)")
    try:
        res = CliRunner().invoke(main, ["batch", str(dataset), "--task", "occupancy", "--n-points", "20000", "-o",
                                        str(full / "out"), "-q"])
        left = sorted(os.listdir(full / "out")) if (full / "out").exists() else []
    finally:
        subprocess.run(["umount", str(full)])
    assert res.exit_code != 0, res.output
    assert left in ([], ["manifest.jsonl"]), left  # a manifest that says why, nothing else


# ----------------------------------------------------------------------------- a real Dask LocalCluster


@pytest.fixture(scope="module")
def dask2():
    pytest.importorskip("distributed")
    ex = DaskExecutor.local(2)
    yield ex
    ex.close()


def test_dask_matches_single_process_bit_for_bit(dask2, local_run, dataset, tmp_path):
    _, out0 = local_run
    r = run_batch(str(dataset), "sdf-samples", str(tmp_path / "d"), {"n_samples": N}, executor=dask2)
    assert r.counts["done"] == 4 and r.counts["failed"] == 1
    assert "out of range" in r.failed[0]["error"]
    assert len({x["worker"] for x in r.records}) >= 1
    for p in GOOD:
        a, b = np.load(out0 / p), np.load(tmp_path / "d" / p)
        assert a.files == b.files
        for k in a.files:
            assert a[k].tobytes() == b[k].tobytes(), (p, k)
    assert all(x["threads"] == max(1, os.cpu_count() // 2) for x in r.records if x["status"] == "done")
    again = run_batch(str(dataset), "sdf-samples", str(tmp_path / "d"), {"n_samples": N}, executor=dask2)
    assert again.counts["skipped"] == 5


def test_dask_connect_shares_host_cores(dask2, dataset, tmp_path):
    ex = DaskExecutor.connect(dask2.client.scheduler.address, timeout=5)
    try:
        assert set(ex.threads_by_worker.values()) == {max(1, os.cpu_count() // 2)}  # 2 workers on this host
        r = run_batch([str(dataset / "sphere.obj")], "occupancy", str(tmp_path / "c"), {"n_points": 500},
                      executor=ex)
    finally:
        ex.close()
    assert r.counts["done"] == 1 and r.records[0]["threads"] == max(1, os.cpu_count() // 2)
    assert np.load(tmp_path / "c" / "sphere.npz")["occupancy"].shape == (500,)


def test_dask_worker_killed_loses_no_item(dask2, dataset, tmp_path):
    items = [str(p) for p in sorted(dataset.rglob("*.*"))]
    killed = []

    def kill_one(stage, fraction):
        if not killed:
            pid = dask2.worker_pids()[0]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    t0 = time.perf_counter()
    r = run_batch(items, "sdf-samples", str(tmp_path / "k"), {"n_samples": 60_000}, executor=dask2,
                  progress=kill_one)
    assert killed and time.perf_counter() - t0 < 60
    assert {x["output"] for x in r.records} == GOOD | {"corrupt.npz"}
    assert all(x["status"] in ("done", "failed") for x in r.records)
    assert {x["output"] for x in r.records if x["status"] == "failed"} <= {"corrupt.npz"} | GOOD
    assert _outputs(tmp_path / "k") == {x["output"] for x in r.records if x["status"] == "done"}
    assert r.counts["done"] >= 3  # the killed worker's item was rescheduled (or recorded as failed)


# ------------------------------------------------------------------------------------------ bad input


def test_bad_inputs_are_clear_errors(dataset, tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="holds no mesh"):
        run_batch(str(tmp_path / "empty"), "sdf-samples", str(tmp_path / "o"))
    with pytest.raises(ValueError, match="matches no file"):
        run_batch(str(tmp_path / "*.nothing"), "sdf-samples", str(tmp_path / "o"))
    with pytest.raises(ValueError, match="does not exist"):
        run_batch(str(tmp_path / "missing"), "sdf-samples", str(tmp_path / "o"))
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="not a folder"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "file"))
    with pytest.raises(ValueError, match="cannot write"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "file" / "sub"))
    with pytest.raises(ValueError, match="cannot write"):
        run_batch(str(dataset), "sdf-samples", "/proc/gsdf-batch-out")
    with pytest.raises(ValueError, match="conflicting options: workers and the scheduler"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "o"), workers=2, executor="tcp://127.0.0.1:1")
    with pytest.raises(ValueError, match="executor: expected"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "o"), executor=3)
    with pytest.raises(ValueError, match="batch_options"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "o"), batch_options={"resume": False})
    with pytest.raises(ValueError, match="'resolution' does not apply to task 'sdf-samples'"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "o"), {"resolution": 64})
    with pytest.raises(ValueError, match="task: unknown task"):
        run_batch(str(dataset), "voxels", str(tmp_path / "o"))
    with pytest.raises(ValueError, match="workers: expected a positive integer"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "o"), workers=True)
    assert not (tmp_path / "o").exists()  # nothing was created for a refused run


def test_numpy_integers_are_counts_like_their_value(dataset, tmp_path, monkeypatch):
    """BatchOptions(max_retries=np.int32(2)) was accepted by the dataclass, then refused by run_batch."""
    from gsdf.batch import _run

    bo = BatchOptions(max_retries=np.int32(2), threads=np.int64(1), scheduler_timeout=np.float32(5))
    assert (bo.max_retries, bo.threads) == (2, 1) and type(bo.max_retries) is int and type(bo.threads) is int
    assert _run._count("workers", np.int16(3)) == 3
    with pytest.raises(ValueError, match="workers: expected a positive integer"):
        _run._count("workers", np.bool_(True))


def test_sizes_that_do_not_depend_on_the_input_are_refused_before_any_item(dataset, tmp_path):
    """n_points=10^9 failed item by item (exit 3, a manifest of failures); heat_resolution=10^9 was accepted."""
    out = tmp_path / "o"
    with pytest.raises(ValueError, match="n_points: 1,000,000,000 samples: needs about"):
        run_batch(str(dataset), "occupancy", str(out), {"n_points": 10 ** 9})
    with pytest.raises(ValueError, match="heat_resolution: 1,000,000,000 nodes per side make a grid of 1e"):
        sdf_samples(str(next(iter(sorted(dataset.iterdir())))), n_samples=100,
                    options=SdfSamplesOptions(heat_resolution=10 ** 9))
    assert not out.exists()


def test_unreachable_scheduler_fails_fast(dataset, tmp_path):
    pytest.importorskip("distributed")
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="cannot reach the Dask scheduler"):
        run_batch(str(dataset), "sdf-samples", str(tmp_path / "o"), executor="tcp://127.0.0.1:9",
                  batch_options=BatchOptions(scheduler_timeout=2))
    assert time.perf_counter() - t0 < 10


# ------------------------------------------------------------------------------------------------ CLI


def test_cli_batch(dataset, tmp_path):
    runner = CliRunner()
    out = tmp_path / "cli"
    res = runner.invoke(main, ["batch", str(dataset), "--task", "sdf-grid", "--resolution", "12", "-o", str(out),
                               "--normalize", "cube", "-q"])
    assert res.exit_code == 3, res.output  # an item failed: scripts and CI must see it
    assert "done" in res.output and "failed" in res.output and "corrupt.obj" in res.output
    assert "1 of 5 item(s) failed" in res.output and "--allow-failures" in res.output
    res = runner.invoke(main, ["batch", str(dataset), "--task", "sdf-grid", "--resolution", "12", "-o", str(out),
                               "--normalize", "cube", "-q", "--retry-failed", "--allow-failures"])
    assert res.exit_code == 0, res.output  # the failure again, allowed
    assert "corrupt.obj" in res.output
    z = np.load(out / "a" / "cube.npz")
    assert z["sdf"].shape == (12, 12, 12) and z["scale"] == pytest.approx(0.5)
    assert -1.0 <= z["sdf"].min() <= -0.85  # the centre is 1 frame unit from every face
    res = runner.invoke(main, ["batch", str(dataset), "--task", "sdf-samples", "--bisection", "3", "--output-dir",
                               str(out)])
    assert res.exit_code != 0 and "--bisection does not apply to --task sdf-samples" in res.output
    res = runner.invoke(main, ["batch", str(dataset), "--task", "occupancy", "--resolution", "12", "-o", str(out)])
    assert res.exit_code != 0 and "--resolution does not apply to --task occupancy" in res.output
    res = runner.invoke(main, ["batch", str(dataset), "--task", "sdf-samples", "-o", str(out), "--workers", "2",
                               "--dask-local", "2"])
    assert res.exit_code != 0 and "conflicting options: --workers and --dask-local" in res.output
    res = runner.invoke(main, ["batch", str(tmp_path / "none*.obj"), "--task", "surface", "--out", str(out)])
    assert res.exit_code == 1 and "matches no file" in res.output  # --out: the old name, kept for one release


def test_cli_batch_options_reach_the_library_under_their_names(monkeypatch, tmp_path):
    """--n-points is n_samples (sdf-samples) or n_points (occupancy); --resolution is the heat grid of
    sdf-samples; --threads (group or command) is the per-item thread count."""
    import gsdf.batch
    import gsdf.threads

    monkeypatch.setattr(gsdf.threads, "set_num_threads", lambda n: None)  # leave this process's setting alone
    seen = []
    monkeypatch.setattr(gsdf.batch, "run_batch", lambda inputs, task, out, opts, **kw: seen.append((task, opts, kw))
                        or (_ for _ in ()).throw(ValueError("stop")))
    runner = CliRunner()
    for args in (["--task", "sdf-samples", "--n-points", "7", "--resolution", "9", "--margin", "0.2"],
                 ["--task", "occupancy", "--n-points", "5", "--threads", "3"]):
        res = runner.invoke(main, ["batch", str(tmp_path), "-o", str(tmp_path / "o"), *args])
        assert res.exit_code == 1 and "stop" in res.output, res.output
    res = runner.invoke(main, ["--threads", "2", "batch", str(tmp_path), "-o", str(tmp_path / "o"), "--task",
                               "sdf-grid"])
    assert res.exit_code == 1
    assert [(t, o, kw["batch_options"].threads) for t, o, kw in seen] == [
        ("sdf-samples", {"n_samples": 7, "heat_resolution": 9, "margin": 0.2}, None),
        ("occupancy", {"n_points": 5}, 3), ("sdf-grid", {}, 2)]


def test_surface_mesh_files_and_input_topology(dataset, tmp_path, local1):
    """surface_format writes each surface also as a mesh file next to its .npz; the manifest records whether each
    input mesh is open, non-manifold, oriented and how many components it has."""
    from gsdf.batch import check_options

    out = tmp_path / "surf"
    r = run_batch(str(dataset), "surface", str(out), {"resolution": 12, "surface_format": "stl"}, executor=local1)
    done = {x["output"]: x for x in r.records if x["status"] == "done"}
    assert set(done) == GOOD
    for name, rec in done.items():
        mesh = out / (name[:-4] + ".stl")
        assert rec["mesh"] == mesh.name and mesh.is_file()
        with np.load(out / name) as z:
            V, F = read_mesh(str(mesh))
            assert len(F) == len(z["faces"])
    assert done["a/b/open.npz"]["topology"]["open"] and not done["a/cube.npz"]["topology"]["open"]
    assert all(not x["topology"]["non_manifold"] and x["topology"]["components"] == 1 for x in done.values())
    assert "input meshes: 1 open, 0 non-manifold, 0 with several components, of 4" in r.summary()
    # a rerun skips them; a lost mesh file is written again
    os.unlink(out / "sphere.stl")
    r2 = run_batch(str(dataset), "surface", str(out), {"resolution": 12, "surface_format": "stl"}, executor=local1)
    assert [x["output"] for x in r2.records if x["status"] == "done"] == ["sphere.npz"]
    with pytest.raises(ValueError, match="surface_format"):
        check_options("surface", {"surface_format": "jpg"})
    with pytest.raises(ValueError, match="surface_format"):
        check_options("sdf-grid", {"surface_format": "ply"})
    res = CliRunner().invoke(main, ["batch", str(dataset / "sphere.obj"), "--task", "surface", "--resolution", "10",
                                    "--surface-format", "ply", "-o", str(tmp_path / "c"), "-q"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "c" / "sphere.ply").is_file()
