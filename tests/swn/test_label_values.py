"""Projective interpolation of the labels at interior endpoints (SurfaceWindingNumbers.label_values)."""

import numpy as np

from gsdf.data._shapes import grid_mesh
from gsdf.swn._solver import SurfaceWindingNumbers


def _case():
    V, F = grid_mesh(16)                     # 17 x 17 vertices, vertex (i, j) = 17 i + j
    swn = SurfaceWindingNumbers(V, F)
    # a straight horizontal line j = 8 across the grid, with 1-edge gaps between runs of 2 edges
    full = [17 * i + 8 for i in range(17)]
    runs = [full[k:k + 3] for k in range(0, 15, 3)]
    return swn, runs, full


def test_label_values_fill_endpoint_corners():
    swn, runs, _ = _case()
    res = swn.solve(runs)
    ends = res.endpoints
    assert ends.any()
    w = np.arange(3 * swn.dec.n_faces, dtype=float).reshape(-1, 3)
    out = swn.label_values(w, ends)
    E = ends[swn.dec.F]
    one = E.sum(1) == 1
    f = np.flatnonzero(one)[0]
    k = int(np.argmax(E[f]))
    assert np.isclose(out[f, k], np.delete(w[f], k).mean())
    assert np.array_equal(out[~E.any(1)], w[~E.any(1)])          # faces off the endpoints untouched
    allend = E.all(1)
    assert np.array_equal(out[allend], w[allend])


def test_gapped_line_labels_follow_the_line():
    swn, runs, full = _case()
    res = swn.solve(runs)                    # simply connected: branch rule, projective labels
    lab_full = swn.solve([full]).face_labels
    assert np.array_equal(np.round(res.corner_values.mean(1)).astype(np.int64), res.face_labels)
    # the faces of the deleted edges are labelled as with the whole line
    g_full = swn.chain([full])
    g_run = swn.chain(runs)
    gone = np.flatnonzero((g_full != 0) & (g_run == 0))
    fs = swn.topology.edge_faces[gone].ravel()
    fs = fs[fs >= 0]
    shift = np.bincount((lab_full - res.face_labels) + 5).argmax() - 5
    assert np.array_equal(res.face_labels[fs] + shift, lab_full[fs])


def test_solve_fills_endpoint_corners():
    # through solve(): a corner at an interior endpoint holds the mean of its face's other two corners (the raw
    # branch-rule ramp value there is different), so the face is labelled by its far edge
    swn, runs, _ = _case()
    res = swn.solve(runs)
    E = res.endpoints[swn.dec.F]
    one = np.flatnonzero(E.sum(1) == 1)
    assert len(one) > 0
    w = res.corner_values[one]
    e = E[one]
    others = (w * ~e).sum(1) / 2.0
    assert np.allclose(w[e], others)
