"""Tests of gsdf.recon: the guarantee layer, topology checks, and reconstruct_simply_connected end to end."""

import numpy as np
import pytest
from scipy.spatial import Delaunay, cKDTree

import gsdf
from gsdf.dec._tet import TetComplex
from gsdf.recon._grow import grow_regions, region_boundary
from gsdf.recon._orient import orient_normals
from gsdf.mesh._topology import is_sphere, mesh_topology
from tests.shapes import cube, uv_sphere


def _sphere(n, seed=0, r=1.0, c=(0, 0, 0)):
    P = np.random.default_rng(seed).normal(size=(n, 3))
    return P / np.linalg.norm(P, axis=1)[:, None] * r + np.asarray(c, float)


def _torus(n, R=1.0, r=0.35, seed=0):
    rng = np.random.default_rng(seed)
    u, v = rng.uniform(0, 2 * np.pi, (2, 4 * n))
    # area-uniform: accept by the ring radius
    keep = rng.uniform(0, R + r, 4 * n) < R + r * np.cos(v)
    u, v = u[keep][:n], v[keep][:n]
    return np.column_stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)])


def _chamfer(V, F, P):
    """Symmetric mean distance between the vertices/face centroids of (V, F) and the points P."""
    S = np.concatenate([V, V[F].mean(axis=1)])
    return 0.5 * (cKDTree(P).query(S)[0].mean() + cKDTree(S).query(P)[0].mean())


# ---------------------------------------------------------------- topology checker
def test_topology_checker_against_known_meshes():
    V, F = cube()
    t = mesh_topology(V, F)
    assert t["closed"] and t["edge_manifold"] and t["vertex_manifold"] and t["oriented"]
    assert (t["components"], t["euler"], t["genus"]) == (1, 2, [0])
    V2 = np.concatenate([V, V + 3])
    assert is_sphere(V2, np.concatenate([F, F + 8]), components=2)
    assert not is_sphere(V, F[:-1])                                  # open
    assert mesh_topology(V, F[:-1])["closed"] is False
    assert not mesh_topology(V, F[:, ::-1].copy() if False else np.concatenate([F[:6], F[6:, ::-1]]))["oriented"]
    # two cubes sharing one vertex: closed and edge-manifold, but not vertex-manifold
    Vb = np.concatenate([V, V + 1.0])
    Fb = np.concatenate([F, F + 8])
    Fb[Fb == 8] = 7                                                # vertex 0 of cube 2 == vertex 7 of cube 1
    tb = mesh_topology(Vb, Fb)
    assert tb["closed"] and tb["edge_manifold"] and not tb["vertex_manifold"]
    # a torus (UV grid): genus 1
    n, m = 12, 8
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    Ft = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    tt = mesh_topology(np.zeros((n * m, 3)), Ft)
    assert tt["euler"] == 0 and tt["genus"] == [1]


# ---------------------------------------------------------------- the guarantee layer
@pytest.mark.parametrize("seed", range(4))
def test_growth_boundary_is_always_one_sphere(seed):
    rng = np.random.default_rng(seed)
    P = rng.uniform(-1, 1, (1500, 3))
    K = TetComplex(P, Delaunay(P).simplices)
    c = K.V[K.T].mean(axis=1)
    # a field whose ½ set is a torus with noisy bubbles and a second blob: the naive rounding is not a sphere
    R = np.hypot(c[:, 0], c[:, 1])
    w = 0.5 + 2.0 * (0.3 - np.hypot(R - 0.55, c[:, 2])) + 0.3 * rng.normal(size=K.n_tets)
    w = np.maximum(w, 0.5 + 2.0 * (0.25 - np.linalg.norm(c - [0, 0, 0.75], axis=1)))
    naive = region_boundary(K, np.where(w > 0.5, 0, -1))
    assert not is_sphere(K.V, naive)
    label, rejected = grow_regions(K, w)
    assert rejected > 0
    F = region_boundary(K, label)
    assert is_sphere(K.V, F)
    assert np.all(w[label >= 0][1:] > 0.5)
    # two vertex-disjoint regions: two spheres
    allowed = np.where(c[:, 0] < -0.05, 0, np.where(c[:, 0] > 0.05, 1, -1))
    seeds = [np.flatnonzero(allowed == r)[np.argmax(w[allowed == r])] for r in (0, 1)]
    label2, _ = grow_regions(K, w, seeds=seeds, allowed=allowed)
    assert is_sphere(K.V, region_boundary(K, label2), components=2)


def test_grow_validates_field():
    P = np.random.default_rng(0).uniform(-1, 1, (50, 3))
    K = TetComplex(P, Delaunay(P).simplices)
    with pytest.raises(ValueError, match="w"):
        grow_regions(K, np.zeros(3))
    with pytest.raises(ValueError, match="w"):
        grow_regions(K, np.full(K.n_tets, np.nan))


# ---------------------------------------------------------------- orientation
def test_orientation_recovers_30_percent_flips():
    rng = np.random.default_rng(2)
    P = _torus(3000, seed=2)
    # true outward normals of the torus
    ring = P.copy()
    ring[:, 2] = 0
    ring = ring / np.linalg.norm(ring, axis=1)[:, None]
    Nt = P - ring * 1.0
    Nt /= np.linalg.norm(Nt, axis=1)[:, None]
    flip = rng.uniform(size=len(P)) < 0.3
    N = orient_normals(P, np.where(flip[:, None], -Nt, Nt))
    agree = np.mean(np.sum(N * Nt, axis=1) > 0)
    assert max(agree, 1 - agree) > 0.99


# ---------------------------------------------------------------- end to end
def test_sphere_reconstruction_is_a_sphere_close_to_the_points():
    P = _sphere(2000)
    V, F, rep = gsdf.reconstruct_simply_connected(P, return_report=True)
    assert is_sphere(V, F)
    assert _chamfer(V, F, P) < 0.05
    # outward orientation: positive enclosed volume ≈ 4π/3
    vol = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6
    assert 0.8 * 4 * np.pi / 3 < vol < 1.05 * 4 * np.pi / 3
    assert rep["outliers"].sum() < 0.02 * len(P)
    # with the global fit (default) every vertex moves, onto the sphere; without it, vertices that are input
    # points keep their exact coordinates
    assert np.abs(np.linalg.norm(V, axis=1) - 1).max() < 0.01
    V0, F0 = gsdf.reconstruct_simply_connected(P, options=gsdf.ReconstructionOptions(fit=False))
    d, _ = cKDTree(P).query(V0)
    assert np.sum(d == 0) > 0.9 * len(P)


def test_outliers_sphere_cc1_chi2_and_cd_falls_with_inliers():
    rng = np.random.default_rng(5)
    cds = []
    for n in (800, 2500):
        S = _sphere(n, seed=n)
        O = _sphere(300, seed=7) * (1 + rng.uniform(-0.5, 0.5, (300, 1)))
        V, F, rep = gsdf.reconstruct_simply_connected(np.concatenate([S, O]), return_report=True)
        t = mesh_topology(V, F)
        assert t["components"] == 1 and t["euler"] == 2 and t["closed"] and t["vertex_manifold"]
        cds.append(_chamfer(V, F, S))
        far = np.abs(np.linalg.norm(O, axis=1) - 1) > 0.15
        assert rep["outliers"][n:][far].mean() > 0.85              # far outliers are judged outliers
        inc = rep["inlier_counts"]
        assert all(a >= b for a, b in zip(inc, inc[1:])) and rep["iterations"] <= 4   # alternation monotone
    assert cds[1] < cds[0] < 0.08


def test_torus_cloud_still_gives_one_genus0_sphere():
    P = _torus(2000)
    V, F = gsdf.reconstruct_simply_connected(P)
    assert is_sphere(V, F)
    assert _chamfer(V, F, P) < 0.1


def test_two_spheres_clusters():
    P = np.concatenate([_sphere(800, 1), _sphere(800, 2, c=(3, 0, 0))])
    V, F = gsdf.reconstruct_simply_connected(P, clusters=True)
    assert is_sphere(V, F, components=2)
    V1, F1 = gsdf.reconstruct_simply_connected(P)
    assert is_sphere(V1, F1, components=1)


def test_harmonic_part_is_zero_on_the_hull_tetrahedralisation():
    """Seed 003 §4.2 removes the harmonic part γ of the Darboux derivative by an L0 correction chain; on the
    Delaunay tetrahedralisation of the hull (a ball) γ is zero up to solver tolerance, so the pipeline skips the
    correction (notes 2(b).4)."""
    from gsdf.recon._cloud import pca_normals, prepare_cloud
    from gsdf.recon._orient import face_chain
    from gsdf.recon._pipeline import _solver, _tetrahedralise
    X = prepare_cloud(_sphere(300))[0]
    K, _, spacing = _tetrahedralise(X)
    G = face_chain(K, X, orient_normals(X, pca_normals(X)), spacing, band=10.0)
    u, info = K.jump_laplace(G, solver=_solver)
    gamma = K.hodge().decompose(info["omega"]).harmonic
    assert np.count_nonzero(G) > 100
    assert np.linalg.norm(gamma) < 1e-8 * np.linalg.norm(info["omega"])


def test_normals_given_and_duplicates():
    P = _sphere(1500)
    P2 = np.concatenate([P, P[:100]])                              # duplicates are removed
    N2 = np.concatenate([P, P[:100]]) * np.where(np.arange(1600) % 2, 1, -1)[:, None]   # signs ignored
    V, F, rep = gsdf.reconstruct_simply_connected(P2, N2, return_report=True)
    assert is_sphere(V, F) and rep["duplicates"] == 100
    assert not rep["outliers"][1500:].any()


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize("P, N, kw, msg", [
    (np.zeros((3, 3)), None, {}, "at least 4"),
    (np.ones((10, 3)), None, {}, "at least 4"),                                    # all duplicates
    (np.random.default_rng(0).uniform(size=(50, 2)) @ np.eye(2, 3), None, {}, "coplanar"),
    (np.outer(np.linspace(0, 1, 20), [1, 2, 3]), None, {}, "collinear"),
    (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, np.nan]]), None, {}, "NaN"),
    (np.random.default_rng(0).normal(size=(10, 3)), np.zeros((9, 3)) + 1, {}, "rows"),
    (np.random.default_rng(0).normal(size=(10, 3)), np.ones((10, 2)), {}, "shape"),
    (np.random.default_rng(0).normal(size=(10, 4)), None, {}, "shape"),
    (np.random.default_rng(0).normal(size=(50, 3)), None, {"outliers": "maybe"}, "outliers"),
    (np.random.default_rng(0).normal(size=(50, 3)), None, {"clusters": 1}, "clusters"),
    (np.random.default_rng(0).normal(size=(50, 3)), None, {"options": {"band": 1.0}}, "options"),
    (np.random.default_rng(0).normal(size=(50, 3)), None, {"return_report": "no"}, "return_report"),  # was obeyed
    (np.random.default_rng(0).normal(size=(50, 3)), None, {"return_report": 2}, "return_report"),
])
def test_bad_input(P, N, kw, msg):
    with pytest.raises(ValueError, match=msg):
        gsdf.reconstruct_simply_connected(P, N, **kw)


@pytest.mark.parametrize("kw, msg", [({"max_iterations": 0}, "max_iterations"),
                                     ({"max_iterations": 10 ** 9}, "<= 20"), ({"band": -1.0}, "band"),
                                     ({"outlier_gap": float("nan")}, "outlier_gap"),
                                     ({"cluster_gap": True}, "cluster_gap"), ({"fit_k": 2}, "fit_k")])
def test_bad_options(kw, msg):
    with pytest.raises(ValueError, match=msg):
        gsdf.ReconstructionOptions(**kw)


def test_all_outliers_is_a_documented_result():
    V, F, rep = gsdf.reconstruct_simply_connected(np.random.default_rng(0).uniform(-1, 1, (1500, 3)),
                                                  return_report=True)
    assert is_sphere(V, F)
    assert rep["surface_fraction"] < 0.45
    _, _, rep2 = gsdf.reconstruct_simply_connected(np.concatenate([_sphere(1000), 1.3 * _sphere(800, 1)]),
                                                   return_report=True)
    assert rep2["surface_fraction"] > 0.5


def test_tiny_valid_inputs_still_give_a_sphere():
    # a tetrahedron's corners and a cube's corners (no surface density at all): still one sphere
    for P in (np.eye(4)[:, :3], cube()[0], uv_sphere(6, 8)[0]):
        V, F = gsdf.reconstruct_simply_connected(P, outliers="none")
        assert is_sphere(V, F)


def test_comparison_reconstructions_report_topology():
    from gsdf.recon._compare import reconstruct_winding
    P = np.concatenate([_sphere(1200), _sphere(600, 3, r=0.3, c=(2.0, 0, 0))])
    V, F, rep = reconstruct_winding(P, resolution=32, return_report=True)
    # two separate blobs: the level set has two components, and the report says so (no promise there)
    assert rep["components"] == 2 and rep["genus"] == [0, 0] and rep["manifold"]
    assert mesh_topology(V, F)["components"] == 2
    with pytest.raises(ValueError, match="resolution"):
        reconstruct_winding(P, resolution=True)


def test_cli_reconstruct(tmp_path):
    from click.testing import CliRunner

    from gsdf.cli.main import main
    cloud = tmp_path / "s.xyz"
    np.savetxt(cloud, _sphere(1500))
    out, png = tmp_path / "o" / "s.ply", tmp_path / "s.png"
    r = CliRunner().invoke(main, ["reconstruct", str(cloud), "-o", str(out), "--png", str(png), "-q"])
    assert r.exit_code == 0, r.output
    assert "components 1, genus [0], closed manifold" in r.output
    V, F = gsdf.read_mesh(str(out))
    assert is_sphere(V, F) and png.stat().st_size > 1000
    bad = CliRunner().invoke(main, ["reconstruct", str(cloud), "-o", str(tmp_path / "x.txt")])
    assert bad.exit_code == 1 and "extension" in bad.output
    missing = CliRunner().invoke(main, ["reconstruct", str(tmp_path / "nope.xyz"), "-o", str(out)])
    assert missing.exit_code != 0
