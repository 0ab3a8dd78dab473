"""Old-vs-new: ``gsdf.reconstruct_simply_connected`` as named stages with :class:`gsdf.ReconstructionOptions` gives
bit-identical meshes (V, F) to the 437-line function it replaced (the previous checkout, ``GSDF_OLD_SRC``,
default /work/main/src, run in a subprocess). Skipped when that checkout is absent."""

import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np
import pytest

OLD_SRC = pathlib.Path(os.environ.get("GSDF_OLD_SRC", "/work/main/src"))
NEW_SRC = pathlib.Path(__file__).resolve().parents[2] / "src"

pytestmark = pytest.mark.skipif(not (OLD_SRC / "gsdf").is_dir() or OLD_SRC.resolve() == NEW_SRC.resolve(),
                                reason="no previous checkout to compare with")

_SCRIPT = r'''
import sys
import numpy as np
import gsdf

def fibonacci(n, r=1.0, c=(0.0, 0.0, 0.0)):
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    return r * np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)]) + c

def case(name):
    """(P, N, keyword arguments of the previous code, of the new code: callables, built on their side only)"""
    if name == "sphere":                                  # the docstring's example: defaults
        return fibonacci(800), None, dict, dict
    if name == "ellipsoid_outliers":                      # samples + outliers moved along the normal
        rng = np.random.default_rng(1)
        a = np.array([1.0, 0.6, 0.4])
        X = fibonacci(1200) * a
        N = X / a ** 2
        N /= np.linalg.norm(N, axis=1)[:, None]
        i = rng.integers(0, len(X), 150)
        O = X[i] + N[i] * rng.uniform(-0.25, 0.25, (150, 1)) * np.linalg.norm(2 * a)
        return np.concatenate([X, O]), None, dict, dict
    if name == "two_spheres":                             # clusters, normals given, no subdivision, no fit
        P = np.concatenate([fibonacci(700), fibonacci(500, 0.7, (2.5, 0.0, 0.0))])
        N = np.concatenate([fibonacci(700), fibonacci(500)]) * np.where(np.arange(1200) % 3, 1.0, -1.0)[:, None]
        old = lambda: dict(clusters=True, subdivide=0, fit=False, max_iterations=2)
        new = lambda: dict(clusters=True, options=gsdf.ReconstructionOptions(subdivide=0, fit=False,
                                                                             max_iterations=2))
        return P, N, old, new
    raise KeyError(name)

side, path = sys.argv[1], sys.argv[2]
out = {}
for name in sys.argv[3:]:
    P, N, old, new = case(name)
    V, F = gsdf.reconstruct_simply_connected(P, N, **(old() if side == "old" else new()))
    out[name + ":V"], out[name + ":F"] = V, F
np.savez(path, **out)
'''

CASES = ["sphere", "ellipsoid_outliers", "two_spheres"]


def _run(side, src, path):
    # the previous checkout's numba cache goes to a temporary folder (nothing is written into that checkout)
    env = dict(os.environ, PYTHONPATH=str(src), PYTHONDONTWRITEBYTECODE="1")
    if side == "old":
        env["NUMBA_CACHE_DIR"] = os.path.join(tempfile.gettempdir(), "gsdf-old-vs-new-numba")
    subprocess.run([sys.executable, "-c", _SCRIPT, side, str(path)] + CASES, check=True, env=env, cwd=path.parent)
    return dict(np.load(path))


def test_meshes_bit_identical_to_the_previous_code(tmp_path):
    old = _run("old", OLD_SRC, tmp_path / "old.npz")
    new = _run("new", NEW_SRC, tmp_path / "new.npz")
    assert sorted(old) == sorted(new)
    for k in old:
        assert old[k].shape == new[k].shape, k
        assert np.array_equal(old[k], new[k]), k
