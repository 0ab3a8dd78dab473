"""The signed heat method on digital surfaces (Feng & Crane 2024 §8.5): surface extraction, corrected normals,
de Goes 2020 operators, convergence on a slanted digital plane and a digital sphere, broken curves, bad input."""

import numpy as np
import pytest
import scipy.sparse as sp

import gsdf
from gsdf.contour import region_boundary_curves
from gsdf.heat.voxel._degoes import face_operators
from gsdf.heat.voxel._digital import digital_surface, integral_invariant_normals
from gsdf.heat.voxel._domain import VoxelSurfaceDomain, VoxelSurfaceSignedHeatSolver


# ------------------------------------------------------------------------------------------------ helpers
def ball(N, R):
    x = np.indices((N,) * 3) - (N - 1) / 2
    return (x ** 2).sum(0) <= R ** 2


def half_space(N, nrm):
    """Voxels of the box [0, N)³ whose centres lie below the plane through the box centre with normal nrm."""
    nrm = np.asarray(nrm, float) / np.linalg.norm(nrm)
    x = np.indices((N,) * 3).transpose(1, 2, 3, 0) + 0.5
    return ((x - N / 2) @ nrm) < 0, nrm


def eps(phi, ref, A):
    """§9.1 error: L2 (mass-weighted) error normalized by the range of the reference and √area."""
    return float(np.sqrt((A * (phi - ref) ** 2).sum() / A.sum()) / (ref.max() - ref.min()))


def sphere_run(N, normal_radius=3.0, broken=False, connection="A", **kw):
    """Digital sphere R = N/2 − 2, curve = boundary of {quads with centre z < z0}, z0 = c + 0.3 R.
    Returns (ε vs R(θ − θ0), fraction of area with the right sign, solver)."""
    R = N / 2 - 2
    s = VoxelSurfaceSignedHeatSolver(ball(N, R), normal_radius=normal_radius, **kw)
    if connection != "A":                     # the cross-check of the connection Laplacian (Option B)
        from gsdf.heat._core import SignedHeatCore

        s.domain = VoxelSurfaceDomain(ball(N, R), normal_radius=normal_radius, connection=connection, **kw)
        s.core = SignedHeatCore(s.domain)
    c = N / 2
    # the curve at the grid plane z = zc nearest to c + 0.3 R (quads with centres below zc + ¼: the region's
    # boundary edges then lie on that plane, not up to half a voxel off it)
    zc = c + np.round(0.3 * R)
    region = s.face_centres[:, 2] < zc + 0.25
    curves = region_boundary_curves(s.faces, region)
    if broken:                                                  # delete every other run of 4 segments (50 %)
        pieces = []
        for g in curves:
            for a in range(0, len(g) - 1, 8):
                pieces.append(g[a:a + 5])
        curves = [p for p in pieces if len(p) >= 2]
    phi = s.compute_distance(curves)
    P = s.vertices - c
    theta = np.arccos(np.clip(-P[:, 2] / np.linalg.norm(P, axis=1), -1, 1))     # polar angle from the south pole
    ref = R * (theta - np.arccos(-(zc - c) / R))
    A = s.domain.mass()
    # the true sign is the digital region's: inside = all incident quads in the region (curve vertices excluded)
    nin = np.bincount(s.faces.ravel(), weights=np.repeat(region, 4).astype(float), minlength=len(P))
    nall = np.bincount(s.faces.ravel(), minlength=len(P))
    inside, outside = nin == nall, nin == 0
    ok = (inside & (phi < 0)) | (outside & (phi > 0))
    return eps(phi, ref, A), float(A[ok].sum() / A[inside | outside].sum()), s


def plane_run(N, nrm=(1, 1, 1), mdir=(1, -1, 0), **kw):
    """Slanted digital plane with a straight curve (the in-plane line m·x = 0 through the centre, closed over the
    box walls); ε over the plane's vertices within 0.3 N of the centre, where φ⁰ = m·x exactly."""
    occ, nrm = half_space(N, nrm)
    m = np.asarray(mdir, float) / np.linalg.norm(mdir)
    s = VoxelSurfaceSignedHeatSolver(occ, **kw)
    ctr = np.full(3, N / 2)
    phi = s.compute_distance(region_boundary_curves(s.faces, (s.face_centres - ctr) @ m < 0))
    P = s.vertices - ctr
    sel = (np.linalg.norm(P - np.outer(P @ nrm, nrm), axis=1) < 0.3 * N) & (np.abs(P @ nrm) < 1.0)
    return eps(phi[sel], (P @ m)[sel], s.domain.mass()[sel])


# ------------------------------------------------------------------------------------------------ the surface
def _halfedge_counts(F, n):
    he = np.stack([F.ravel(), np.roll(F, -1, axis=1).ravel()], 1)
    fwd = np.unique(he[:, 0] * n + he[:, 1], return_counts=True)
    bwd = np.unique(he[:, 1] * n + he[:, 0], return_counts=True)
    return fwd, bwd


def test_surface_is_a_closed_oriented_manifold_on_random_volumes():
    rng = np.random.default_rng(3)
    for _ in range(8):
        occ = rng.random((7, 6, 5)) < rng.uniform(0.2, 0.8)
        sp_ = np.array([0.5, 1.0, 2.0])
        S = digital_surface(occ, sp_)
        (k, c), (kr, cr) = _halfedge_counts(S.faces, len(S.vertices))
        assert np.array_equal(k, kr) and np.array_equal(c, cr)          # every edge: opposite twins
        # outward: the divergence theorem gives the occupied volume
        X = S.vertices[S.faces]
        a = 0.5 * np.cross(X, np.roll(X, -1, axis=1)).sum(1)
        vol = (a * X.mean(1)).sum() / 3
        assert vol == pytest.approx(occ.sum() * sp_.prod(), rel=1e-12)
        # every vertex umbrella is one cycle of quads: #quads at a vertex == #out-going half-edges == #in-going
        deg = np.bincount(S.faces.ravel(), minlength=len(S.vertices))
        assert deg.min() >= 3


def test_nonmanifold_configurations_are_split():
    edge = np.zeros((2, 2, 1), bool)
    edge[0, 0, 0] = edge[1, 1, 0] = True                               # two voxels sharing one edge
    corner = np.zeros((2, 2, 2), bool)
    corner[0, 0, 0] = corner[1, 1, 1] = True                           # sharing one corner
    for occ in (edge, corner):
        S = digital_surface(occ, np.ones(3))
        assert S.vertices.shape == (16, 3) and S.faces.shape == (12, 4)    # two separate cubes
        assert len(np.unique(S.pointels, axis=0)) == (14 if occ is edge else 15)
    # a 4-valent edge whose end points are rejoined elsewhere: the two voxels are 6-connected through a third
    occ = np.zeros((2, 2, 2), bool)
    occ[0, 0, 0] = occ[1, 1, 0] = occ[0, 0, 1] = occ[0, 1, 1] = occ[1, 1, 1] = True
    S = digital_surface(occ, np.ones(3))
    (k, c), (kr, cr) = _halfedge_counts(S.faces, len(S.vertices))
    assert np.array_equal(c, cr)
    assert len(S.vertices) - 2 * len(S.faces) + len(S.faces) == 2            # still a sphere (χ = 2)


def test_integral_invariant_normals_on_a_sphere_and_a_plane():
    N, R = 40, 16
    occ = ball(N, R)
    S = digital_surface(occ, np.ones(3))
    u = integral_invariant_normals(occ, np.ones(3), S, 3.0)
    radial = S.centres - N / 2
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    ang = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", u, radial), -1, 1)))
    triv = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", S.trivial_normals, radial), -1, 1)))
    assert ang.mean() < 4.0 and ang.max() < 8.0                          # r = 3 voxels
    assert triv.mean() > 10 * ang.mean()
    occ, nrm = half_space(24, (1, 1, 1))
    S = digital_surface(occ, np.ones(3))
    u = integral_invariant_normals(occ, np.ones(3), S, 3.0)
    mid = (np.abs(S.centres - 12) < 6).all(1) & (np.abs((S.centres - 12) @ nrm) < 1)
    assert np.degrees(np.arccos((u[mid] @ nrm).min())) < 1.0


# ------------------------------------------------------------------------------------------------ operators
def test_face_operators_identities_on_random_planar_polygons():
    rng = np.random.default_rng(0)
    ang = np.sort(rng.uniform(0, 2 * np.pi, (50, 5)), axis=1)
    P2 = np.stack([np.cos(ang), np.sin(ang)], -1) * rng.uniform(0.5, 2, (50, 5, 1))
    Q = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    X = np.concatenate([P2, np.zeros((50, 5, 1))], -1) @ Q.T + rng.normal(size=3)
    ops = face_operators(X)
    g = rng.normal(size=(50, 3))
    g -= ops.normal * np.einsum("ij,ij->i", g, ops.normal)[:, None]
    phi = np.einsum("mkj,mj->mk", X, g)                                      # linear functions
    assert np.allclose(np.einsum("mik,mk->mi", ops.gradient, phi), g)                       # G exact
    assert np.allclose(np.einsum("mik,kl->mil", ops.sharp, ops.D), ops.gradient)           # U D = G
    assert np.allclose(np.einsum("mik,mkj,mj->mi", ops.sharp, ops.flat, g), g)             # U V = I
    assert np.allclose(ops.laplacian.sum(2), 0)                                             # L 1 = 0
    assert np.linalg.eigvalsh(ops.laplacian).min() > -1e-12                                 # PSD
    lhs = np.einsum("mkl,mlj,mj->mk", ops.divergence, ops.flat, g)
    assert np.allclose(lhs, np.einsum("mkl,ml->mk", ops.laplacian, phi))                   # div ♭∇φ = Lφ
    Q2 = np.roll(P2, -1, 1)
    shoelace = 0.5 * np.abs((P2[..., 0] * Q2[..., 1] - P2[..., 1] * Q2[..., 0]).sum(1))
    assert np.allclose(ops.area, shoelace)


def _corrected_plane(N=16, nrm=(1, 2, 0)):
    occ, nrm = half_space(N, nrm)
    S = digital_surface(occ, np.ones(3))
    on = ((S.trivial_normals @ nrm) > 0) & (np.abs((S.centres - N / 2) @ nrm) < 1.0)
    u = np.where(on[:, None], nrm, S.trivial_normals)
    d = VoxelSurfaceDomain(occ, normals=u)
    interior = np.ones(d.n, bool)
    interior[d.faces[~on].ravel()] = False                       # vertices all of whose quads are corrected
    return d, nrm, interior


def test_linear_precision_on_a_corrected_plane():
    d, nrm, interior = _corrected_plane()
    assert interior.sum() > 50
    g = np.cross(nrm, [0.3, -0.2, 0.9])                           # an in-plane gradient
    phi = d.vertices @ g
    assert np.abs((d.L @ phi)[interior]).max() < 1e-10
    onf = interior[d.faces].all(1)
    assert np.allclose(d.gradient(phi)[onf], g)
    # the corrected quads tile the plane: their areas add up to the projected area of the region
    assert np.all(d.face_ops.area[onf] <= 1 + 1e-12)
    Y = np.tile(g, (d.m, 1))
    Y[~onf] = d.gradient(phi)[~onf]
    assert np.allclose(d.divergence(d.gradient(phi)), d.L @ phi)         # div ♭∇φ = Lφ
    assert np.allclose(d.L @ np.ones(d.n), 0)


def test_connection_laplacian_hermitian_psd_and_flat_equals_scalar():
    d = VoxelSurfaceDomain(ball(12, 4.5))
    A = d.Lconn
    assert abs(A - A.conj().T).max() < 1e-12
    w = np.linalg.eigvalsh(A.toarray())
    assert w.min() > -1e-10 * w.max()
    assert abs(A.diagonal() - d.L.diagonal()).max() < 1e-12
    # step I operator: M + t L∇, Hermitian positive definite
    H = d.vector_heat_matrix()
    assert abs(H - H.conj().T).max() < 1e-12 and abs(H - sp.diags(d.Mv) - d.t * A).max() < 1e-12
    # Option B has the same diagonal and the same |entries|
    B = VoxelSurfaceDomain(ball(12, 4.5), connection="B").Lconn
    assert abs(abs(B) - abs(d.L)).max() < 1e-12
    # flat: a slab seen from above, trivial normals → every frame the same → L∇ = L (i.e. L ⊗ I₂ in real form)
    occ = np.zeros((6, 6, 3), bool)
    occ[:, :, :2] = True
    f = VoxelSurfaceDomain(occ, normal_radius=0)
    top = f.faces[f.surface.direction == 4]
    sel = np.zeros(f.n, bool)
    sel[top.ravel()] = True
    sel[f.faces[f.surface.direction != 4].ravel()] = False
    Lc = f.Lconn[sel][:, sel].toarray()
    assert np.allclose(Lc, f.L[sel][:, sel].toarray(), atol=1e-12)
    # real 2n×2n form of the complex operator is L ⊗ I₂ there
    R = np.block([[Lc.real, -Lc.imag], [Lc.imag, Lc.real]])
    Ls = f.L[sel][:, sel].toarray()
    assert np.allclose(R, np.kron(np.eye(2), Ls), atol=1e-12)


def test_option_a_and_b_agree():
    eA, sA, a = sphere_run(24)
    eB, sB, b = sphere_run(24, connection="B")
    assert abs(eA - eB) < 0.25 * eA
    ring = region_boundary_curves(a.faces, a.face_centres[:, 2] < 14)
    pa, pb = a.compute_distance(ring), b.compute_distance(ring)
    assert np.abs(pa - pb).max() < 0.05 * np.abs(pa).max()


# ------------------------------------------------------------------------------------------------ convergence
def test_slanted_plane_corrected_normals_converge_trivial_do_not():
    corr = [plane_run(N) for N in (16, 32, 64)]
    triv = [plane_run(N, normal_radius=0) for N in (16, 32, 64)]
    assert corr[1] < 0.75 * corr[0] and corr[2] < 0.75 * corr[1] and corr[2] < 0.013
    assert min(triv) > 0.03 and triv[2] > 0.8 * triv[0]                      # ℓ1-type bias stays
    assert triv[2] > 3 * corr[2]


def test_digital_sphere_converges_with_resolution():
    runs = [sphere_run(N) for N in (16, 32, 64)]
    e = [r[0] for r in runs]
    assert e[1] < e[0] and e[2] < e[1] and e[2] < 0.007
    assert np.log2(e[0] / e[2]) / 2 > 0.3                                   # order of convergence
    assert runs[2][1] >= 0.99
    triv = sphere_run(64, normal_radius=0)[0]
    assert triv > 4 * e[2]
    # a radius growing like r ∝ h^(1/3) in world units (½ N^(2/3) voxels) removes the fixed-radius bias
    s32, s64 = (sphere_run(N, normal_radius=0.5 * N ** (2 / 3))[0] for N in (32, 64))
    assert s64 < 0.6 * s32 and s64 < 0.5 * e[2]


def test_broken_sphere_curve():
    e0, s0, _ = sphere_run(48)
    e1, s1, _ = sphere_run(48, broken=True)
    assert e1 < 2.0 * e0 and s1 >= 0.95 and s0 >= 0.99


# ---------------------------------------------------------------------------------------- sources and constraints
@pytest.fixture(scope="module")
def sphere32():
    s = VoxelSurfaceSignedHeatSolver(ball(32, 13))
    ring = region_boundary_curves(s.faces, s.face_centres[:, 2] < 20)     # off the mirror plane z = 16
    return s, ring


def test_constraint_modes_and_soft_weight(sphere32):
    s, ring = sphere32
    zero = s.compute_distance(ring)
    assert np.abs(zero[np.unique(np.concatenate(ring))]).max() < 1e-9
    none = s.compute_distance(ring, level_set_constraint="none")
    mult = s.compute_distance(ring, level_set_constraint="multiple")
    soft = s.compute_distance(ring, soft_weight=1e3)
    for phi in (none, mult, soft):
        assert np.abs(phi - zero).max() < 0.1 * np.abs(zero).max()
    v = np.unique(np.concatenate(ring))
    assert np.ptp(mult[v]) < 1e-8
    assert np.ptp(none[v]) > 1e-4
    # the south pole is inside (negative), the north pole outside, at R(θ − θ0) from the ring at z = 20
    south = np.argmin(np.linalg.norm(s.vertices - [16, 16, 0], axis=1))
    north = np.argmin(np.linalg.norm(s.vertices - [16, 16, 32], axis=1))
    th0 = np.arccos(-4 / 13)
    assert zero[south] == pytest.approx(-13 * th0, rel=0.06)
    assert zero[north] == pytest.approx(13 * (np.pi - th0), rel=0.06)
    # reversing the curve flips the sign
    assert np.allclose(s.compute_distance([g[::-1] for g in ring]), -zero, atol=1e-9)


def test_point_sources_and_unsigned_curves(sphere32):
    s, ring = sphere32
    P = s.vertices - 16
    for src in (int(np.argmin(np.linalg.norm(P - [0, 0, -13], axis=1))),      # a flat patch (south pole)
                int(np.argmin(np.linalg.norm(P - [1, -4, -13], axis=1))),     # a digital corner
                int(np.argmin(np.linalg.norm(P - [10, 9, -1], axis=1)))):
        phi = s.compute_distance([], points=[src])
        Q = P[src] / np.linalg.norm(P[src])
        geo = 13 * np.arccos(np.clip(P @ Q / np.linalg.norm(P, axis=1), -1, 1))
        assert phi[src] == 0 and eps(phi, geo, s.domain.mass()) < 0.035
    uns = s.compute_distance(ring, curve_signs=[False] * len(ring))
    signed = s.compute_distance(ring)
    assert uns.min() > -1e-6
    assert eps(uns, np.abs(signed), s.domain.mass()) < 0.03


def test_curves_across_quad_diagonals(sphere32):
    s, ring = sphere32
    f = s.faces[np.argmin(s.vertices[s.faces].mean(1)[:, 2])]          # the quad at the south pole
    phi = s.compute_distance([np.array([f[0], f[2]])], level_set_constraint="none")
    assert np.isfinite(phi).all()


# ------------------------------------------------------------------------------------------------ bad input
def test_bad_input():
    occ = ball(10, 3)
    with pytest.raises(ValueError, match="occupancy.*empty"):
        VoxelSurfaceSignedHeatSolver(np.zeros((4, 4, 4), bool))
    with pytest.raises(ValueError, match="occupancy.*empty"):
        VoxelSurfaceSignedHeatSolver(np.zeros((0, 4, 4), bool))
    with pytest.raises(ValueError, match="occupancy.*full"):
        VoxelSurfaceSignedHeatSolver(np.ones((4, 4, 4), bool))
    with pytest.raises(ValueError, match="occupancy.*dimensions"):
        VoxelSurfaceSignedHeatSolver(np.ones((4, 4), bool))
    with pytest.raises(ValueError, match="occupancy.*boolean"):
        VoxelSurfaceSignedHeatSolver(occ * 2.5)
    with pytest.raises(ValueError, match="occupancy: expected a boolean array, got strings"):
        VoxelSurfaceSignedHeatSolver(np.full((3, 3, 3), "a"))
    for bad in (np.nan, -1.0, 0.0, [1, 1], [1, np.inf, 1], True, "x"):
        with pytest.raises(ValueError, match="spacing"):
            VoxelSurfaceSignedHeatSolver(occ, spacing=bad)
    for bad in (1e308, [1.0, 1.0, 1e200]):
        with pytest.raises(ValueError, match="spacing: .* is too large"):
            VoxelSurfaceSignedHeatSolver(occ, spacing=bad)
    for bad in (-1.0, np.nan, True, "x"):
        with pytest.raises(ValueError, match="normal_radius"):
            VoxelSurfaceSignedHeatSolver(occ, normal_radius=bad)
    with pytest.raises(ValueError, match="connection"):
        VoxelSurfaceDomain(occ, connection="C")
    with pytest.raises(ValueError, match="t_coef"):
        VoxelSurfaceSignedHeatSolver(occ, t_coef=0)
    s = VoxelSurfaceSignedHeatSolver(occ)
    with pytest.raises(ValueError, match="normals"):
        VoxelSurfaceDomain(occ, normals=-s.normals)
    with pytest.raises(ValueError, match="normals"):
        VoxelSurfaceDomain(occ, normals=s.normals[:-1])
    n = len(s.vertices)
    f = s.faces[0]
    with pytest.raises(ValueError, match=r"curves\[0\].*out of range"):
        s.compute_distance([np.array([0, n])])
    with pytest.raises(ValueError, match=r"curves\[0\].*out of range"):
        s.compute_distance([np.array([-1, 0])])
    with pytest.raises(ValueError, match=r"curves\[0\].*(booleans|integers)"):
        s.compute_distance([np.array([True, False])])
    with pytest.raises(ValueError, match=r"curves.*integer"):
        s.compute_distance([np.array([0.5, 1.0])])
    far = int(np.argmax(np.linalg.norm(s.vertices - s.vertices[f[0]], axis=1)))
    with pytest.raises(ValueError, match=r"curves\[0\].*common quad"):
        s.compute_distance([np.array([f[0], far])])
    with pytest.raises(ValueError, match="points"):
        s.compute_distance([], points=[True])
    with pytest.raises(ValueError, match="points"):
        s.compute_distance([], points=[n])
    with pytest.raises(ValueError, match="no sources"):
        s.compute_distance([])
    with pytest.raises(ValueError, match="level_set_constraint"):
        s.compute_distance([f[[0, 1, 2, 3, 0]]], level_set_constraint="all")
    with pytest.raises(ValueError, match="soft_weight"):
        s.compute_distance([f[[0, 1, 2, 3, 0]]], soft_weight=-1)
    with pytest.raises(ValueError, match="curve_signs"):
        s.compute_distance([f[[0, 1, 2, 3, 0]]], curve_signs=[True, False])
    with pytest.raises(TypeError):
        s.compute_distance([f[[0, 1, 2, 3, 0]]], [True])                    # points is keyword-only


def test_entry_point_and_spacing():
    occ = ball(16, 6)
    a = gsdf.VoxelSurfaceSignedHeatSolver(occ)
    b = gsdf.VoxelSurfaceSignedHeatSolver(occ, spacing=0.5)
    assert a.faces.shape[1] == 4 and a.vertices.shape == (len(a.vertices), 3)
    assert np.allclose(b.vertices, 0.5 * a.vertices)
    ring = region_boundary_curves(a.faces, a.face_centres[:, 2] < 8)
    assert np.allclose(b.compute_distance(ring), 0.5 * a.compute_distance(ring), atol=1e-8)
    # anisotropic voxels: a stretched ball is a sphere again
    c = gsdf.VoxelSurfaceSignedHeatSolver(occ, spacing=[1.0, 1.0, 2.0])
    assert np.ptp(c.vertices[:, 2]) == pytest.approx(2 * np.ptp(a.vertices[:, 2]))
    assert isinstance(a.domain.L, sp.csr_matrix)


# ------------------------------------------------------------------------------------------------ CLI
def test_cli_heat_surface_voxels(tmp_path):
    from click.testing import CliRunner

    from gsdf.cli.main import main
    from gsdf.io import read_mesh

    occ = ball(20, 7)
    np.save(tmp_path / "ball.npy", occ)
    out = tmp_path / "ball.ply"
    r = CliRunner().invoke(main, ["heat-surface", str(tmp_path / "ball.npy"), "--voxels", "--cut", "z<5",
                                  "--spacing", "0.5", "-o", str(out)])
    assert r.exit_code == 0, r.output
    s = VoxelSurfaceSignedHeatSolver(occ, spacing=0.5)
    phi = s.compute_distance(region_boundary_curves(s.faces, s.face_centres[:, 2] < 5))
    from plyfile import PlyData

    d = PlyData.read(str(out))["vertex"]["distance"]
    assert np.allclose(d, phi)
    V, _ = read_mesh(str(out))
    assert np.allclose(V[:, 2].max(), s.vertices[:, 2].max())
    for args, msg in ((["--cut", "q<1"], "--cut"), ([], "exactly one of"), (["--cut", "z<99"], "no curve")):
        r = CliRunner().invoke(main, ["heat-surface", str(tmp_path / "ball.npy"), "--voxels", *args, "-o",
                                      str(out)])
        assert r.exit_code != 0 and msg in r.output
    np.save(tmp_path / "bad.npy", np.zeros((3, 3), bool))
    r = CliRunner().invoke(main, ["heat-surface", str(tmp_path / "bad.npy"), "--voxels", "--cut", "z<1", "-o",
                                  str(out)])
    assert r.exit_code != 0 and "occupancy" in r.output


def test_typed_curves_edge_sets(sphere32):
    Curve = gsdf.Curve
    s, ring = sphere32
    E = np.stack([ring[0][:-1], ring[0][1:]], 1)[np.random.default_rng(0).permutation(len(ring[0]) - 1)]
    assert np.allclose(s.compute_distance([Curve(E)]), s.compute_distance(ring))             # chained edges
    assert np.allclose(s.compute_distance([Curve(ring[0], signed=False)]),
                       s.compute_distance(ring, curve_signs=[False]))


def test_t_coef_bounded_for_every_solver():
    """t = t_coef h² overflowed at t_coef = 1e308 and gave a field uncorrelated with t_coef = 1."""
    from tests.shapes import fibonacci_sphere, uv_sphere

    V, F = uv_sphere(6, 12)
    P = fibonacci_sphere(60)
    occ = np.zeros((6, 6, 6), bool)
    occ[2:4, 2:4, 2:4] = True
    for make in (lambda t: gsdf.SurfaceSignedHeatSolver(V, F, t_coef=t),
                 lambda t: gsdf.PointCloudSignedHeatSolver(P, P, t_coef=t),
                 lambda t: gsdf.PolygonMeshSignedHeatSolver(V, F, t_coef=t),
                 lambda t: gsdf.VoxelSurfaceSignedHeatSolver(occ, t_coef=t),
                 lambda t: gsdf.signed_heat_volume(mesh=(V, F), resolution=8, t_coef=t)):
        for t in (1e308, np.inf, np.nan, 0, -1, 1j, "1"):
            with pytest.raises(ValueError, match="t_coef"):
                make(t)


def test_point_cloud_k_bounded_by_the_cloud():
    from tests.shapes import fibonacci_sphere

    P = fibonacci_sphere(60)
    with pytest.raises(ValueError, match="k: 1000000000 neighbours asked for, but the cloud has 60 points"):
        gsdf.PointCloudSignedHeatSolver(P, P, k=10 ** 9)
    assert gsdf.PointCloudSignedHeatSolver(fibonacci_sphere(20), fibonacci_sphere(20)).P.shape == (20, 3)
