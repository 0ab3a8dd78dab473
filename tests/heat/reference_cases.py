"""Inputs of the old-vs-new agreement tests of the signed heat core (tests/heat/test_core.py).

``python3 tests/heat/reference_cases.py`` (with ``PYTHONPATH=src``) regenerates tests/data/heat_core_reference.npz
from the code as it is; the fixture committed was generated from the pre-core solvers (commit 3c084cb), so the
tests compare the core against the old per-domain implementations.
"""

import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))  # run as a script



def surface_cases():
    """(name, build_solver, curves, kwargs) for triangle, intrinsic, polygon and point-cloud domains."""
    from gsdf.heat import PolygonMeshSignedHeatSolver, PointCloudSignedHeatSolver, SurfaceSignedHeatSolver
    from gsdf.contour._surface_curves import level_set_curves
    from gsdf.data._shapes import grid_mesh, sphere_mesh

    from tests.shapes import fibonacci_sphere

    V, F = grid_mesh(20, jitter=0.2, seed=1)
    circle = level_set_curves(V, F, np.linalg.norm(V, axis=1) - 0.5)
    open_seg = np.array([22, 23, 24, 25])
    Vs, Fs = sphere_mesh(2)
    z = Vs[:, 2]
    eq = level_set_curves(Vs, Fs, z - 0.1)
    bary_curve = [(3, np.array([0.2, 0.3, 0.5])), (10, np.array([0.6, 0.2, 0.2])), (40, np.array([0.3, 0.3, 0.4]))]
    cases = []
    tri = lambda: SurfaceSignedHeatSolver(V, F)          # noqa: E731
    sph = lambda: SurfaceSignedHeatSolver(Vs, Fs)        # noqa: E731
    intr = lambda: SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=True)  # noqa: E731
    for mode in ("zero", "multiple", "none"):
        cases.append((f"tri_circle_{mode}", tri, circle, dict(level_set_constraint=mode)))
        cases.append((f"sph_eq_{mode}", sph, eq, dict(level_set_constraint=mode)))
        cases.append((f"intr_circle_{mode}", intr, circle, dict(level_set_constraint=mode)))
    cases.append(("tri_soft", tri, circle, dict(soft_weight=10.0)))
    cases.append(("tri_soft_multiple", tri, circle + [open_seg], dict(soft_weight=5.0, level_set_constraint="multiple")))
    cases.append(("tri_points", tri, [], dict(points=[5, 100, (7, np.array([0.2, 0.3, 0.5]))])))
    cases.append(("tri_unsigned", tri, [open_seg], dict(curve_signs=[False])))
    cases.append(("tri_mixed", tri, circle + [open_seg], dict(curve_signs=[True] * len(circle) + [False],
                                                                 points=[300])))
    cases.append(("sph_bary", sph, [bary_curve], dict()))
    cases.append(("sph_bary_multiple", sph, [bary_curve], dict(level_set_constraint="multiple")))
    cases.append(("sph_bary_soft", sph, [bary_curve], dict(soft_weight=3.0)))
    cases.append(("intr_bary", intr, [[(30, np.array([0.2, 0.3, 0.5])), (31, np.array([0.3, 0.3, 0.4]))]], dict()))
    cases.append(("intr_points", intr, [], dict(points=[5, (7, np.array([0.2, 0.3, 0.5]))])))

    # polygon mesh: a quad grid (and its curve along quad edges)
    n = 16
    x = np.linspace(-1, 1, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    Vq = np.column_stack([X.ravel(), Y.ravel(), 0.1 * np.sin(2 * X.ravel()) * np.cos(Y.ravel())])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    Q = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()], 1)
    loop = np.concatenate([idx[4, 4:12], idx[4:12, 12], idx[12, 12:4:-1], idx[12:3:-1, 4]])
    poly = lambda: PolygonMeshSignedHeatSolver(Vq, Q)    # noqa: E731
    for mode in ("zero", "multiple", "none"):
        cases.append((f"poly_loop_{mode}", poly, [loop], dict(level_set_constraint=mode)))
    cases.append(("poly_soft", poly, [loop], dict(soft_weight=10.0)))
    cases.append(("poly_soft_multi", poly, [loop, idx[2, 2:6]], dict(soft_weight=10.0, level_set_constraint="multiple")))
    cases.append(("poly_points_unsigned", poly, [idx[2, 2:6]], dict(curve_signs=[False], points=[200])))
    try:
        import robust_laplacian  # noqa: F401
    except ImportError:
        return cases
    P = fibonacci_sphere(800)
    d = P[:, 2]
    ring = np.flatnonzero(np.abs(d - 0.2) < 0.04)
    ang = np.arctan2(P[ring, 1], P[ring, 0])
    ring = ring[np.argsort(ang)]
    ring = np.append(ring, ring[0])
    pc = lambda: PointCloudSignedHeatSolver(P, P)        # noqa: E731
    for mode in ("zero", "multiple", "none"):
        cases.append((f"pc_ring_{mode}", pc, [ring], dict(level_set_constraint=mode)))
    cases.append(("pc_soft", pc, [ring], dict(soft_weight=10.0)))
    cases.append(("pc_points", pc, [], dict(points=[3, 400])))
    return cases


def volume_cases():
    """(name, kwargs of signed_heat_volume) on small grids and tets."""
    from tests.shapes import fibonacci_sphere, uv_sphere

    V, F = uv_sphere(8, 16)
    F = F[:-6]                                                     # a hole
    P = fibonacci_sphere(300)
    return [
        ("grid_mesh_none", dict(mesh=(V, F), resolution=16, level_set_constraint="none")),
        ("grid_pts_none", dict(points=(P, P), resolution=16, level_set_constraint="none")),
        ("grid_mesh_soft", dict(mesh=(V, F), resolution=16, level_set_constraint="zero")),
        ("grid_mesh_exact", dict(mesh=(V, F), resolution=12, level_set_constraint="zero", constraint="exact")),
        ("tet_mesh_zero", dict(mesh=(V, F), domain="tet", resolution=10)),
        ("tet_mesh_multiple", dict(mesh=(V, F), domain="tet", resolution=10, level_set_constraint="multiple")),
        ("tet_mesh_none", dict(mesh=(V, F), domain="tet", resolution=10, level_set_constraint="none")),
        ("tet_heat", dict(mesh=(V, F), domain="tet", resolution=10, step1="heat")),
    ]


def main():
    from gsdf.heat.volume import signed_heat_volume

    out = {}
    for name, build, curves, kw in surface_cases():
        out[name] = build().compute_distance(curves, **kw)
    for name, kw in volume_cases():
        f = signed_heat_volume(**kw)
        out[name] = np.asarray(f.values).ravel()
    path = os.path.join(os.path.dirname(__file__), "..", "data", "heat_core_reference.npz")
    np.savez_compressed(path, **out)
    print(f"wrote {len(out)} arrays to {path}")


if __name__ == "__main__":
    main()
