"""gsdf.threads: one setting for numba and BLAS threads; validation of --threads and GSDF_NUM_THREADS."""

import threading
import time

import numba
import numpy as np
import pytest
from click.testing import CliRunner
from threadpoolctl import threadpool_info

from gsdf import threads
from gsdf.cli.main import main


def _blas_threads():
    return [d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"]


@pytest.fixture
def clean(monkeypatch):
    """Restore the module state, numba's and BLAS's thread counts and the BLAS env vars afterwards."""
    for var in threads._BLAS_ENV + (threads.ENV_VAR,):
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setattr(threads, "_setting", None)
    monkeypatch.setattr(threads, "_env_applied", False)
    before_numba = numba.get_num_threads()
    from threadpoolctl import threadpool_limits

    before = threadpool_limits(limits=None)  # records the current limits
    yield
    numba.set_num_threads(before_numba)
    before.restore_original_limits()


@pytest.mark.parametrize("bad", [0, -1, -8, "0", "abc", "1.5", 1.5, True, False, None, "", [2]])
def test_parse_rejects(bad):
    with pytest.raises(ValueError, match="positive integer"):
        threads.parse_num_threads(bad)


def test_thread_count_beyond_any_machine_refused():
    before = threads.get_num_threads()
    with pytest.raises(ValueError, match="threads must be at most 65536"):
        threads.parse_num_threads(10**9)
    with pytest.raises(ValueError, match="at most 65536"):
        threads.set_num_threads(10**9)
    assert threads.get_num_threads() == before


def test_parse_accepts():
    assert threads.parse_num_threads("3") == 3
    assert threads.parse_num_threads(" 2 ") == 2
    assert threads.parse_num_threads(np.int64(4)) == 4


def test_set_num_threads_sets_numba_and_blas(clean):
    np.linalg.svd(np.ones((3, 3)))  # BLAS loaded
    threads.set_num_threads(1)
    assert threads.get_num_threads() == 1
    assert numba.get_num_threads() == 1
    assert _blas_threads() and all(n == 1 for n in _blas_threads())
    import os

    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"  # BLAS libraries loaded later


def test_set_num_threads_rejects(clean):
    with pytest.raises(ValueError, match="threads"):
        threads.set_num_threads(0)
    with pytest.raises(ValueError, match="threads"):
        threads.set_num_threads("two")


def test_limit_restores(clean):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs 2 cores")
    numba.set_num_threads(2)
    with threads.limit(1) as n:
        assert n == 1 and numba.get_num_threads() == 1 and threads.get_num_threads() == 1
        with threads.blas_region():
            assert all(k == 1 for k in _blas_threads())
    assert numba.get_num_threads() == 2
    assert threads.get_num_threads() == threads.available_cpus()


def test_numba_capped_at_pool(clean):
    threads.set_num_threads(10_000)
    assert numba.get_num_threads() == numba.config.NUMBA_NUM_THREADS
    assert threads.get_num_threads() == 10_000


def test_env_var(clean, monkeypatch):
    monkeypatch.setenv(threads.ENV_VAR, "1")
    assert threads.get_num_threads() == 1
    assert threads.apply_env() == 1
    assert numba.get_num_threads() == 1


@pytest.mark.parametrize("bad", ["0", "-3", "many", "2.0"])
def test_env_var_garbage(clean, monkeypatch, bad):
    monkeypatch.setenv(threads.ENV_VAR, bad)
    with pytest.raises(ValueError, match="GSDF_NUM_THREADS"):
        threads.get_num_threads()


@pytest.mark.parametrize("bad", ["0", "-1", "x", "1.5"])
def test_cli_threads_usage_error(clean, bad):
    res = CliRunner().invoke(main, ["--threads", bad, "demo", "--help"])
    assert res.exit_code == 2
    assert "--threads" in res.output and "positive integer" in res.output


def test_cli_env_garbage_usage_error(clean, monkeypatch):
    monkeypatch.setenv(threads.ENV_VAR, "lots")
    res = CliRunner().invoke(main, ["demo", "--help"])
    assert res.exit_code == 2
    assert "GSDF_NUM_THREADS" in res.output


def test_cli_threads_applies(clean, tmp_path):
    from tests.shapes import uv_sphere

    V, F = uv_sphere(10, 20)
    from gsdf.io import write_mesh

    write_mesh(str(tmp_path / "s.obj"), V, F)
    np.save(tmp_path / "q.npy", np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]]))
    res = CliRunner().invoke(main, ["--threads", "1", "winding", str(tmp_path / "s.obj"),
                                    str(tmp_path / "q.npy"), "-o", str(tmp_path / "w.npy")])
    assert res.exit_code == 0, res.output
    assert numba.get_num_threads() == 1 and threads.get_num_threads() == 1
    w = np.load(tmp_path / "w.npy")
    assert abs(w[0] - 1) < 1e-3 and abs(w[1]) < 1e-3


def test_blas_solve_threads_default_one(clean, monkeypatch):
    assert threads.blas_solve_threads() == 1  # no explicit setting: BLAS single-threaded around solves
    np.linalg.svd(np.ones((3, 3)))
    with threads.blas_region():
        assert all(k == 1 for k in _blas_threads())
    monkeypatch.setenv(threads.ENV_VAR, "2")
    assert threads.blas_solve_threads() == 2
    monkeypatch.delenv(threads.ENV_VAR)
    threads.set_num_threads(3)
    assert threads.blas_solve_threads() == 3


def test_cli_default_blas_one_thread(clean):
    import os

    res = CliRunner().invoke(main, ["demo", "--help"])
    assert res.exit_code == 0
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"
    assert all(k == 1 for k in _blas_threads())
    assert threads._setting is None  # numba keeps its default


# --- the persistent worker pool (threads.run_tasks / run_ranges) ---


def test_run_tasks_every_item_once():
    from gsdf.threads import run_tasks

    seen = []
    lock = threading.Lock()

    def take(i):
        with lock:
            seen.append(i)

    run_tasks(take, range(1000), threads=3)
    assert sorted(seen) == list(range(1000))


def test_run_tasks_exception_propagates_and_pool_survives():
    from gsdf.threads import run_tasks

    def boom(i):
        if i == 5:
            raise RuntimeError("item 5")

    with pytest.raises(RuntimeError, match="item 5"):
        run_tasks(boom, range(50), threads=2)
    out = np.zeros(10)

    def fill(i):
        out[i] = i + 1

    run_tasks(fill, range(10), threads=2)
    assert out.tolist() == list(range(1, 11))


def test_run_tasks_concurrent_callers_and_nesting_finish():
    """Several user threads (a threaded Dask worker) and a call from inside a task share one pool: every
    call finishes (a queued submission of a busy pool is cancelled, not waited for)."""
    from gsdf.threads import run_ranges, run_tasks

    def job(seed):
        total = np.zeros(1)
        lock = threading.Lock()

        def inner(s, e):
            with lock:
                total[0] += np.arange(s, e).sum()

        def outer(i):  # nested: a task that itself fans out
            run_ranges(inner, 2000, grain=100)

        run_tasks(outer, range(4), threads=2)
        return total[0]

    expected = 4 * np.arange(2000).sum()
    results = [None] * 8

    def run(k):
        results[k] = job(k)

    callers = [threading.Thread(target=run, args=(k,), daemon=True) for k in range(8)]
    for t in callers:
        t.start()
    deadline = time.monotonic() + 60
    for t in callers:
        t.join(timeout=max(0.0, deadline - time.monotonic()))
    assert not any(t.is_alive() for t in callers), "run_tasks hung (a call waited on a queued submission)"
    assert results == [expected] * 8
