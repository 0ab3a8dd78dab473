"""``gsdf view``: the files gsdf reads and writes, shown headless (--screenshot) and checked as pictures.

The screenshot tests are skipped, with the reason, where polyscope or EGL is missing."""

import sys

import numpy as np
import pytest
from click.testing import CliRunner

import gsdf
from gsdf.cli.main import main
from tests.shapes import uv_sphere
from tests.render import picture


@pytest.fixture(scope="module")
def headless():
    pytest.importorskip("polyscope", reason="polyscope is not installed (pip install -e '.[view]')")
    from gsdf.render import _polyscope

    why = _polyscope.available()
    if why is not None:
        pytest.skip(why)


def _run(*args):
    r = CliRunner().invoke(main, ["view", *map(str, args)])
    return r


def _sphere():
    V, F = uv_sphere(20, 40)
    return np.asarray(V, float), np.asarray(F, np.int64)


def _grid():
    x = np.linspace(-1, 1, 21)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    return gsdf.GridField(np.sqrt(X ** 2 + Y ** 2 + Z ** 2) - 0.6, [-1] * 3, [1] * 3)


@pytest.mark.parametrize("ext", [".npz", ".vti"])
def test_saved_grid_field(headless, tmp_path, ext):
    f = tmp_path / f"sdf{ext}"
    _grid().save(f)
    r = _run(f, "--screenshot", tmp_path / "out.png", "--size", "800x600", "--axis", "z", "--at", "0.1")
    assert r.exit_code == 0, r.output
    assert "800x600" in r.output
    assert picture.problems(picture.load(tmp_path / "out.png")) == []


def test_heat_surface_mesh_with_its_curves(headless, tmp_path):
    V, F = _sphere()
    gsdf.write_mesh(tmp_path / "d.ply", V, F, vertex_data={"distance": V[:, 2] - 0.2})
    loop = np.flatnonzero(np.abs(V[:, 2] - V[:, 2][np.argmin(np.abs(V[:, 2] - 0.2))]) < 1e-9)
    (tmp_path / "c.txt").write_text("signed_curve\n" + "".join(f"v {i}\n" for i in [*loop, loop[0]]))
    r = _run(tmp_path / "d.ply", tmp_path / "c.txt", "-o", tmp_path / "out.png", "--size", "800x600")
    assert r.exit_code == 0, r.output
    assert picture.problems(picture.load(tmp_path / "out.png")) == []


def test_swn_output_shows_labels_and_voxels_and_clouds_render(headless, tmp_path):
    from gsdf.cli.swn import write_swn_ply

    V, F = _sphere()
    labels = (V[F].mean(1)[:, 0] > 0.3).astype(int)
    write_swn_ply(tmp_path / "w.ply", V, F, np.repeat(labels[:, None], 3, 1).astype(float), labels)
    r = _run(tmp_path / "w.ply", "--screenshot", tmp_path / "w.png", "--size", "800x600")
    assert r.exit_code == 0, r.output
    img = picture.load(tmp_path / "w.png")
    assert picture.problems(img, colour_bar=False) == [] and picture.inspect(img)["annotations"]
    occ = np.zeros((8, 8, 8), bool)
    occ[2:6, 2:5, 3:7] = True
    gsdf.save_voxels(tmp_path / "v.npz", occ, [0, 0, 0], [1, 1, 1])
    gsdf.write_points(tmp_path / "p.xyz", V, V)
    for name in ("v.npz", "p.xyz"):
        r = _run(tmp_path / name, "--screenshot", tmp_path / "x.png", "--size", "640x480", "-q")
        assert r.exit_code == 0 and r.output == "", r.output
        assert picture.problems(picture.load(tmp_path / "x.png"), colour_bar=False) == []


def test_errors_are_one_line(tmp_path, monkeypatch):
    V, F = _sphere()
    gsdf.write_mesh(tmp_path / "m.off", V, F)
    (tmp_path / "c.txt").write_text("signed_curve\nv 0\nv 1\n")
    r = _run(tmp_path / "c.txt", tmp_path / "m.off", "--screenshot", tmp_path / "x.png")
    assert r.exit_code == 1 and "needs the mesh it lies on before it" in r.output
    r = _run(tmp_path / "m.off", "--screenshot", tmp_path / "x.jpg")
    assert r.exit_code == 1 and ".png" in r.output
    (tmp_path / "junk.off").write_bytes(b"OFF\n3 1 0\n0 0 nan\n")
    r = _run(tmp_path / "junk.off", "--screenshot", tmp_path / "x.png")
    assert r.exit_code == 1 and r.output.count("Error") == 1 and "junk.off" in r.output
    r = _run(tmp_path / "m.off", "--screenshot", tmp_path / "m.off")
    assert r.exit_code == 1 and "refusing to overwrite an input" in r.output
    r = _run(tmp_path / "m.off", "--axis", "w")
    assert r.exit_code == 2 and "--axis" in r.output
    r = _run(tmp_path / "m.off", "--field", "", "--screenshot", tmp_path / "x.png")
    assert r.exit_code == 1 and "--field: expected the name of a vertex property" in r.output
    r = _run(tmp_path / "m.off", "--field", "distance", "--screenshot", tmp_path / "x.png")
    assert r.exit_code == 1 and "--field distance: none of the files" in r.output
    gsdf.write_mesh(tmp_path / "d.ply", V, F, vertex_data={"distance": V[:, 0]})
    r = _run(tmp_path / "d.ply", "--field", "other", "--screenshot", tmp_path / "x.png")
    assert r.exit_code == 1 and "no vertex property 'other'" in r.output
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if sys.platform.startswith("linux"):          # elsewhere a window can always open
        r = _run(tmp_path / "m.off")
        assert r.exit_code == 1 and "no display" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "x.png").exists()


def test_help_has_the_shared_flags():
    r = CliRunner().invoke(main, ["view", "--help"])
    assert r.exit_code == 0 and "-q, --quiet" in r.output and "--threads N" in r.output
    assert "--screenshot" in r.output and "Example" in r.output
