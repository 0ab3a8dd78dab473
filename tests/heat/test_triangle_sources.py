"""Triangle-mesh sources assembled from :class:`gsdf.Curve` directly against the frozen outputs of the former
path (Curve → raw lists → parsed sources → Sources, commit 6762c9c): the assembled sources are bit-identical, and
so are φ, sharpening, the L1 integration and split curves up to the factorizations' rounding."""

import os

import numpy as np
import pytest

from tests.heat.reference_cases import triangle_source_cases, triangle_source_outputs

REF = np.load(os.path.join(os.path.dirname(__file__), "..", "data", "heat_sources_reference.npz"))
CASES = triangle_source_cases()
SOURCE_FIELDS = ("X0", "node_vertex", "node_curve", "shift_weights", "point_vertex", "/indptr", "/indices", "/data")


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_sources_from_curves_match_the_former_path(case):
    got = triangle_source_outputs(*case)
    want = {k: REF[k] for k in REF.files if k.startswith(case[0] + "/")}
    assert sorted(got) == sorted(want)
    for key, ref in want.items():
        if key.endswith(SOURCE_FIELDS):
            assert got[key].dtype == ref.dtype and np.array_equal(got[key], ref), key     # bit-identical
        elif ref.size:                              # solves: saddle systems amplify BLAS rounding (test_core.py)
            tol = 1e-6 * max(1.0, float(np.abs(ref).max()))
            assert got[key].shape == ref.shape and np.abs(got[key] - ref).max() <= tol, key


def test_split_curve_takes_one_curve():
    from gsdf.data._shapes import grid_mesh
    from gsdf.heat import SurfaceSignedHeatSolver

    s = SurfaceSignedHeatSolver(*grid_mesh(6))
    assert [v for v, _ in s.split_curve([8, 9, 10])] == [8, 9, 10]
    with pytest.raises(ValueError, match="one curve"):
        s.split_curve(np.array([[1, 2], [8, 9]]))
