"""gsdf.mesh_topology validates its mesh like every mesh entry point (issue: 17 of 20 bad inputs returned a dict;
faces with -1 gave genus 0)."""

import numpy as np
import pytest

import gsdf
from tests.shapes import uv_sphere

V, F = uv_sphere(6, 12)


@pytest.mark.parametrize("Vb, Fb, why", [
    (V, F - 1, "F: negative vertex index -1"),
    (V, F + 1000, "out of range"),
    (V, F + 0.5, "non-integral"),
    (V * np.nan, F, "V: contains NaN"),
    (V, F[:, :2], r"F: expected shape \(m, 3\)"),
    ([["a", "b", "c"]] * 3, [[0, 1, 2]], "V: expected numeric coordinates, got strings"),
    (V, "y", "F: expected an array of numbers, got a string"),
    (V, F * 1j, "F: expected integer indices, got complex"),
])
def test_mesh_topology_refuses_bad_meshes(Vb, Fb, why):
    with pytest.raises(ValueError, match=why):
        gsdf.mesh_topology(Vb, Fb)


def test_mesh_topology_answers():
    t = gsdf.mesh_topology(V, F)
    assert t["closed"] and t["oriented"] and t["genus"] == [0]
    assert gsdf.mesh_topology(V.tolist(), F.tolist())["genus"] == [0]  # lists are meshes too
    assert gsdf.mesh_topology(V, F[:0])["n_faces"] == 0  # no faces: an empty summary, not an error
