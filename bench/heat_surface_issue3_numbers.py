"""Numbers of issue 3 items 1-2 (intrinsic Delaunay with sources inside faces; nonorientable transport), on the
test geometry of tests/heat/test_intrinsic.py / test_heat_surface_normals.py. Run from the repo root:

    python3 bench/heat_surface_issue3_numbers.py
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from test_heat_surface_intrinsic import _circle, _eps
from test_heat_surface_normals import folded_mobius, _circle_on_strip, _eps as _eps2
from gsdf.heat import SurfaceSignedHeatSolver
from gsdf.data._shapes import anisotropic_mesh, grid_mesh
c = np.array([0.03, 0.02])
for name, (V, F) in (("sliver 32 (stretch 8)", anisotropic_mesh(32, stretch=8)),
                     ("clean jittered Delaunay 32", grid_mesh(32, jitter=0.25, delaunay=True, seed=3))):
    exact = np.linalg.norm(V[:, :2] - c, axis=1) - 0.5
    curve = _circle(V, F)
    p = np.array([0.2, 0.3, 0.5]) @ V[F[100]]
    for idt in (False, True):
        s = SurfaceSignedHeatSolver(V, F, intrinsic_delaunay=idt)
        e = {m: _eps(s.input_ops, s.compute_distance([curve], level_set_constraint=m), exact) for m in ("none", "zero")}
        ep = _eps(s.input_ops, s.compute_distance([], points=[(100, np.array([0.2, 0.3, 0.5]))]), np.linalg.norm(V - p, axis=1))
        print(f"{name}, intrinsic_delaunay={idt}: circle (97 face points) eps none {e['none']:.4f} zero {e['zero']:.4f}; face point source eps {ep:.4f}")
V, F, R, L = folded_mobius()
up = np.array([0, 0, 1.0])
for cc, r in (((0.45, 0.15), 0.25), ((0.15, 0.1), 0.3)):
    exact, curves = _circle_on_strip(V, F, R, L, np.array(cc), r)
    for conn in ("auto", "complex"):
        s = SurfaceSignedHeatSolver(V, F, connection=conn)
        for m in ("zero", "none"):
            phi = s.compute_distance(curves, curve_normals=[up] * len(curves), level_set_constraint=m)
            print(f"flat Mobius, circle c={cc} r={r}, connection={conn}, {m}: eps {_eps2(V, F, phi, exact):.4f}, max err (|SDF|<0.8) {np.abs(phi - exact)[exact < 0.8].max():.4f}")
