"""The result protocol (gsdf.field), safe writers (gsdf.io._safe_write) and gsdf.signed_distance_grid."""

import base64
import os
import re
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

import gsdf
from gsdf.field import GridField, SurfaceField, TetField, load_field
from gsdf.io._safe_write import atomic_output, check_output_path

from tests.shapes import cube, uv_sphere


def _grid_field():
    x = np.linspace(-1, 1, 5)
    y = np.linspace(-1, 2, 7)
    z = np.linspace(0, 1, 4)
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    return GridField(X + 10 * Y + 100 * Z, [-1, -1, 0], [1, 2, 1])


# ------------------------------------------------------------------------------------------------ safe writes


def test_atomic_output_keeps_the_old_file_when_the_writer_fails(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_output(p) as tmp:
            open(tmp, "w").write("half")
            raise RuntimeError("boom")
    assert p.read_text() == "old" and os.listdir(tmp_path) == ["a.txt"]
    with atomic_output(p) as tmp:
        assert os.path.dirname(tmp) == str(tmp_path) and tmp.endswith(".txt") and tmp != str(p)
        open(tmp, "w").write("new")
    assert p.read_text() == "new" and os.listdir(tmp_path) == ["a.txt"]
    mask = os.umask(0)
    os.umask(mask)
    assert (os.stat(p).st_mode & 0o777) == 0o666 & ~mask


def test_check_output_path_refusals(tmp_path):
    src = tmp_path / "in.ply"
    src.write_text("x")
    with pytest.raises(ValueError, match="input"):
        check_output_path(src, inputs=[src])
    (tmp_path / "hard.ply").hardlink_to(src)
    with pytest.raises(ValueError, match="input"):
        check_output_path(tmp_path / "hard.ply", inputs=[src])
    (tmp_path / "soft.ply").symlink_to(src)
    with pytest.raises(ValueError, match="input"):
        check_output_path(tmp_path / "soft.ply", inputs=[str(src)])
    with pytest.raises(ValueError, match="already exists"):
        check_output_path(src, overwrite=False)
    assert check_output_path(src) == str(src)  # not an input, overwrite allowed
    with pytest.raises(ValueError, match="is not a folder"):
        check_output_path(src / "x.ply")
    with pytest.raises(ValueError, match="is a directory"):
        check_output_path(tmp_path)
    with pytest.raises(ValueError, match="does not exist"):
        check_output_path(tmp_path / "no" / "x.ply")
    assert check_output_path(tmp_path / "no" / "x.ply", make_parents=True)
    with pytest.raises(ValueError, match=r"supported extensions: \.a, \.b"):
        check_output_path(tmp_path / "x.c", extensions=(".a", ".b"))
    for bad in (None, True, 3, ""):
        with pytest.raises(ValueError):
            check_output_path(bad)


def test_library_writers_refuse_unknown_extensions_without_writing(tmp_path):
    V, F = cube()
    with pytest.raises(ValueError, match="supported"):
        gsdf.write_mesh(tmp_path / "m.vdb", V, F)
    with pytest.raises(ValueError, match="supported"):
        gsdf.write_points(tmp_path / "p.vdb", V)
    (tmp_path / "f").write_text("x")
    with pytest.raises(ValueError, match="not a folder"):
        gsdf.write_mesh(tmp_path / "f" / "x.ply", V, F)
    with pytest.raises(ValueError, match=r"\.png"):
        from gsdf.render._png import write_png

        write_png(tmp_path / "i.jpg", np.zeros((2, 2, 3), np.uint8))
    assert sorted(os.listdir(tmp_path)) == ["f"]


# ------------------------------------------------------------------------------------------------ field.save


@pytest.mark.parametrize("ext", [".vdb", ".txt", "", ".npz.bak"])
def test_save_refuses_other_extensions_and_never_renames(tmp_path, ext):
    f = _grid_field()
    with pytest.raises(ValueError, match=r"supported extensions: \.npz, \.npy, \.vtk, \.vti, \.vtu"):
        f.save(tmp_path / f"f{ext}")
    assert os.listdir(tmp_path) == []


def test_grid_field_save_every_format(tmp_path):
    f = _grid_field()
    f.save(tmp_path / "f.NPZ")  # extensions are case-insensitive and the name is kept as given
    assert os.listdir(tmp_path) == ["f.NPZ"]
    f.save(tmp_path / "f.npz")
    g = GridField.load(tmp_path / "f.npz")
    np.testing.assert_array_equal(g.values, f.values)
    np.testing.assert_array_equal(g.bbox_max, f.bbox_max)
    f.save(tmp_path / "f.npy")
    np.testing.assert_array_equal(np.load(tmp_path / "f.npy"), f.values)
    with pytest.raises(ValueError, match="not a gsdf grid field"):
        GridField.load(tmp_path / "f.npy")
    f.save(tmp_path / "f.vtu")
    m = meshio.read(tmp_path / "f.vtu")
    np.testing.assert_allclose(m.points, f.grid_points())
    np.testing.assert_allclose(m.point_data["values"], f.values.ravel())
    f.save(tmp_path / "f.vtk")
    m = meshio.read(tmp_path / "f.vtk")
    np.testing.assert_allclose(np.sort(np.ravel(m.point_data["values"])), np.sort(f.values.ravel()))
    # .vti: VTK XML ImageData; decode by the file format's rules (UInt64 byte count, then x-fastest doubles)
    f.save(tmp_path / "f.vti")
    root = ET.parse(tmp_path / "f.vti").getroot()
    img = root.find("ImageData")
    assert img.get("WholeExtent") == "0 4 0 6 0 3"
    np.testing.assert_allclose([float(t) for t in img.get("Origin").split()], [-1, -1, 0])
    np.testing.assert_allclose([float(t) for t in img.get("Spacing").split()], [0.5, 0.5, 1 / 3])
    raw = base64.b64decode(img.find("Piece/PointData/DataArray").text)
    n = int(np.frombuffer(raw[:8], "<u8")[0])
    vals = np.frombuffer(raw[8:8 + n], "<f8")
    i, j, k = 3, 5, 2
    assert vals[i + 5 * (j + 7 * k)] == f.values[i, j, k]
    assert f.values[i, j, k] == pytest.approx(0.5 + 10 * (-1 + 5 * 0.5) + 100 * (2 / 3), abs=1e-12)
    np.testing.assert_array_equal(vals, f.values.transpose(2, 1, 0).ravel())


def test_tet_field_formats(tmp_path):
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0], [1, 1, 1.0]])
    T = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
    f = TetField(V, T, V.sum(axis=1))
    with pytest.raises(ValueError, match=r"supported extensions: \.npz, \.npy, \.vtk, \.vtu"):
        f.save(tmp_path / "t.vti")
    for ext in (".vtk", ".vtu"):
        f.save(tmp_path / f"t{ext}")
        m = meshio.read(tmp_path / f"t{ext}")
        np.testing.assert_allclose(m.points, V)
        np.testing.assert_array_equal(m.cells_dict["tetra"], T)
        np.testing.assert_allclose(np.ravel(m.point_data["values"]), f.values)
    f.save(tmp_path / "t.npz")
    np.testing.assert_allclose(TetField.load(tmp_path / "t.npz").values, f.values)
    with pytest.raises(FileNotFoundError):
        TetField.load(tmp_path / "missing.npz")
    (tmp_path / "junk.npz").write_bytes(b"\x00garbage")
    with pytest.raises(ValueError, match="junk.npz"):
        TetField.load(tmp_path / "junk.npz")


# ------------------------------------------------------------------------------------------------ SurfaceField


def test_surface_field_isolines_on_a_sphere():
    V, F = uv_sphere(24, 48)
    f = SurfaceField(V, F, V[:, 2])
    lines = f.isolines(0.3)
    assert len(lines) == 1
    L = lines[0]
    np.testing.assert_array_equal(L[0], L[-1])  # closed
    np.testing.assert_allclose(L[:, 2], 0.3, atol=1e-12)  # z is linear along edges: crossings are exact
    assert len(L) - 1 == 96  # one crossing per edge between the two rings: 48 meridian edges, 48 diagonals
    r = np.linalg.norm(L[:, :2], axis=1)
    assert np.all(r <= np.sqrt(1 - 0.09) + 1e-12) and np.all(r > 0.9 * np.sqrt(1 - 0.09))
    # orientation: the region below the level (z < 0.3) is on the left seen from the outward normal
    d = np.diff(L, axis=0)
    m = 0.5 * (L[1:] + L[:-1])
    left = np.cross(m, d)
    assert np.all(left[:, 2] < 0)
    assert f.isolines(2.0) == []
    with pytest.raises(ValueError, match="isolines"):
        f.isosurface(0.0)


def test_surface_field_open_isoline_and_evaluation(tmp_path):
    n = 6
    x = np.linspace(0, 1, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.column_stack([X.ravel(), Y.ravel(), np.zeros(n * n)])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    f = SurfaceField(V, F, 2 * V[:, 0] + V[:, 1])  # linear: interpolation is exact
    Q = np.array([[0.3, 0.7, 0.0], [0.9, 0.1, 0.5], [2.0, 0.5, 0.0]])
    np.testing.assert_allclose(f(Q), [1.3, 1.9, 2.5])  # off the surface: at the closest surface point
    (L,) = f.isolines(1.0)
    np.testing.assert_allclose(2 * L[:, 0] + L[:, 1], 1.0, atol=1e-12)
    assert not np.allclose(L[0], L[-1])  # reaches the border: open
    np.testing.assert_allclose(f.at(np.array([0]), np.array([[1 / 3, 1 / 3, 1 / 3]])), f(V[F[[0]]].mean(axis=1)))
    f.save(tmp_path / "s.npz")
    np.testing.assert_array_equal(SurfaceField.load(tmp_path / "s.npz").values, f.values)
    f.save(tmp_path / "s.ply")
    import plyfile

    np.testing.assert_array_equal(plyfile.PlyData.read(str(tmp_path / "s.ply"))["vertex"]["values"], f.values)
    f.save(tmp_path / "s.vtu")
    np.testing.assert_allclose(meshio.read(tmp_path / "s.vtu").point_data["values"], f.values)
    with pytest.raises(ValueError, match="supported extensions"):
        f.save(tmp_path / "s.vti")
    with pytest.raises(ValueError, match="values"):
        SurfaceField(V, F, np.zeros(3))
    with pytest.raises(ValueError, match="values"):
        SurfaceField(V, F, np.full(len(V), np.nan))
    with pytest.raises(ValueError, match="face"):
        f.at(np.array([True]), np.ones((1, 3)) / 3)


# ------------------------------------------------------------------------------------------------ grid SDF


def _cube_sdf(Q, h=0.5):
    q = np.abs(Q) - h
    return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)


@pytest.mark.parametrize("sign", ["winding", "pseudonormal"])
def test_signed_distance_grid_matches_the_exact_cube_distance(sign):
    V, F = cube()
    S = gsdf.signed_distance_grid(V, F, resolution=11, sign=sign)
    assert isinstance(S, gsdf.GridField) and S.shape == (11, 11, 11)
    np.testing.assert_allclose(S.spacing, S.spacing[0])  # cubic cells
    Q = S.grid_points()
    np.testing.assert_allclose(S.values.ravel(), _cube_sdf(Q), atol=1e-12)
    np.testing.assert_allclose(S.values.ravel(), gsdf.signed_distance(V, F, Q, sign=sign), atol=1e-12)


@pytest.mark.parametrize("sign", ["winding", "pseudonormal"])
def test_signed_distance_grid_return_closest(sign):
    V, F = cube()
    S, I, C, N = gsdf.signed_distance_grid((V, F), resolution=gsdf.Grid.fit(([-1, -1, -1], [1, 1, 1]), 9),
                                           sign=sign, return_closest=True)
    assert S.shape == (9, 9, 9) and np.array_equal(S.bbox_min, [-1, -1, -1])
    Q = S.grid_points()
    assert I.shape == (len(Q),) and C.shape == N.shape == (len(Q), 3) and I.dtype == np.int64
    np.testing.assert_allclose(np.linalg.norm(Q - C, axis=1), np.abs(S.values.ravel()), atol=1e-12)
    # C lies on triangle I (distance from C to that single triangle is 0)
    for q in range(0, len(Q), 37):
        assert gsdf.unsigned_distance(V, F[I[q]:I[q] + 1], C[q:q + 1])[0] < 1e-12
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0)
    # where the closest point is inside a face, N is that face's outward normal: here the nodes straight
    # above the top face's interior
    top = (np.abs(Q[:, 0]) < 0.4) & (np.abs(Q[:, 1]) < 0.4) & (Q[:, 2] > 0.6)
    np.testing.assert_allclose(N[top], np.tile([0, 0, 1.0], (top.sum(), 1)), atol=1e-12)
    if sign == "pseudonormal":  # at the corner regions, the vertex pseudonormal points diagonally out
        corner = np.all(Q > 0.6, axis=1)
        np.testing.assert_allclose(N[corner], np.tile(np.ones(3) / np.sqrt(3), (corner.sum(), 1)), atol=1e-12)


def test_signed_distance_grid_points_and_bad_input():
    P = np.random.default_rng(1).normal(size=(400, 3))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    S, I, C, N = gsdf.signed_distance_grid(None, points=(P, P), resolution=8, return_closest=True)
    Q = S.grid_points()
    d_ref = np.min(np.linalg.norm(Q[:, None] - P[None], axis=2), axis=1)
    np.testing.assert_allclose(np.abs(S.values.ravel()), d_ref, atol=1e-12)
    np.testing.assert_array_equal(C, P[I])
    assert S([[0, 0, 0]])[0] < 0
    V, F = cube()
    for kw, msg in [(dict(resolution=1), "resolution"), (dict(resolution=True), "resolution"),
                    (dict(sign="bogus"), "sign"), (dict(return_closest="yes"), "return_closest"),
                    (dict(resolution=(8, 8, 8)), "resolution"), (dict(progress=1), "progress"),
                    (dict(points=(P, P)), "points")]:
        with pytest.raises(ValueError, match=msg):
            gsdf.signed_distance_grid(V, F, **kw)
    with pytest.raises(ValueError, match="pseudonormal"):
        gsdf.signed_distance_grid(None, points=(P, P), sign="pseudonormal")
    with pytest.raises(ValueError):
        gsdf.signed_distance_grid(V)


def _old_grid(X, resolution, pad):
    """The former node layout of signed_distance_grid (before gsdf.Grid), written out."""
    lo, hi = X.min(axis=0), X.max(axis=0)
    d = float(np.linalg.norm(hi - lo)) or 1.0
    lo, hi = lo - pad * d, hi + pad * d
    ext = hi - lo
    h = ext.max() / (resolution - 1)
    shape = tuple(int(max(2, np.ceil(e / h - 1e-9) + 1)) for e in ext)
    hi = lo + (np.array(shape) - 1) * h
    axes = [np.linspace(lo[k], hi[k], shape[k]) for k in range(3)]
    X3 = np.meshgrid(*axes, indexing="ij")
    return lo, hi, shape, np.column_stack([a.ravel() for a in X3])


@pytest.mark.parametrize("pad", [0.05, 0.1])
def test_signed_distance_grid_same_nodes_same_values_as_before(pad):
    """Grid.around reproduces the former box and nodes bit for bit, and the values there are the former
    computation's (exact distance signed by the fast winding number at 1/2), bit for bit."""
    from gsdf.distance import TriangleDistance
    from gsdf.winding import FastWindingNumber

    V, F = cube()
    V = V * [1.0, 0.7, 0.45] + [0.1, 0.2, 0.3]
    lo, hi, shape, Q = _old_grid(V, 13, pad)
    g = gsdf.Grid.around(V, 13, pad)
    assert g.shape == shape and np.array_equal(g.bbox_min, lo) and np.array_equal(g.bbox_max, hi)
    assert np.array_equal(g.points(), Q)
    d = TriangleDistance(V, F).query(Q)[0]
    old = np.where(FastWindingNumber(V, F, beta=2.0)(Q) > 0.5, -d, d)
    S = gsdf.signed_distance_grid(V, F, resolution=g)
    assert np.array_equal(S.values.ravel(), old)
    if pad == 0.1:  # the default box
        assert np.array_equal(gsdf.signed_distance_grid(V, F, resolution=13).values, S.values)


def test_signed_distance_grid_progress():
    V, F = cube()
    calls = []
    gsdf.signed_distance_grid(V, F, resolution=6, progress=lambda stage, f: calls.append((stage, f)))
    assert calls == [("winding numbers", 1.0)]


def test_load_field_dispatches_on_the_arrays(tmp_path):
    g = _grid_field()
    g.save(tmp_path / "g.npz")
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    TetField(V, [[0, 1, 2, 3]], V[:, 0]).save(tmp_path / "t.npz")
    SurfaceField(V, [[0, 1, 2], [0, 1, 3]], V[:, 1]).save(tmp_path / "s.npz")
    assert isinstance(gsdf.load_field(tmp_path / "g.npz"), GridField)
    assert isinstance(gsdf.load_field(tmp_path / "t.npz"), TetField)
    s = gsdf.load_field(tmp_path / "s.npz")
    assert isinstance(s, SurfaceField) and np.array_equal(s.values, V[:, 1])
    np.savez(tmp_path / "other.npz", a=1)
    with pytest.raises(ValueError, match="not a gsdf field"):
        gsdf.load_field(tmp_path / "other.npz")
    with pytest.raises(FileNotFoundError):
        gsdf.load_field(tmp_path / "missing.npz")


def test_load_field_reads_every_saved_form_back(tmp_path):
    """load_field(field.save(path)): the same values, box or mesh, for every form that stores the domain."""
    from scipy.spatial import Delaunay

    x = np.linspace(-1, 1, 5)
    X, Y, Z = np.meshgrid(x, np.linspace(0, 2, 6), np.linspace(-1, 0.5, 4), indexing="ij")
    g = GridField(X + 2 * Y + 3 * Z, [-1, 0, -1], [1, 2, 0.5])
    for ext in (".npz", ".vti", ".vtk", ".vtu"):
        h = gsdf.load_field(g.save(tmp_path / f"g{ext}") or tmp_path / f"g{ext}")
        assert isinstance(h, GridField), ext
        assert np.array_equal(h.values, g.values) and np.allclose(h.bbox_min, g.bbox_min, rtol=0, atol=1e-15)
        assert np.allclose(h.bbox_max, g.bbox_max, rtol=0, atol=1e-15), ext
    P = np.random.default_rng(0).random((40, 3))
    t = TetField(P, Delaunay(P).simplices, P[:, 1])
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    s = SurfaceField(V, [[0, 1, 2], [0, 1, 3]], V[:, 1] - 0.5)
    for f, exts in ((t, (".vtk", ".vtu")), (s, (".ply", ".vtk", ".vtu"))):
        for ext in exts:
            f.save(tmp_path / f"f{ext}")
            h = gsdf.load_field(tmp_path / f"f{ext}")
            assert type(h) is type(f) and np.array_equal(h.values, f.values), ext
            assert np.array_equal(h.vertices, f.vertices), ext
    g.save(tmp_path / "g.npy")
    with pytest.raises(ValueError, match="without their grid"):
        gsdf.load_field(tmp_path / "g.npy")
    (tmp_path / "bad.vti").write_text("<VTKFile><nothing/></VTKFile>")
    with pytest.raises(ValueError, match="bad.vti: not a VTK ImageData"):
        gsdf.load_field(tmp_path / "bad.vti")
    with pytest.raises(FileNotFoundError):
        gsdf.load_field(tmp_path / "missing.vti")


# ----------------------------------------------------------------- values are real numbers; saved fields checked


@pytest.mark.parametrize("bad, why", [(1j, "complex numbers"), ("a", "strings"), (True, "booleans")])
def test_field_values_must_be_real(bad, why):
    T = np.eye(4, 3)
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.]])
    cases = [lambda v: GridField(np.full((3, 3, 3), v), [0, 0, 0], [1, 1, 1]),
             lambda v: TetField(T, [[0, 1, 2, 3]], np.full(4, v)),
             lambda v: SurfaceField(V, [[0, 1, 2], [0, 2, 3]], np.full(4, v))]
    for make in cases:
        with pytest.raises(ValueError, match=f"values: expected real numbers, got {why}"):
            make(bad)


def test_tet_field_checks_its_tets():
    T = np.eye(4, 3)
    for tets, why in (([[0, 1, 2, 4]], "vertex index 4 out of range"), ([[0, 1, 2, -1]], "negative vertex index"),
                      ([[0, 1, 2]], r"expected shape \(m, 4\)"), ([[0, 1, 2, 3.5]], "integers")):
        with pytest.raises(ValueError, match=why):
            TetField(T, tets, np.zeros(4))


def test_tet_field_checks_its_delaunay_locator():
    from scipy.spatial import Delaunay

    P = np.vstack([np.eye(4, 3), [[1.0, 1.0, 1.0]]])
    D = Delaunay(P)
    f = TetField(P, D.simplices, P[:, 0], delaunay=D)
    assert f([[0.2, 0.2, 0.2]]) == pytest.approx([0.2])
    for bad in (float("nan"), 1j, object(), "delaunay"):
        with pytest.raises(ValueError, match="delaunay: expected a scipy.spatial.Delaunay"):
            TetField(P, D.simplices, P[:, 0], delaunay=bad)
    with pytest.raises(ValueError, match="are not the 1 tets"):
        TetField(P, D.simplices[:1], P[:, 0], delaunay=D)


def test_surface_field_takes_lists_and_empty_queries():
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    F = [[0, 1, 2], [0, 2, 3]]
    f = SurfaceField(V, F, [0, 1, 1, 0])
    assert len(f.isolines(0.5)) == 1
    assert f.at([0, 1], [[1, 0, 0], [0, 1, 0]]).tolist() == [0.0, 1.0]
    assert f.at([], []).shape == (0,)
    assert f([[0.5, 0.5, 0]]).shape == (1,) and f(np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError, match="face: expected a 1-d integer array"):
        f.at([0.5], [[1, 0, 0]])
    with pytest.raises(ValueError, match="bary: contains NaN"):
        f.at([0], [[np.nan, 0, 0]])
    with pytest.raises(ValueError, match="level: must be a finite number"):
        f.isolines(np.nan)


@pytest.mark.parametrize("tamper, why", [
    ({"values": lambda z: z["values"] + 1j}, "values: expected real numbers, got complex numbers"),
    ({"values": lambda z: z["values"].astype(str)}, "values: expected real numbers, got strings"),
    ({"kind": lambda z: np.array("bogus")}, "its 'kind' is 'bogus', expected 'grid'"),
    ({"kind": lambda z: np.array(5)}, "its 'kind' is 5, expected 'grid'"),
])
def test_load_field_refuses_tampered_files(tmp_path, tamper, why):
    p = tmp_path / "g.npz"
    GridField(np.zeros((3, 3, 3)), [0, 0, 0], [1, 1, 1]).save(p)
    z = dict(np.load(p))
    z.update({k: f(z) for k, f in tamper.items()})
    np.savez(tmp_path / "t.npz", **z)
    with pytest.raises(ValueError, match=why) as e:
        load_field(tmp_path / "t.npz")
    assert str(e.value).startswith(str(tmp_path / "t.npz"))


def test_load_field_of_a_folder_or_fifo(tmp_path):
    (tmp_path / "d.npz").mkdir()
    with pytest.raises(ValueError, match="is a directory"):
        load_field(tmp_path / "d.npz")
    os.mkfifo(tmp_path / "p.vti")
    with pytest.raises(ValueError, match="is a FIFO"):
        load_field(tmp_path / "p.vti")


def _vti_ascii(tmp_path, extent="0 1 0 1 0 1", spacing="1 1 1", data="0 1 2 3 4 5 6 7"):
    p = tmp_path / "g.vti"
    p.write_text(f'<VTKFile type="ImageData"><ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="{spacing}">'
                 f'<Piece Extent="{extent}"><PointData><DataArray type="Float64" Name="values" format="ascii">'
                 f'{data}</DataArray></PointData></Piece></ImageData></VTKFile>')
    return p


@pytest.mark.parametrize("kw,why", [({"data": "0 1 2 x7 4 5 6 7"}, "non-numeric value 'x7'"),
                                    ({"extent": "0 1 0 x 0 1"}, "WholeExtent: expected 6 numbers, got '0 1 0 x"),
                                    ({"extent": "0 1 0 1"}, "WholeExtent: expected 6 numbers, got 4"),
                                    ({"spacing": "1 1"}, "Spacing: expected 3 numbers, got 2")])
def test_vti_malformed_named_in_words(tmp_path, kw, why):
    """A broken .vti: a ValueError naming the file and the attribute or value, not Python's conversion text."""
    p = _vti_ascii(tmp_path, **kw)
    with pytest.raises(ValueError, match="^" + str(p) + ".*" + re.escape(why)) as e:
        load_field(p)
    assert "could not convert" not in str(e.value) and "invalid literal" not in str(e.value)
    assert load_field(_vti_ascii(tmp_path)).values.shape == (2, 2, 2)
