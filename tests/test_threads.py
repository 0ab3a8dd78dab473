"""gsdf.threads: one setting for numba and BLAS threads; validation of --threads and GSDF_NUM_THREADS."""

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
