"""gsdf.read_curves / gsdf.write_curves refuse what the solver would refuse, with the file and line (issue: curve
files with out-of-range, negative or float indices read and written without complaint; NaN barycentrics)."""

import numpy as np
import pytest

import gsdf
from tests.shapes import uv_sphere

V, F = uv_sphere(6, 12)


@pytest.mark.parametrize("body, why", [
    ("signed_curve\nv 0\nv -5\n", "negative vertex index -5"),
    ("signed_curve\nv 0\nv 99999\n", f"vertex 99999 out of range for {len(V)} vertices"),
    ("signed_curve\nf 99999 0.3 0.3 0.4\nf 1 0.3 0.3 0.4\n", f"face 99999 out of range for {len(F)} faces"),
    ("signed_curve\nf 0 5 -4 0\nf 1 0.3 0.3 0.4\n", "are not in the face"),
    ("signed_curve\nf 0 nan 0.5 0.5\nf 1 0.3 0.3 0.4\n", "NaN or infinite"),
    ("signed_curve\nv 0\ne 0 7.5\n", r"edge parameter 7.5 outside \[0, 1\]"),
    ("signed_curve 7\nv 0\nv 1\n", "flip: expected 0 or 1"),
    ("signed_curve\nv 0\nv 1.5\n", "vertex index '1.5' is not an integer"),
    ("l 1 0\n", "OBJ line indices must be positive"),
])
def test_read_curves_refuses_bad_nodes_with_file_and_line(tmp_path, body, why):
    p = tmp_path / "c.txt"
    p.write_text(body)
    with pytest.raises(ValueError, match=why) as e:
        gsdf.read_curves(str(p), F=F)
    assert str(e.value).startswith(f"{p}:")


def test_read_curves_without_faces_checks_signs_only(tmp_path):
    p = tmp_path / "c.txt"
    p.write_text("signed_curve\nv 0\nv 99999\n")
    assert gsdf.read_curves(str(p)).curves[0].tolist() == [0, 99999]  # no mesh given: range unknown
    p.write_text("signed_curve\nv 0\nv -1\n")
    with pytest.raises(ValueError, match="negative vertex index"):
        gsdf.read_curves(str(p))


@pytest.mark.parametrize("curves, kw, why", [
    ([[0, -5, 2]], {}, "negative vertex index -5"),
    ([[0.7, 1.2, 2.9]], {}, "vertex indices must be integers"),
    ([np.array([0, np.nan, 2])], {}, "vertex indices must be integers"),
    ([[0, 1], [2, 3], [4, 5]], {"curve_signs": [True]}, "curve_signs: has 1 entries but there are 3 curves"),
    ([[True, False]], {}, "expected integer indices, got booleans"),
    ([[(0, [0.5, 0.5, np.nan]), (1, [1, 0, 0])]], {}, "not finite"),
    ([[(0, [2.0, -1.0, 0.0]), (1, [1, 0, 0])]], {}, "not those of a point in the face"),
])
def test_write_curves_refuses_what_read_curves_would(tmp_path, curves, kw, why):
    p = tmp_path / "c.txt"
    with pytest.raises(ValueError, match=why):
        gsdf.write_curves(str(p), curves, **kw)
    assert not p.exists()


def test_write_read_round_trip(tmp_path):
    p = tmp_path / "c.txt"
    pts = [(3, np.array([0.2, 0.3, 0.5])), 7]
    gsdf.write_curves(str(p), [[0, 1, 2, 0], [(0, [1, 0, 0]), (2, [0.25, 0.25, 0.5])]], [True, False], pts)
    src = gsdf.read_curves(str(p), F=F)
    assert src.curves[0].tolist() == [0, 1, 2, 0] and src.curve_signs == [True, False]
    assert src.curves[1][1][0] == 2 and np.allclose(src.curves[1][1][1], [0.25, 0.25, 0.5])
    assert src.points[0][0] == 3 and src.points[1] == 7
    gsdf.write_curves(str(p), [gsdf.Curve([[0, 1], [1, 2]])])  # an edge set: written as its polyline
    assert gsdf.read_curves(str(p)).curves[0].tolist() == [0, 1, 2]


def test_swn_curve_files_read_obj_polylines(tmp_path):
    """The documented OBJ `l` lines of the surface winding number curve files (a mesh + `l` in one OBJ too)."""
    from gsdf.io._swn_curves import read_swn_curves

    a, b, c = (int(x) + 1 for x in F[0])
    p = tmp_path / "loop.obj"
    p.write_text(f"l {a} {b} {c} {a}\n")
    assert len(read_swn_curves(str(p), F).segments) == 3
    m = tmp_path / "m.obj"
    gsdf.write_mesh(m, V, F)
    with open(m, "a") as fh:
        fh.write(f"l {a} {b} {c} {a}\n")
    assert len(read_swn_curves(str(m), F).segments) == 3


@pytest.mark.parametrize("F,why", [("abc", "F: expected an array of numbers, got a string"),
                                   ([[0, 1, -2]], "F: negative vertex index"),
                                   ([[0, 1, np.nan]], "F: face indices must be integers"),
                                   ([[0, 1j, 2]], "F: expected integer indices, got complex"),
                                   ([[0, 1]], r"F: expected shape \(m, 3\)")])
def test_read_curves_checks_faces(tmp_path, F, why):
    """``F`` goes through the one check of face indices, also when the file has vertex nodes only."""
    p = tmp_path / "c.txt"
    p.write_text("signed_curve\nv 0\nv 1\nv 2\n")
    with pytest.raises(ValueError, match=why):
        gsdf.read_curves(p, F)


def test_read_curves_path_not_a_file_name():
    with pytest.raises(ValueError, match="path: expected a file name, got 3"):
        gsdf.read_curves(3)
