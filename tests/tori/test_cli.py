"""`gsdf tori` / `gsdf render` commands and the sphere tracer (the lead registers the commands in cli/main.py)."""

import numpy as np
from click.testing import CliRunner

from gsdf.cli.render import render
from gsdf.cli.tori import tori
from gsdf.io import read_mesh, write_points
from gsdf.tori import PointsAsTori
from gsdf.render._trace import sphere_trace


def _cloud(path, n=1500, radius=0.5, normals=True):
    i = np.arange(n) + 0.5
    ph, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    N = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    write_points(path, radius * N, N if normals else None)
    return str(path)


def test_tori_cli_mesh_offsets_grid_and_tori(tmp_path):
    src = _cloud(tmp_path / "ball.xyz")
    r = CliRunner().invoke(tori, [src, "-o", str(tmp_path / "zero.ply"), "--resolution", "24"])
    assert r.exit_code == 0, r.output
    V, F = read_mesh(tmp_path / "zero.ply")
    np.testing.assert_allclose(np.linalg.norm(V, axis=1), 0.5, atol=5e-3)
    r = CliRunner().invoke(tori, [src, "-o", str(tmp_path / "s.obj"), "--resolution", "20", "--offsets", "-0.1,0.1"])
    assert r.exit_code == 0, r.output
    V, _ = read_mesh(tmp_path / "s_0.1.obj")
    np.testing.assert_allclose(np.linalg.norm(V, axis=1), 0.6, atol=1e-2)
    r = CliRunner().invoke(tori, [src, "-o", str(tmp_path / "g.npz"), "--resolution", "16"])
    assert r.exit_code == 0, r.output
    z = np.load(tmp_path / "g.npz")
    assert z["values"].shape == (16, 16, 16) and z["values"].min() < -0.4
    r = CliRunner().invoke(tori, [src, "-o", str(tmp_path / "t.npz")])
    assert r.exit_code == 0, r.output
    assert PointsAsTori.load(tmp_path / "t.npz").signed_distance([[0, 0, 0.0]])[0] < -0.45
    r = CliRunner().invoke(render, [str(tmp_path / "t.npz"), "-o", str(tmp_path / "img.png"), "--size", "24"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "img.png").stat().st_size > 0


def test_tori_cli_errors(tmp_path):
    src = _cloud(tmp_path / "bare.xyz", normals=False)
    r = CliRunner().invoke(tori, [src, "-o", str(tmp_path / "x.ply")])
    assert r.exit_code != 0 and "normals" in r.output
    r = CliRunner().invoke(tori, [str(tmp_path / "missing.xyz"), "-o", str(tmp_path / "x.ply")])
    assert r.exit_code != 0
    small = _cloud(tmp_path / "small.xyz", n=20)
    r = CliRunner().invoke(tori, [small, "-o", str(tmp_path / "x.ply")])
    assert r.exit_code != 0 and "k=64" in r.output


def test_sphere_trace_hits_an_analytic_sphere_where_expected():
    img = sphere_trace(lambda Q: np.linalg.norm(Q, axis=1) - 0.5, [-1] * 3, [1] * 3, 40, 40, view=(0, 0, 1))
    hit = (img < 255).any(axis=2)
    # the camera frames what a first small picture hit: the disc is centred and spans 0.86 - 2/40 of the side
    # (up to a pixel), so it covers about π (0.81 / 2)² of the picture
    ys, xs = np.nonzero(hit)
    assert hit[20, 20] and not hit[0, 0]
    assert abs(xs.mean() - 19.5) < 1 and abs(ys.mean() - 19.5) < 1
    assert 0.76 * 40 <= np.ptp(xs) + 1 <= 0.88 * 40 and 0.76 * 40 <= np.ptp(ys) + 1 <= 0.88 * 40
    assert abs(hit.mean() - np.pi * 0.405 ** 2) < 0.15 * np.pi * 0.405 ** 2
