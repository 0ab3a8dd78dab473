"""Curves through face interiors (curve-file 'f' nodes) are inserted by cutting the mesh, geometry unchanged
(gsdf.swn._insert.insert_curves): a loop through face points around a vertex of a flat grid bounds
exactly the polygon it draws."""

import numpy as np
import pytest

from gsdf.data._shapes import grid_mesh
from gsdf.io._swn_curves import SWNCurves, read_swn_curves
from gsdf.swn._solver import SurfaceWindingNumbers
from gsdf.swn._insert import insert_curves


def ring_nodes(V, F, v, bary_of):
    """Nodes of a loop around vertex v: a point inside each incident face (barycentric ``bary_of(face)``), and
    between consecutive faces their shared corner other than v (counter-clockwise). Returns (kinds, index,
    params, polygon points)."""
    fs = np.flatnonzero((F == v).any(1))
    ang = []
    C = V[F[fs]].mean(1) - V[v]
    ang = np.arctan2(C[:, 1], C[:, 0])
    fs = fs[np.argsort(ang)]
    kinds, index, params, poly = [], [], [], []
    for a, b in zip(fs, np.roll(fs, -1)):
        bc = np.asarray(bary_of(a), dtype=float)
        kinds.append("f")
        index.append(int(a))
        params.append(bc)
        poly.append(bc @ V[F[a]])
        shared = sorted(set(F[a]) & set(F[b]) - {v})
        assert len(shared) == 1
        kinds.append("v")
        index.append(shared[0])
        params.append(np.zeros(3))
        poly.append(V[shared[0]])
    return kinds, index, params, np.array(poly)


def shoelace(P):
    return 0.5 * abs(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1]))


@pytest.mark.parametrize("bary", [(1 / 3, 1 / 3, 1 / 3), (0.6, 0.3, 0.1)])
def test_loop_through_face_points_bounds_its_polygon(bary):
    V, F = grid_mesh(6)
    v = 24                                                      # an interior vertex (7 x 7 grid, centre)
    kinds, index, params, poly = ring_nodes(V, F, v, lambda f: bary)
    k = len(kinds)
    segs = np.array([(i, (i + 1) % k) for i in range(k)])
    c = SWNCurves(np.array(kinds), np.array(index), np.array(params), np.full((k, 2), -1), segs)
    V2, F2, S, parent = insert_curves(V, F, c)
    # geometry unchanged: the same total area, every new face inside its parent's plane (z = 0 here)
    area = lambda X, T: 0.5 * np.linalg.norm(np.cross(X[T[:, 1]] - X[T[:, 0]], X[T[:, 2]] - X[T[:, 0]]), axis=1)  # noqa: E731
    assert abs(area(V2, F2).sum() - area(V, F).sum()) < 1e-12
    assert np.allclose(np.bincount(parent, weights=area(V2, F2), minlength=len(F)), area(V, F))
    assert len(V2) == len(V) + k // 2                           # one new vertex per face point
    res = SurfaceWindingNumbers(V2, F2).solve([np.r_[S[:, 0], S[0, 0]]])
    W = res.face_labels
    a2 = area(V2, F2)
    inside = a2[W == W.max()].sum()
    assert W.max() - W.min() == 1
    assert abs(inside - shoelace(poly[:, :2])) < 1e-12


def test_face_points_from_a_curve_file(tmp_path):
    V, F = grid_mesh(6)
    kinds, index, params, poly = ring_nodes(V, F, 24, lambda f: (0.5, 0.25, 0.25))
    lines = ["#offset 0"]
    for kd, i, p in zip(kinds, index, params):
        lines.append(f"f {i} {p[0]} {p[1]} {p[2]}" if kd == "f" else f"v {i}")
    lines.append("l " + " ".join(str(i) for i in list(range(len(kinds))) + [0]))
    path = tmp_path / "ring.txt"
    path.write_text("\n".join(lines) + "\n")
    c = read_swn_curves(str(path), F)
    V2, F2, S, _ = insert_curves(V, F, c)
    res = SurfaceWindingNumbers(V2, F2).solve([np.r_[S[:, 0], S[0, 0]]])
    a2 = 0.5 * np.linalg.norm(np.cross(V2[F2[:, 1]] - V2[F2[:, 0]], V2[F2[:, 2]] - V2[F2[:, 0]]), axis=1)
    assert abs(a2[res.face_labels == res.face_labels.max()].sum() - shoelace(poly[:, :2])) < 1e-12


def test_face_points_on_a_side_or_corner_and_two_in_one_face():
    V, F = grid_mesh(2)
    f = 0
    a, b, c = F[f]
    # node 0 inside, node 1 on the side (b, c) (barycentric 0 at a), node 2 at corner a, node 3 inside too
    kinds = np.array(["f", "f", "f", "f"])
    params = np.array([[0.5, 0.3, 0.2], [0.0, 0.5, 0.5], [1.0, 0.0, 0.0], [0.2, 0.3, 0.5]])
    segs = np.array([[2, 0], [0, 3], [3, 1]])
    cur = SWNCurves(kinds, np.zeros(4, dtype=np.int64), params, np.full((4, 2), -1), segs)
    V2, F2, S, parent = insert_curves(V, F, cur)
    assert len(V2) == len(V) + 3                                # two interior points + one side point
    assert S[0, 0] == a and np.allclose(V2[S[-1, 1]], 0.5 * (V[b] + V[c]))
    assert np.allclose(V2[S[0, 1]], params[0] @ V[F[f]]) and np.allclose(V2[S[1, 1]], params[3] @ V[F[f]])
    # every segment is an edge of the cut mesh
    E = {tuple(sorted(e)) for t in F2 for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert all(tuple(sorted(s)) in E for s in S.tolist())


def test_face_points_bad_input():
    V, F = grid_mesh(4)
    one = lambda i, p: SWNCurves(np.array(["f", "v"]), np.array([i, 0]), np.array([p, [0, 0, 0]]),  # noqa: E731
                                 np.full((2, 2), -1), np.array([[0, 1]]))
    with pytest.raises(ValueError, match="out of range"):
        insert_curves(V, F, one(len(F), [0.3, 0.3, 0.4]))
    with pytest.raises(ValueError, match="barycentric"):
        insert_curves(V, F, one(3, [0.8, 0.8, -0.6]))
    with pytest.raises(ValueError, match="barycentric"):
        insert_curves(V, F, one(3, [np.nan, 0.5, 0.5]))
    far = int(np.argmax(np.linalg.norm(V[F].mean(1) - V[0], axis=1)))   # a face far from vertex 0
    with pytest.raises(ValueError, match="share no face"):
        insert_curves(V, F, one(far, [0.3, 0.3, 0.4]))


def test_signed_heat_curves_on_a_flat_disk_cut_and_solved():
    """The signed heat method's curve spelling works for surface winding numbers too: a level-set loop of a
    circle (a list of (face, barycentric) points from level_set_curves) is cut into the mesh and bounds the
    disk it draws (area against the circle's own polygon), and gsdf.Curve objects give the same chain as raw
    polylines."""
    from gsdf import Curve
    from gsdf.contour._surface_curves import level_set_curves
    from gsdf.swn._insert import insert_surface_points

    V, F = grid_mesh(20)
    V = V - V.mean(0)
    r = 0.3 * np.ptp(V[:, 0])
    f = np.linalg.norm(V[:, :2], axis=1) - r
    curves = level_set_curves(V, F, f)
    assert len(curves) == 1
    with pytest.raises(ValueError, match="insert_surface_points"):
        SurfaceWindingNumbers(V, F).solve(curves)
    V2, F2, S, parent = insert_surface_points(V, F, curves)
    res = SurfaceWindingNumbers(V2, F2).solve(list(S))
    area = lambda X, T: 0.5 * np.linalg.norm(np.cross(X[T[:, 1]] - X[T[:, 0]], X[T[:, 2]] - X[T[:, 0]]), axis=1)  # noqa: E731
    a2 = area(V2, F2)
    W = res.face_labels - res.face_labels.min()
    assert set(np.unique(W)) == {0, 1}
    P = np.array([b @ V[F[e]] for e, b in curves[0][:-1]])
    assert abs(a2[W == 1].sum() - shoelace(P)) < 1e-9 * a2.sum()
    # the inside is the side where f < 0 (level_set_curves puts {f < value} on the left)
    cen = V2[F2].mean(1)
    assert np.all(np.linalg.norm(cen[W == 1, :2], axis=1) < r + 1e-9)
    # gsdf.Curve spellings: a vertex polyline, its oriented edges, and surface points on vertices
    swn = SurfaceWindingNumbers(V, F)
    n = int(round(np.sqrt(len(V))))
    c0 = n // 2 * n + n // 2                                   # a centre vertex and a square loop around it
    loop = np.array([c0 - n - 1, c0 - n, c0 - n + 1, c0 + 1, c0 + n + 1, c0 + n, c0 + n - 1, c0 - 1, c0 - n - 1])
    g = swn.chain([loop])
    assert np.array_equal(swn.chain([Curve(loop)]), g)
    assert np.array_equal(swn.chain([Curve(np.c_[loop[:-1], loop[1:]])]), g)
    at_vertices = [(int(v), ()) for v in loop]
    assert np.array_equal(swn.chain([at_vertices]), g)
    with pytest.raises(ValueError, match="oriented"):
        swn.chain([Curve(loop, signed=False)])
    with pytest.raises(ValueError, match=r"curves\[0\]\[1\].*face index"):
        swn.chain([[(0, [1.0, 0.0, 0.0]), (10 ** 9, [1.0, 0.0, 0.0])]])
    with pytest.raises(ValueError, match="oriented"):
        insert_surface_points(V, F, [Curve(curves[0], signed=False)])
    with pytest.raises(ValueError, match="non-empty"):
        insert_surface_points(V, F, [])
