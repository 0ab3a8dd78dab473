"""mesh2sdf's use: ShapeNet models (its example is ``data/plane.obj``, an airplane) whose wings and tail are
single-layer sheets, made watertight with ``mesh2sdf.compute(V, F, size, fix=True, level=L)``: the sheets become
a shell of half-thickness L around the surface. gsdf does that only when asked: ``shell=2 L``.

Source (read, not copied): github.com/wang-ps/mesh2sdf (MIT), example/test.py. Geometry: a generated airplane of
the same kind (helpers.airplane: a closed fuselage and single-layer wings crossing it); mesh2sdf itself is not
run (no recorded output), the checks are the properties of its fixed field.
"""

from __future__ import annotations

import numpy as np
import pytest

import gsdf
from tests.conformance.helpers import airplane


@pytest.fixture(scope="module")
def plane():
    return airplane()


def test_sheets_have_no_inside_without_shell(plane):
    """The winding number of an open sheet is ±1/2 on its sides: a point 0.01 above or below a wing is outside
    (gsdf never thickens sheets silently); the closed fuselage's inside is inside."""
    V, F = plane
    s = gsdf.signed_distance(V, F, [[0.0, 0.8, 0.01], [0.0, 0.8, -0.01], [0.5, 0.0, 0.0]])
    assert s[0] > 0 and s[1] > 0 and s[2] < 0


def test_fix_level_is_shell(plane):
    """mesh2sdf.compute(..., size=64, fix=True, level=2/64) on vertices in [-1, 1]: a grid whose zero level set
    is watertight around every part — the wings a plate of thickness 2 level. signed_distance_grid(shell=2 L):
    negative within L of the wings, the fuselage inside, |S| - L away from the surface; the zero isosurface is
    a closed surface."""
    V, F = plane
    L = 2 / 64
    G = gsdf.signed_distance_grid(V, F, resolution=64, shell=2 * L)
    Q = np.array([[0.0, 0.8, 0.0], [0.0, -1.0, 0.5 * L], [0.5, 0.0, 0.0], [0.0, 0.8, 0.5]])
    S = gsdf.signed_distance(V, F, Q, shell=2 * L)
    assert S[0] == pytest.approx(-L) and S[1] < 0 and S[2] < 0 and S[3] == pytest.approx(0.5 - L)
    U, W = G.isosurface(0.0)
    assert gsdf.mesh_topology(U, W)["closed"]
    # the plate's volume: about the wing area times 2 L (plus the fuselage)
    vol = np.einsum("ij,ij->i", U[W[:, 0]], np.cross(U[W[:, 1]], U[W[:, 2]])).sum() / 6
    assert vol > 0.6 * 2.4 * 2 * L
