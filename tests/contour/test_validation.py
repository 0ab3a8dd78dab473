"""Contouring entry points refuse values that are not real numbers (issue: complex values had their imaginary part
dropped, strings were parsed, NaN levels gave [] and a string level leaked numpy's UFuncTypeError)."""

import numpy as np
import pytest

import gsdf
from tests.shapes import uv_sphere

V, F = uv_sphere(6, 12)
T = np.eye(4, 3)


@pytest.mark.parametrize("f, why", [
    (V[:, 2] + 1j, "f: expected real numbers, got complex"),
    (V[:, 2].astype(str), "f: expected real numbers, got strings"),
    (V[:, 2:3], r"f: expected shape \(62,\), got \(62, 1\)"),
    (np.where(V[:, 2] > 0, np.nan, V[:, 2]), "f: contains NaN"),
])
def test_level_set_curves_values(f, why):
    with pytest.raises(ValueError, match=why):
        gsdf.level_set_curves(V, F, f)


@pytest.mark.parametrize("value, why", [(np.nan, "finite"), (np.inf, "finite"), ("a", "expected a real number"),
                                        (1j, "expected a real number"), ([0.5], "expected a real number")])
def test_level_set_curves_level(value, why):
    with pytest.raises(ValueError, match=f"value: .*{why}"):
        gsdf.level_set_curves(V, F, V[:, 2], value=value)


def test_level_set_curves_takes_lists():
    Vq = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    Fq = [[0, 1, 2], [0, 2, 3]]
    assert len(gsdf.level_set_curves(Vq, Fq, [0, 1, 1, 0], 0.5)) == 1
    assert len(gsdf.level_set_curves(tuple(map(tuple, Vq)), tuple(map(tuple, Fq)), (0, 1, 1, 0), 0.5)) == 1


def test_marching_tetrahedra_checks_its_arrays():
    tets = np.array([[0, 1, 2, 3]])
    assert len(gsdf.marching_tetrahedra(T, tets, [-1.0, 1, 1, 1])[1]) == 1
    for args, why in (((T, tets, np.array([-1, 1, 1, 1]) + 1j), "values: expected real numbers, got complex"),
                      ((T, tets, np.array(["a"] * 4)), "values: expected real numbers, got strings"),
                      ((T, [[0, 1, 2, 9]], [-1.0, 1, 1, 1]), "T: vertex index 9 out of range"),
                      ((T, tets, [-1.0, 1, 1]), r"values: expected shape \(4,\)")):
        with pytest.raises(ValueError, match=why):
            gsdf.marching_tetrahedra(*args)


@pytest.mark.parametrize("bad, why", [(lambda q: np.linalg.norm(q, axis=1) - 0.5 + 1j, "func: expected real values"),
                                      (lambda q: np.full(len(q), "x"), "func: expected real values, got strings")])
def test_contouring_functions_returning_non_real_values(bad, why):
    with pytest.raises(ValueError, match=why):
        gsdf.extract_isosurface(bad, [-1] * 3, [1] * 3, resolution=8, level=0)
    with pytest.raises(ValueError, match=why):
        gsdf.slice_contours(bad, [0.0], [-1] * 3, [1] * 3, resolution=8, level=0)


def test_region_boundary_curves_checks_its_arrays():
    from gsdf.contour._surface_curves import region_boundary_curves

    F = np.array([[0, 1, 2], [0, 2, 3]])
    assert [c.tolist() for c in region_boundary_curves(F, [1, 1])] == [[0, 1, 2, 3, 0]]
    with pytest.raises(ValueError, match="F: expected integer indices, got booleans"):
        region_boundary_curves(F.astype(bool), [True, True])
    with pytest.raises(ValueError, match="face_mask: expected booleans, got strings"):
        region_boundary_curves(F, np.array(["no", "no"]))
    with pytest.raises(ValueError, match="face_mask: expected booleans .or 0/1 values."):
        region_boundary_curves(F, [0.5, 1.0])
    with pytest.raises(ValueError, match=r"face_mask: expected 2 booleans \(shape \(2,\)\), got shape \(3,\)"):
        region_boundary_curves(F, [True, True, False])
    for bad in (F[:, :2], F[:, :1]):                       # edges are not faces (an empty answer before)
        with pytest.raises(ValueError, match="F: expected faces of at least 3 corners"):
            region_boundary_curves(bad, [True, True])
