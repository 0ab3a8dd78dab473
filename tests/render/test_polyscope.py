"""Headless screenshots of gsdf.view (polyscope on EGL; Mesa's software renderer where there is no GPU), checked as
pictures: not empty, the object framed and not cut off, the colour bar or legend in a corner.

Skipped, with the reason, where polyscope or EGL is missing (install: pip install -e '.[view]'; Debian/Ubuntu:
apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri).
"""

import os

import numpy as np
import pytest

import gsdf
from tests.shapes import uv_sphere
from tests.render import picture


@pytest.fixture(scope="module")
def headless():
    pytest.importorskip("polyscope", reason="polyscope is not installed (pip install -e '.[view]')")
    from gsdf.render import _polyscope

    why = _polyscope.available()
    if why is not None:
        pytest.skip(why)


def _sphere(scale=(1.0, 1.0, 1.0)):
    V, F = uv_sphere(24, 48)
    return np.asarray(V, float) * scale, np.asarray(F, np.int64)


def _ball_grid(n=33):
    x = np.linspace(-1.2, 1.2, n)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    return gsdf.GridField(np.sqrt(X ** 2 + 1.5 * Y ** 2 + Z ** 2) - 0.8, [-1.2] * 3, [1.2] * 3)


def test_mesh_field_screenshot_is_framed_with_a_colour_bar(headless, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    V, F = _sphere((1.6, 1.0, 0.7))
    out = tmp_path / "mesh.png"
    img = gsdf.view(("height [m]", (V, F, V[:, 1])), screenshot=out, size=(800, 600))
    assert img.shape == (600, 800, 3) and out.exists()
    assert np.array_equal(picture.load(out), img)
    assert picture.problems(img) == []
    r = picture.inspect(img)
    assert r["annotations"][0][0] < 40 and r["annotations"][0][1] < 40         # the bar, top left
    x0, y0, x1, y1 = r["annotations"][0]
    ax0, ay0, ax1, ay1 = r["bbox"]
    assert x1 < ax0 or y1 < ay0                                               # not over the object
    assert sorted(os.listdir(tmp_path)) == ["mesh.png"]                       # no polyscope .ini files


def test_default_size_is_at_least_800_pixels(headless, tmp_path):
    V, F = _sphere()
    img = gsdf.view((V, F, V[:, 0]), screenshot=tmp_path / "a.png")
    assert img.shape[:2] == (900, 1200)


def test_grid_field_slice_and_isosurface(headless, tmp_path):
    img = gsdf.view(("signed distance [model units]", _ball_grid()), screenshot=tmp_path / "g.png",
                    size=(800, 600))
    assert picture.problems(img) == []
    # the slice shows both sides of the zero level: blue (inside) and red (outside) pixels of coolwarm
    r, g, b = (img[..., k].astype(int) for k in range(3))
    obj = np.zeros(img.shape[:2], bool)
    x0, y0, x1, y1 = picture.inspect(img)["bbox"]
    obj[y0:y1, x0:x1] = True
    assert ((b - r > 40) & obj).sum() > 500 and ((r - b > 40) & obj).sum() > 500


def test_tet_field_slice(headless, tmp_path):
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(0)
    P = np.vstack([rng.uniform(-1, 1, (3000, 3)), np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T])
    f = gsdf.TetField(P, Delaunay(P).simplices, np.linalg.norm(P, axis=1) - 0.7)
    img = gsdf.view(f, screenshot=tmp_path / "t.png", size=(800, 600),
                    options=gsdf.ViewOptions(slice_axis="z", isolines=8))
    assert picture.problems(img) == []


def test_labels_legend_cloud_and_curves(headless, tmp_path):
    V, F = _sphere()
    labels = (V[F].mean(1)[:, 2] > 0.4).astype(int)
    ring = [np.c_[np.cos(t), np.sin(t), np.zeros_like(t)] * 1.05 for t in [np.linspace(0, 2 * np.pi, 60)]]
    img = gsdf.view(("surface winding number", (V, F, labels)), ring, screenshot=tmp_path / "l.png",
                    size=(800, 600))
    assert picture.problems(img, colour_bar=False) == [] and picture.inspect(img)["annotations"]
    P = V[::3]
    img = gsdf.view((P, P), screenshot=tmp_path / "c.png", size=(800, 600))       # cloud with normals
    assert picture.problems(img, colour_bar=False) == []
    img = gsdf.view(ring, screenshot=tmp_path / "r.png", size=(800, 600))          # a thin curve alone
    assert picture.problems(img, min_fill=0.002, colour_bar=False) == []


def test_camera_options_turn_the_view(headless, tmp_path):
    V, F = _sphere((2.0, 0.5, 0.5))
    a = gsdf.view((V, F), screenshot=tmp_path / "a.png", size=(400, 300), azimuth=0, elevation=0)
    b = gsdf.view((V, F), screenshot=tmp_path / "b.png", size=(400, 300), up="x", azimuth=0, elevation=0)
    wa = np.ptp(np.nonzero((a < 250).any(-1))[1])
    wb = np.ptp(np.nonzero((b < 250).any(-1))[1])
    assert wa > 1.5 * wb          # the long x axis lies across the picture, then (up = x) along its height


def test_save_png_uses_polyscope_or_gsdf_renderers(headless, tmp_path):
    from gsdf.render import save_png

    g = _ball_grid(17)
    assert save_png(tmp_path / "p.png", g, size=(640, 480)) == "polyscope"
    assert picture.load(tmp_path / "p.png").shape == (480, 640, 3)
    assert save_png(tmp_path / "f.png", g, renderer="gsdf") == "gsdf"
    V, F = _sphere()
    assert save_png(tmp_path / "m.png", (V, F, V[:, 0]), view=(0, 0, 1), renderer="gsdf") == "gsdf"
    assert picture.problems(picture.load(tmp_path / "m.png"), colour_bar=False) == []


def test_window_extras_register(headless):
    """The interactive window adds the whole volume field (polyscope's volume grid / tet mesh, disabled); the
    registration is checked headless (a window cannot open here)."""
    from scipy.spatial import Delaunay

    from gsdf.render import _polyscope, _scene

    ps = _polyscope.session(headless=True)
    P = np.random.default_rng(0).uniform(-1, 1, (200, 3))
    for f in (_ball_grid(9), gsdf.TetField(P, Delaunay(P).simplices, P[:, 0])):
        (it,) = _scene.coerce([f])
        sc = _scene.build([it], gsdf.ViewOptions(), np.array([0, 0, 1.0]), np.array([0, 1.0, 0]))
        try:
            _polyscope._register_volume(ps, sc.volumes[0])
            assert ps.has_volume_grid("field (volume)") or ps.has_volume_mesh("field (volume)")
        finally:
            ps.remove_all_structures()
