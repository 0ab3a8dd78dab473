"""Old-vs-new: ``gsdf.surface_winding_number`` with its defaults gives the results of the code before the options
were folded into :class:`gsdf.SWNOptions` and the DEC operators into the shared triangle operator set (the previous
checkout: set ``GSDF_OLD_SRC`` to its src folder; run in a subprocess): identical labels, values up to rounding.
Skipped unless GSDF_OLD_SRC is set."""

import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np
import pytest

OLD_SRC = pathlib.Path(os.environ.get("GSDF_OLD_SRC", "/nonexistent"))
NEW_SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
SHAPES = pathlib.Path(__file__).resolve().parents[1] / "shapes.py"

pytestmark = pytest.mark.skipif(not (OLD_SRC / "gsdf").is_dir() or OLD_SRC.resolve() == NEW_SRC.resolve(),
                                reason="no previous checkout to compare with")

# cases: (name, method); the meshes and curves are built by _SCRIPT from tests/shapes.py
CASES = [("sphere_broken_equator", "lp"), ("torus_broken_meridian", "lp"), ("torus_broken_meridian", "reduced"),
         ("torus_broken_meridian", "none"), ("annulus_arcs", "lp"), ("double_torus_walks", "lp"),
         ("torus_band", "lp")]

_SCRIPT = r'''
import importlib.util, sys
import numpy as np
spec = importlib.util.spec_from_file_location("shapes", sys.argv[1])
shapes = importlib.util.module_from_spec(spec); spec.loader.exec_module(shapes)
import gsdf

def case(name):
    if name == "sphere_broken_equator":
        V, F = shapes.uv_sphere(24, 48)
        ring = 1 + 11 * 48 + np.arange(48)
        return V, F, [[int(ring[(s + t) % 48]) for t in range(3)] for s in range(0, 48, 4)]
    if name == "torus_broken_meridian":
        V, F, idx = shapes.torus(48, 24)
        return V, F, [idx[5, :17], idx[30, 3:15]]
    if name == "annulus_arcs":
        V, F, idx = shapes.annulus(6, 32)
        return V, F, [idx[0, 3:20], idx[:, 7], idx[2, list(range(10, 32)) + [0, 1, 2]]]
    if name == "double_torus_walks":
        V, F = shapes.double_torus(24)
        rng = np.random.default_rng(3)
        E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
        curves = []
        for _ in range(4):
            walk = [int(rng.integers(len(V)))]
            for _ in range(25):
                nb = np.concatenate([E[E[:, 0] == walk[-1], 1], E[E[:, 1] == walk[-1], 0]])
                nb = nb[~np.isin(nb, walk)]
                if len(nb) == 0:
                    break
                walk.append(int(rng.choice(nb)))
            curves.append(walk)
        return V, F, curves
    if name == "torus_band":                        # 12 288 faces: the banded LP of the default
        V, F, idx = shapes.torus(96, 64)
        return V, F, [idx[5, :40], idx[50, 10:60]]
    raise KeyError(name)

out = {}
for spec_ in sys.argv[3:]:
    name, method = spec_.split(":")
    V, F, curves = case(name)
    r = gsdf.surface_winding_number(V, F, curves, method=method)
    for k in ("face_labels", "corner_values", "residual", "u", "bounding"):
        out[f"{name}:{method}:{k}"] = np.asarray(getattr(r, k))
np.savez(sys.argv[2], **out)
'''


def _run(src, path, cases):
    # the previous checkout's numba cache goes to a temporary folder (nothing is written into that checkout)
    env = dict(os.environ, PYTHONPATH=str(src), PYTHONDONTWRITEBYTECODE="1")
    if src == OLD_SRC:
        env["NUMBA_CACHE_DIR"] = os.path.join(tempfile.gettempdir(), "gsdf-old-vs-new-numba")
    subprocess.run([sys.executable, "-c", _SCRIPT, str(SHAPES), str(path)] + [f"{n}:{m}" for n, m in cases],
                   check=True, env=env, cwd=path.parent)
    return dict(np.load(path))


def test_defaults_agree_with_the_previous_code(tmp_path):
    """Labels and bounding parts are bit-identical. The DEC operators now come from the shared triangle operator
    set (gsdf.mesh._triangle_ops: Eq. 5 cotangents, arccos angles, edge lengths from the face slots), which moves
    ⋆1 and the weights by a few ulps (tests/mesh/test_triangle_ops.py); downstream, measured on these cases:
    corner values ≤ 1.9e-14; u by a constant ≤ 3.5e-9 (the jump solve's 1e-8 regularization fixes the constant
    only to ~ulp / 1e-8), ≤ 3.5e-14 after removing it; the residual (the LP's solution) ≤ 1.2e-9, within HiGHS'
    tolerances."""
    old = _run(OLD_SRC, tmp_path / "old.npz", CASES)
    new = _run(NEW_SRC, tmp_path / "new.npz", CASES)
    assert sorted(old) == sorted(new)
    for k in old:
        a, b = old[k], new[k]
        assert a.shape == b.shape, k
        kind = k.rsplit(":", 1)[1]
        if kind in ("face_labels", "bounding"):
            assert np.array_equal(a, b), k
        elif kind == "u":
            assert np.abs(a - b).max() < 1e-7 and np.ptp(a - b) < 1e-12, k
        elif kind == "residual":
            assert np.abs(a - b).max() < 1e-8, k
        else:
            assert np.abs(a - b).max() < 1e-12, k


_INSERT_SCRIPT = r'''
import sys
import numpy as np
import gsdf
try:                                            # the module's place before and after the layout change
    from gsdf.swn._insert import insert_curves, insert_surface_points
    from gsdf.io._swn_curves import read_swn_curves
except ImportError:
    from gsdf.winding.surface_curves import insert_curves, insert_surface_points
    from gsdf.io.swn_curves import read_swn_curves

out = {}
data = sys.argv[2]
for name, mesh, cur in (("double-torus", "double-torus.obj", "double-torus.txt"), ("annulus", "annulus.obj",
                        "annulus.txt"), ("S", "S.obj", "S.txt"), ("torus", "torus.obj", "torus-phi.txt"),
                        ("bunny", "bunny.obj", "bunny-heart.txt")):
    V, F = gsdf.read_mesh(f"{data}/{mesh}")
    r = insert_curves(V, F, read_swn_curves(f"{data}/{cur}", F))
    for k, a in zip("VFSP", r):
        out[f"{name}:{k}"] = a
n = 16
i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
V = np.column_stack([i.ravel() / n, j.ravel() / n, np.zeros(i.size)])
a = (i[:-1, :-1] * (n + 1) + j[:-1, :-1]).ravel()
F = np.vstack([np.column_stack([a, a + n + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + 1])])
circle = gsdf.level_set_curves(V, F, np.linalg.norm(V[:, :2] - 0.5, axis=1) - 0.3)
inner = [(100, b) for b in ([0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6], [0.6, 0.2, 0.2])]   # inside a face
for name, curves in (("circle", circle), ("interior", [inner])):
    r = insert_surface_points(V, F, curves)
    for k, a in zip("VFSP", r):
        out[f"{name}:{k}"] = a
np.savez(sys.argv[1], **out)
'''

DATA = pathlib.Path("/work/shared/data/swn")


@pytest.mark.skipif(not DATA.is_dir(), reason="no author data")
def test_curve_insertion_bit_identical_to_the_previous_code(tmp_path):
    res = []
    for side, src in (("old", OLD_SRC), ("new", NEW_SRC)):
        env = dict(os.environ, PYTHONPATH=str(src), PYTHONDONTWRITEBYTECODE="1")
        if side == "old":
            env["NUMBA_CACHE_DIR"] = os.path.join(tempfile.gettempdir(), "gsdf-old-vs-new-numba")
        path = tmp_path / f"{side}.npz"
        subprocess.run([sys.executable, "-c", _INSERT_SCRIPT, str(path), str(DATA)], check=True, env=env,
                       cwd=tmp_path)
        res.append(dict(np.load(path)))
    old, new = res
    assert sorted(old) == sorted(new)
    for k in old:
        assert old[k].shape == new[k].shape and np.array_equal(old[k], new[k]), k
