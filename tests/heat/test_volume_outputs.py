"""Field export, several offsets, morphology (§9.3.1) and the ``gsdf heat`` command."""

import numpy as np
import pytest
from click.testing import CliRunner

import gsdf
from gsdf.cli.heat import heat
from gsdf.field import GridField
from gsdf.heat.volume import signed_heat_volume
from gsdf.ops._morphology import dilate_erode, erode_dilate, offset_surface

from tests.shapes import uv_sphere


def _closed(F):
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    return bool(np.all(np.unique(E, axis=0, return_counts=True)[1] == 2))


@pytest.fixture(scope="module")
def two_spheres():
    V, F = uv_sphere(16, 32)
    V, F = np.vstack([V * 0.5 - [0.6, 0, 0], V * 0.5 + [0.6, 0, 0]]), np.vstack([F, F + len(V)])
    return V, F, signed_heat_volume(mesh=(V, F), resolution=36)


def test_closing_fills_gap_opening_keeps_parts(two_spheres):
    V, F, f = two_spheres
    assert f([[0, 0, 0]])[0] > 0.0  # the gap (0.2 wide) is outside
    Vc, Fc = dilate_erode(f, 0.15)
    assert _closed(Fc) and gsdf.winding_number(Vc, Fc, [[0, 0, 0]])[0] > 0.5
    Vo, Fo = erode_dilate(f, 0.15)
    w = gsdf.winding_number(Vo, Fo, [[0.6, 0, 0], [-0.6, 0, 0], [0, 0, 0]])
    assert w[0] > 0.5 and w[1] > 0.5 and w[2] < 0.5
    Vs, Fs = offset_surface(f, 0.05)
    assert _closed(Fs)
    with pytest.raises(ValueError, match="radius"):
        dilate_erode(f, -1)
    with pytest.raises(ValueError, match="GridField"):
        offset_surface(np.zeros(3), 0.1)


def test_several_offsets_and_exports(tmp_path, two_spheres):
    _, _, f = two_spheres
    surfs = f.isosurfaces([-0.1, 0.0, 0.1])
    assert len(surfs) == 3 and all(_closed(Fs) for _, Fs in surfs)
    f.save(tmp_path / "f.npz")
    g = GridField.load(tmp_path / "f.npz")
    np.testing.assert_array_equal(g.values, f.values)
    f.save(tmp_path / "f.vtk")
    import meshio

    m = meshio.read(tmp_path / "f.vtk")
    np.testing.assert_allclose(np.sort(np.asarray(m.point_data["values"]).ravel()), np.sort(f.values.ravel()))
    small = GridField(f.values[:6, :5, :4], f.bbox_min, f.bbox_min + f.spacing * [5, 4, 3])
    small.save(tmp_path / "f.vtu")
    m = meshio.read(tmp_path / "f.vtu")
    np.testing.assert_allclose(m.points, small.grid_points())
    np.testing.assert_allclose(m.point_data["values"], small.values.ravel())


def test_cli_heat(tmp_path):
    V, F = uv_sphere(12, 24)
    src = tmp_path / "s.obj"
    gsdf.write_mesh(str(src), V, F)
    out = tmp_path / "out" / "s.npz"
    r = CliRunner().invoke(heat, [str(src), "--resolution", "20", "--offsets", "0,0.05", "--relative", "-o", str(out), "-q"])
    assert r.exit_code == 0, r.output
    assert out.exists() and (tmp_path / "out" / "s_offset_0.05.ply").exists()
    f = GridField.load(out)
    assert f([[0, 0, 0]])[0] < -0.8
    r = CliRunner().invoke(heat, [str(src), "--resolution", "4000", "-o", str(out), "-q"])
    assert r.exit_code != 0 and ("absurd" in r.output or "allowed" in r.output)
    # --t-scale input: t from the mesh's own edge length, a different (shorter) diffusion time
    out2 = tmp_path / "s2.npz"
    r = CliRunner().invoke(heat, [str(src), "--resolution", "20", "--t-scale", "input", "-o", str(out2), "-q"])
    assert r.exit_code == 0, r.output
    f2 = GridField.load(out2)
    assert f2([[0, 0, 0]])[0] < -0.8
    assert not np.allclose(f2.values, f.values)
    r = CliRunner().invoke(heat, [str(src), "--t-scale", "mesh", "-o", str(out2), "-q"])
    assert r.exit_code != 0


def test_isosurface_close_caps_at_the_box():
    x = np.linspace(-1, 1, 21)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    f = GridField(np.sqrt((X - 0.8) ** 2 + Y ** 2 + Z ** 2) - 0.5, [-1] * 3, [1] * 3)  # cut by the box
    _, F_open = f.isosurface(0.0)
    assert not _closed(F_open)
    V, F = f.isosurface(0.0, close=True)
    assert _closed(F) and V.max() <= 1.0 + 1e-12
