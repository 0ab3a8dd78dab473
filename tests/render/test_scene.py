"""The scene of gsdf.view without polyscope: items, colour ranges, isolines, slices, camera framing; the names
gsdf.view and gsdf.ViewOptions; the message without polyscope."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import gsdf
from gsdf.render import _scene
from tests.shapes import uv_sphere

SRC = os.path.join(os.path.dirname(__file__), "..", "..", "src")


def _sphere():
    V, F = uv_sphere(16, 24)
    return np.asarray(V, float), np.asarray(F, np.int64)


def test_items_become_meshes_clouds_curves_and_volumes():
    V, F = _sphere()
    x = np.linspace(-1, 1, 9)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    grid = gsdf.GridField(X ** 2 + Y ** 2 + Z ** 2 - 0.5, [-1] * 3, [1] * 3)
    labels = (V[F].mean(1)[:, 0] > 0).astype(int)
    items = _scene.coerce([
        (V, F), (V, F, V[:, 0]), (V, F, labels), ("distance [mm]", gsdf.SurfaceField(V, F, V[:, 1])),
        grid, V, (V, V), (V, V[:, 2]), [V[:5], V[5:9]], gsdf.Curve(np.arange(3)), [np.array([0, 1, 2])],
        (V, F, {"report": 1}), (V, np.hstack([F[:4], F[:4, :1]])),
    ])
    kinds = [type(i).__name__ for i in items]
    assert kinds == ["MeshItem"] * 4 + ["VolumeItem", "CloudItem", "CloudItem", "CloudItem", "CurvesItem",
                                        "CurvesItem", "CurvesItem", "MeshItem", "MeshItem"]
    assert items[3].name == "distance [mm]"
    assert items[2].values.dtype.kind == "i"
    assert items[6].N is not None and items[7].values is not None
    # vertex-index curves lie on the mesh before them
    assert np.array_equal(items[9].polylines[0], V[:3])
    assert items[11].values is None                     # the report of a reconstruction is not a field
    assert len(items[12].F) == 8                       # quads split in two triangles


def test_curves_need_their_mesh_and_bad_items_are_named():
    with pytest.raises(ValueError, match="need the mesh before them"):
        _scene.coerce([gsdf.Curve(np.arange(3))])
    with pytest.raises(ValueError, match="item 0: cannot show a str"):
        _scene.coerce(["bunny.off"])
    V, F = _sphere()
    with pytest.raises(ValueError, match="per vertex"):
        _scene.coerce([(V, F, np.zeros(7))])
    with pytest.raises(ValueError, match="nothing to show"):
        _scene.coerce([])


def test_surface_winding_number_result_shows_its_face_labels():
    V, F = _sphere()

    class Result:                                         # what gsdf.surface_winding_number returns
        face_labels = (V[F].mean(1)[:, 2] > 0.3).astype(np.int64)
        corner_values = np.zeros((len(F), 3))

    (it,) = _scene.coerce([(V, F, Result())])
    assert np.array_equal(it.values, Result.face_labels)
    sc = _scene.build([it], gsdf.ViewOptions(), np.array([0, 0, 1.0]), np.array([0, 1.0, 0]))
    mesh = sc.parts[0]
    assert mesh.labels is not None and sorted(mesh.labels.legend) == [0, 1]
    assert math.isclose(sum(share for _, share in mesh.labels.legend.values()), 1.0)
    # the boundary between the two labels is drawn: edges whose two faces differ
    seg = _scene.label_boundaries(F, Result.face_labels)
    assert len(seg) > 0 and [p.name for p in sc.parts[1:]] == ["mesh boundaries"]


def test_field_kinds_ranges_and_levels():
    assert _scene.field_kind(np.linspace(-1, 2, 50)) == "signed"
    w = np.r_[np.zeros(60), np.ones(30), np.linspace(0, 1, 10), [-0.02, 1.03]]
    assert _scene.field_kind(w) == "winding"
    assert _scene.field_kind(np.linspace(0, 3, 50)) == "plain"
    assert _scene.colour_range(np.array([-0.2, 0.7495]), "signed") == (-0.8, 0.8)
    assert [_scene.round_up(a) for a in (0.59, 13.5, 1.0, 2.3, 9.1)] == [0.6, 15.0, 1.0, 2.5, 10.0]
    assert _scene.colour_range(w, "winding") == (0.0, 1.0)
    assert _scene.colour_range(np.array([1.0, 3.0]), "plain") == (1.0, 3.0)
    assert _scene.nice_levels(-0.74, 0.74, 16) == pytest.approx([k / 10 for k in range(-7, 8)])
    assert _scene.nice_levels(0, 1, 4) == [0, 0.25, 0.5, 0.75, 1.0]
    assert _scene.default_level("signed") == 0.0 and _scene.default_level("winding") == 0.5


def test_isolines_of_a_vertex_field_with_a_bold_level():
    V, F = _sphere()
    parts = _scene.isoline_parts("m", V, F, V[:, 1], [-0.5, 0.0, 0.5], 0.0)
    thin, bold = parts
    assert bold.radius > thin.radius and bold.name == "m isoline 0"
    assert np.allclose(bold.nodes[:, 1], 0.0, atol=1e-12)       # the level-0 isoline of the height
    assert np.allclose(np.abs(thin.nodes[:, 1]), 0.5, atol=1e-12)


def test_grid_and_tet_slices_carry_the_field():
    x = np.linspace(-1, 1, 11)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    g = gsdf.GridField(X + 2 * Y + 3 * Z, [-1] * 3, [1] * 3)
    P, F, v = _scene.grid_slice(g.values, g.bbox_min, g.bbox_max, 2, 0.33)
    assert np.allclose(P[:, 2], 0.33) and np.allclose(v, P @ [1, 2, 3])
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(0)
    Pt = np.vstack([rng.uniform(-1, 1, (300, 3)), np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T])
    t = gsdf.TetField(Pt, Delaunay(Pt).simplices, Pt @ [1.0, -2.0, 0.5])
    P, F, v = _scene.tet_slice(t, 0, 0.1)
    assert len(F) > 50 and np.allclose(P[:, 0], 0.1)
    assert np.allclose(v, P @ [1.0, -2.0, 0.5], atol=1e-12)          # linear field: exact on the slice
    A = 0.5 * np.linalg.norm(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]), axis=1).sum()
    assert A == pytest.approx(4.0, rel=1e-9)                           # the cube's full cross-section


def test_volume_scene_has_slice_isolines_isosurface_and_cut():
    x = np.linspace(-1, 1, 17)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    g = gsdf.GridField(np.sqrt(X ** 2 + Y ** 2 + Z ** 2) - 0.6, [-1] * 3, [1] * 3)
    V, F = _sphere()
    items = _scene.coerce([("signed distance [m]", g), (V * 0.6, F)])
    d, up = _scene.camera_direction("auto", "auto", 35, 25, np.array([2, 2, 2.0]))
    sc = _scene.build(items, gsdf.ViewOptions(), d, up)
    names = [p.name for p in sc.parts]
    assert names[:2] == ["signed distance [m] slice", "signed distance [m] slice isolines"]
    assert "signed distance [m] level 0" in names and len(sc.planes) == 1
    iso = sc.parts[names.index("signed distance [m] level 0")]
    assert iso.cut == 0 and iso.transparency is not None
    mesh = sc.parts[names.index("mesh")]
    assert mesh.cut == 0 and mesh.edges                   # the mesh shown with the field is cut open too
    assert [b.title for b in sc.bars()] == ["signed distance [m]"]
    assert sc.bars()[0].vrange == pytest.approx((-1.2, 1.2))     # rounded, symmetric about 0


def test_fields_with_one_title_and_two_scales_get_two_colour_bars():
    V, F = _sphere()
    items = _scene.coerce([("d", (V, F, V[:, 0])), ("d", (V + 3, F, 5 * V[:, 0]))])
    sc = _scene.build(items, gsdf.ViewOptions(), np.array([0, 0, 1.0]), np.array([0, 1.0, 0]))
    assert [b.title for b in sc.bars()] == ["d", "d (2)"]


@pytest.mark.parametrize("up,front,az,el", [("auto", "auto", 35, 25), ("z", "auto", -60, 40), ("-y", "x", 0, 0)])
def test_camera_frames_the_points(up, front, az, el):
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(2000, 3)) * [3.0, 1.0, 0.5] + [10, -4, 2]
    d, upv = _scene.camera_direction(up, front, az, el, np.ptp(pts, axis=0))
    assert math.isclose(np.linalg.norm(d), 1) and math.isclose(abs(d @ upv), math.sin(math.radians(el)),
                                                                abs_tol=1e-9)
    W, H, fov = 1200, 900, 45.0
    cam, target = _scene.frame_camera(pts, W, H, fov, d, upv, fill=0.8)
    x, y = _project(pts, cam, target, upv, W, H, fov)
    span = max(np.ptp(x) / W, np.ptp(y) / H)
    assert span == pytest.approx(0.8, abs=0.01)                    # fills 80 % of the tighter side
    assert (x.min() + x.max()) / 2 == pytest.approx(W / 2, abs=3)  # centred
    assert (y.min() + y.max()) / 2 == pytest.approx(H / 2, abs=3)


def test_framing_keeps_a_corner_clear():
    pts = np.random.default_rng(2).uniform(-1, 1, (3000, 3)) * [4.0, 1.0, 0.2]
    d, upv = np.array([0, 0, 1.0]), np.array([0, 1.0, 0])
    box = (0, 0, 300, 400)
    cam, target = _scene.frame_camera(pts, 1200, 900, 45.0, d, upv, 0.86, keep_clear=[box])
    x, y = _project(pts, cam, target, upv, 1200, 900, 45.0)
    assert not np.any((x <= 300) & (y <= 400)) and x.max() < 1200


def _project(pts, cam, target, upv, W, H, fov):
    back = (cam - target) / np.linalg.norm(cam - target)
    right = np.cross(upv, back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    rel = pts - cam
    z = -(rel @ back)
    t = math.tan(math.radians(fov) / 2)
    return (0.5 + 0.5 * (rel @ right) / z / (t * W / H)) * W, (0.5 - 0.5 * (rel @ up) / z / t) * H


def test_view_options_are_checked():
    assert gsdf.ViewOptions(isolines=[0.1, 0.2]).isolines == (0.1, 0.2)
    for bad in (dict(level=float("nan")), dict(isolines=-1), dict(slice_axis="w"), dict(front="up"),
                dict(fill=0), dict(vrange=(1, 0))):
        with pytest.raises(ValueError):
            gsdf.ViewOptions(**bad)
    V, F = _sphere()
    with pytest.raises(ValueError, match="elevation"):
        gsdf.view((V, F), screenshot="x.png", elevation=95)
    with pytest.raises(ValueError, match="png"):
        gsdf.view((V, F), screenshot="x.jpg")
    with pytest.raises(ValueError, match="options"):
        gsdf.view((V, F), screenshot="x.png", options={"level": 0})


def test_view_is_the_function_of_the_render_package():
    """gsdf.view is the function; its package is gsdf.render, whatever is imported first."""
    code = ("import gsdf{first}; import gsdf; from gsdf.render import ViewOptions, view; "
            "print(gsdf.view is view, gsdf.ViewOptions is ViewOptions)")
    for first in ("", ".render._png", ".render"):
        out = subprocess.run([sys.executable, "-c", code.format(first=first)], capture_output=True, text=True,
                             env={**os.environ, "PYTHONPATH": SRC}, check=True).stdout
        assert out.split() == ["True", "True"], (first, out)


def test_without_polyscope_the_error_says_how_to_install():
    code = ("import sys; sys.modules['polyscope'] = None\n"
            "import numpy as np, gsdf\n"
            "V = np.eye(3); F = np.array([[0, 1, 2]])\n"
            "try:\n    gsdf.view((V, F), screenshot='never.png')\n"
            "except ImportError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=os.path.dirname(__file__),
                         env={**os.environ, "PYTHONPATH": SRC}, check=True).stdout
    assert "pip install 'gsdf[view]'" in out and "pip install -e '.[view]'" in out
    assert not os.path.exists(os.path.join(os.path.dirname(__file__), "never.png"))


def test_no_window_without_a_display(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if not sys.platform.startswith("linux"):
        pytest.skip("the display check is Linux's $DISPLAY / $WAYLAND_DISPLAY")
    V, F = _sphere()
    with pytest.raises(RuntimeError, match="no display.*screenshot="):
        gsdf.view((V, F))


def test_view_fill_takes_numpy_floats():
    opts = gsdf.ViewOptions(fill=np.float32(0.86), vrange=(np.float32(-1), 2))
    assert opts.fill == np.float32(0.86) and type(opts.fill) is float        # float32 made the framing float32
    assert opts.vrange == (-1.0, 2.0) and all(type(x) is float for x in opts.vrange)
    for bad in (1.5, 0.0, 1e-308, 0.009):                # a tiny fill made the framing loop forever
        with pytest.raises(ValueError, match=r"fill: expected a number in \[0.01, 1\]"):
            gsdf.ViewOptions(fill=bad)
    assert gsdf.ViewOptions(fill=0.01).fill == 0.01


@pytest.mark.parametrize("bad", [b"viridis", "", 3])
def test_colormap_must_be_a_name(bad):
    with pytest.raises(ValueError, match="colormap: expected the name of a polyscope colour map"):
        gsdf.ViewOptions(colormap=bad)
    assert gsdf.ViewOptions(colormap="turbo").colormap == "turbo"


@pytest.mark.parametrize("view, why", [("x", "string"), ([1j, 0, 0], "complex"), ([object()] * 3, "objects"),
                                       ([0, 0, 0], r"\[0, 0, 0\]"), ([1, 0], r"\[1, 0\]"), ([np.nan, 0, 1], "NaN")])
def test_save_png_checks_view_and_options_before_drawing(tmp_path, view, why):
    """A bad view direction leaked numpy's own errors (could not convert string to float, TypeError)."""
    V, F = _sphere()
    out = tmp_path / "p.png"
    with pytest.raises(ValueError, match=f"view: expected a nonzero direction.*{why}"):
        gsdf.save_png(out, (V, F), view=view, renderer="gsdf")
    with pytest.raises(ValueError, match="options: expected a gsdf.ViewOptions"):
        gsdf.save_png(out, (V, F), options={"fill": 0.5}, renderer="gsdf")
    assert not out.exists()


@pytest.mark.parametrize("kw, why", [(dict(isolines="x"), "isolines: expected a count"),
                                     (dict(isolines=[1j]), "isolines: expected a count"),
                                     (dict(vrange="ab"), "vrange: expected"), (dict(vrange=()), "vrange: expected"),
                                     (dict(vrange=("a", "b")), "vrange: expected"),
                                     (dict(front=b"x"), "front: expected an axis"), (dict(front=1), "front: expected")])
def test_view_options_refuse_what_numpy_would_choke_on(kw, why):
    with pytest.raises(ValueError, match=why):
        gsdf.ViewOptions(**kw)


@pytest.mark.parametrize("up", [b"x", 1, True, "w", [0, 0, 0], ["a", "b", "c"]])
def test_view_up_is_an_axis_name_or_a_vector(tmp_path, up):
    V, F = _sphere()
    with pytest.raises(ValueError, match="up: expected an axis"):
        gsdf.view((V, F), screenshot=str(tmp_path / "x.png"), up=up)
