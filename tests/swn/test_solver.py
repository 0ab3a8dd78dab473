"""Surface winding numbers (gsdf.SurfaceWindingNumbers): the test cases of spec §1(f) and the bad inputs of
issue 12."""

import numpy as np
import pytest

from gsdf import SWNOptions
from gsdf.swn._solver import SurfaceWindingNumbers, surface_winding_number
from tests.shapes import uv_sphere
from tests.shapes import annulus, double_torus, torus


def mislabeled(res, truth, area):
    """Mislabeled area fraction, minimised over a global integer shift."""
    W = res.face_labels
    best = 1.0
    for k in np.unique(truth - W):
        best = min(best, float(area[(W + k) != truth].sum() / area.sum()))
    return best


def boundary_chain(swn, faces):
    """Oriented boundary (nE,) of a face set: its faces are on the left (label 1)."""
    ind = np.zeros(swn.dec.n_faces)
    ind[faces] = 1.0
    g = swn.dec.d1.T @ ind
    g[swn.topology.boundary_edges] = 0
    return np.rint(g)


@pytest.fixture(scope="module")
def sphere():
    V, F = uv_sphere(24, 48)
    return V, F, SurfaceWindingNumbers(V, F)


@pytest.fixture(scope="module")
def tor():
    V, F, idx = torus(48, 24)
    return V, F, idx, SurfaceWindingNumbers(V, F)


def test_sphere_closed_latitude_loop(sphere):
    V, F, swn = sphere
    ring = 1 + 8 * 48 + np.arange(48)
    res = swn.solve([np.r_[ring, ring[0]]])
    assert swn.simply_connected and "lp" not in res.timings
    truth = (V[F].mean(1)[:, 2] > V[ring[0], 2]).astype(int)
    area = swn.dec.areas
    assert mislabeled(res, truth, area) == 0.0
    assert np.abs(res.omega).max() < 1e-6
    # the ring runs counter-clockwise seen from +z: the cap above it is on its left, label 1
    assert set(np.unique(res.face_labels[truth == 1])) == {1}
    assert set(np.unique(res.face_labels[truth == 0])) == {0}


def test_sphere_broken_loop(sphere):
    V, F, swn = sphere
    ring = 1 + 14 * 48 + np.arange(48)
    truth = (V[F].mean(1)[:, 2] > V[ring[0], 2]).astype(int)
    rng = np.random.default_rng(0)
    keep = np.ones(48, bool)
    for start in rng.choice(48, 3, replace=False):         # delete ~30 % in three random intervals
        keep[np.arange(start, start + 5) % 48] = False
    pieces, cur = [], []
    for k in range(49):
        if keep[k % 48] and keep[(k + 1) % 48] and k < 48:
            cur += [ring[k % 48], ring[(k + 1) % 48]] if not cur else [ring[(k + 1) % 48]]
        elif cur:
            pieces.append(cur)
            cur = []
    assert 0.25 <= 1 - keep.mean() <= 0.35
    res = swn.solve(pieces)
    assert res.endpoints.sum() >= 4
    assert mislabeled(res, truth, swn.dec.areas) <= 0.05


def test_torus_meridian(tor):
    V, F, idx, swn = tor
    mer = np.r_[idx[5], idx[5, 0]]
    area = swn.dec.areas
    naive = swn.solve([mer], method="none")
    uf = naive.u.mean(1)
    assert np.ptp(uf) > 0.9                                   # u ramps once around the torus (Fig. 6.1)
    # rounding the ramp (gauge: its minimum at 0) puts a phantom curve at u = ½, half way round: ~50 % mislabeled
    ph = np.round(uf - uf.min())
    assert 0.4 < area[ph == 1].sum() / area.sum() < 0.6
    truth = np.zeros(len(F), int)
    full = swn.solve([mer], method="lp")
    red = swn.solve([mer], method="reduced")
    for r in (full, red):
        assert mislabeled(r, truth, area) == 0.0
        assert np.ptp(r.corner_values) < 1e-6                  # w constant
        on = r.chain != 0
        assert np.allclose(r.residual[on], r.chain[on], atol=1e-6)     # Jv = g: the meridian is nonbounding
        assert np.abs(r.residual[~on]).max() < 1e-6
    assert np.allclose(full.residual, red.residual, atol=1e-6)


def test_torus_broken_meridian_gap_closes(tor):
    V, F, idx, swn = tor
    jv = []
    for keep in (16, 22):                                      # 1/3 and 1/12 of the meridian deleted
        r = swn.solve([idx[5, :keep]])
        on = r.chain != 0
        gap = (~on) & (np.abs(r.residual) > 0.1)       # (a ~1e-3 circulation along a longitude aside)
        assert gap.any()                                       # the gap closes ...
        gl = swn.dec.edge_len[gap].sum()
        assert gl < 1.3 * (24 - keep + 1) * swn.dec.edge_len[on].mean()   # ... by the short arc
        jv.append(np.median(np.abs(r.residual[on])))
        # spec §1(f): the LP optimum is at most ε·(nonbounding input length) + gap length (closing by Jv = 1)
        el = swn.dec.edge_len
        assert r.lp_objective <= 1e-2 * el[on].sum() + (24 - keep + 1) * el[on].mean() * 1.001
        assert mislabeled(r, np.zeros(len(F), int), swn.dec.areas) == 0.0
    assert jv[0] < jv[1] <= 1.0 + 1e-9 and jv[1] > 0.85         # Jv -> 1 as the breakage shrinks (Fig. 6.6)


def test_torus_opposite_meridians_bound_a_band(tor):
    V, F, idx, swn = tor
    a, b = np.r_[idx[5], idx[5, 0]], np.r_[idx[20], idx[20, 0]][::-1]
    res = swn.solve([a, b])
    assert np.abs(res.gamma).max() < 1e-6 and np.abs(res.residual).max() < 1e-6
    i_face = (F // 24).min(1), (F // 24).max(1)
    band = (i_face[0] >= 5) & (i_face[1] <= 20) & (i_face[1] - i_face[0] <= 1)
    # loop a runs along +j at i = 5: the face holding (5, j) -> (5, j+1) has i = 4, so the left of the curves
    # (winding number 1) is the outside of the band
    truth = (~band).astype(int)
    assert mislabeled(res, truth, swn.dec.areas) == 0.0
    assert set(np.unique(res.face_labels[band])) == {0} and set(np.unique(res.face_labels[~band])) == {1}
    for m in ("reduced", "none"):
        assert mislabeled(swn.solve([a, b], method=m), truth, swn.dec.areas) == 0.0


def test_torus_three_meridians_either_optimum(tor):
    V, F, idx, swn = tor
    loops = [np.r_[idx[i], idx[i, 0]] for i in (4, 20, 36)]
    loops[2] = loops[2][::-1]                                 # orientations +, +, −
    res = swn.solve(loops)
    imin = (F // 24).min(1)
    imax = (F // 24).max(1)
    seg = np.where(imax - imin > 1, 47, imin)                  # wrap-around faces belong to the last band
    band = np.digitize(seg, [4, 20, 36])                       # 0..3 (3 wraps to 0)
    band[band == 3] = 0
    # either the first + loop or the second is the nonbounding one; the other bounds with the − loop. Label 1 is
    # on the left of each loop: i < 4 / i < 20 for the + loops, i ≥ 36 for the reversed one
    t1 = (band != 2).astype(int)                               # loop 4 nonbounding: 1 outside [20, 36)
    t2 = (band == 0).astype(int)                               # loop 20 nonbounding: 1 on [36, 48) ∪ [0, 4)
    area = swn.dec.areas
    assert min(mislabeled(res, t1, area), mislabeled(res, t2, area)) == 0.0
    assert np.isclose(np.abs(res.residual).sum(), np.abs(res.chain).sum() / 3, rtol=0.05)


def test_double_torus_waist_and_handle():
    V, F = double_torus(48)
    swn = SurfaceWindingNumbers(V, F)
    assert swn.betti_1 == 4
    cen = V[F].mean(1)
    waist = boundary_chain(swn, np.flatnonzero(cen[:, 0] < 0))
    strip = np.flatnonzero((np.abs(cen[:, 1]) < 0.08) & (cen[:, 0] < -1.3))
    ring = boundary_chain(swn, strip)
    mid = V[swn.dec.edges].mean(1)
    a1 = np.where(mid[:, 1] > 0, ring, 0)                    # one of the strip's two meridian loops
    assert swn.dec.chain_endpoints(a1).sum() == 0 and np.abs(a1).sum() > 6
    res = swn.solve(waist + a1)
    on_a1 = a1 != 0
    assert np.allclose(res.residual[on_a1], a1[on_a1], atol=1e-6)          # Jv = a1
    assert np.abs(res.residual[~on_a1]).max() < 1e-6
    truth = (cen[:, 0] < 0).astype(int)
    assert mislabeled(res, truth, swn.dec.areas) == 0.0
    naive = swn.solve(waist + a1, method="none")
    assert mislabeled(naive, truth, swn.dec.areas) > 0.0
    assert np.ptp(naive.u.mean(1)[truth == 1]) > 0.5            # naive u ramps around the handle


def test_annulus_circle_and_radial_arc():
    V, F, idx = annulus(8, 48)
    swn = SurfaceWindingNumbers(V, F)
    assert swn.betti_1 == 1 and not swn.simply_connected
    res = swn.solve([np.r_[idx[3], idx[3, 0]]])               # counter-clockwise circle
    r_face = np.linalg.norm(V[F].mean(1), axis=1)
    inner = r_face < np.linalg.norm(V[idx[3, 0]])
    assert np.abs(res.residual).max() < 1e-6
    assert mislabeled(res, inner.astype(int), swn.dec.areas) == 0.0
    assert set(np.unique(res.face_labels[inner])) == {1}
    arc = swn.solve([idx[:, 0]])
    assert arc.endpoints.sum() == 0                           # endpoints on the boundary: closed
    assert np.ptp(arc.corner_values) < 1e-6                   # constant w: the arc is nonbounding
    assert np.allclose(np.abs(arc.residual[arc.chain != 0]), 1, atol=1e-6)


def test_one_call_form_and_timings(tor):
    V, F, idx, swn = tor
    r = surface_winding_number(V, F, [np.r_[idx[5], idx[5, 0]]], method="reduced")
    assert r.face_labels.shape == (len(F),) and r.face_labels.dtype == np.int64
    assert r.corner_values.shape == (len(F), 3) and r.u.shape == (len(F), 3)
    assert r.residual.shape == (swn.dec.n_edges,)
    assert {"jump_solve", "darboux", "lp", "final_solve", "total"} <= set(r.timings)
    assert np.array_equal(np.round(r.corner_values.mean(1)).astype(np.int64), r.face_labels)


def test_bad_input(tor):
    V, F, idx, swn = tor
    with pytest.raises(ValueError, match="empty"):
        swn.solve([])
    with pytest.raises(ValueError, match="out of range"):
        swn.solve([[0, 1, 10 ** 6]])
    with pytest.raises(ValueError, match="not joined by a mesh edge"):
        swn.solve([[0, 500]])
    with pytest.raises(ValueError, match="dtype bool"):
        swn.solve([np.array([True, False])])
    with pytest.raises(ValueError, match="at least 2"):
        swn.solve([[3]])
    with pytest.raises(ValueError, match="method"):
        swn.solve([idx[5]], method="gurobi")
    with pytest.raises(ValueError, match="epsilon"):
        SWNOptions(epsilon=0)
    with pytest.raises(ValueError, match="epsilon"):
        SWNOptions(epsilon=True)
    with pytest.raises(ValueError, match="time_limit"):
        SWNOptions(time_limit=-1.0)
    with pytest.raises(ValueError, match="options"):
        swn.solve([idx[5]], options={"epsilon": 0.1})
    with pytest.raises(ValueError, match="curves"):
        swn.solve("0 1 2")
    with pytest.raises(ValueError, match="repeats"):
        swn.solve([[0, 0, 1]])
    # non-manifold and non-orientable meshes
    with pytest.raises(ValueError, match="non-manifold"):
        SurfaceWindingNumbers(np.random.rand(5, 3), np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))
    n = 10
    Fm = []
    for i in range(n):
        a, b, ta, tb = i, (i + 1) % n, i + n, (i + 1) % n + n
        if i == n - 1:
            tb, b = b, tb
        Fm += [[a, b, tb], [a, tb, ta]]
    th = np.linspace(0, 2 * np.pi, n, endpoint=False)
    Vm = np.concatenate([np.stack([np.cos(th), np.sin(th), 0 * th], 1), np.stack([np.cos(th), np.sin(th), 0 * th + .3], 1)])
    with pytest.raises(ValueError, match="not orientable"):
        SurfaceWindingNumbers(Vm, np.array(Fm))
    with pytest.raises(ValueError, match="NaN"):
        SurfaceWindingNumbers(np.full((3, 3), np.nan), [[0, 1, 2]])


def test_lp_time_limit_names_the_fallback(tor):
    V, F, idx, swn = tor
    with pytest.raises(ValueError, match="method='reduced'"):
        swn.solve([idx[5, :12], idx[30, 3:15]], options=SWNOptions(time_limit=1e-4))


# ------------------------------------------------------------------------------------------ files and CLI
DATA = "/work/shared/data/swn"


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def test_curve_file_reader_and_insertion(tmp_path):
    from gsdf.io._swn_curves import read_swn_curves
    from gsdf.mesh._connectivity import MeshTopology
    from gsdf.swn._insert import insert_curves

    V, F, idx = torus(16, 8)
    # a loop around the tube through face interiors: midpoints of the edges (3, j)-(4, j) and of the diagonals
    # (3, j)-(4, j+1) between them
    from gsdf.io._curves import gc_edges
    gce, _ = gc_edges(F)
    lines = ["#offset 0"]
    for j in range(8):
        for a, b in ((idx[3, j], idx[4, j]), (idx[3, j], idx[4, (j + 1) % 8])):
            e = int(np.flatnonzero(((gce[:, 0] == a) & (gce[:, 1] == b)) | ((gce[:, 0] == b) & (gce[:, 1] == a)))[0])
            lines.append(f"e {e} 0.5")
    lines.append("l " + " ".join(str(k) for k in list(range(16)) + [0]))
    lines.append("#l 0 3")                                     # commented-out segments are ignored
    c = read_swn_curves(_write(tmp_path, "c.txt", "\n".join(lines) + "\n"), F)
    assert list(c.kinds) == ["e"] * 16 and len(c.segments) == 16
    V2, F2, segs, parent = insert_curves(V, F, c)
    assert len(V2) == len(V) + 16
    A = lambda V, F: np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)  # noqa
    assert np.isclose(A(V2, F2).sum(), A(V, F).sum()) and A(V2, F2).min() > 1e-8
    t = MeshTopology(F2)
    assert t.is_manifold and t.is_consistently_oriented and t.euler_characteristic == 0
    res = SurfaceWindingNumbers(V2, F2).solve(list(segs))
    assert np.allclose(np.abs(res.residual[res.chain != 0]), 1, atol=1e-6)     # a nonbounding meridian
    # single-edge curves are split so the endpoint exclusion does not swallow them
    from gsdf.swn._insert import polylines_to_curves
    V3, F3, s3, _ = insert_curves(V, F, polylines_to_curves([np.array([idx[3, 2], idx[3, 3]])]))
    assert len(V3) == len(V) + 1 and len(s3) == 2


@pytest.mark.parametrize("text, match", [
    ("#offset 0\nv 0\nl 0 7\n", "node 7"),
    ("#offset 0\nv 100000\nl 0 0\n", "out of range"),
    ("#offset 0\ne 0 1.5\nv 0\nl 0 1\n", "outside"),
    ("#offset 0\ne 0 abc\nv 0\nl 0 1\n", "not a number"),
    ("#offset 0\nv 0\nv 1\n", "no curve segments"),
    ("#offset 0\nq 1 2\n", "unknown directive"),
    ("#offset 0\nv 0\nv 1\nc 0 1\nl 0 1\n", "dual chains"),
    ("l 1 99999\n", "out of range"),
])
def test_curve_file_errors(tmp_path, text, match):
    from gsdf.io._swn_curves import read_swn_curves

    _, F, _ = torus(16, 8)
    with pytest.raises(ValueError, match=match):
        read_swn_curves(_write(tmp_path, "bad.txt", text), F)


def test_insertion_rejects_disconnected_segments(tmp_path):
    from gsdf.io._swn_curves import read_swn_curves
    from gsdf.swn._insert import insert_curves

    V, F, idx = torus(16, 8)
    c = read_swn_curves(_write(tmp_path, "c.txt", f"#offset 0\nv {idx[0, 0]}\nv {idx[8, 4]}\nl 0 1\n"), F)
    with pytest.raises(ValueError, match="share no face"):
        insert_curves(V, F, c)


def test_cli_swn(tmp_path):
    import os

    from click.testing import CliRunner
    from plyfile import PlyData

    from gsdf.cli.main import main

    if not os.path.isdir(DATA):
        pytest.skip("author data not present")
    out = str(tmp_path / "dt.ply")
    r = CliRunner().invoke(main, ["swn", f"{DATA}/double-torus.obj", f"{DATA}/double-torus.txt", "-o", out,
                                  "--method", "reduced", "--png", str(tmp_path / "dt.png"), "-q"])
    assert r.exit_code == 0, r.output
    ply = PlyData.read(out)
    lab = np.asarray(ply["face"]["label"])
    assert len(lab) == ply["face"].count and set(np.unique(lab)) == {0, 1}
    assert os.path.getsize(tmp_path / "dt.png") > 1000
    out2 = str(tmp_path / "dt.obj")
    r = CliRunner().invoke(main, ["swn", f"{DATA}/double-torus.obj", f"{DATA}/double-torus.txt", "-o", out2, "-q"])
    assert r.exit_code == 0, r.output
    txt = open(out2).read()
    assert txt.count("\nvt ") == 3 * ply["face"].count and "f 1/" in txt or "/1 " in txt
    bad = CliRunner().invoke(main, ["swn", f"{DATA}/double-torus.obj", f"{DATA}/double-torus.txt", "-o",
                                    str(tmp_path / "x.vtk")])
    assert bad.exit_code != 0 and ".ply, .obj" in bad.output
    badc = CliRunner().invoke(main, ["swn", f"{DATA}/double-torus.obj", _write(tmp_path, "b.txt", "zz\n"),
                                     "-o", out])
    assert badc.exit_code != 0 and "unknown directive" in badc.output


def test_progress_callback(tor):
    V, F, idx, swn = tor
    seen = []
    swn.solve([idx[5, :12]], progress=lambda stage, f: seen.append((stage, f)))
    fractions = [f for _, f in seen]
    assert seen[0] == ("jump Laplace solve", 0.0) and seen[-1] == ("done", 1.0)
    assert fractions == sorted(fractions) and all(isinstance(s, str) for s, _ in seen)
    with pytest.raises(ValueError, match="progress"):
        swn.solve([idx[5, :12]], progress=3)


def test_cli_heat_surface_swn(tmp_path):
    from click.testing import CliRunner
    from plyfile import PlyData

    from gsdf.cli.main import main
    from gsdf.io import write_mesh

    V, F, idx = torus(48, 24)
    write_mesh(str(tmp_path / "t.obj"), V, F)
    loops = [np.r_[idx[5], idx[5, 0]], np.r_[idx[20], idx[20, 0]][::-1], np.r_[idx[35], idx[35, 0]]]
    (tmp_path / "c.obj").write_text("".join("l " + " ".join(str(i + 1) for i in L) + "\n" for L in loops))
    out = str(tmp_path / "d.ply")
    r = CliRunner().invoke(main, ["heat-surface", str(tmp_path / "t.obj"), "--curves", str(tmp_path / "c.obj"),
                                  "-o", out, "--swn", "-q"])
    assert r.exit_code == 0, r.output
    assert "67% of the curve edges bound a region" in r.output
    phi = np.asarray(PlyData.read(out)["vertex"]["distance"])
    on = [np.abs(phi[L]).max() < 1e-6 for L in loops]
    assert on[1] and sum(on) == 2                # the reversed loop and one + loop remain; the other + is dropped


@pytest.mark.parametrize("gap", [0.25, 0.45])
def test_flat_circle_one_big_gap_offset_is_the_curve_level(gap):
    """A circle with one large gap on a flat grid. In the plane, the jump-harmonic w of an arc is its winding
    number (subtended angle / 2π); by the inscribed-angle theorem it equals f/2 on the whole missing part of the
    circle (f = fraction present), which is also the mean of the two sides on the arc, (f ± 1)/2 averaged. So
    rounding at the curve's own level (the rounding offset rule, ``rounding_offset``) closes the gap along the
    circle. Checks the jump solve, the endpoint handling and the offset rule against this."""
    from gsdf.data._shapes import grid_mesh

    V, F = grid_mesh(120)                  # [-1, 1]²; r = 0.15 keeps the zero-Neumann sides far (at r = 0.3 their
    # reflection already lifts the level on the missing arc by 0.03 above the curve's: 9 % error at a 45 % gap)
    swn = SurfaceWindingNumbers(V, F)
    C = V[F].mean(1)
    disk = np.flatnonzero(np.linalg.norm(C[:, :2], axis=1) < 0.15)
    truth = np.zeros(len(F), int)
    truth[disk] = 1
    g = boundary_chain(swn, disk)
    M = V[swn.dec.edges].mean(1)
    ang = np.mod(np.arctan2(M[:, 1], M[:, 0]), 2 * np.pi)
    g[ang < 2 * np.pi * gap] = 0                                     # one gap, `gap` of the circle's edges
    res = swn.solve(g)
    assert res.endpoints.sum() == 2
    A = swn.dec.areas
    err = mislabeled(res, truth, A) * A.sum() / A[disk].sum()        # relative to the disk's area
    assert err < 0.06
    # the level on the arc ≈ the level on the missing part of the circle (inscribed-angle theorem)
    w = res.corner_values.mean(1)
    ring = np.abs(np.linalg.norm(C[:, :2], axis=1) - 0.15) < 0.01
    th = np.mod(np.arctan2(C[:, 1], C[:, 0]), 2 * np.pi)
    missing = ring & (th > 2 * np.pi * 0.03) & (th < 2 * np.pi * (gap - 0.03))
    assert abs(np.median(w[missing]) - 0.5) < 0.03                  # labels round(w): the level sits at ½


@pytest.mark.parametrize("t", [0, -5, float("nan"), float("inf"), "x", True, 1j])
def test_time_limit_must_be_finite_positive(t):
    from gsdf import SWNOptions

    with pytest.raises(ValueError, match="time_limit: "):
        SWNOptions(time_limit=t)
    with pytest.raises(ValueError, match="epsilon: "):
        SWNOptions(epsilon=2.0)
