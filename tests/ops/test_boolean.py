"""mesh_boolean on the cases trimming by vertex winding numbers got wrong: empty operands, coincident and coplanar
faces, holes cut in the middle of triangles; and the exact arrangement underneath."""

from __future__ import annotations

import numpy as np
import pytest

from gsdf.ops import mesh_boolean
from gsdf.ops._arrangement import arrange

BOX_F = np.array([[0, 2, 1], [0, 3, 2], [5, 0, 1], [5, 4, 0], [2, 6, 1], [3, 6, 2], [5, 1, 6], [5, 6, 4],
                  [0, 7, 3], [0, 4, 7], [3, 7, 6], [6, 7, 4]])


def box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    V = np.array([[lo[0], lo[1], lo[2]], [hi[0], lo[1], lo[2]], [hi[0], hi[1], lo[2]], [lo[0], hi[1], lo[2]],
                  [lo[0], lo[1], hi[2]], [hi[0], lo[1], hi[2]], [hi[0], hi[1], hi[2]], [lo[0], hi[1], hi[2]]])
    return V, BOX_F.copy()


def volume(V, F):
    t = V[F]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6)


def closed_euler(V, F):
    """(closed and every edge in exactly two faces, Euler characteristic over the used vertices)."""
    D = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    d = np.unique(D, axis=0, return_counts=True)[1]
    u = np.unique(np.sort(D, axis=1), axis=0, return_counts=True)[1]
    ok = bool((d == 1).all() and (u == 2).all())
    return ok, len(np.unique(F)) - len(u) + len(F)


def test_empty_operands():
    V, F = box([0, 0, 0], [1, 1, 1])
    E = (np.zeros((0, 3)), np.zeros((0, 3), int))
    for op, want in (("union", 1.0), ("difference", 1.0), ("intersection", 0.0)):
        Vo, Fo = mesh_boolean(V, F, *E, op)
        assert volume(Vo, Fo) == pytest.approx(want, abs=1e-15)
    assert mesh_boolean(*E, V, F, "difference")[1].shape == (0, 3)
    assert mesh_boolean(*E, *E, "union")[1].shape == (0, 3)


def test_union_with_nothing_resolves_a_self_intersecting_soup():
    """A ∪ ∅ is the boundary of A's own winding region: two overlapping boxes in one mesh become one closed
    genus-0 surface enclosing the union's volume."""
    V1, F1 = box([-0.5] * 3, [0.5] * 3)
    V2, F2 = box([0, -0.25, -0.25], [1, 0.25, 0.25])
    V, F = np.vstack([V1, V2]), np.vstack([F1, F2 + 8])
    Vo, Fo = mesh_boolean(V, F, np.zeros((0, 3)), np.zeros((0, 3), int), "union")
    ok, chi = closed_euler(Vo, Fo)
    assert ok and chi == 2
    assert volume(Vo, Fo) == pytest.approx(1 + 0.5 * 0.25, abs=1e-12)


@pytest.mark.parametrize("op", ["union", "intersection"])
def test_coincident_operands_give_the_operand_once(op):
    V, F = box([-0.5] * 3, [0.5] * 3)
    Vo, Fo = mesh_boolean(V, F, V, F, op)
    ok, chi = closed_euler(Vo, Fo)
    assert ok and chi == 2 and len(Fo) == 12
    assert volume(Vo, Fo) == pytest.approx(1.0, abs=1e-15)
    assert mesh_boolean(V, F, V, F, "difference")[1].shape == (0, 3)


def test_difference_cuts_a_hole_inside_faces_and_handles_a_coplanar_end():
    """libigl's MinusTest: the unit cube minus a bar through it whose end face lies on the cube's face x = 0
    (and whose sides cross the faces x = 0 and x = 1 inside their two triangles): a tunnel, genus 1."""
    A = box([0, 0, 0], [1, 1, 1])
    B = box([0, 0.375, 0.375], [2, 0.625, 0.625])
    V, F = mesh_boolean(*A, *B, "difference")
    ok, chi = closed_euler(V, F)
    assert ok and chi == 0
    assert volume(V, F) == pytest.approx(1 - 0.0625, abs=1e-15)
    V, F = mesh_boolean(*A, *B, "union")
    ok, chi = closed_euler(V, F)
    assert ok and chi == 2 and volume(V, F) == pytest.approx(1 + 0.0625, abs=1e-15)


def test_closed_inputs_give_closed_outputs_random_boxes():
    rng = np.random.default_rng(3)
    for _ in range(10):
        R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        A = box([0, 0, 0], [1, 1, 1])
        Vb, Fb = box([0, 0, 0], [1, 1, 1])
        Vb = (Vb - 0.5) @ R.T * 0.9 + 0.5 + rng.uniform(-0.5, 0.5, 3)
        if np.linalg.det(R) < 0:
            Fb = Fb[:, ::-1]
        vols = {}
        for op in ("union", "intersection", "difference"):
            V, F = mesh_boolean(*A, Vb, Fb, op)
            if len(F):
                D = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
                assert (np.unique(D, axis=0, return_counts=True)[1] == 1).all()  # closed, oriented
                assert (np.unique(np.sort(D, axis=1), axis=0, return_counts=True)[1] % 2 == 0).all()
            vols[op] = volume(V, F) if len(F) else 0.0
        assert vols["union"] == pytest.approx(1 + 0.729 - vols["intersection"], abs=1e-12)
        assert vols["difference"] == pytest.approx(1 - vols["intersection"], abs=1e-12)


def test_arrangement_shares_exact_intersection_points():
    """Two triangles crossing: both are cut along the same segment, whose endpoints are the same vertices in
    both (exact arithmetic), lying on both planes."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, -0.5], [0.3, 0.25, 0.5], [0.9, 0.1, 0.3]])
    F = np.array([[0, 1, 2], [3, 4, 5]])
    arr = arrange(V, F)
    assert set(arr.parent.tolist()) == {0, 1} and len(arr.F) > 2
    new = np.arange(len(V), len(arr.V))
    assert len(new) == 2
    np.testing.assert_allclose(arr.V[new, 2], 0, atol=1e-15)  # on the plane z = 0 of triangle 0
    for f in (0, 1):  # both endpoints are vertices of pieces of both triangles
        used = set(arr.F[arr.parent == f].ravel().tolist())
        assert set(new.tolist()) <= used
    # the pieces tile each triangle
    for f in (0, 1):
        a = np.linalg.norm(np.cross(*(arr.V[arr.F[arr.parent == f]][:, 1:] - arr.V[arr.F[arr.parent == f]][:, :1])
                                    .transpose(1, 0, 2)), axis=1).sum() / 2
        T = V[F[f]]
        assert a == pytest.approx(np.linalg.norm(np.cross(T[1] - T[0], T[2] - T[0])) / 2, rel=1e-12)


@pytest.mark.parametrize("s", [1e150, 1e-150])
def test_scaled_operands_give_the_scaled_result(s):
    A, B = box([0.0] * 3, [1.0] * 3), box([0.5] * 3, [1.5] * 3)
    V0, F0 = mesh_boolean(*A, *B, "union")
    Vs, Fs = mesh_boolean(A[0] * s, A[1], B[0] * s, B[1], "union")
    assert np.array_equal(Fs, F0)
    np.testing.assert_allclose(Vs / s, V0, rtol=1e-12, atol=0)
