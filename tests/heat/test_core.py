"""The signed heat core (gsdf.heat._core) against the frozen outputs of the pre-core solvers, and typed sources."""

import os

import numpy as np
import pytest


from tests.heat.reference_cases import surface_cases, volume_cases  # noqa: E402

REF = np.load(os.path.join(os.path.dirname(__file__), "..", "data", "heat_core_reference.npz"))


SURFACE = surface_cases()
# cases whose hard constraint is solved through the saddle system (see the tolerance below)
SADDLE_CASES = {"sph_eq_zero", "sph_eq_multiple", "intr_bary"}


@pytest.mark.parametrize("name,build,curves,kw", SURFACE, ids=[c[0] for c in SURFACE])
def test_surface_core_matches_pre_core_solvers(name, build, curves, kw):
    phi = build().compute_distance(curves, **kw)
    ref = REF[name]
    scale = max(1.0, float(np.abs(ref).max()))
    # the soft penalty is solved by preconditioned CG to a relative residual of 1e-3 (GridPoisson.penalty_tol):
    # agreement with the frozen run holds to that tolerance (φ within 4.2e-4 of its range), not to rounding
    # (issue 17). The hard constraints
    # through points inside faces are a saddle system with a -1e-12 I block (FactorizedPoisson.constrained): rounding
    # in the BLAS kernels under SuperLU is amplified there, so the same code gives phi differing by up to
    # 1.7e-7 with OpenBLAS's SkylakeX kernels against the Haswell/Zen ones the fixture was made with
    # (OPENBLAS_CORETYPE=SkylakeX vs Haswell, measured 2026-12-03); elsewhere they agree to 3e-14.
    tol = 1e-3 if name == "grid_mesh_soft" else 1e-6 if name in SADDLE_CASES else 1e-8
    assert np.abs(phi - ref).max() <= tol * scale, f"{name}: max diff {np.abs(phi - ref).max():.3g}"


# ------------------------------------------------------------------------------------------ typed sources
def _grid_solver():
    from gsdf.heat import SurfaceSignedHeatSolver
    from gsdf.contour._surface_curves import region_boundary_curves
    from gsdf.data._shapes import grid_mesh

    V, F = grid_mesh(12)
    inside = (np.abs(V[F][:, :, :2]) <= 0.5 + 1e-9).all(axis=(1, 2))
    (loop,) = region_boundary_curves(F, inside)
    return SurfaceSignedHeatSolver(V, F), loop


def test_curve_is_exported_and_equals_raw_arrays():
    import gsdf

    solver, loop = _grid_solver()
    raw = solver.compute_distance([loop])
    np.testing.assert_array_equal(solver.compute_distance([gsdf.Curve(loop)]), raw)
    np.testing.assert_array_equal(solver.compute_distance(gsdf.Curve(loop)), raw)       # one curve alone
    edges = np.stack([loop[:-1], loop[1:]], 1)[::-1]                                    # shuffled edge set
    np.testing.assert_allclose(solver.compute_distance([gsdf.Curve(edges)]), raw, atol=1e-12)
    uns = solver.compute_distance([loop], curve_signs=[False])
    np.testing.assert_array_equal(solver.compute_distance([gsdf.Curve(loop, signed=False)]), uns)
    assert uns.min() > -1e-9 and raw.min() < -0.3                                       # unsigned vs signed


def test_points_and_curve_signs_are_keyword_only():
    solver, loop = _grid_solver()
    with pytest.raises(TypeError):
        solver.compute_distance([loop], [True])            # potpourri3d's curve_signs position: refused


@pytest.mark.parametrize("kw,match", [
    (dict(points=[True]), r"points\[0\]"),
    (dict(points=np.array([True, False])), "points"),
    (dict(points=[1.5]), r"points\[0\]"),
    (dict(points=["3"]), r"points\[0\]"),
    (dict(curve_signs=[1.0]), r"curve_signs\[0\]"),
    (dict(curve_signs=["yes"]), r"curve_signs\[0\]"),
    (dict(curve_signs=[True, False]), "curve_signs"),
])
def test_bad_source_types_name_the_argument(kw, match):
    solver, loop = _grid_solver()
    with pytest.raises(ValueError, match=match):
        solver.compute_distance([loop], **kw)


def test_bad_curves_name_the_argument():
    import gsdf

    solver, loop = _grid_solver()
    for bad, match in [([np.array([True, False, True])], r"curves\[0\]"), ([True, False], r"curves\[0\]"),
                       ([[0.5, 1.5]], r"curves\[0\]"), ([loop, 7], r"curves\[1\]"), ("abc", "curves"),
                       ([np.array([0, 10_000])], r"curves\[0\]")]:
        with pytest.raises(ValueError, match=match):
            solver.compute_distance(bad)
    with pytest.raises(ValueError, match="signed"):
        gsdf.Curve(loop, signed=1)
    with pytest.raises(ValueError, match="contradicts"):
        solver.compute_distance([gsdf.Curve(loop)], curve_signs=[False])


def test_curve_refuses_negative_indices_and_a_name_that_is_not_text():
    import gsdf

    for nodes in (np.array([-1, 1, 2, 3]), np.array([[0, 1], [1, -2]]), [(-1, np.array([1.0, 0, 0])), (1, ())]):
        with pytest.raises(ValueError, match=r"curve.*(negative vertex index|>= 0)"):
            gsdf.Curve(nodes)
    for name in (b"x", None, 3):
        with pytest.raises(ValueError, match="name: expected a string"):
            gsdf.Curve([0, 1, 2], name=name)


def test_every_front_end_takes_curve_and_rejects_bools():
    import gsdf

    n = 8
    x = np.linspace(-1, 1, n + 1)
    V = np.array([[a, b, 0.0] for a in x for b in x])
    i = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    Q = np.stack([i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel(), i[:-1, 1:].ravel()], 1)
    loop = np.concatenate([i[2, 2:6], i[2:6, 6], i[6, 6:2:-1], i[6:1:-1, 2]])
    s = gsdf.PolygonMeshSignedHeatSolver(V, Q)
    np.testing.assert_array_equal(s.compute_distance([gsdf.Curve(loop)]), s.compute_distance([loop]))
    with pytest.raises(ValueError, match=r"points\[0\]"):
        s.compute_distance([loop], points=[True])
    with pytest.raises(ValueError, match=r"curves\[0\]"):
        s.compute_distance([gsdf.Curve([(0, np.array([1.0, 0, 0])), (1, np.array([1.0, 0, 0]))])])


def test_chain_edges():
    from gsdf.curves import chain_edges

    assert [p.tolist() for p in chain_edges(np.array([[2, 3], [0, 1], [1, 2]]))] == [[0, 1, 2, 3]]
    loops = chain_edges(np.array([[0, 1], [1, 2], [2, 0], [5, 6]]))
    assert sorted(len(p) for p in loops) == [2, 4] and any(p[0] == p[-1] for p in loops)
    und = chain_edges(np.array([[1, 0], [1, 2]]), directed=False)
    assert len(und) == 1 and sorted(und[0].tolist()) == [0, 1, 2]


def test_core_progress_signature():
    solver, loop = _grid_solver()
    seen = []
    solver.compute_distance([loop], progress=lambda stage, fraction: seen.append((stage, fraction)))
    assert ("heat (step I)", 1.0) in seen and ("poisson (step III)", 1.0) in seen
    assert all(0.0 <= f <= 1.0 for _, f in seen)


# ------------------------------------------------------------------------------------------ volumes
VOLUME = volume_cases()


@pytest.fixture
def tree_step1(monkeypatch):
    """Step I on grids by the Yukawa tree sum, as in the frozen runs (grids choose the screened grid solve where
    it is trusted since, :class:`gsdf.heat.grid._domain.GridDomain`)."""
    import functools

    import gsdf.heat.volume._solve as solve
    from gsdf.heat.grid._domain import GridDomain

    monkeypatch.setattr(solve, "GridDomain", functools.partial(GridDomain, step1="yukawa"))


@pytest.mark.parametrize("name,kw", VOLUME, ids=[c[0] for c in VOLUME])
def test_volume_core_matches_pre_core_solvers(name, kw, monkeypatch, tree_step1):
    import gsdf.heat.volume as hv
    from gsdf.heat.volume import signed_heat_volume

    if "points" in kw:
        # the frozen run estimated cloud areas from 8·k candidates; the default is now 2·k (lower error on the
        # benchmark clouds): the default stays within 1e-4, the old areas reproduce the run exactly
        phi = np.asarray(signed_heat_volume(**kw).values).ravel()
        assert np.abs(phi - REF[name]).max() <= 1e-4 * max(1.0, float(np.abs(REF[name]).max()))
        monkeypatch.setattr(hv, "_cloud_sources", lambda P, N: hv._sources._cloud_sources(P, N, candidates=8))
    phi = np.asarray(signed_heat_volume(**kw).values).ravel()
    ref = REF[name]
    scale = max(1.0, float(np.abs(ref).max()))
    # the soft penalty is solved by preconditioned CG to a relative residual of 1e-3 (GridPoisson.penalty_tol):
    # agreement with the frozen run holds to that tolerance (φ within 4.2e-4 of its range), not to rounding.
    # The hard constraints
    # through points inside faces are a saddle system with a -1e-12 I block (FactorizedPoisson.constrained): rounding
    # in the BLAS kernels under SuperLU is amplified there, so the same code gives phi differing by up to
    # 1.7e-7 with OpenBLAS's SkylakeX kernels against the Haswell/Zen ones the fixture was made with
    # (OPENBLAS_CORETYPE=SkylakeX vs Haswell, measured 2026-12-03); elsewhere they agree to 3e-14.
    tol = 1e-3 if name == "grid_mesh_soft" else 1e-6 if name in SADDLE_CASES else 1e-8
    assert np.abs(phi - ref).max() <= tol * scale, f"{name}: max diff {np.abs(phi - ref).max():.3g}"


def test_grid_multiple_and_hard_zero():
    """Two disjoint spheres: "multiple" makes φ one constant per sphere (cell rows), "zero" makes it 0 on both,
    the soft penalty only nearly; inside is negative in every case."""
    from gsdf.heat.volume import VolumeHeatOptions, signed_heat_volume
    from gsdf.heat.grid._poisson import cell_constraint_matrix

    from tests.shapes import uv_sphere

    V, F = uv_sphere(10, 20, radius=0.5)
    V2 = np.concatenate([V - [0.8, 0, 0], V + [0.8, 0, 0]])
    F2 = np.concatenate([F, F + len(V)])
    kw = dict(mesh=(V2, F2), resolution=(20, 12, 12), bbox_min=[-1.5, -0.7, -0.7], bbox_max=[1.5, 0.7, 0.7])
    fields = {m: signed_heat_volume(**kw, options=VolumeHeatOptions(level_set_constraint=m, soft_weight=None))
              for m in ("zero", "multiple")}
    fields["soft"] = signed_heat_volume(**kw, options=VolumeHeatOptions(soft_weight=10.0))
    T = V2[F2]
    B = T.mean(axis=1)
    a = 0.5 * np.linalg.norm(np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]), axis=1)
    side = B[:, 0] > 0
    for name, f in fields.items():
        assert f([[-0.8, 0, 0]])[0] < -0.3 and f([[0.8, 0, 0]])[0] < -0.3, name
        assert f([[0, 0.65, 0]])[0] > 0.05, name
    lo, sp_ = fields["zero"].bbox_min, fields["zero"].spacing
    for s in (side, ~side):
        C, _ = cell_constraint_matrix(B[s], a[s], lo, sp_, fields["zero"].shape)
        z = C @ fields["zero"].values.ravel()
        m = C @ fields["multiple"].values.ravel()
        soft = C @ fields["soft"].values.ravel()
        h = float(sp_.max())
        assert np.abs(z).max() < 1e-3 * h                     # hard: zero on every cell row
        assert np.ptp(m) < 1e-3 * h                           # multiple: one constant per component
        assert np.ptp(soft) > 10 * np.ptp(m)                  # the penalty only pulls
    assert fields["multiple"].meta["constraint_rows"] > 0


# ------------------------------------------------------------------------------------------ the protocol
def test_a_new_vertex_domain_plugs_into_the_core():
    """A planar triangle mesh written as a 17-line VertexSurfaceDomain (flat: transport is the identity, so the
    connection Laplacian is the cotan Laplacian) gives the distance to a circle through the core."""
    import scipy.sparse as sp

    from gsdf.heat._core import SignedHeatCore
    from gsdf.heat._domain import VertexSurfaceDomain, tangent_frames
    from gsdf.data._shapes import grid_mesh
    from gsdf.mesh._triangle_ops import TriangleOperators

    class FlatVertexDomain(VertexSurfaceDomain):
        def __init__(self, V, F):
            self.ops = TriangleOperators(V, F)
            L = self.ops.cotan_laplacian()
            N = np.tile([0.0, 0, 1], (len(V), 1))
            e1, e2 = tangent_frames(N)
            h = float(self.ops.edge_len.mean())
            super().__init__(V, L, self.ops.vertex_mass(), sp.csr_matrix(L, dtype=np.complex128), N, e1, e2, h * h)

        def gather(self, X):
            return self.to_3d(X)[self.ops.F].sum(axis=1)

        def divergence(self, Y):
            return self.ops.divergence(Y)

    V, F = grid_mesh(40)
    r = np.linalg.norm(V[:, :2], axis=1)
    loop = np.flatnonzero(np.abs(r - 0.5) < 0.03)                         # vertices near the circle, in order
    loop = loop[np.argsort(np.arctan2(V[loop, 1], V[loop, 0]))]
    assert len(loop) > 20
    core = SignedHeatCore(FlatVertexDomain(V, F))
    phi = core.compute_distance([np.append(loop, loop[0])], level_set_constraint="none")
    exact = r - 0.5
    inner = r < 0.9
    err = np.abs(phi[inner] - exact[inner]).mean()
    assert err < 0.02, err                                                  # measured 0.005
    assert abs(phi[np.argmin(r)] + 0.5) < 0.05


def test_grid_multiple_on_a_cloud_uses_its_components():
    from gsdf.heat.volume import VolumeHeatOptions, signed_heat_volume
    from gsdf.heat.volume._sources import cloud_components, point_sources

    from tests.shapes import fibonacci_sphere

    P = fibonacci_sphere(400, radius=0.5)
    P2 = np.concatenate([P - [0.8, 0, 0], P + [0.8, 0, 0]])
    src = point_sources(P2, P2 - np.repeat([[-0.8, 0, 0], [0.8, 0, 0]], 400, axis=0))
    lab = cloud_components(src.B)
    assert len(np.unique(lab)) == 2 and np.all(lab[:400] == lab[0]) and np.all(lab[400:] == lab[400])
    N = P2 - np.repeat([[-0.8, 0, 0], [0.8, 0, 0]], 400, axis=0)
    f = signed_heat_volume(points=(P2, N), resolution=(20, 12, 12), bbox_min=[-1.5, -0.7, -0.7],
                           bbox_max=[1.5, 0.7, 0.7], options=VolumeHeatOptions(level_set_constraint="multiple"))
    assert f([[-0.8, 0, 0]])[0] < -0.3 and f([[0.8, 0, 0]])[0] < -0.3 and f([[0, 0.65, 0]])[0] > 0.05


def test_grid_default_is_the_fast_penalty_and_none_is_hard(tree_step1):
    """soft_weight="auto": the penalty (c = 10) on grids, so the default call stays as fast as before the core."""
    from gsdf.heat.volume import VolumeHeatOptions, signed_heat_volume

    kw = dict(volume_cases())["grid_mesh_soft"]
    phi = np.asarray(signed_heat_volume(**kw).values).ravel()
    # to the CG tolerance (relative residual 1e-3), see test_volume_core_matches_pre_core_solvers
    assert np.abs(phi - REF["grid_mesh_soft"]).max() <= 1e-3 * max(1.0, float(np.abs(REF["grid_mesh_soft"]).max()))
    with pytest.raises(ValueError, match="soft_weight"):
        signed_heat_volume(**kw, options=VolumeHeatOptions(soft_weight="bogus"))
