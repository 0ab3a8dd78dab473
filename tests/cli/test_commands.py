import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from click.testing import CliRunner

import gsdf
from gsdf.cli.main import main

from tests.shapes import fibonacci_sphere, uv_sphere


@pytest.fixture
def files(tmp_path):
    V, F = uv_sphere(16, 32)
    mesh = str(tmp_path / "sphere.obj")
    gsdf.write_mesh(mesh, V, F)
    P = fibonacci_sphere(2000)
    cloud = str(tmp_path / "sphere.xyz")
    gsdf.write_points(cloud, P, P)
    bare = str(tmp_path / "bare.xyz")
    gsdf.write_points(bare, P)
    queries = str(tmp_path / "q.xyz")
    gsdf.write_points(queries, np.array([[0, 0, 0], [0.2, 0.1, 0], [3, 0, 0]]))
    return {"mesh": mesh, "cloud": cloud, "bare": bare, "queries": queries, "dir": tmp_path, "V": V, "F": F}


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def test_help_lists_subcommands_with_examples():
    r = run("--help")
    assert r.exit_code == 0
    for cmd in ("demo", "winding", "sdf", "voxelize", "surface", "boolean", "slice"):
        assert cmd in r.output
        sub = run(cmd, "--help")
        assert sub.exit_code == 0 and "Example" in sub.output


def test_winding_mesh_and_cloud(files):
    out = files["dir"] / "w.npy"
    r = run("winding", files["mesh"], files["queries"], "-o", out, "-q")
    assert r.exit_code == 0, r.output
    np.testing.assert_allclose(np.load(out), [1, 1, 0], atol=5e-3)
    out2 = files["dir"] / "w.txt"
    r = run("winding", files["cloud"], files["queries"], "-o", out2, "--exact")
    assert r.exit_code == 0, r.output
    np.testing.assert_allclose(np.loadtxt(out2), [1, 1, 0], atol=0.02)


def test_sdf_grid_png_and_surface(files):
    out = files["dir"] / "sdf.npz"
    png = files["dir"] / "slice.png"
    surf = files["dir"] / "zero.ply"
    r = run("sdf", files["mesh"], "-o", out, "--resolution", 24, "--png", png, "--mesh-output", surf, "-q")
    assert r.exit_code == 0, r.output
    field = gsdf.GridField.load(out)
    # the CLI's grid equals the library's signed distance at the nodes (and interpolates them exactly)
    X = field.grid_points()
    np.testing.assert_allclose(field.values.ravel(), gsdf.signed_distance(files["V"], files["F"], X), atol=1e-12)
    np.testing.assert_allclose(field(X), field.values.ravel(), atol=1e-12)
    # analytic check: |d| = | |x| - 1 | up to the polyhedral approximation of the sphere
    r = np.linalg.norm(X, axis=1)
    assert np.abs(field.values.ravel() - (r - 1))[r > 1.05].max() < 0.02
    from PIL import Image

    assert Image.open(png).size[0] >= 512
    Vs, Fs = gsdf.read_mesh(surf)
    assert np.abs(np.linalg.norm(Vs, axis=1) - 1).max() < 0.08


def test_voxelize_and_surface_of_cloud(files):
    out = files["dir"] / "vox.npz"
    r = run("voxelize", files["cloud"], "-o", out, "--resolution", 20, "--mesh-output", files["dir"] / "vox.obj", "-q")
    assert r.exit_code == 0, r.output
    with np.load(out) as d:
        occ = d["occupancy"]
    frac = occ.mean()
    assert 0.15 < frac < 0.6  # a unit ball in its bounding box padded by 0.1 of the diagonal: ~0.2
    surf = files["dir"] / "s.ply"
    r = run("surface", files["cloud"], "-o", surf, "--resolution", 32)
    assert r.exit_code == 0, r.output
    Vs, _ = gsdf.read_mesh(surf)
    assert np.abs(np.linalg.norm(Vs, axis=1) - 1).max() < 0.05


def test_boolean_and_slice(files):
    V, F = files["V"], files["F"]
    other = str(files["dir"] / "other.obj")
    gsdf.write_mesh(other, V + [0.8, 0, 0], F)
    out = files["dir"] / "diff.ply"
    r = run("boolean", files["mesh"], other, "--op", "difference", "-o", out)
    assert r.exit_code == 0, r.output
    Vd, Fd = gsdf.read_mesh(out)
    assert Vd[:, 0].max() < 1.0  # nothing of B beyond A's extent survives
    svg = files["dir"] / "s.svg"
    r = run("slice", files["mesh"], "-o", svg, "--heights", "0,0.5", "--resolution", 64)
    assert r.exit_code == 0, r.output
    paths = [e for e in ET.parse(svg).iter() if e.tag.endswith("path")]
    assert len(paths) == 2


def test_cli_errors_are_clean(files, tmp_path):
    r = CliRunner().invoke(main, ["winding", str(tmp_path / "missing.obj"), files["queries"], "-o", "x.npy"])
    assert r.exit_code == 1 and "missing.obj" in r.output
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n")
    r = CliRunner().invoke(main, ["sdf", str(bad), "-o", str(tmp_path / "o.npz")])
    assert r.exit_code == 1 and "bad.off" in r.output
    r = CliRunner().invoke(main, ["surface", files["bare"], "-o", str(tmp_path / "o.ply")])
    assert r.exit_code == 1 and "no normals" in r.output
    r = run("surface", files["bare"], "--estimate-normals", "-o", tmp_path / "o.ply", "--resolution", 24)
    assert r.exit_code == 0, r.output


def test_demo_runs_and_reports_outputs(tmp_path):
    out = tmp_path / "demo"
    r = run("demo", "-o", out, "--resolution", 24)
    assert r.exit_code == 0, r.output
    for name in ("soup_sdf.npz", "soup_sdf_slice.png", "soup_surface.ply", "cloud_surface.ply", "soup_slices.svg"):
        assert os.path.exists(out / name)
        assert name in r.output
    with np.load(out / "soup_winding_samples.npz") as d:
        assert np.mean((d["winding_fast"] > 0.5) == (d["winding_exact"] > 0.5)) > 0.99


def test_slice_svg_size_units_and_scale(files):
    """The viewBox spans the drawing; --units mm gives it --scale millimetres per model unit, --units model no
    physical size (a browser fits it to the window); auto picks mm only for a plausible print size."""
    svg = files["dir"] / "u.svg"

    def root(*args):
        r = run("slice", files["mesh"], "-o", svg, "--layers", 3, "--resolution", 48, "-q", *args)
        assert r.exit_code == 0, r.output
        return ET.parse(svg).getroot(), r.output

    el, out = root("--units", "mm", "--scale", 25.4)
    W, H = map(float, el.get("viewBox").split()[2:])
    assert 2.0 < W < 2.2 and 2.0 < H < 2.2                       # the unit sphere, 2 % margin
    assert float(el.get("width")[:-2]) == pytest.approx(25.4 * W)
    assert "mm (25.4 mm per model unit)" in out
    el, out = root("--units", "model")
    assert el.get("width") is None and el.get("height") is None and "no physical size" in out
    el, _ = root()                                                # auto: 2 mm would be dot-sized
    assert el.get("width") is None
    el, _ = root("--scale", 50)                                   # auto: 100 mm prints at true size
    assert el.get("width").endswith("mm")
    path = [e for e in el.iter() if e.tag.endswith("path")][0]
    assert path.get("vector-effect") == "non-scaling-stroke" and path.get("stroke") not in (None, "none")


def test_pseudonormal_sign_on_an_open_mesh_warns(files):
    V, F = files["V"], files["F"]
    open_F = F[V[F].mean(axis=1)[:, 2] < 0.8]
    with pytest.warns(UserWarning, match="open"):
        gsdf.signed_distance(V, open_F, [[0.0, 0.0, 0.0]], sign="pseudonormal")
    with pytest.warns(UserWarning, match="non-manifold"):
        gsdf.signed_distance_grid(V, np.vstack([F, F[:1]]), resolution=6, sign="pseudonormal")
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gsdf.signed_distance(V, F, [[0.0, 0.0, 0.0]], sign="pseudonormal")     # closed: no warning
    mesh = files["dir"] / "open.obj"
    gsdf.write_mesh(mesh, V, open_F)
    try:
        runner = CliRunner(mix_stderr=False)          # click < 8.2
    except TypeError:
        runner = CliRunner()                          # click >= 8.2: stderr apart by default
    r = runner.invoke(main, ["sdf", str(mesh), "-o", str(files["dir"] / "o.npz"), "--sign", "pseudonormal",
                             "--resolution", "8", "-q"])
    assert r.exit_code == 0, r.output
    assert r.stderr.count("gsdf: warning: sign='pseudonormal' on a mesh that is open") == 1
