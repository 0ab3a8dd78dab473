"""Curve files (demo format, OBJ l lines) and the ``gsdf heat-surface`` command."""

import numpy as np
import pytest
from click.testing import CliRunner

from gsdf.cli.heat_surface import heat_surface
from gsdf.heat import SurfaceSignedHeatSolver
from gsdf.contour._surface_curves import region_boundary_curves
from gsdf.data._shapes import grid_mesh
from gsdf.io import read_mesh, write_mesh
from gsdf.io._curves import gc_edges, read_curves, write_curves


def test_demo_format_blocks(tmp_path):
    V, F = grid_mesh(4)
    edges, first = gc_edges(F)
    p = tmp_path / "c.txt"
    p.write_text("# comment\nsigned_curve 1\nv 0\nv 1\nv 2\n\nunsigned_curve\nv 6\nv 7\n"
                 "signed_curve\nf 3 0.2 0.3 0.5\ne 4 0.25\nunsigned_point\nv 12\nf 5 0.1 0.2 0.7\n")
    src = read_curves(str(p), F)
    assert len(src.curves) == 3 and src.curve_signs == [True, False, True]
    assert src.curves[0].tolist() == [2, 1, 0]                  # flip = 1 reverses
    f, b = src.curves[2][1]
    a, c = edges[4]
    np.testing.assert_allclose(b @ V[F[f]], 0.75 * V[a] + 0.25 * V[c])
    assert src.points[0] == 12 and src.points[1][0] == 5
    solver = SurfaceSignedHeatSolver(V, F)
    phi = solver.compute_distance(src.curves, points=src.points, curve_signs=src.curve_signs,
                                  level_set_constraint="none")
    assert np.isfinite(phi).all()


def test_obj_lines_and_roundtrip(tmp_path):
    V, F = grid_mesh(6)
    inside = (np.abs(V[F][:, :, :2]) <= 0.4).all(axis=(1, 2))
    (loop,) = region_boundary_curves(F, inside)
    p = tmp_path / "c.obj"
    p.write_text("v 0 0 0\nl " + " ".join(str(i + 1) for i in loop) + "\nl 1 2\n")
    src = read_curves(str(p))
    assert len(src.curves) == 2 and src.curves[0].tolist() == loop.tolist()
    q = tmp_path / "c.txt"
    write_curves(str(q), [loop, [(0, [0.2, 0.3, 0.5]), (0, [0.5, 0.3, 0.2])]], [True, True], points=[3])
    src2 = read_curves(str(q))
    assert src2.curves[0].tolist() == loop.tolist() and src2.points == [3]


@pytest.mark.parametrize("text,match", [
    ("signed_curve\nv x\n", "cannot parse"),
    ("signed_curve\ne 1 0.5\n", "need the mesh faces"),
    ("l 0 1\n", "1-based"),
    ("# nothing\n", "no curves or points"),
])
def test_bad_curve_files(tmp_path, text, match):
    p = tmp_path / "bad.txt"
    p.write_text(text)
    with pytest.raises(ValueError, match=match):
        read_curves(str(p))


def test_cli_heat_surface(tmp_path):
    V, F = grid_mesh(12)
    mesh = tmp_path / "m.obj"
    write_mesh(str(mesh), V, F)
    inside = (np.abs(V[F][:, :, :2]) <= 0.5 + 1e-9).all(axis=(1, 2))
    curves = tmp_path / "c.txt"
    write_curves(str(curves), region_boundary_curves(F, inside))
    out, png = tmp_path / "o.ply", tmp_path / "o.png"
    r = CliRunner().invoke(heat_surface, [str(mesh), "--curves", str(curves), "-o", str(out), "--png", str(png),
                                          "--level-set", "multiple", "--t-coef", "2"])
    assert r.exit_code == 0, r.output
    assert out.exists() and png.exists() and png.stat().st_size > 1000
    from plyfile import PlyData

    d = np.asarray(PlyData.read(str(out))["vertex"]["distance"])
    assert d.shape == (len(V),) and d[np.argmin(np.linalg.norm(V, axis=1))] < 0
    V2, F2 = read_mesh(str(out))
    assert len(F2) == len(F)
    bad = CliRunner().invoke(heat_surface, [str(mesh), "--curves", str(curves), "-o", str(tmp_path / "o.obj")])
    assert bad.exit_code != 0 and ".ply" in bad.output
