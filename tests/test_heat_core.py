"""The signed heat core (gsdf.heat.core) against the frozen outputs of the pre-core solvers, and typed sources."""

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))

from heat_reference_cases import surface_cases, volume_cases  # noqa: E402

REF = np.load(os.path.join(os.path.dirname(__file__), "data", "heat_core_reference.npz"))


SURFACE = surface_cases()


@pytest.mark.parametrize("name,build,curves,kw", SURFACE, ids=[c[0] for c in SURFACE])
def test_surface_core_matches_pre_core_solvers(name, build, curves, kw):
    phi = build().compute_distance(curves, **kw)
    ref = REF[name]
    scale = max(1.0, float(np.abs(ref).max()))
    assert np.abs(phi - ref).max() <= 1e-8 * scale, f"{name}: max diff {np.abs(phi - ref).max():.3g}"
