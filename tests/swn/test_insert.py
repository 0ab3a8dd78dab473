"""Re-triangulation of faces around inserted curve points."""

import numpy as np

from gsdf.swn._insert import _ear_clip


def test_ear_clip_far_from_the_origin_makes_no_zero_area_triangle():
    """The SWN demo's twirl: a small face (area ~5e-7) at coordinates ~15 with the midpoint of one edge
    inserted. The midpoint is off the edge's line by an ulp of 15; compared in absolute coordinates with
    1e-12 of the face's area, the collinear triple (a, mid, b) passed as a triangle and its edge got 4 faces."""
    rng = np.random.default_rng(0)
    for _ in range(200):
        a = np.array([15.0, -3.0, 7.0]) + rng.uniform(-1, 1, 3)
        b = a + rng.normal(size=3) * 1e-3
        c = a + rng.normal(size=3) * 1e-3
        X = np.array([a, b, c, 0.5 * (a + b)])
        tris = _ear_clip([0, 3, 1, 2], X)
        assert len(tris) == 2
        for t in tris:
            assert set(t) != {0, 1, 3}  # never the degenerate a, mid, b
            n = np.cross(X[t[1]] - X[t[0]], X[t[2]] - X[t[0]])
            assert np.linalg.norm(n) > 1e-3 * np.linalg.norm(np.cross(b - a, c - a))
