"""Isosurfaces with bisection (Barill et al. 2018, Fig. 9) and slicing for 3D printing (Fig. 3)."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from gsdf.contour import extract_isosurface, refine_on_edges, slice_contours, write_slices_svg, write_svg
from gsdf.grid import Grid

R0 = 0.61  # deliberately not on a grid node
BOX = ([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0])


def sigmoid_ball(r0=R0, center=(0.0, 0.0, 0.0), width=0.02):
    """Smooth indicator-like field: 1 inside, 0 outside, exactly 1/2 on the sphere |q - c| = r0."""
    c = np.asarray(center, float)

    def f(Q):
        return 1.0 / (1.0 + np.exp(-(r0 - np.linalg.norm(Q - c, axis=1)) / width))

    return f


def shell(r_in=0.3, r_out=R0):
    """Winding-number-like field of a hollow shell: ~1 between the spheres, ~0 elsewhere."""
    a, b = sigmoid_ball(r_out), sigmoid_ball(r_in)
    return lambda Q: a(Q) - b(Q)


def signed_area(P):
    x, y = P[:, 0], P[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def mesh_stats(V, F):
    E = np.sort(np.concatenate((F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]])), axis=1)
    Eu, counts = np.unique(E, axis=0, return_counts=True)
    chi = V.shape[0] - Eu.shape[0] + F.shape[0]
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    return chi, counts, vol


# ------------------------------------------------------------------------------ isosurface


def test_isosurface_bisection_beats_linear_interpolation():
    f = sigmoid_ball()
    V, F = extract_isosurface(f, *BOX, resolution=32, bisection_steps=10)
    V0, F0 = extract_isosurface(f, *BOX, resolution=32, bisection_steps=0)
    assert V.dtype == np.float64 and F.dtype == np.int64
    err = np.abs(np.linalg.norm(V, axis=1) - R0)
    err0 = np.abs(np.linalg.norm(V0, axis=1) - R0)
    assert err.max() < 1e-4
    assert err0.max() > 1e-3 and err0.max() > 100 * err.max()
    assert np.array_equal(F, F0)  # bisection only moves vertices


def test_isosurface_closed_sphere_outward():
    V, F = extract_isosurface(sigmoid_ball(center=(0.1, -0.05, 0.02)), *BOX, resolution=32)
    chi, counts, vol = mesh_stats(V, F)
    assert chi == 2
    assert np.all(counts == 2)  # closed: every edge in exactly two faces
    assert vol == pytest.approx(4.0 / 3.0 * np.pi * R0**3, rel=2e-2)  # positive: outward normals


def test_isosurface_signed_distance_inside_below(monkeypatch):
    import gsdf.contour._isosurface as iso

    sdf = lambda Q: np.linalg.norm(Q, axis=1) - 0.5  # noqa: E731
    V, F = extract_isosurface(sdf, [-1, -1, -1], [1, 1, 1.2], resolution=24, level=0.0, inside="below")
    chi, counts, vol = mesh_stats(V, F)
    assert chi == 2 and np.all(counts == 2) and vol > 0
    assert np.abs(np.linalg.norm(V, axis=1) - 0.5).max() < 1e-6
    calls = []
    monkeypatch.setattr(iso, "CHUNK", 1000)
    V2, F2 = extract_isosurface(lambda Q: calls.append(len(Q)) or sdf(Q), [-1, -1, -1], [1, 1, 1.2],
                                resolution=24, level=0.0, inside="below")
    assert max(calls) == 1000 and np.array_equal(V, V2) and np.array_equal(F, F2)  # chunking changes nothing


def test_isosurface_grid_rule_and_same_nodes_same_mesh():
    """The grid is Grid.fit of the box (cubic cells, upper corner up to the last node); given as a Grid, the
    nodes the former rule used (np.linspace of the exact box) give the former mesh bit for bit."""
    f = sigmoid_ball(center=(0.1, -0.05, 0.02))
    lo, hi = np.array([-1.0, -1.0, -0.9]), np.array([1.0, 1.0, 1.0])
    g = Grid.fit((lo, hi), 24)
    assert g.shape == (24, 24, 23) and np.allclose(g.spacing, 2 / 23)
    assert np.array_equal(extract_isosurface(f, lo, hi, 24)[0], extract_isosurface(f, resolution=g)[0])
    # the former rule kept the box exactly: nodes np.linspace(lo, hi, n) with the same node counts
    old = Grid((lo, hi), g.shape)
    V, F = extract_isosurface(f, resolution=old)
    axes = [np.linspace(lo[d], hi[d], g.shape[d]) for d in range(3)]
    assert all(np.array_equal(a, b) for a, b in zip(old.axes(), axes))
    chi, counts, vol = mesh_stats(V, F)
    assert chi == 2 and np.all(counts == 2)
    with pytest.raises(ValueError, match="omit"):
        extract_isosurface(f, lo, hi, resolution=g)
    with pytest.raises(ValueError, match="box"):
        extract_isosurface(f, resolution=24)


def test_refine_on_edges():
    f = lambda Q: Q[:, 0] ** 3 + 0.0 * Q[:, 1]  # noqa: E731
    A = np.array([[0.0, 0, 0], [1.0, 5, 0]])
    B = np.array([[1.0, 0, 0], [0.0, 5, 0]])  # second segment reversed
    X = refine_on_edges(f, A, B, f(A), f(B), level=0.125, steps=40)
    assert np.allclose(X[:, 0], 0.5, atol=1e-12) and np.allclose(X[:, 1], [0, 5])
    # steps=0: linear interpolation
    X0 = refine_on_edges(f, A, B, f(A), f(B), level=0.125, steps=0)
    assert np.allclose(X0[:, 0], [0.125, 0.125])
    assert refine_on_edges(f, np.zeros((0, 3)), np.zeros((0, 3)), [], [], 0.5, 5).shape == (0, 3)
    with pytest.raises(ValueError, match="straddle"):
        refine_on_edges(f, A, B, [0.2, 0.2], [0.3, 0.3], level=0.125)
    with pytest.raises(ValueError, match="fa"):
        refine_on_edges(f, A, B, [0.0], [1.0, 0.0], level=0.125)


def test_isosurface_bad_input():
    f = sigmoid_ball()
    with pytest.raises(ValueError, match="resolution"):
        extract_isosurface(f, *BOX, resolution=1)
    with pytest.raises(ValueError, match="not crossed"):
        extract_isosurface(f, *BOX, resolution=8, level=2.0)
    with pytest.raises(ValueError, match="shape"):
        extract_isosurface(lambda Q: f(Q)[:, None], *BOX, resolution=8)
    with pytest.raises(ValueError, match="shape"):
        extract_isosurface(lambda Q: f(Q)[:-1], *BOX, resolution=8)
    with pytest.raises(ValueError, match="NaN"):
        extract_isosurface(lambda Q: np.where(Q[:, 0] > 0.5, np.nan, f(Q)), *BOX, resolution=8)
    with pytest.raises(ValueError, match="callable"):
        extract_isosurface("not a function", *BOX)
    with pytest.raises(ValueError, match="bbox_max"):
        extract_isosurface(f, [0, 0, 0], [1, 0, 1])
    with pytest.raises(ValueError, match="bisection_steps"):
        extract_isosurface(f, *BOX, bisection_steps=-1)
    with pytest.raises(ValueError, match="inside"):
        extract_isosurface(f, *BOX, inside="left")


# ------------------------------------------------------------------------------ slicing


def test_slice_sphere_equator():
    f = sigmoid_ball()
    (C,) = slice_contours(f, [0.0], *BOX, resolution=32)
    assert len(C) == 1
    P = C[0]
    assert P.ndim == 2 and P.shape[1] == 2 and P.shape[0] > 20
    assert not np.allclose(P[0], P[-1])  # closed, last vertex not repeated
    err = np.abs(np.linalg.norm(P, axis=1) - R0).max()
    assert err < 1e-4
    assert signed_area(P) == pytest.approx(np.pi * R0**2, rel=2e-2) and signed_area(P) > 0  # CCW



def test_slice_bisection_beats_linear_interpolation(monkeypatch):
    import gsdf.contour._slicing as sl

    f = sigmoid_ball()
    (C,) = slice_contours(f, [0.0], *BOX, resolution=32)
    err = np.abs(np.linalg.norm(C[0], axis=1) - R0).max()
    monkeypatch.setattr(sl, "BISECTION_STEPS", 0)
    (C0,) = slice_contours(f, 0.0, *BOX, resolution=32)
    err0 = np.abs(np.linalg.norm(C0[0], axis=1) - R0).max()
    assert err0 > 1e-3 and err0 > 100 * err


def test_slice_on_a_grid():
    f = sigmoid_ball()
    g = Grid.fit(BOX, 32)
    (C,) = slice_contours(f, [0.0], *BOX, resolution=32)
    (Cg,) = slice_contours(f, [0.0], resolution=g)
    assert len(C) == len(Cg) == 1 and np.array_equal(C[0], Cg[0])


def test_slice_heights_and_empty_slices():
    f = sigmoid_ball()
    z = np.array([-0.8, -0.4, 0.0, 0.3, 0.9])
    S = slice_contours(f, z, *BOX, resolution=48)
    assert [len(s) for s in S] == [0, 1, 1, 1, 0]
    for zz, s in zip(z, S):
        for P in s:
            assert np.abs(np.linalg.norm(P, axis=1) - np.sqrt(R0**2 - zz**2)).max() < 1e-4


def test_slice_hollow_shell_orientation():
    (C,) = slice_contours(shell(), [0.1], *BOX, resolution=64)
    assert len(C) == 2
    radii = [np.linalg.norm(P, axis=1).mean() for P in C]
    outer, inner = (C[0], C[1]) if radii[0] > radii[1] else (C[1], C[0])
    assert signed_area(outer) > 0  # counter-clockwise
    assert signed_area(inner) < 0  # clockwise
    assert np.abs(np.linalg.norm(outer, axis=1) - np.sqrt(R0**2 - 0.01)).max() < 1e-4
    assert np.abs(np.linalg.norm(inner, axis=1) - np.sqrt(0.09 - 0.01)).max() < 1e-4


def test_slice_other_axes():
    c = np.array([0.3, 0.1, -0.2])
    f = sigmoid_ball(0.4, center=c)
    # axis=1: plane coordinates are (z, x)
    (C,) = slice_contours(f, [c[1]], *BOX, resolution=40, axis=1)
    assert len(C) == 1 and signed_area(C[0]) > 0
    assert np.abs(np.linalg.norm(C[0] - c[[2, 0]], axis=1) - 0.4).max() < 1e-4
    # axis=0: plane coordinates are (y, z)
    (C,) = slice_contours(f, c[0], *BOX, resolution=40, axis=0)
    assert np.abs(np.linalg.norm(C[0] - c[[1, 2]], axis=1) - 0.4).max() < 1e-4


def test_slice_cut_by_box_closes():
    f = sigmoid_ball(1.2)  # bigger than the box: the cross-section is cut by the box
    (C,) = slice_contours(f, [0.0], *BOX, resolution=32)
    assert len(C) == 1
    P = C[0]
    assert np.all(np.abs(P) <= 1.0 + 1e-12)
    # disk of radius 1.2 intersected with the square [-1, 1]^2
    x = np.linspace(-1.0, 1.0, 200001)
    y = 2.0 * np.minimum(1.0, np.sqrt(1.2**2 - x**2))
    exact = (x[1] - x[0]) * (y.sum() - 0.5 * (y[0] + y[-1]))  # trapezoid rule
    assert signed_area(P) == pytest.approx(exact, rel=2e-3)


def test_slice_bad_input():
    f = sigmoid_ball()
    with pytest.raises(ValueError, match="resolution"):
        slice_contours(f, [0.0], *BOX, resolution=1)
    with pytest.raises(ValueError, match="not crossed"):
        slice_contours(f, [0.0, 0.1], *BOX, level=2.0)
    with pytest.raises(ValueError, match="not crossed"):
        slice_contours(f, [0.95], *BOX, resolution=16)  # plane misses the ball
    with pytest.raises(ValueError, match="shape"):
        slice_contours(lambda Q: np.ones((3, 3)), [0.0], *BOX)
    with pytest.raises(ValueError, match="NaN"):
        slice_contours(lambda Q: np.where(Q[:, 0] > 0.5, np.nan, f(Q)), [0.0], *BOX, resolution=16)
    with pytest.raises(ValueError, match="axis"):
        slice_contours(f, [0.0], *BOX, axis=3)
    with pytest.raises(ValueError, match="z_values"):
        slice_contours(f, [np.nan], *BOX)
    with pytest.raises(ValueError, match="z_values"):
        slice_contours(f, [], *BOX)


# ------------------------------------------------------------------------------ SVG


SVG = "{http://www.w3.org/2000/svg}"


def test_write_svg(tmp_path):
    two_balls = lambda Q: sigmoid_ball(0.3, (-0.5, 0, 0))(Q) + sigmoid_ball(0.3, (0.5, 0, 0))(Q)  # noqa: E731
    z = [0.0, 0.8]
    S1 = slice_contours(shell(), [0.1, 0.45], *BOX, resolution=48)
    S2 = slice_contours(two_balls, z, *BOX, resolution=48)
    assert [len(s) for s in S1] == [2, 1] and [len(s) for s in S2] == [2, 0]
    out = write_svg(tmp_path / "s.svg", S1 + S2, z_values=[0.1, 0.45] + z, bbox=[[-1, -1], [1, 1]])
    root = ET.parse(out).getroot()
    assert root.tag == SVG + "svg"
    assert root.get("width").endswith("mm") and len(root.get("viewBox").split()) == 4
    groups = root.findall(SVG + "g")
    assert len(groups) == 4
    paths = [g.findall(SVG + "path") for g in groups]
    # shell at z=0.1: one island (outer + hole as two subpaths); z=0.45: one; two balls: two; empty: none
    assert [len(p) for p in paths] == [1, 1, 2, 0]
    assert paths[0][0].get("d").count("M") == 2 and paths[0][0].get("fill-rule") == "evenodd"
    assert groups[1].get("data-z") == "0.45"
    # stacked layout and metre->mm scaling
    out2 = write_svg(tmp_path / "t.svg", S1, layout="stack", unit_mm=1000.0)
    r2 = ET.parse(out2).getroot()
    W, H = map(float, r2.get("viewBox").split()[2:])
    assert float(r2.get("width")[:-2]) == pytest.approx(1000 * W)
    assert H == pytest.approx(2 * W, rel=0.05)  # two slices of a square frame
    out3 = write_svg(tmp_path / "o.svg", S1, style={"fill": "none", "stroke": "red"})
    p3 = ET.parse(out3).getroot().find(f"{SVG}g/{SVG}path")
    assert (p3.get("fill"), p3.get("stroke"), p3.get("fill-rule")) == ("none", "red", "evenodd")
    with pytest.raises(ValueError, match="style"):
        write_svg(tmp_path / "u.svg", S1, style="red")
    with pytest.raises(ValueError, match="slice"):
        write_svg(tmp_path / "u.svg", [np.zeros((4, 2))])
    with pytest.raises(ValueError, match="bbox"):
        write_svg(tmp_path / "u.svg", [[], []])
    with pytest.raises(ValueError, match="z_values"):
        write_svg(tmp_path / "u.svg", S1, z_values=[0.0])


def test_write_slices_svg(tmp_path):
    z = np.linspace(-0.5, 0.5, 6)
    C = write_slices_svg(tmp_path / "b.svg", sigmoid_ball(), z, *BOX, resolution=32)
    assert len(C) == 6 and all(len(c) == 1 for c in C)
    root = ET.parse(tmp_path / "b.svg").getroot()
    assert len(root.findall(f"{SVG}g/{SVG}path")) == 6
