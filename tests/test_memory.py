"""gsdf._memory: one guard estimating memory AND work before a size-driven request starts (issue: 10^9 queries,
10^12 voxels, many slice heights, `gsdf slice --resolution 8192`, sdf_samples(n=10^12) ran for minutes or raised
a raw MemoryError). Each refusal must come in well under a second (asserted with slack for a loaded machine)."""

import subprocess
import sys
import time

import numpy as np
import pytest

import gsdf
from gsdf._memory import SECONDS_PER_QUERY, available_bytes, check_work, work_limit
from tests.shapes import uv_sphere

FAST = 10.0  # seconds: the guard itself takes milliseconds; loading numba kernels on a busy machine takes seconds


@pytest.fixture
def limits(monkeypatch):
    """Deterministic limits: plenty of memory, one second of work (the default, 5 minutes at gsdf's thread
    count, refuses the same requests on a 2-core machine)."""
    monkeypatch.setenv("GSDF_MEMORY_LIMIT", "1T")
    monkeypatch.setenv("GSDF_WORK_LIMIT", "1")


def _refused(fn, match):
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=match) as e:
        fn()
    dt = time.perf_counter() - t0
    assert dt < FAST, f"refused after {dt:.1f} s"
    return str(e.value)


def test_work_limit_env(monkeypatch):
    monkeypatch.delenv("GSDF_WORK_LIMIT", raising=False)
    assert work_limit() == 300.0
    for text, secs in (("90", 90.0), ("30m", 1800.0), ("2h", 7200.0), ("1d", 86400.0), ("none", np.inf)):
        monkeypatch.setenv("GSDF_WORK_LIMIT", text)
        assert work_limit() == secs
    monkeypatch.setenv("GSDF_WORK_LIMIT", "soon")
    with pytest.raises(ValueError, match="GSDF_WORK_LIMIT: expected seconds like 600, 30m, 2h or none"):
        work_limit()
    monkeypatch.setenv("GSDF_WORK_LIMIT", "none")
    check_work(10 ** 15, 1.0, "anything")  # no limit


def test_check_work_message_names_size_estimate_and_limit():
    with pytest.raises(ValueError) as e:
        check_work(10 ** 12, SECONDS_PER_QUERY, "Q: 1,000,000,000,000 points", limit=60, parallel=False)
    msg = str(e.value)
    assert msg.startswith("Q: 1,000,000,000,000 points: would take at least 11.6 days")
    assert "the 60 s allowed" in msg and "GSDF_WORK_LIMIT" in msg


def test_1e9_queries_refused_by_the_work_guard(limits):
    V, F = uv_sphere()
    Q = np.broadcast_to(np.array([0.1, 0.2, 0.3]), (10 ** 9, 3))  # no memory: only the guard stops it
    msg = _refused(lambda: gsdf.fast_winding_number(V, F, Q), "1,000,000,000 query points: would take")
    assert "GSDF_WORK_LIMIT" in msg
    _refused(lambda: gsdf.FastWindingNumber(V, F)(Q), "1,000,000,000 query points")
    _refused(lambda: gsdf.winding_number(V, F, Q), "1,000,000,000")
    _refused(lambda: gsdf.unsigned_distance(V, F, Q), "Q: 1,000,000,000 points")
    _refused(lambda: gsdf.signed_distance(V, F, Q), "Q: 1,000,000,000 points")
    _refused(lambda: gsdf.point_cloud_distance(V, Q), "Q: 1,000,000,000 points")
    _refused(lambda: gsdf.GridField(np.zeros((2, 2, 2)), [0] * 3, [1] * 3)(Q), "Q: 1,000,000,000 points")


def test_1e9_queries_refused_by_the_memory_guard(monkeypatch):
    monkeypatch.setenv("GSDF_MEMORY_LIMIT", "1G")
    monkeypatch.setenv("GSDF_WORK_LIMIT", "none")
    V, F = uv_sphere()
    Q = np.broadcast_to(np.array([0.1, 0.2, 0.3]), (10 ** 9, 3))
    _refused(lambda: gsdf.fast_winding_number(V, F, Q), "needs about 7.5 GB, more than the 1.0 GB allowed")
    _refused(lambda: gsdf.unsigned_distance(V, F, Q), "Q: an array of 3,000,000,000 numbers: needs about")


def test_1e12_voxels_refused():
    B = np.broadcast_to(np.array(True), (10000, 10000, 10000))
    for fn in (lambda: gsdf.VoxelSurfaceSignedHeatSolver(B), lambda: gsdf.voxels_to_mesh(B, [0] * 3, [1] * 3)):
        _refused(fn, r"10000x10000x10000 voxel grid \(1,000,000,000,000 voxels\): needs about")


def test_1e12_voxels_not_saved(tmp_path):
    B = np.broadcast_to(np.array(True), (10000, 10000, 10000))
    _refused(lambda: gsdf.save_voxels(tmp_path / "v.npz", B, [0] * 3, [1] * 3), "1,000,000,000,000 voxels")
    assert list(tmp_path.iterdir()) == []  # no temporary left behind


def test_grids_refused(limits):
    V, F = uv_sphere()
    _refused(lambda: gsdf.voxelize(mesh=(V, F), resolution=4000), "winding grid: 4000x4000x4000")
    _refused(lambda: gsdf.signed_distance_grid(V, F, resolution=4000), "signed_distance_grid: a 4000x")
    _refused(lambda: gsdf.extract_isosurface(lambda q: q[:, 0], [0] * 3, [1] * 3, resolution=4000),
             "extract_isosurface: resolution=4000")
    _refused(lambda: gsdf.signed_heat_volume(mesh=(V, F), resolution=1000), "signed_heat_volume: a grid of")


def test_many_slice_heights_refused(limits):
    ball = lambda q: np.linalg.norm(q, axis=1) - 0.5  # noqa: E731
    _refused(lambda: gsdf.slice_contours(ball, np.linspace(-.5, .5, 10 ** 4), [-1] * 3, [1] * 3, resolution=256),
             r"slice_contours: 10,000 heights × a 256x256 grid \(655,360,000 nodes\): would take")


def test_many_coarse_slices_refused_by_their_contouring_cost(monkeypatch):
    """100,000 slices of an 8x8 grid are only 6.4M nodes, but each slice costs milliseconds of serial contouring
    (2.8-4.3 ms measured at load 10): `gsdf slice --layers 100000 --resolution 8` ran past two minutes."""
    monkeypatch.setenv("GSDF_WORK_LIMIT", "10")
    ball = lambda q: np.linalg.norm(q, axis=1) - 0.5  # noqa: E731
    _refused(lambda: gsdf.slice_contours(ball, np.linspace(-.5, .5, 10 ** 5), [-1] * 3, [1] * 3, resolution=8),
             r"slice_contours: 100,000 heights × a 8x8 grid \(6,400,000 nodes\): would take at least 3[01] s")
    assert len(gsdf.slice_contours(ball, np.linspace(-.5, .5, 100), [-1] * 3, [1] * 3, resolution=8)) == 100


def test_slice_memory_refused_without_a_raw_memory_error():
    ball = lambda q: np.linalg.norm(q, axis=1) - 0.5  # noqa: E731
    _refused(lambda: gsdf.slice_contours(ball, np.linspace(-.5, .5, 10 ** 6), [-1] * 3, [1] * 3,
                                         resolution=10000), "slice_contours: 1,000,000 heights.*needs about")


def test_contouring_uses_the_evaluators_cost(monkeypatch):
    """A fast winding number costs a tree query per point: the slicing guard knows it (gsdf slice)."""
    from gsdf._memory import seconds_per_point

    V, F = uv_sphere()
    assert seconds_per_point(gsdf.FastWindingNumber(V, F)) == SECONDS_PER_QUERY
    assert seconds_per_point(lambda q: q) < SECONDS_PER_QUERY


def test_sample_counts_refused(tmp_path, limits):
    V, F = uv_sphere()
    gsdf.write_mesh(tmp_path / "s.off", V, F)
    _refused(lambda: gsdf.sdf_samples(str(tmp_path / "s.off"), n_samples=10 ** 12), "n_samples: 1,000,000,000,000")
    from gsdf.batch._tasks import occupancy

    _refused(lambda: occupancy(str(tmp_path / "s.off"), n_points=10 ** 9), "n_points: 1,000,000,000 samples")


def test_address_space_limit_is_respected():
    """Under `ulimit -v` the machine's free memory is not what a request may use."""
    code = ("import resource; resource.setrlimit(resource.RLIMIT_AS, (6 << 30, 6 << 30)); "
            "from gsdf._memory import available_bytes; print(available_bytes())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert int(out) < 6 << 30
    assert available_bytes() > 0


def test_cli_slice_resolution_8192_refused(tmp_path, monkeypatch):
    from click.testing import CliRunner

    from gsdf.cli.main import main

    monkeypatch.setenv("GSDF_WORK_LIMIT", "10")
    V, F = uv_sphere()
    gsdf.write_mesh(tmp_path / "s.off", V, F)
    t0 = time.perf_counter()
    res = CliRunner().invoke(main, ["slice", str(tmp_path / "s.off"), "-o", str(tmp_path / "a.svg"), "-q",
                                    "--resolution", "8192"])
    assert time.perf_counter() - t0 < FAST + 5  # + the command's imports and input
    assert res.exit_code == 1 and "slice_contours: 10 heights × a 8192x8192 grid" in res.output, res.output
    assert "GSDF_WORK_LIMIT" in res.output and "Traceback" not in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.off"]
