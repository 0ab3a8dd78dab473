"""Tests for gsdf.io: mesh and point-cloud readers and writers."""

import os
import re

import numpy as np
import plyfile
import pytest

from gsdf.io import read_mesh, read_points, write_mesh, write_points

# ------------------------------------------------------------------------------------------
# geometry
# ------------------------------------------------------------------------------------------

TET_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])

# a unit square (quad) and a regular pentagon of circumradius 1, side by side in z = 0
_ang = np.pi / 2 + 2 * np.pi * np.arange(5) / 5
POLY_V = np.vstack([[[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
                    np.column_stack([3 + np.cos(_ang), np.sin(_ang), np.zeros(5)]),
                    [[0.0, 0, 1]]])
POLY_F = [np.array([0, 1, 2, 3]), np.array([4, 5, 6, 7, 8]), np.array([0, 1, 9])]
POLY_AREA = 1.0 + 2.5 * np.sin(2 * np.pi / 5) + 0.5


def area(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()


def write(path, text):
    path.write_text(text)
    return path


def errmsg(path):
    """Regex: a ValueError message starting with the path."""
    return "^" + re.escape(str(path))


# ------------------------------------------------------------------------------------------
# meshes: round trips
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply", ".OFF", ".Obj"])
def test_tet_round_trip_exact(tmp_path, ext):
    V = TET_V + np.array([0.1, 1 / 3, -2e-17])  # values that need full precision
    p = tmp_path / f"tet{ext}"
    write_mesh(p, V, TET_F)
    V2, F2 = read_mesh(p)
    assert V2.dtype == np.float64 and F2.dtype == np.int64
    np.testing.assert_array_equal(V2, V)
    np.testing.assert_array_equal(F2, TET_F)


def test_tet_round_trip_ascii_ply(tmp_path):
    p = tmp_path / "tet.ply"
    write_mesh(p, TET_V, TET_F, binary=False)
    assert p.read_bytes().startswith(b"ply\nformat ascii")
    V2, F2 = read_mesh(p)
    np.testing.assert_array_equal(V2, TET_V)
    np.testing.assert_array_equal(F2, TET_F)


def test_tet_round_trip_stl(tmp_path):
    p = tmp_path / "tet.stl"
    write_mesh(p, TET_V, TET_F)
    assert p.stat().st_size == 84 + 50 * 4  # binary STL
    V2, F2 = read_mesh(p)
    assert V2.shape == (4, 3)  # the 12 corners are merged back into 4 vertices
    np.testing.assert_array_equal(V2[F2], TET_V[TET_F])  # same triangles, in the same order


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply"])
def test_polygon_mesh_fan_triangulation(tmp_path, ext):
    p = tmp_path / f"poly{ext}"
    write_mesh(p, POLY_V, POLY_F)
    V, F = read_mesh(p)
    assert F.shape == (2 + 3 + 1, 3)
    np.testing.assert_array_equal(F[:2], [[0, 1, 2], [0, 2, 3]])  # fan from the first corner
    assert area(V, F) == pytest.approx(POLY_AREA)
    V, polys = read_mesh(p, triangulate=False)
    assert len(polys) == 3
    for a, b in zip(polys, POLY_F):
        assert a.dtype == np.int64
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("binary", [True, False])
def test_polygon_ply_is_readable_by_plyfile(tmp_path, binary):
    p = tmp_path / "poly.ply"
    write_mesh(p, POLY_V, POLY_F, binary=binary)
    ply = plyfile.PlyData.read(str(p))
    assert ply.text == (not binary)
    np.testing.assert_array_equal(np.column_stack([ply["vertex"][c] for c in "xyz"]), POLY_V)
    for a, b in zip(ply["face"]["vertex_indices"], POLY_F):
        np.testing.assert_array_equal(a, b)
    assert [len(q) for q in read_mesh(p, triangulate=False)[1]] == [4, 5, 3]


def test_polygon_mesh_stl_is_triangulated(tmp_path):
    p = tmp_path / "poly.stl"
    write_mesh(p, POLY_V, POLY_F)
    V, F = read_mesh(p)
    assert F.shape == (6, 3)
    assert area(V, F) == pytest.approx(POLY_AREA, rel=1e-6)


def test_write_mesh_accepts_quad_array(tmp_path):
    p = tmp_path / "quads.off"
    write_mesh(p, POLY_V[:4], np.array([[0, 1, 2, 3]]))
    assert read_mesh(p)[1].shape == (2, 3)


def test_degenerate_and_duplicate_faces_are_kept(tmp_path):
    F = np.vstack([TET_F, TET_F[:1], [[0, 0, 1]]])
    for ext in (".obj", ".off", ".ply"):
        write_mesh(tmp_path / f"m{ext}", TET_V, F)
        np.testing.assert_array_equal(read_mesh(tmp_path / f"m{ext}")[1], F)


# ------------------------------------------------------------------------------------------
# meshes: format details
# ------------------------------------------------------------------------------------------


def test_obj_slash_forms_and_negative_indices(tmp_path):
    p = write(tmp_path / "m.obj", """# comment
mtllib m.mtl
o thing
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0 0.5 0.5 0.5
vt 0 0
vn 0 0 1
g group
s off
usemtl mat
f 1/1/1 2/1/1 3/1/1
f 1//1 3//1 4//1
f -4/1 -2/1 -1/1
l 1 2
v 0 0 1
f -1 1 2 3
""")
    V, F = read_mesh(p)
    assert V.shape == (5, 3)
    np.testing.assert_array_equal(F, [[0, 1, 2], [0, 2, 3], [0, 2, 3], [4, 0, 1], [4, 1, 2]])
    _, polys = read_mesh(p, triangulate=False)
    assert [len(q) for q in polys] == [3, 3, 3, 4]


def test_off_comments_colours_and_header_variants(tmp_path):
    p = write(tmp_path / "m.off", """# leading comment
COFF
# counts follow

4 3 0
0 0 0 255 0 0 255   # coloured vertex
1 0 0 0 255 0 255
0 1 0 0 0 255 255
0 0 1 9 9 9 9

3 0 2 1   0.9 0.0 0.0#red
3 0 1 3 1 1 1
4 0 3 2 1
""")
    V, F = read_mesh(p)
    np.testing.assert_array_equal(V, TET_V)
    np.testing.assert_array_equal(F, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [0, 2, 1]])
    p = write(tmp_path / "inline.off", "OFF 4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n")
    assert read_mesh(p)[1].shape == (2, 3)
    p = write(tmp_path / "n.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n")
    V, F = read_mesh(p)
    np.testing.assert_array_equal(V, TET_V[:3])
    P, N = read_points(p)
    np.testing.assert_array_equal(N, [[0, 0, 1]] * 3)


def test_ascii_ply_with_extra_properties(tmp_path):
    p = write(tmp_path / "m.ply", """ply
format ascii 1.0
comment extra properties everywhere
element vertex 4
property float x
property float y
property float z
property uchar red
property float nx
property float ny
property float nz
element face 2
property uchar flags
property list uchar int vertex_indices
property float quality
element edge 1
property int vertex1
property int vertex2
end_header
0 0 0 1 0 0 1
1 0 0 2 0 0 1
0 1 0 3 0 0 1
0 0 1 4 0 0 1
7 3 0 1 2 0.5
7 4 0 1 3 2 0.5
0 1
""")
    V, F = read_mesh(p)
    np.testing.assert_array_equal(V, TET_V)
    np.testing.assert_array_equal(F, [[0, 1, 2], [0, 1, 3], [0, 3, 2]])
    P, N = read_points(p)
    np.testing.assert_array_equal(N, [[0, 0, 1]] * 4)


@pytest.mark.parametrize("order", ["<", ">"])
def test_binary_ply_written_by_plyfile(tmp_path, order):
    vert = np.array([tuple(v) for v in TET_V], dtype=[("x", "f4"), ("y", "f4"), ("z", "f4")])
    face = np.empty(3, dtype=[("vertex_indices", "O")])
    face["vertex_indices"] = [np.array([0, 2, 1]), np.array([0, 1, 3, 2]), np.array([1, 2, 3])]
    p = tmp_path / "m.ply"
    elements = [plyfile.PlyElement.describe(vert, "vertex"), plyfile.PlyElement.describe(face, "face")]
    plyfile.PlyData(elements, byte_order=order).write(str(p))
    V, F = read_mesh(p)
    np.testing.assert_array_equal(V, TET_V)
    np.testing.assert_array_equal(F, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_ply_vertex_data(tmp_path):
    d = np.array([0.5, -1.0, 1e300, 2.0])
    p = tmp_path / "m.ply"
    write_mesh(p, TET_V, TET_F, vertex_data={"distance": d, "winding": np.arange(4)})
    ply = plyfile.PlyData.read(str(p))
    assert ply.header.startswith("ply\nformat binary_little_endian")
    np.testing.assert_array_equal(ply["vertex"]["distance"], d)
    np.testing.assert_array_equal(ply["vertex"]["winding"], np.arange(4))
    np.testing.assert_array_equal(read_mesh(p)[1], TET_F)
    with pytest.raises(ValueError, match=errmsg(tmp_path / "m.obj") + ".*only PLY"):
        write_mesh(tmp_path / "m.obj", TET_V, TET_F, vertex_data={"distance": d})
    with pytest.raises(ValueError, match="shape"):
        write_mesh(p, TET_V, TET_F, vertex_data={"distance": d[:3]})
    with pytest.raises(ValueError, match="name"):
        write_mesh(p, TET_V, TET_F, vertex_data={"x": d})
    for bad, why in ((np.inf, "NaN or infinite"), (np.nan, "NaN or infinite"), (1j, "complex")):
        with pytest.raises(ValueError, match=why):  # refused, not written: a reader cannot tell them from data
            write_mesh(tmp_path / "bad.ply", TET_V, TET_F, vertex_data={"distance": d + bad})
    assert not (tmp_path / "bad.ply").exists()


def test_ascii_stl_merges_vertices(tmp_path):
    facets = "".join(
        "facet normal 0 0 0\n outer loop\n"
        + "".join(f"  vertex {x:g} {y:g} {z:g}\n" for x, y, z in TET_V[f])
        + " endloop\nendfacet\n"
        for f in TET_F
    )
    p = write(tmp_path / "tet.stl", f"solid tet\n{facets}endsolid tet\n")
    V, F = read_mesh(p)
    assert V.shape == (4, 3) and F.shape == (4, 3)
    np.testing.assert_array_equal(V[F], TET_V[TET_F])


# ------------------------------------------------------------------------------------------
# points
# ------------------------------------------------------------------------------------------

RNG = np.random.default_rng(0)
P0 = RNG.normal(size=(50, 3))
N0 = P0 / np.linalg.norm(P0, axis=1, keepdims=True)


@pytest.mark.parametrize("ext", [".xyz", ".pwn", ".ply", ".obj", ".pc", ".npy", ".npz", ".XYZ"])
@pytest.mark.parametrize("with_normals", [True, False])
def test_points_round_trip(tmp_path, ext, with_normals):
    p = tmp_path / f"pts{ext}"
    write_points(p, P0, N0 if with_normals else None)
    P, N = read_points(p)
    assert P.dtype == np.float64
    np.testing.assert_array_equal(P, P0)
    if with_normals:
        np.testing.assert_array_equal(N, N0)
    else:
        assert N is None


def test_points_ascii_ply(tmp_path):
    p = tmp_path / "pts.ply"
    write_points(p, P0, N0, binary=False)
    P, N = read_points(p)
    np.testing.assert_array_equal(P, P0)
    np.testing.assert_array_equal(N, N0)


def test_pwn_with_count_line_and_comments(tmp_path):
    p = write(tmp_path / "a.pwn", "3\n0 0 0 0 0 1\n\n1 0 0 0 0 1  # end\n0 1 0 0 0 1\n")
    P, N = read_points(p)
    np.testing.assert_array_equal(P, TET_V[:3])
    p = write(tmp_path / "b.pwn", "4\n0 0 0 0 0 1\n1 0 0 0 0 1\n")
    with pytest.raises(ValueError, match=errmsg(p) + ".*count 4"):
        read_points(p)


def test_obj_points_normals_only_when_counts_match(tmp_path):
    p = write(tmp_path / "a.obj", "v 0 0 0\nv 1 0 0\nvn 0 0 1\nf 1 2 1\n")
    P, N = read_points(p)
    assert P.shape == (2, 3) and N is None
    p = write(tmp_path / "a.pc", "v 0 0 0\nvn 0 0 1\nv 1 0 0\nvn 0 1 0\n")
    P, N = read_points(p)
    np.testing.assert_array_equal(N, [[0, 0, 1], [0, 1, 0]])


def test_npz_alternative_keys(tmp_path):
    p = tmp_path / "a.npz"
    np.savez(p, points=P0, normals=N0)
    P, N = read_points(p)
    np.testing.assert_array_equal(N, N0)


def test_point_cloud_files_read_as_points(tmp_path):
    p = write(tmp_path / "cloud.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n")
    np.testing.assert_array_equal(read_points(p)[0], TET_V[:3])
    with pytest.raises(ValueError, match=errmsg(p) + ": no faces; is this a point cloud\\? use read_points"):
        read_mesh(p)
    p = tmp_path / "cloud.ply"
    write_points(p, P0)
    with pytest.raises(ValueError, match=errmsg(p) + ": no faces"):
        read_mesh(p)
    p = write(tmp_path / "cloud.obj", "v 0 0 0\nv 1 0 0\n")
    with pytest.raises(ValueError, match=errmsg(p) + ": no faces"):
        read_mesh(p)


# ------------------------------------------------------------------------------------------
# errors
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("reader,ext", [(read_mesh, ".off"), (read_mesh, ".stl"), (read_points, ".xyz"),
                                        (read_points, ".npy"), (read_mesh, ".ply")])
def test_missing_file(tmp_path, reader, ext):
    p = tmp_path / f"missing{ext}"
    with pytest.raises(FileNotFoundError, match=re.escape(str(p))):
        reader(p)


def test_unsupported_extension(tmp_path):
    p = write(tmp_path / "m.vdb", "x")  # (was .vtk, which read_mesh now reads through meshio)
    with pytest.raises(ValueError, match=errmsg(p) + ".*unsupported.*'.vdb'.*\\.obj, \\.off, \\.ply, \\.stl"):
        read_mesh(p)
    with pytest.raises(ValueError, match=errmsg(p) + ".*supported: \\.xyz"):
        read_points(p)
    with pytest.raises(ValueError, match=errmsg(p)):
        write_mesh(p, TET_V, TET_F)
    with pytest.raises(ValueError, match=errmsg(tmp_path / "noext")):
        write_points(tmp_path / "noext", P0)


@pytest.mark.parametrize("reader,ext", [(read_mesh, ".off"), (read_mesh, ".obj"), (read_mesh, ".ply"),
                                        (read_mesh, ".stl"), (read_points, ".xyz"), (read_points, ".pwn"),
                                        (read_points, ".ply"), (read_points, ".npy")])
def test_empty_file(tmp_path, reader, ext):
    p = write(tmp_path / f"empty{ext}", "")
    with pytest.raises(ValueError, match=errmsg(p) + ".*empty"):
        reader(p)


def test_comment_only_file_is_empty(tmp_path):
    p = write(tmp_path / "c.xyz", "# nothing\n\n   \n")
    with pytest.raises(ValueError, match=errmsg(p) + ".*empty"):
        read_points(p)


MALFORMED = [
    ("bad.off", "OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "line 4: non-numeric value 'zero'"),
    ("bad.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "line 4: vertex: expected 3 values, got 2"),
    ("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "line 6: face announces 4 vertices"),
    ("bad.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "announces 3 vertices and 2 faces"),
    ("bad.off", "OFF\nthree 1 0\n", "line 2: expected the counts"),
    ("bad.obj", "v 0 0 0\nv 1 0\nf 1 2 1\n", "line 2: 'v' line: expected 3 values, got 2"),
    ("bad.obj", "v 0 0 0\nv 1 0 x\nf 1 2 1\n", "line 2: non-numeric value 'x'"),
    ("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 0\n", "line 3: face vertex index 0 is invalid"),
    ("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 a\n", "line 3: non-numeric value 'a'"),
    ("bad.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
     "end_header\n0 0 0\n1 0\n", "line 9: vertex: expected 3 values, got 2"),
    ("bad.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n\x00\x00", "malformed PLY"),
    ("bad.ply", "not a ply file\n", "not a PLY file"),
    ("bad.stl", "solid x\n facet normal 0 0 0\n  outer loop\n   vertex 0 0 zz\n   vertex 0 0 0\n   vertex 1 0 0\n",
     "line 4: non-numeric value 'zz'"),
    ("bad.stl", "solid x\n facet normal 0 0 0\n  outer loop\n   vertex 0 0 0\n", "not a multiple of 3"),
    ("bad.stl", "garbage that is no stl\n", "malformed STL"),
]


@pytest.mark.parametrize("name,text,message", MALFORMED)
def test_malformed_mesh_files(tmp_path, name, text, message):
    p = write(tmp_path / name, text)
    with pytest.raises(ValueError, match=errmsg(p) + ".*" + re.escape(message)):
        read_mesh(p)


@pytest.mark.parametrize("name,text,message", [
    ("a.xyz", "0 0 0\n1 0 0\n0 1 0 5\n", "line 3: expected 3 values like line 1, got 4"),
    ("a.xyz", "0 0 0 1\n", "line 1: expected 3 (x y z) or 6 (x y z nx ny nz) values, got 4"),
    ("a.xyz", "0 0 0\n\n1 0 zero\n", "line 3: non-numeric value 'zero'"),
    ("a.pwn", "0 0 0 0 0 1\n1 0 0 0 0\n", "line 2: expected 6 values like line 1, got 5"),
    ("a.pc", "v 0 0\n", "line 1: 'v' line: expected 3 values, got 2"),
])
def test_malformed_point_files(tmp_path, name, text, message):
    p = write(tmp_path / name, text)
    with pytest.raises(ValueError, match=errmsg(p) + ".*" + re.escape(message)):
        read_points(p)


@pytest.mark.parametrize("name,text,message", [
    ("r.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6: face vertex index 3 out of range for 3 vertices"),
    ("r.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
     "line 6: face vertex index -1 out of range for 3 vertices"),
    ("r.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n4 0 1 2 7\n", "line 7: face vertex index 7 out of range"),
    ("r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4: face vertex index 4 out of range for 3 vertices"),
    ("r.obj", "v 0 0 0\nf -2 1 1\nv 1 0 0\n", "line 2: face vertex index -2 out of range for 1 vertices"),
    ("r.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
     "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n",
     "face vertex index 5 out of range for 3 vertices"),
])
def test_face_index_out_of_range(tmp_path, name, text, message):
    p = write(tmp_path / name, text)
    with pytest.raises(ValueError, match=errmsg(p) + ".*" + re.escape(message)):
        read_mesh(p)


def test_binary_ply_index_out_of_range(tmp_path):
    p = tmp_path / "r.ply"
    write_mesh(p, TET_V, TET_F)
    ply = plyfile.PlyData.read(str(p), mmap=False)  # no memory map: the file is overwritten below
    ply["face"].data["vertex_indices"][0] = [0, 1, 9]
    ply.write(str(p))
    with pytest.raises(ValueError, match=errmsg(p) + ".*index 9 out of range for 4 vertices"):
        read_mesh(p)


@pytest.mark.parametrize("name,text", [
    ("n.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
    ("n.obj", "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n"),
    ("n.xyz", "0 0 0\n1 -inf 0\n"),
    ("n.pwn", "0 0 0 0 0 1\n1 0 0 0 nan 1\n"),
])
def test_nan_and_inf(tmp_path, name, text):
    p = write(tmp_path / name, text)
    reader = read_points if name.endswith(("xyz", "pwn")) else read_mesh
    with pytest.raises(ValueError, match=errmsg(p) + ".*NaN or infinite"):
        reader(p)


def test_nan_in_binary_formats(tmp_path):
    V = TET_V.copy()
    V[2, 1] = np.nan
    p = tmp_path / "n.npy"
    np.save(p, V)
    with pytest.raises(ValueError, match=errmsg(p) + ".*NaN or infinite"):
        read_points(p)
    p = tmp_path / "n.stl"
    write_mesh(tmp_path / "n.stl", TET_V, TET_F)
    data = bytearray(p.read_bytes())
    data[84 + 12:84 + 16] = np.array(np.nan, "<f4").tobytes()  # first corner of the first facet
    p.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=errmsg(p) + ".*NaN or infinite"):
        read_mesh(p)


@pytest.mark.parametrize("name,text", [
    ("z.off", "OFF\n0 0 0\n"),
    ("z.xyz", "0\n"),
    ("z.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
     "end_header\n"),
    ("z.obj", "vt 0 0\n"),
])
def test_zero_points(tmp_path, name, text):
    p = write(tmp_path / name, text)
    with pytest.raises(ValueError, match=errmsg(p) + ".*no points"):
        read_points(p)


def test_npz_without_known_keys(tmp_path):
    p = tmp_path / "a.npz"
    np.savez(p, a=P0, b=N0)
    with pytest.raises(ValueError, match=errmsg(p) + ".*'P'"):
        read_points(p)
    np.savez(p, N=N0)                                           # lone normals were read as the points
    with pytest.raises(ValueError, match=errmsg(p) + ".*'P'"):
        read_points(p)
    np.savez(p, P0)                                             # arr_0: the one array is the cloud
    np.testing.assert_array_equal(read_points(p)[0], P0)


def test_writer_argument_errors(tmp_path):
    with pytest.raises(ValueError, match="out of range"):
        write_mesh(tmp_path / "a.off", TET_V, TET_F + 1)
    with pytest.raises(ValueError, match="NaN"):
        write_points(tmp_path / "a.xyz", np.full((2, 3), np.nan))
    with pytest.raises(ValueError, match="rows"):
        write_points(tmp_path / "a.xyz", P0, N0[:3])
    with pytest.raises(ValueError, match="at least 3"):
        write_mesh(tmp_path / "a.off", TET_V, [[0, 1]])


# ------------------------------------------------------------------------------------------
# soups survive exactly; formats read through trimesh / meshio; malformed files of every kind
# ------------------------------------------------------------------------------------------

# a broken soup: a quad, a pentagon, a duplicated triangle, a degenerate triangle (repeated index), a zero-area
# sliver, and an unreferenced vertex (index 6)
SOUP_V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 1.5, 0], [0, 0, 1], [7, 7, 7], [2, 0, 0]])
SOUP_P = [np.array([0, 1, 2, 3]), np.array([1, 2, 4, 3, 0]), np.array([0, 1, 5]), np.array([0, 1, 5]),
          np.array([0, 0, 1]), np.array([0, 1, 7])]
SOUP_FAN = np.array([[0, 1, 2], [0, 2, 3], [1, 2, 4], [1, 4, 3], [1, 3, 0], [0, 1, 5], [0, 1, 5], [0, 0, 1],
                     [0, 1, 7]])


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply", ".vtk", ".vtu"])
def test_soup_round_trip_is_exact(tmp_path, ext):
    p = tmp_path / f"soup{ext}"
    write_mesh(p, SOUP_V, SOUP_P)
    V, polys = read_mesh(p, triangulate=False)
    np.testing.assert_array_equal(V, SOUP_V)  # unreferenced vertex kept, order kept
    assert [q.tolist() for q in polys] == [q.tolist() for q in SOUP_P]  # polygons stay polygons, in order
    V, F = read_mesh(p)
    np.testing.assert_array_equal(F, SOUP_FAN)  # fan triangulation; duplicates and degenerate faces kept


def test_vtk_vertex_data(tmp_path):
    import meshio

    write_mesh(tmp_path / "m.vtu", TET_V, TET_F, vertex_data={"d": TET_V[:, 1]})
    np.testing.assert_array_equal(meshio.read(tmp_path / "m.vtu").point_data["d"], TET_V[:, 1])
    with pytest.raises(ValueError, match="vertex_data"):
        write_mesh(tmp_path / "m.obj", TET_V, TET_F, vertex_data={"d": TET_V[:, 1]})


def test_glb_through_trimesh(tmp_path):
    import trimesh

    F = SOUP_FAN
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.Trimesh(SOUP_V, F, process=False), node_name="a", geom_name="a")
    shift = np.eye(4)
    shift[:3, 3] = [10, 0, 0]
    scene.add_geometry(trimesh.Trimesh(TET_V, TET_F, process=False), node_name="b", geom_name="b", transform=shift)
    p = tmp_path / "s.glb"
    scene.export(p)
    V, G = read_mesh(p)
    # GLB stores float32 positions; every vertex (also the unreferenced one) and every face comes back in order
    np.testing.assert_allclose(V, np.vstack([SOUP_V, TET_V + [10, 0, 0]]), rtol=0, atol=1e-6)
    np.testing.assert_array_equal(G, np.vstack([F, TET_F + len(SOUP_V)]))


def test_gmsh_and_medit_through_meshio(tmp_path):
    import meshio

    cells = [("triangle", np.array([[0, 1, 5], [0, 1, 5]])), ("quad", np.array([[0, 1, 2, 3]])),
             ("tetra", np.array([[0, 1, 2, 5]])), ("line", np.array([[0, 1]]))]
    for name, fmt in (("m.msh", "gmsh22"), ("m.mesh", "medit")):
        meshio.write(tmp_path / name, meshio.Mesh(SOUP_V, cells), file_format=fmt)
        V, polys = read_mesh(tmp_path / name, triangulate=False)
        np.testing.assert_allclose(V, SOUP_V)
        assert [q.tolist() for q in polys] == [[0, 1, 5], [0, 1, 5], [0, 1, 2, 3]]  # tetra and line ignored
    meshio.write(tmp_path / "vol.vtu", meshio.Mesh(SOUP_V, [("hexahedron", np.array([[0, 1, 2, 3, 4, 5, 0, 1]]))]))
    with pytest.raises(ValueError, match=errmsg(tmp_path / "vol.vtu") + ".*only volume cells \\(hexahedron\\)"):
        read_mesh(tmp_path / "vol.vtu")


def test_tets_only_give_their_boundary(tmp_path):
    """A volume mesh of tetrahedra only (.msh, .mesh, .vtu): its surface is the boundary of the tets, outward
    (libigl's readMESH test case: one tet, no triangle section)."""
    import meshio

    X = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [1, 0, 0], [1, 1, 1.0]])
    T = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])  # negative, then positive volume: both come out outward
    for name, fmt in (("t.msh", "gmsh22"), ("t.mesh", "medit"), ("t.vtu", None)):
        meshio.write(tmp_path / name, meshio.Mesh(X, [("tetra", T)]), file_format=fmt)
        V, F = read_mesh(tmp_path / name)
        np.testing.assert_allclose(V, X)
        assert F.shape == (6, 3)  # 8 tet faces, the shared one dropped
        vol = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6
        assert vol == pytest.approx(1 / 6 + 1 / 3)


def test_gmsh_element_data_meshio_cannot_attach_is_skipped(tmp_path):
    """Element data over the tets of a Gmsh file that also has triangles: meshio refuses the file ("Incompatible
    cell data"); read_mesh reads it without the data sections (libigl's readMSH test file is of this kind)."""
    X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    txt = ("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n"
           + "".join(f"{i + 1} {x} {y} {z}\n" for i, (x, y, z) in enumerate(X))
           + "$EndNodes\n$Elements\n2\n1 2 2 1 1 1 3 2\n2 4 2 2 2 1 2 3 4\n$EndElements\n"
           + '$ElementData\n1\n"c"\n1\n0.0\n3\n0\n1\n1\n2 0.5\n$EndElementData\n')
    p = write(tmp_path / "m.msh", txt)
    V, F = read_mesh(p)
    np.testing.assert_allclose(V, X)
    np.testing.assert_array_equal(F, [[0, 2, 1]])


GARBAGE = bytes(range(256)) * 4 + b"\xff\xfe\x00"


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply", ".stl", ".glb", ".gltf", ".vtk", ".vtu", ".msh", ".mesh"])
@pytest.mark.parametrize("kind", ["garbage", "truncated"])
def test_malformed_files_of_every_format(tmp_path, ext, kind):
    p = tmp_path / f"m{ext}"
    if kind == "garbage":
        p.write_bytes(GARBAGE)
    else:
        if ext in (".glb", ".gltf"):
            import trimesh

            trimesh.Trimesh(SOUP_V, SOUP_FAN, process=False).export(p)
        elif ext in (".msh", ".mesh"):
            import meshio

            meshio.write(p, meshio.Mesh(SOUP_V, [("triangle", SOUP_FAN)]), file_format="gmsh22" if ext == ".msh"
                         else "medit")
        else:
            write_mesh(p, SOUP_V, SOUP_FAN)
        data = p.read_bytes()
        p.write_bytes(data[: len(data) // 2 + 3])
    with pytest.raises(ValueError, match=errmsg(p)):
        read_mesh(p)


@pytest.mark.parametrize("binary", [True, False])
def test_negative_ply_counts(tmp_path, binary):
    fmt = "binary_little_endian" if binary else "ascii"
    p = tmp_path / "neg.ply"
    p.write_bytes(f"ply\nformat {fmt} 1.0\nelement vertex -3\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  .encode() + b"3 0 1 2\n")
    with pytest.raises(ValueError, match=errmsg(p) + ": line 3: negative element count -3"):
        read_mesh(p)
    with pytest.raises(ValueError, match=errmsg(p)):
        read_points(p)
    from gsdf.io import read_vertex_data                  # plyfile's "negative dimensions" leaked from here

    with pytest.raises(ValueError, match=errmsg(p) + ": line 3: negative element count -3"):
        read_vertex_data(p)


def test_bytes_after_the_binary_ply_elements_are_refused(tmp_path):
    """A byte inserted into the data shifts every value after it; only the length shows it."""
    from gsdf.io import read_vertex_data

    p = tmp_path / "c.ply"
    write_points(p, P0, N0)
    good = p.read_bytes()
    k = len(good) // 3
    p.write_bytes(good[:k] + b"\x00" + good[k:])
    for read in (read_points, read_vertex_data):
        with pytest.raises(ValueError, match=errmsg(p) + ": 1 bytes after the PLY elements"):
            read(p)
    p.write_bytes(good + b"\n")                                 # a final newline some writers add: fine
    np.testing.assert_array_equal(read_points(p)[0], P0)
    q = tmp_path / "m.ply"
    write_mesh(q, TET_V, TET_F)
    q.write_bytes(q.read_bytes() + b"\x07")
    with pytest.raises(ValueError, match="1 bytes after the PLY elements"):
        read_mesh(q)


def test_binary_curve_file(tmp_path):
    from gsdf.io._curves import read_curves

    p = tmp_path / "c.txt"
    p.write_bytes(b"signed_curve\nv 0\n" + GARBAGE)  # GARBAGE holds a newline (byte 10) before byte 0x80
    with pytest.raises(ValueError, match=errmsg(p) + ":4: not a text curve file"):
        read_curves(p)
    with pytest.raises(ValueError, match="is a directory"):
        read_curves(tmp_path)


def test_directory_as_mesh(tmp_path):
    d = tmp_path / "d.vtu"
    d.mkdir()
    with pytest.raises(ValueError, match="directory"):
        read_mesh(d)


@pytest.mark.parametrize("ext,binary", [(".ply", True), (".ply", False), (".vtk", True), (".vtu", True)])
def test_read_vertex_data(tmp_path, ext, binary):
    from gsdf.io import read_vertex_data

    d = {"distance": TET_V[:, 0] - 0.25, "flag": np.array([1, 0, 0, 1])}
    p = tmp_path / f"m{ext}"
    write_mesh(p, TET_V, TET_F, vertex_data=d, binary=binary)
    got = read_vertex_data(p)
    assert list(got) == ["distance", "flag"]
    np.testing.assert_array_equal(got["distance"], d["distance"])
    np.testing.assert_array_equal(got["flag"], [1.0, 0, 0, 1])
    np.testing.assert_array_equal(read_mesh(p)[0], TET_V)


def test_read_vertex_data_errors(tmp_path):
    from gsdf.io import read_vertex_data

    with pytest.raises(ValueError, match="supported"):
        read_vertex_data(tmp_path / "m.obj")
    with pytest.raises(FileNotFoundError):
        read_vertex_data(tmp_path / "missing.ply")
    (tmp_path / "g.ply").write_bytes(b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n")
    with pytest.raises(ValueError, match=errmsg(tmp_path / "g.ply")):
        read_vertex_data(tmp_path / "g.ply")
    (tmp_path / "g.vtu").write_bytes(GARBAGE)
    with pytest.raises(ValueError, match=errmsg(tmp_path / "g.vtu")):
        read_vertex_data(tmp_path / "g.vtu")
    p = tmp_path / "inf.ply"
    write_mesh(p, TET_V, TET_F, vertex_data={"d": np.arange(4.0) + 0.5}, binary=False)
    p.write_bytes(p.read_bytes().replace(b" 2.5\n", b" inf\n"))
    with pytest.raises(ValueError, match=errmsg(p) + ": vertex property 'd': contains NaN or infinite"):
        read_vertex_data(p)


def test_3mf_without_its_optional_packages_is_a_clear_error(tmp_path):
    pytest.importorskip("trimesh")
    try:
        import lxml  # noqa: F401

        pytest.skip("lxml is installed: 3MF is readable")
    except ImportError:
        pass
    p = tmp_path / "m.3mf"
    p.write_bytes(b"PK\x03\x04" + GARBAGE)
    with pytest.raises(ValueError, match=errmsg(p) + ".*lxml"):
        read_mesh(p)


def test_damaged_files_of_every_reader_give_value_errors(tmp_path):
    """Truncations, byte flips and inserted junk in valid files of every format, through every reader: each
    either reads (finite arrays) or raises a ValueError — never another exception (fixed seed, ~900 cases)."""
    import warnings

    import meshio
    import trimesh

    from gsdf.field import GridField, SurfaceField
    from gsdf.io import read_vertex_data
    from gsdf.io._curves import read_curves

    rng = np.random.default_rng(0)
    V = rng.normal(size=(30, 3))
    F = rng.integers(0, 30, (40, 3))
    readers = {}
    for e in (".obj", ".off", ".ply", ".stl", ".vtk", ".vtu"):
        write_mesh(tmp_path / f"m{e}", V, F)
        readers[f"m{e}"] = read_mesh
    write_mesh(tmp_path / "a.ply", V, [np.array([0, 1, 2, 3]), np.array([4, 5, 6])] * 3, binary=False)
    readers["a.ply"] = read_mesh
    trimesh.Trimesh(V, F, process=False).export(tmp_path / "m.glb")
    readers["m.glb"] = read_mesh
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        meshio.write(tmp_path / "m.msh", meshio.Mesh(V, [("triangle", F)]), file_format="gmsh22", binary=False)
    readers["m.msh"] = read_mesh
    for e in (".xyz", ".ply", ".obj", ".npy", ".npz", ".pc"):
        write_points(tmp_path / f"p{e}", V, V)
        readers[f"p{e}"] = read_points
    (tmp_path / "c.txt").write_text("signed_curve\nv 0\nv 1\nv 2\nunsigned_point\nf 0 0.2 0.3 0.5\n")
    readers["c.txt"] = lambda p: read_curves(p, F)
    write_mesh(tmp_path / "d.ply", V, F, vertex_data={"d": V[:, 0]})
    readers["d.ply"] = read_vertex_data
    GridField(rng.normal(size=(4, 4, 4)), [0, 0, 0], [1, 1, 1]).save(tmp_path / "g.npz")
    readers["g.npz"] = GridField.load
    SurfaceField(V, F, V[:, 0]).save(tmp_path / "s.npz")
    readers["s.npz"] = SurfaceField.load
    outcomes = {"ok": 0, "ValueError": 0}
    for name, reader in readers.items():
        data = (tmp_path / name).read_bytes()
        for trial in range(45):
            b = bytearray(data)
            if trial % 3 == 0:
                b = b[: rng.integers(0, len(b))]
            elif trial % 3 == 1:
                for _ in range(rng.integers(1, 8)):
                    b[rng.integers(0, len(b))] = rng.integers(0, 256)
            else:
                i = rng.integers(0, len(b))
                b = b[:i] + bytes(rng.integers(0, 256, rng.integers(1, 40)).astype(np.uint8)) + b[i:]
            p = tmp_path / f"damaged{os.path.splitext(name)[1]}"
            p.write_bytes(bytes(b))
            try:
                r = reader(p)
            except ValueError:
                outcomes["ValueError"] += 1
                continue
            parts = r if isinstance(r, tuple) else [r]
            arrays = [x for x in parts if isinstance(x, np.ndarray) and x.dtype.kind == "f"]
            assert all(np.isfinite(a).all() for a in arrays), (name, trial)
            outcomes["ok"] += 1
    assert outcomes["ValueError"] > 0.7 * sum(outcomes.values())


@pytest.mark.parametrize("byte_order", ["<", ">"])
@pytest.mark.parametrize("layout", ["plain", "scalars_around_the_list"])
def test_binary_ply_mixed_polygons_fast_path(tmp_path, byte_order, layout):
    """Mixed polygon sizes in binary PLY (the compiled face scan) equal what plyfile's row-by-row reader gives,
    whatever the count / index types, byte order and scalar properties around the list."""
    rng = np.random.default_rng(3)
    V = rng.normal(size=(50, 3))
    polys = [rng.integers(0, 50, k) for k in rng.integers(3, 9, 300)]
    vert = np.array([tuple(r) for r in V], dtype=[("x", "f4"), ("y", "f4"), ("z", "f4")])
    if layout == "plain":
        face = np.empty(len(polys), dtype=[("vertex_indices", "O")])
        face["vertex_indices"] = [q.astype(np.int32) for q in polys]
        lt = {"vertex_indices": ("u1", "i4")}
    else:
        face = np.empty(len(polys), dtype=[("flag", "u1"), ("vertex_index", "O"), ("q", "f8")])
        face["flag"] = 7
        face["vertex_index"] = [q.astype(np.uint32) for q in polys]
        face["q"] = 0.5
        lt = {"vertex_index": ("u2", "u4")}
    el_v = plyfile.PlyElement.describe(vert, "vertex")
    el_f = plyfile.PlyElement.describe(face, "face", len_types={k: v[0] for k, v in lt.items()},
                                       val_types={k: v[1] for k, v in lt.items()})
    p = tmp_path / "m.ply"
    plyfile.PlyData([el_v, el_f], text=False, byte_order=byte_order).write(str(p))
    V2, polys2 = read_mesh(p, triangulate=False)
    np.testing.assert_array_equal(V2, V.astype(np.float32).astype(np.float64))
    assert [q.tolist() for q in polys2] == [q.tolist() for q in polys]
    data = p.read_bytes()
    p.write_bytes(data[:-5])
    with pytest.raises(ValueError, match=errmsg(p) + ".*ends early"):
        read_mesh(p)


def test_off_faces_continuing_on_the_next_lines(tmp_path):
    """OFF face records whose indices continue on the following lines (libigl reads
    inspired_mesh_quads_Conjugate.off, written one index per line); a colour after the last index is skipped."""
    p = write(tmp_path / "w.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 \n1 \n3 \n2 \n3 0\n1 2 255 0 0\n")
    V, polys = read_mesh(p, triangulate=False)
    assert [q.tolist() for q in polys] == [[0, 1, 3, 2], [0, 1, 2]]
    p = write(tmp_path / "short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n")
    with pytest.raises(ValueError, match="line 6: face announces 4 vertices"):
        read_mesh(p)


@pytest.mark.parametrize("bad", ["yes", "no", 0, None, [1]])
def test_read_mesh_triangulate_is_a_switch(tmp_path, bad):
    p = tmp_path / "t.off"
    write_mesh(p, TET_V, TET_F)
    with pytest.raises(ValueError, match="triangulate: expected True or False"):
        read_mesh(p, triangulate=bad)


@pytest.mark.parametrize("kind", ["fifo", "dir", "dev"])
@pytest.mark.parametrize("ext", [".off", ".obj", ".ply", ".stl", ".xyz", ".npy"])
def test_readers_take_regular_files_only(tmp_path, kind, ext):
    """A FIFO blocked the reader forever, a link to /dev/zero read until memory ran out, a folder leaked
    IsADirectoryError."""
    import os

    from gsdf.io import read_points

    p = tmp_path / f"x{ext}"
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "dir":
        p.mkdir()
    elif os.path.exists("/dev/zero"):
        p.symlink_to("/dev/zero")
    else:
        pytest.skip("no /dev/zero")
    why = {"fifo": "is a FIFO", "dir": "is a directory", "dev": "is a device"}[kind]
    readers = ([read_points] if ext != ".stl" else []) + ([read_mesh] if ext not in (".xyz", ".npy") else [])
    for reader in readers:
        with pytest.raises(ValueError, match=why):
            reader(p)


def _npy_with_rows(path, rows: bytes):
    """An .npy of 4 points whose header's row count is replaced by ``rows``."""
    np.save(path, np.zeros((4, 3)))
    data = path.read_bytes()
    m = re.search(rb"'shape': \((\d+)", data[:256])
    path.write_bytes(data[:m.start(1)] + rows + data[m.end(1):])
    return path


@pytest.mark.parametrize("rows,words", [(b"999999999999", "declares shape (999999999999, 3)"),
                                        (b"-5", "negative size"), (b"5", "declares shape (5, 3)")])
def test_npy_header_checked_against_file_size(tmp_path, rows, words):
    """A header declaring more rows than the file holds (or a negative count) is refused before numpy allocates."""
    p = _npy_with_rows(tmp_path / "c.npy", rows)
    with pytest.raises(ValueError, match=errmsg(p)) as e:
        read_points(p)
    assert words in str(e.value) and "allocate" not in str(e.value)


def test_npz_member_header_checked(tmp_path):
    inner = _npy_with_rows(tmp_path / "P.npy", b"999999999999")
    import zipfile

    p = tmp_path / "c.npz"
    with zipfile.ZipFile(p, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(inner, "P.npy")
    with pytest.raises(ValueError, match=errmsg(p) + ".*array 'P'.*declares shape"):
        read_points(p)


def _vtk_bytes(tmp_path, ext):
    p = tmp_path / f"m{ext}"
    write_mesh(p, TET_V, TET_F)
    return p, p.read_bytes()


@pytest.mark.parametrize("ext,edit,words", [
    (".vtk", lambda b: b.replace(b"# vtk", b"#\xc4vtk", 1), "a byte that is not text (0xc4)"),
    (".vtk", lambda b: re.sub(rb"POINTS \d+", b"POINTS 999999999999", b, count=1), "POINTS 999999999999 declares"),
    (".vtu", lambda b: re.sub(rb'NumberOfPoints="\d+"', b'NumberOfPoints="-5"', b, count=1), "is negative"),
    (".vtu", lambda b: re.sub(rb'NumberOfPoints="\d+"', b'NumberOfPoints="999999999999"', b, count=1),
     "counts declare an array of shape (999999999999,3)"),
])
def test_vtk_malformed_messages_in_words(tmp_path, ext, edit, words):
    """Broken VTK/VTU files: a ValueError naming the file and the problem, without Python's or numpy's text."""
    p, data = _vtk_bytes(tmp_path, ext)
    p.write_bytes(edit(data))
    for reader in (read_mesh, lambda q: __import__("gsdf").read_vertex_data(q)):
        with pytest.raises(ValueError, match=errmsg(p)) as e:
            reader(p)
        msg = str(e.value)
        assert words in msg, msg
        assert not re.search(r"codec|Unable to allocate|cannot reshape|Error:", msg), msg


def test_reader_path_not_a_file_name():
    with pytest.raises(ValueError, match="path: expected a file name, got int"):
        read_points(3)
    with pytest.raises(ValueError, match="path: expected a file name, got int"):
        read_mesh(3)


@pytest.mark.parametrize("content,words", [(b"\x80\x03garbage" * 20, "not a numpy file"),
                                           (None, "holds Python objects")])
def test_numpy_files_that_are_not_numbers(tmp_path, content, words):
    p = tmp_path / "c.npy"
    if content is None:
        np.save(p, np.array([object(), None]), allow_pickle=True)
    else:
        p.write_bytes(content)
    with pytest.raises(ValueError, match=errmsg(p) + ".*" + words) as e:
        read_points(p)
    assert "allow_pickle" not in str(e.value)


def test_npy_with_a_byte_inserted_in_its_data(tmp_path):
    p = tmp_path / "c.npy"
    np.save(p, TET_V)
    data = p.read_bytes()
    k = len(data) - 40
    p.write_bytes(data[:k] + b"\x00" + data[k:])
    with pytest.raises(ValueError, match=errmsg(p) + ".*1 more bytes follow; the file is damaged"):
        read_points(p)


def test_ply_with_bom_in_words(tmp_path):
    import gsdf

    p = tmp_path / "c.ply"
    write_mesh(p, TET_V, TET_F, binary=False)
    p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())
    for reader in (read_points, read_mesh, gsdf.read_vertex_data):
        with pytest.raises(ValueError, match=errmsg(p)) as e:
            reader(p)
        assert "codec" not in str(e.value)
