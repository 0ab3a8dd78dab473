"""Cold start: the compile notice, clean compile-failure messages, the numba cache-dir fallback, gsdf warmup."""

import io
import os
import subprocess
import sys

import click
import numpy as np
import pytest
from click.testing import CliRunner
from numba import njit
from numba.core import event

from gsdf import _jit
from gsdf.cli.main import main

SRC = os.path.join(os.path.dirname(__file__), "..", "..", "src")


def _gsdf_function(source: str, name: str):
    """A jitted function that numba sees as living in a gsdf module (the notice only watches gsdf kernels)."""
    scope = {"__name__": "gsdf._test_kernels", "np": np}
    exec(source, scope)
    return njit(scope[name])


@pytest.fixture
def fresh_listener(monkeypatch):
    monkeypatch.setattr(_jit, "_listener", None)
    stream = io.StringIO()
    listener = _jit.install_compile_notice(stream=stream)
    yield stream
    event.unregister("numba:compile", listener)


def test_notice_printed_once_on_compile(fresh_listener):
    f = _gsdf_function("def add_one(x):\n    return x + 1\n", "add_one")
    assert fresh_listener.getvalue() == ""
    assert f(1) == 2
    assert fresh_listener.getvalue().count("compiling kernels, once per install") == 1
    assert f(1.5) == 2.5  # a second specialisation compiles, no second line
    assert fresh_listener.getvalue().count("\n") == 1


def test_notice_ignores_other_kernels(fresh_listener):
    g = njit(lambda x: x * 2)  # module is this test file, not gsdf
    assert g(3) == 6
    assert fresh_listener.getvalue() == ""


def test_compile_failure_names_kernel(fresh_listener):
    bad = _gsdf_function("def broken(x):\n    return x + undefined_name\n", "broken")
    with pytest.raises(Exception) as info:
        bad(1)
    msg = _jit.compile_error_message(info.value)
    assert msg is not None and "gsdf._test_kernels.broken" in msg and "failed on this platform" in msg
    assert _jit.failed_kernel() == "gsdf._test_kernels.broken"


def test_cli_compile_failure_is_clean_error(fresh_listener):
    bad = _gsdf_function("def broken2(x):\n    return x + undefined_name\n", "broken2")

    @click.command("broken-test")
    def broken_cmd():
        bad(1)

    main.add_command(broken_cmd)
    try:
        res = CliRunner().invoke(main, ["broken-test"])
    finally:
        main.commands.pop("broken-test")
    assert res.exit_code == 1
    assert "compiling the numba kernel gsdf._test_kernels.broken2 failed" in res.output
    assert "Traceback" not in res.output


def test_other_errors_still_raise(fresh_listener):
    @click.command("boom-test")
    def boom():
        raise RuntimeError("not a compile error")

    main.add_command(boom)
    try:
        res = CliRunner().invoke(main, ["boom-test"])
    finally:
        main.commands.pop("boom-test")
    assert isinstance(res.exception, RuntimeError)


def test_cache_dir_fallback(monkeypatch, tmp_path):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.delitem(sys.modules, "numba")  # as before numba is imported (restored afterwards)
    monkeypatch.setattr(_jit, "_writable", lambda path: False)  # read-only install and read-only home
    path = _jit.configure_cache(str(tmp_path))
    assert path is not None and os.environ["NUMBA_CACHE_DIR"] == path
    assert os.path.basename(path).startswith("gsdf-numba-cache")


def test_cache_dir_untouched_when_writable_or_set(monkeypatch, tmp_path):
    monkeypatch.delitem(sys.modules, "numba")
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    assert _jit.configure_cache(str(tmp_path)) is None and "NUMBA_CACHE_DIR" not in os.environ
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    monkeypatch.setattr(_jit, "_writable", lambda path: False)
    assert _jit.configure_cache(str(tmp_path)) is None
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "mine")


def test_writable_checks_nearest_existing_parent(tmp_path):
    assert _jit._writable(str(tmp_path / "not" / "yet" / "there"))


def test_cli_prints_notice_on_cold_cache_only(tmp_path):
    """A real `gsdf winding --exact` in a fresh process with an empty cache dir, then again (warm)."""
    from gsdf.io import write_mesh

    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    write_mesh(str(tmp_path / "t.obj"), V, F)
    np.save(tmp_path / "q.npy", np.array([[0.1, 0.1, 0.1], [2.0, 2.0, 2.0]]))
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=os.path.abspath(SRC))
    cmd = [sys.executable, "-m", "gsdf.cli.main", "winding", str(tmp_path / "t.obj"), str(tmp_path / "q.npy"),
           "--exact", "-o", str(tmp_path / "w.npy"), "-q"]
    first = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    assert first.stderr.count("compiling kernels, once per install") == 1
    w = np.load(tmp_path / "w.npy")
    assert abs(w[0] - 1) < 1e-12 and abs(w[1]) < 1e-12
    second = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert second.returncode == 0 and "compiling kernels" not in second.stderr


def test_warmup_rejects_unknown_job():
    res = CliRunner().invoke(main, ["warmup", "--only", "nonsense"])
    assert res.exit_code == 1 and "unknown warm-up job 'nonsense'" in res.output
    for empty in ("", " , "):
        res = CliRunner().invoke(main, ["warmup", "--only", empty])
        assert res.exit_code == 1 and "--only: expected comma-separated job names" in res.output
    from gsdf.cli.warmup import warm

    with pytest.raises(ValueError, match="unknown warm-up job"):
        warm(["soup", "x"])


def test_background_warmup_withdrawn_on_close(fresh_listener):
    from gsdf.cli._background import BackgroundWarmup

    bg = BackgroundWarmup(["demo-cloud"])
    bg.close()  # nothing compiled in between: nothing started, and the callback is gone
    assert bg.proc is None and bg._start not in _jit._first_compile_callbacks


def test_background_wait_for_returns_when_its_job_is_reported(fresh_listener):
    import subprocess
    import time

    from gsdf.cli._background import BackgroundWarmup

    bg = BackgroundWarmup(["demo-cloud", "distance"])
    with pytest.raises(ValueError, match="job"):
        bg.wait_for("soup")
    bg.wait_for("distance")  # nothing started (warm / no compile yet): returns at once
    # a stand-in for the warm-up process: reports demo-cloud, then keeps running
    bg._attach(subprocess.Popen([sys.executable, "-c", "import time; print('compiling ...', flush=True); "
                                 "print('  demo-cloud     1.0 s  the cloud', flush=True); time.sleep(60)"],
                                stdout=subprocess.PIPE, text=True))
    t = time.perf_counter()
    bg.wait_for("demo-cloud")
    assert time.perf_counter() - t < 30 and bg.proc.poll() is None and bg.done == {"demo-cloud"}
    t = time.perf_counter()
    bg.wait_for("distance", timeout=0.5)  # never reported, process still running: the timeout returns
    assert time.perf_counter() - t < 10 and bg.done == {"demo-cloud"}
    bg.proc.kill()
    bg.wait_for("distance")  # the process ended without reporting it: return, the caller compiles it
    assert bg.done == {"demo-cloud", "distance"}
    bg.close()
    assert bg.proc is None


# kernels that take two array dtypes on purpose (complex and real systems, int and float node arrays)
_TWO_DTYPES = {"gsdf.linalg._ldl._numeric", "gsdf.linalg._ldl._solve", "gsdf.linalg._assembly._principal_submatrix",
               "gsdf.spatial._binned._bigger"}


@pytest.mark.parametrize("job", ["point-areas", "polygon-heat", "reconstruct"])
def test_kernels_compile_once(tmp_path, job):
    """Every gsdf kernel on the point-area, polygon signed heat and reconstruction paths compiles one specialisation
    (a literal int argument, e.g. a count that starts at 0, gives a second one: seconds of cold compile for
    nothing)."""
    work = {
        "point-areas": "rng = np.random.default_rng(0)\n"
                       "P = rng.normal(size=(400, 3)); P /= np.linalg.norm(P, axis=1)[:, None]\n"
                       "gsdf.point_areas(P, P, k=20)\n",
        "polygon-heat": "from gsdf.heat.polygon._solver import PolygonMeshSignedHeatSolver\n"
                        "x = np.linspace(-1, 1, 9); V = np.array([[a, b, 0.0] for a in x for b in x])\n"
                        "i = np.arange(81).reshape(9, 9)\n"
                        "Q = np.stack([i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel(), "
                        "i[:-1, 1:].ravel()], 1)\n"
                        "loop = np.concatenate([i[2, 2:6], i[2:6, 6], i[6, 6:2:-1], i[6:1:-1, 2]])\n"
                        "PolygonMeshSignedHeatSolver(V, Q).compute_distance([loop])\n",
        "reconstruct": "rng = np.random.default_rng(0)\n"
                       "P = rng.normal(size=(600, 3)) * [1.0, 0.7, 0.5]\n"
                       "P /= np.linalg.norm(P / [1.0, 0.7, 0.5], axis=1)[:, None]\n"
                       "gsdf.reconstruct_simply_connected(P)\n",
    }[job]
    code = (
        "import numpy as np, numba, sys, gsdf\n" + work +
        "many = []\n"
        "for name, mod in list(sys.modules.items()):\n"
        "    if not name.startswith('gsdf.'):\n"
        "        continue\n"
        "    for attr, f in vars(mod).items():\n"
        "        if isinstance(f, numba.core.registry.CPUDispatcher) and f.__module__ == name \\\n"
        "                and len(f.signatures) > 1 and f'{name}.{attr}' not in %r:\n"
        "            many.append(f'{name}.{attr}: {len(f.signatures)}')\n"
        "print(';'.join(many))\n" % (_TWO_DTYPES,)
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=SRC)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", out.stdout


def test_warmup_refuses_a_worker_count_the_machine_cannot_start():
    """gsdf warmup --workers 10^9 was accepted (found by the fuzz suite); refused like gsdf batch's, at once."""
    from click.testing import CliRunner

    from gsdf.cli.main import main

    r = CliRunner().invoke(main, ["warmup", "--quiet", "--workers", "1000000000"])
    assert r.exit_code == 1 and "workers: 1,000,000,000 worker processes" in r.output
