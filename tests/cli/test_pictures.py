"""The ``--png`` of the commands: gsdf.render.save_png (polyscope where it renders headless, else gsdf's own
renderers), a framed object, a colour bar or legend titled with the field, ``--axis``/``--at`` for slices of
volume fields; the curves of ``swn`` / ``heat-surface`` drawn; ``gsdf render`` framing its level set."""

import numpy as np
import pytest
from click.testing import CliRunner

import gsdf
from gsdf.cli.main import main
from tests.render import picture
from tests.shapes import torus, uv_sphere


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(params=["polyscope", "gsdf"])
def renderer(request, monkeypatch):
    """Each picture test runs with polyscope (skipped where it cannot render headless) and with gsdf's own
    renderers (polyscope reported unavailable)."""
    from gsdf.render import _picture

    if request.param == "polyscope":
        pytest.importorskip("polyscope", reason="polyscope is not installed (pip install -e '.[view]')")
        why = _picture.polyscope_reason()
        if why is not None:
            pytest.skip(why)
    else:
        monkeypatch.setitem(_picture._DECISION, "reason", "test: gsdf's own renderers")
    return request.param


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    d = tmp_path_factory.mktemp("pictures")
    V, F = uv_sphere(16, 32)
    path = d / "ball.obj"
    gsdf.write_mesh(path, V * [1.0, 0.7, 0.5], F)
    return path


def _checked(png, colour_bar=True):
    img = picture.load(png)
    assert max(img.shape[:2]) >= 800
    assert picture.problems(img, colour_bar=colour_bar) == [], png
    return img


def test_sdf_png_slice_axis_and_position(sphere, tmp_path, renderer):
    r = run("sdf", sphere, "-o", tmp_path / "s.npz", "--resolution", 20, "--png", tmp_path / "a.png", "-q")
    assert r.exit_code == 0, r.output
    assert f"picture ({renderer})" in r.output
    a = _checked(tmp_path / "a.png")
    r = run("sdf", sphere, "-o", tmp_path / "s.npz", "--resolution", 20, "--png", tmp_path / "b.png",
            "--axis", "x", "--at", "0.5", "-q")
    assert r.exit_code == 0, r.output
    b = _checked(tmp_path / "b.png")
    assert a.shape != b.shape or np.abs(a.astype(int) - b).mean() > 1.0     # another slice, another picture
    r = run("sdf", sphere, "-o", tmp_path / "s.npz", "--png", tmp_path / "c.png", "--axis", "z", "--at", "7")
    assert r.exit_code == 1 and "outside the field's box" in r.output


def test_axis_and_at_need_png(sphere, tmp_path):
    r = run("sdf", sphere, "-o", tmp_path / "s.npz", "--axis", "y")
    assert r.exit_code == 2 and "--png" in r.output
    r = run("heat", sphere, "-o", tmp_path / "h.npz", "--png", tmp_path / "h.png", "--axis", "w")
    assert r.exit_code == 2 and "--axis" in r.output


def test_heat_png(sphere, tmp_path, renderer):
    r = run("heat", sphere, "-o", tmp_path / "h.npz", "--resolution", 16, "--png", tmp_path / "h.png",
            "--axis", "y", "-q")
    assert r.exit_code == 0, r.output
    _checked(tmp_path / "h.png")


def _swn_torus(d):
    """An asymmetric torus (tube radius varying around it) with two oppositely oriented meridian loops, one of
    them broken: the band between them is one region."""
    V, F, ij = torus(48, 16, R=1.0, r=0.35)
    ang = np.arctan2(V[:, 1], V[:, 0])
    V = V * (1.0 + 0.25 * np.cos(ang))[:, None]
    gsdf.write_mesh(d / "torus.obj", V, F)
    a = list(ij[6]) + [ij[6][0]]
    b = list(ij[30][::-1])[:-3]                      # reversed, with a gap of three edges
    nodes = a + b
    lines = [f"v {i}\n" for i in nodes]
    lines += [f"l {k} {k + 1}\n" for k in range(len(a) - 1)]
    lines += [f"l {k} {k + 1}\n" for k in range(len(a), len(nodes) - 1)]
    (d / "loops.txt").write_text("".join(lines))
    return d / "torus.obj", d / "loops.txt"


def test_swn_png_shows_labels_and_curves(tmp_path, renderer):
    mesh, curves = _swn_torus(tmp_path)
    r = run("swn", mesh, curves, "-o", tmp_path / "w.obj", "--png", tmp_path / "w.png", "-q")
    assert r.exit_code == 0, r.output
    img = _checked(tmp_path / "w.png", colour_bar=False)
    rep = picture.inspect(img)
    assert rep["annotations"], "no legend"
    x0, y0, x1, y1 = rep["bbox"]
    obj = img[y0:y1, x0:x1].astype(int)
    green = (obj[..., 1] > obj[..., 0] + 50) & (obj[..., 1] > obj[..., 2] + 40)
    assert green.sum() > 100, "the curves are not drawn"
    grey = (np.abs(obj[..., 0] - obj[..., 2]) < 25) & (obj[..., 0] > 90)
    orange = (obj[..., 0] > obj[..., 2] + 60) & ~green
    assert grey.sum() > 1000 and orange.sum() > 1000, "both regions are shown"
    # the labels written to the OBJ are read back by gsdf view (one '#label' comment block per face)
    from gsdf.cli.view import _obj_face_labels

    V2, F2 = gsdf.read_mesh(tmp_path / "w.obj")
    assert _obj_face_labels(tmp_path / "w.obj", len(F2)) is not None


def test_heat_surface_default_view_sees_a_long_shape_from_its_side(tmp_path, renderer):
    """A screwdriver-like shape along z: the default picture shows its length, not its end."""
    V, F = uv_sphere(12, 24)
    V = V * [0.12, 0.12, 1.0]
    gsdf.write_mesh(tmp_path / "rod.ply", V, F)
    ring = np.flatnonzero(np.abs(V[:, 2] - V[:, 2][np.argmin(np.abs(V[:, 2]))]) < 1e-9)
    (tmp_path / "c.txt").write_text("signed_curve\n" + "".join(f"v {i}\n" for i in [*ring, ring[0]]))
    r = run("heat-surface", tmp_path / "rod.ply", "--curves", tmp_path / "c.txt", "-o", tmp_path / "d.ply",
            "--png", tmp_path / "d.png", "-q")
    assert r.exit_code == 0, r.output
    rep = picture.inspect(_checked(tmp_path / "d.png"))
    x0, y0, x1, y1 = rep["bbox"]
    assert max(x1 - x0, y1 - y0) > 3 * min(x1 - x0, y1 - y0), rep["bbox"]


def test_tori_png(tmp_path, renderer):
    from gsdf.data import path

    P, N = gsdf.read_points(path("torus_cloud.xyz"))
    gsdf.write_points(tmp_path / "c.xyz", P, N)
    r = run("tori", tmp_path / "c.xyz", "-o", tmp_path / "t.npz", "--resolution", 24, "--png", tmp_path / "t.png",
            "--axis", "z", "-q")
    assert r.exit_code == 0, r.output
    _checked(tmp_path / "t.png")
    if renderer == "polyscope":          # gsdf's own renderers do not draw bare clouds, only the mesh
        r = run("tori", tmp_path / "c.xyz", "-o", tmp_path / "t.ply", "--resolution", 24, "--png",
                tmp_path / "m.png", "-q")
        assert r.exit_code == 0, r.output
        _checked(tmp_path / "m.png", colour_bar=False)


def test_reconstruct_png(tmp_path, renderer):
    from tests.shapes import fibonacci_sphere

    gsdf.write_points(tmp_path / "c.xyz", fibonacci_sphere(400) * [1.0, 0.6, 0.4])
    r = run("reconstruct", tmp_path / "c.xyz", "-o", tmp_path / "r.ply", "--png", tmp_path / "r.png", "-q")
    assert r.exit_code == 0, r.output
    _checked(tmp_path / "r.png", colour_bar=False)


def test_render_frames_the_level_set(tmp_path):
    from gsdf.data import path

    P, N = gsdf.read_points(path("torus_cloud.xyz"))
    gsdf.write_points(tmp_path / "c.xyz", P, N)
    r = run("render", tmp_path / "c.xyz", "-o", tmp_path / "r.png", "--size", "160x120", "-q")
    assert r.exit_code == 0, r.output
    rep = picture.inspect(picture.load(tmp_path / "r.png"))
    assert rep["extent"] > 0.75 and rep["margin"] >= 2, rep      # was about a third of the frame
