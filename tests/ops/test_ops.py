"""Tests for gsdf.ops: winding-number voxelization and trimming booleans (Barill et al. 2018, §4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gsdf.grid import Grid
from gsdf.ops import (
    BooleanOptions,
    load_voxels,
    mesh_boolean,
    save_voxels,
    trim_mesh,
    voxelize,
    voxels_to_mesh,
    winding_grid,
)

# ----------------------------------------------------------------------------------------------------------
# generated geometry and independent references
# ----------------------------------------------------------------------------------------------------------


def icosphere(level=3, r=1.0, center=(0.0, 0.0, 0.0)):
    """Outward-oriented icosphere (20 * 4**level faces)."""
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
                  [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
                  [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    for _ in range(level):
        E = np.sort(np.concatenate((F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]])), axis=1)
        Eu, inv = np.unique(E, axis=0, return_inverse=True)
        ab, bc, ca = len(V) + inv.reshape(3, -1)
        M = V[Eu[:, 0]] + V[Eu[:, 1]]
        V = np.concatenate((V, M / np.linalg.norm(M, axis=1, keepdims=True)))
        a, b, c = F.T
        F = np.concatenate([np.column_stack(x) for x in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))])
    return V * r + np.asarray(center, float), F.astype(np.int64)


def cube(lo=-0.5, hi=0.5):
    """Outward-oriented axis-aligned cube, 12 triangles."""
    V = np.array([[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (lo, hi)], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return V, F


def fibonacci_sphere(n, r=1.0):
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    N = np.column_stack((np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)))
    return r * N, N, np.full(n, 4 * np.pi * r * r / n)


def ref_winding(V, F, Q):
    """Exact generalized winding number, Van Oosterom-Strackee solid angles (independent numpy reference)."""
    Q = np.asarray(Q, float)
    out = np.zeros(len(Q))
    for s in range(0, len(Q), 2048):
        q = Q[s:s + 2048, None, :]
        a, b, c = V[F[:, 0]] - q, V[F[:, 1]] - q, V[F[:, 2]] - q
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("qfi,qfi->qf", a, np.cross(b, c))
        den = la * lb * lc + np.einsum("qfi,qfi->qf", a, b) * lc + np.einsum("qfi,qfi->qf", b, c) * la \
            + np.einsum("qfi,qfi->qf", c, a) * lb
        out[s:s + 2048] = np.arctan2(det, den).sum(axis=1) / (2 * np.pi)
    return out


def volume(V, F):
    """Enclosed volume by the divergence theorem (sum of signed tetrahedra with the origin)."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def edge_counts(F):
    """(uses of each undirected edge, uses of each directed edge)."""
    H = np.concatenate((F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]))
    _, und = np.unique(np.sort(H, axis=1), axis=0, return_counts=True)
    _, dirc = np.unique(H, axis=0, return_counts=True)
    return und, dirc


def punch(V, F, centers, rad=0.2):
    """Delete the faces whose centroid is within ``rad`` of any of ``centers``."""
    C = V[F].mean(axis=1)
    d = np.linalg.norm(C[:, None, :] - np.asarray(centers, float)[None], axis=2).min(axis=1)
    return F[d > rad]


SPHERE = 4 / 3 * math.pi
LENS = math.pi * (4 + 0.8) * (2 - 0.8) ** 2 / 12  # two unit spheres, centres 0.8 apart
ANALYTIC = {"union": 2 * SPHERE - LENS, "intersection": LENS, "difference": SPHERE - LENS}


@pytest.fixture(scope="module")
def spheres():
    VA, F = icosphere(4)
    VB = VA + np.array([0.8, 0.0, 0.0])
    return VA, F, VB, F.copy()


@pytest.fixture(scope="module")
def boolean_results(spheres):
    VA, FA, VB, FB = spheres
    return {op: mesh_boolean(VA, FA, VB, FB, op) for op in ANALYTIC}


# ----------------------------------------------------------------------------------------------------------
# voxelization (§4, Fig. 11)
# ----------------------------------------------------------------------------------------------------------


def test_voxelize_cube_exact_count():
    V, F = cube()
    grid = Grid.around(V, 20, pad=0.05)
    occ, lo, hi = voxelize(mesh=(V, F), resolution=grid)
    assert occ.shape == (20, 20, 20) and occ.dtype == bool
    # analytic: the voxel centres are the nodes of the grid over the input box padded by 0.05 * diagonal;
    # inside = centres strictly inside [-0.5, 0.5] on every axis
    p = 0.05 * math.sqrt(3)
    h = (1 + 2 * p) / 19
    x = -0.5 - p + np.arange(20) * h
    assert np.allclose(lo, -0.5 - p - h / 2) and np.allclose(hi, 0.5 + p + h / 2)  # the voxels' corners
    n1 = int(np.sum(np.abs(x) < 0.5))
    assert occ.sum() == n1 ** 3
    assert np.array_equal(occ.ravel(), np.all(np.abs(grid.points()) < 0.5, axis=1))
    # the default: resolution voxels along the longest side of the box padded by PAD (0.1) of the diagonal
    occ2, lo2, hi2 = voxelize(mesh=(V, F), resolution=20)
    g2 = Grid.around(V, 20)
    assert occ2.shape == g2.shape and np.allclose(lo2, g2.voxel_box()[0]) and np.allclose(hi2, g2.voxel_box()[1])


def test_voxelize_sphere_volume():
    V, F = icosphere(4)
    occ, lo, hi = voxelize(mesh=(V, F), resolution=40)
    h3 = np.prod((hi - lo) / np.array(occ.shape))
    vol = occ.sum() * h3
    assert abs(vol / SPHERE - 1) < 0.02
    assert abs(vol / volume(V, F) - 1) < 0.02
    # the fast field agrees with the independent exact reference on a slab of voxel centres
    W = winding_grid(mesh=(V, F), resolution=40)
    assert W.shape == occ.shape and np.array_equal(W.values >= 0.5, occ)
    C = W.grid_points().reshape(W.shape + (3,))[:, :, 20]
    Wref = ref_winding(V, F, C.reshape(-1, 3)).reshape(C.shape[:2])
    assert np.abs(W.values[:, :, 20] - Wref).max() < 1e-2
    assert np.array_equal(W.values[:, :, 20] >= 0.5, Wref >= 0.5)


def test_voxelize_holey_sphere_is_robust():
    V, F = icosphere(4)
    rng = np.random.default_rng(1)
    Fh = F[rng.random(len(F)) >= 0.10]  # delete 10% of the faces
    assert len(Fh) < 0.93 * len(F)
    grid = Grid.around(V, 40)
    occ, lo, hi = voxelize(mesh=(V, F), resolution=grid)
    occh, _, _ = voxelize(mesh=(V, Fh), resolution=grid)
    assert (occ == occh).mean() >= 0.99
    assert (occ & occh).sum() >= 0.97 * occ.sum()


def test_voxelize_point_cloud_matches_mesh():
    P, N, A = fibonacci_sphere(6000)
    V, F = icosphere(4)
    grid = Grid.around(V, 30)
    occ, lo, hi = voxelize(mesh=(V, F), resolution=grid)
    occp, lo2, hi2 = voxelize(points=(P, N, A), resolution=grid)
    assert np.array_equal(lo, lo2) and np.array_equal(hi, hi2)
    assert (occ == occp).mean() >= 0.99
    occe, _, _ = voxelize(points=(P, N), resolution=grid)  # estimated areas
    assert (occ == occe).mean() >= 0.98


def test_voxelize_progress_and_chunks(monkeypatch):
    import gsdf.ops._voxelize as vox

    V, F = icosphere(2)
    calls = []
    monkeypatch.setattr(vox, "CHUNK", 500)
    W1 = winding_grid(mesh=(V, F), resolution=12, progress=lambda stage, f: calls.append((stage, f)))
    total = W1.values.size
    assert calls[-1] == ("winding numbers", 1.0)
    assert len(calls) == -(-total // 500)
    assert all(a[1] < b[1] for a, b in zip(calls, calls[1:]))
    monkeypatch.undo()
    W2 = winding_grid(mesh=(V, F), resolution=12)
    assert np.array_equal(W1.values, W2.values)
    occ, _, _ = voxelize(mesh=(V, F), resolution=12)
    assert np.array_equal(occ, W2.values >= 0.5)


def test_voxelize_same_nodes_same_values_as_before():
    """The voxel centres of the former cell-grid rule, given as a Grid, get the winding numbers the former code
    computed there (the fast winding number at the same points, within a few ulps of the node positions)."""
    from gsdf.winding import FastWindingNumber

    V, F = icosphere(2)
    # former rule: `resolution` cells along the longest side, cubic, centred on the box; centres lo + (i + 1/2) h
    lo, hi = V.min(0) - 0.05 * np.linalg.norm(np.ptp(V, 0)), V.max(0) + 0.05 * np.linalg.norm(np.ptp(V, 0))
    r = 16
    h = float((hi - lo).max()) / r
    n = np.maximum(1, np.ceil((hi - lo) / h - 1e-9)).astype(int)
    gmin = 0.5 * (lo + hi) - 0.5 * n * h
    old_centres = gmin + (np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), -1).reshape(-1, 3)
                          + 0.5) * h
    W_old = FastWindingNumber(V, F)(old_centres)
    grid = Grid((gmin + 0.5 * h, gmin + (n - 0.5) * h), tuple(n))
    assert np.abs(grid.points() - old_centres).max() < 1e-14
    W_new = winding_grid(mesh=(V, F), resolution=grid).values.ravel()
    assert np.abs(W_new - W_old).max() < 1e-12
    assert np.array_equal(W_new >= 0.5, W_old >= 0.5)


def test_save_load_voxels(tmp_path):
    occ = np.zeros((3, 4, 5), bool)
    occ[1, 2, 3] = occ[0, 0, 0] = True
    p = tmp_path / "v.npz"
    save_voxels(p, occ, [0, 0, 0], [0.3, 0.4, 0.5])
    o2, lo, hi = load_voxels(p)
    assert np.array_equal(o2, occ) and np.allclose(lo, 0) and np.allclose(hi, [0.3, 0.4, 0.5])
    with np.load(p) as d:
        assert np.allclose(d["voxel_size"], 0.1)
    with pytest.raises(ValueError, match="not a gsdf voxel file"):
        np.savez(tmp_path / "x.npz", a=1)
        load_voxels(tmp_path / "x.npz")


def test_voxels_to_mesh_single_voxel():
    V, F = voxels_to_mesh(np.ones((1, 1, 1), bool), [0, 0, 0], [2, 2, 2])
    assert V.shape == (8, 3) and F.shape == (12, 3) and F.dtype == np.int64
    und, dirc = edge_counts(F)
    assert np.all(und == 2) and np.all(dirc == 1)  # closed and consistently oriented
    assert volume(V, F) == pytest.approx(8.0)  # outward: positive volume


def test_voxels_to_mesh_random_block():
    rng = np.random.default_rng(3)
    occ = rng.random((6, 5, 4)) < 0.5
    lo, hi = np.array([-1.0, 0, 2]), np.array([2.0, 2.5, 4])
    V, F = voxels_to_mesh(occ, lo, hi)
    h3 = np.prod((hi - lo) / np.array(occ.shape))
    assert volume(V, F) == pytest.approx(occ.sum() * h3)
    # closed and consistently oriented: each directed edge is used as often as its reverse
    H = np.concatenate((F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]))
    key = H[:, 0] * len(V) + H[:, 1]
    rkey = H[:, 1] * len(V) + H[:, 0]
    u, c = np.unique(key, return_counts=True)
    cnt = dict(zip(u.tolist(), c.tolist()))
    assert all(cnt.get(k, 0) == cnt[j] for j, k in zip(key.tolist(), rkey.tolist()))
    # all nodes on the grid
    g = (V - lo) / ((hi - lo) / np.array(occ.shape))
    assert np.allclose(g, np.round(g)) and g.min() >= -1e-9 and np.all(g.max(axis=0) <= np.array(occ.shape) + 1e-9)
    Vz, Fz = voxels_to_mesh(np.zeros((2, 2, 2), bool), lo, hi)
    assert Vz.shape == (0, 3) and Fz.shape == (0, 3)


def test_voxelize_bad_input():
    V, F = cube()
    with pytest.raises(ValueError, match="exactly one"):
        voxelize()
    with pytest.raises(ValueError, match="exactly one"):
        voxelize(mesh=(V, F), points=(V, V))
    with pytest.raises(ValueError, match="resolution"):
        voxelize(mesh=(V, F), resolution=1)
    with pytest.raises(ValueError, match="resolution"):
        voxelize(mesh=(V, F), resolution=(4, 4, 4))
    with pytest.raises(ValueError, match="NaN"):
        voxelize(mesh=(np.where(np.arange(24).reshape(8, 3) == 4, np.nan, V), F))
    with pytest.raises(ValueError, match="out of range"):
        voxelize(mesh=(V, F + 1))
    with pytest.raises(ValueError, match="bbox_max"):
        voxelize(mesh=(V, F), resolution=Grid(([0, 0, 0], [1, -1, 1]), (2, 2, 2)))
    with pytest.raises(ValueError, match="pad"):
        Grid.around(V, 10, pad=-1)
    with pytest.raises(ValueError, match="progress"):
        voxelize(mesh=(V, F), resolution=4, progress=3)
    with pytest.raises(ValueError, match="normals"):
        voxelize(points=(V, None))
    with pytest.raises(ValueError, match="beta"):
        voxelize(mesh=(V, F), beta=0)
    with pytest.raises(ValueError, match="occ"):
        voxels_to_mesh(np.ones((2, 2)), [0, 0, 0], [1, 1, 1])


# ----------------------------------------------------------------------------------------------------------
# booleans (§4, Figs. 12-15)
# ----------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("op", sorted(ANALYTIC))
def test_boolean_spheres_closed_oriented_volume(boolean_results, spheres, op):
    V, F = boolean_results[op]
    assert V.dtype == np.float64 and F.dtype == np.int64 and np.isfinite(V).all()
    und, dirc = edge_counts(F)
    assert np.all(und == 2), "every undirected edge is shared by exactly two faces"
    assert np.all(dirc == 1), "consistently oriented: no directed edge repeats"
    assert len(np.unique(F)) == len(V)  # no unused vertices
    assert abs(volume(V, F) / ANALYTIC[op] - 1) < 0.02
    # the polyhedral result, not only the analytic one: compare with the mesh sphere scaled
    VA, FA, _, _ = spheres
    assert abs(volume(V, F) / (ANALYTIC[op] * volume(VA, FA) / SPHERE) - 1) < 0.005


def test_boolean_inclusion_exclusion(boolean_results, spheres):
    """|A u B| + |A n B| = |A| + |B| and |A \\ B| = |A| - |A n B| hold for the polyhedral inputs."""
    VA, FA, VB, FB = spheres
    vu, vi, vd = (volume(*boolean_results[k]) for k in ("union", "intersection", "difference"))
    a, b = volume(VA, FA), volume(VB, FB)
    assert vu + vi == pytest.approx(a + b, rel=2e-4)
    assert vd == pytest.approx(a - vi, rel=2e-4)


def test_boolean_crossing_points_lie_on_other_surface(boolean_results, spheres):
    VA, FA, VB, FB = spheres
    V, F = boolean_results["intersection"]
    # vertices that are neither original vertex of A nor of B are crossing points: on both unit spheres
    rA, rB = np.linalg.norm(V, axis=1), np.linalg.norm(V - [0.8, 0, 0], axis=1)
    new = (np.abs(rA - 1) > 1e-12) & (np.abs(rB - 1) > 1e-12)
    assert new.sum() > 20
    assert np.abs(rA[new] - 1).max() < 0.01 and np.abs(rB[new] - 1).max() < 0.01
    # every kept original vertex of A is inside B and vice versa
    oa = np.abs(rA - 1) <= 1e-12
    assert np.all(rB[oa] < 1 + 1e-9)


def test_boolean_exact_matches_fast():
    VA, FA = icosphere(2)
    VB = VA + [0.8, 0, 0]
    Ve, Fe = mesh_boolean(VA, FA, VB, FA, "difference", options=BooleanOptions(exact=True))
    Vf, Ff = mesh_boolean(VA, FA, VB, FA, "difference")
    assert volume(Ve, Fe) == pytest.approx(volume(Vf, Ff), rel=1e-3)
    assert np.all(edge_counts(Fe)[0] == 2)


def test_boolean_holey_inputs(spheres, boolean_results):
    VA, FA, VB, FB = spheres
    FAh = punch(VA, FA, [[0.4, 0.9165, 0], [-1, 0, 0], [0, 0, 1]])  # one hole across the intersection curve
    FBh = punch(VB, FB, [[0.4, -0.9165, 0], [1.8, 0, 0], [0.8, 0, -1]])
    assert len(FAh) < len(FA) and len(FBh) < len(FB)
    for op, ref in ANALYTIC.items():
        V, F = mesh_boolean(VA, FAh, VB, FBh, op)
        assert np.isfinite(V).all() and len(F) > 0
        # the holey result still encloses (in the winding-number sense) the right volume
        grid = Grid.around(V[np.unique(F)], 40)
        occ, lo, hi = voxelize(mesh=(V, F), resolution=grid)
        vol = occ.sum() * np.prod((hi - lo) / np.array(occ.shape))
        assert abs(vol / ref - 1) < 0.03, op
        occc, _, _ = voxelize(mesh=boolean_results[op], resolution=grid)
        assert (occ == occc).mean() > 0.995, op


def test_boolean_disjoint_and_empty():
    VA, FA = icosphere(1)
    VB = VA + [5.0, 0, 0]
    V, F = mesh_boolean(VA, FA, VB, FA, "intersection")
    assert V.shape == (0, 3) and F.shape == (0, 3) and F.dtype == np.int64
    V, F = mesh_boolean(VA, FA, VB, FA, "union")
    assert F.shape == (2 * len(FA), 3) and volume(V, F) == pytest.approx(2 * volume(VA, FA))
    V, F = mesh_boolean(VA, FA, VB, FA, "difference")
    assert volume(V, F) == pytest.approx(volume(VA, FA))
    # B inside A: difference is a shell (outer A + flipped B)
    VC = 0.5 * VA
    V, F = mesh_boolean(VA, FA, VC, FA, "difference")
    assert volume(V, F) == pytest.approx(volume(VA, FA) - volume(VC, FA))


def test_boolean_with_point_cloud_field(spheres):
    """Fig. 15: the field of B comes from an oriented point cloud instead of B's triangles."""
    from gsdf.winding import FastWindingNumberPoints

    VA, FA, VB, FB = spheres
    P, N, A = fibonacci_sphere(8000)
    wb = FastWindingNumberPoints(P + [0.8, 0, 0], N, areas=A)
    V, F = mesh_boolean(VA, FA, VB, FB, "union", winding_b=wb)
    assert np.isfinite(V).all()
    assert abs(volume(V, F) / ANALYTIC["union"] - 1) < 0.02


def test_trim_mesh_plane():
    V, F = icosphere(3)
    Vt, Ft = trim_mesh(V, F, lambda Q: (Q[:, 2] < 0).astype(float), keep="inside", bisection_steps=20)
    assert Vt[:, 2].max() <= 1e-5  # the cut follows z = 0 up to the bisection tolerance
    on = np.abs(Vt[:, 2]) < 1e-5
    assert on.sum() > 10
    und, _ = edge_counts(Ft)
    assert (und == 1).sum() == on.sum()  # one boundary loop through the crossing points, shared by neighbours


def test_refine_fallback_bisection():
    from gsdf.ops._boolean import _refine_on_edges_fallback

    A = np.zeros((3, 3))
    B = np.array([[1.0, 0, 0], [0, 2.0, 0], [0, 0, -1.0]])
    f = lambda Q: np.linalg.norm(Q, axis=1)  # noqa: E731
    X = _refine_on_edges_fallback(f, A, B, f(A), f(B), 0.3, 30)
    assert np.allclose(np.linalg.norm(X, axis=1), 0.3, atol=1e-8)


def test_boolean_bad_input():
    VA, FA = icosphere(1)
    VB = VA + 0.5
    with pytest.raises(ValueError, match="op"):
        mesh_boolean(VA, FA, VB, FA, "xor")
    Vn = VA.copy()
    Vn[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        mesh_boolean(Vn, FA, VB, FA, "union")
    with pytest.raises(ValueError, match="out of range"):
        mesh_boolean(VA, FA, VB, FA + len(VB), "union")
    with pytest.raises(ValueError, match="negative"):
        mesh_boolean(VA, FA - 1, VB, FA, "union")
    with pytest.raises(ValueError, match="shape"):
        mesh_boolean(VA[:, :2], FA, VB, FA, "union")
    with pytest.raises(ValueError, match="beta"):
        mesh_boolean(VA, FA, VB, FA, "union", options=BooleanOptions(beta=float("nan")))
    with pytest.raises(ValueError, match="options"):
        mesh_boolean(VA, FA, VB, FA, "union", options={"beta": 2.0})
    with pytest.raises(ValueError, match="winding_b"):
        mesh_boolean(VA, FA, VB, FA, "union", winding_b=3)
    with pytest.raises(ValueError, match="winding_b"):
        mesh_boolean(VA, FA, VB, FA, "union", winding_b=lambda Q: np.full(len(Q), np.nan))


def test_signed_distance_grid_of_points_without_v():
    """The documented call `signed_distance_grid(points=(P, N))` (V omitted) raised a TypeError."""
    import gsdf
    from tests.shapes import fibonacci_sphere

    P = fibonacci_sphere(200)
    S = gsdf.signed_distance_grid(points=(P, P), resolution=8)
    assert S.shape == (8, 8, 8) and S([[0, 0, 0]])[0] < 0
    with pytest.raises(ValueError, match="beta: must be a finite positive number"):
        gsdf.signed_distance_grid(points=(P, P), resolution=8, beta=np.nan)


@pytest.mark.parametrize("s", [1e-300, 1e-150, 1e150, 1e300])
def test_voxelize_points_at_extreme_scales(s):
    """The box's diagonal underflowed to 0 at 1e-300 (no cell inside) and overflowed at 1e300 (a refusal)."""
    from tests.shapes import fibonacci_sphere

    P = fibonacci_sphere(300)
    ref, lo1, hi1 = voxelize(points=(P, P), resolution=16)
    occ, lo, hi = voxelize(points=(P * s, P), resolution=16)
    assert np.array_equal(occ, ref)
    np.testing.assert_allclose(lo / s, lo1, rtol=1e-12)


def test_box_diagonal_without_under_or_overflow():
    from gsdf.grid import diagonal, padded_box

    for s in (1e-300, 1.0, 1e300):
        assert diagonal([0, 0, 0], [3 * s, 4 * s, 0]) == pytest.approx(5 * s, rel=1e-15)
        lo, hi = padded_box([[0, 0, 0], [3 * s, 4 * s, 0]], pad=0.1)
        np.testing.assert_allclose(lo / s, [-0.5, -0.5, -0.5], rtol=1e-12)
    assert diagonal([1, 1, 1], [1, 1, 1]) == 0.0
