"""Every public call that takes query points accepts any (..., 3) array and gives (...)-shaped results, and an
empty set of queries gives empty results (Open3D's raycasting scene and numpy behave so)."""

import numpy as np
import pytest

import gsdf

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
P = np.random.default_rng(0).normal(size=(200, 3))
P /= np.linalg.norm(P, axis=1, keepdims=True)

CALLS = {
    "winding_number": lambda Q: gsdf.winding_number(V, F, Q),
    "fast_winding_number": lambda Q: gsdf.fast_winding_number(V, F, Q),
    "fast_winding_number_points": lambda Q: gsdf.fast_winding_number_points(P, P, Q),
    "winding_number_points": lambda Q: gsdf.winding_number_points(P, P, Q),
    "signed_distance": lambda Q: gsdf.signed_distance(V, F, Q),
    "signed_distance pseudonormal": lambda Q: gsdf.signed_distance(V, F, Q, sign="pseudonormal"),
    "signed_distance closest": lambda Q: gsdf.signed_distance(V, F, Q, return_closest=True),
    "signed_distance_points": lambda Q: gsdf.signed_distance_points(P, P, Q),
    "unsigned_distance": lambda Q: gsdf.unsigned_distance(V, F, Q),
    "unsigned_distance closest": lambda Q: gsdf.unsigned_distance(V, F, Q, return_closest=True),
    "point_cloud_distance": lambda Q: gsdf.point_cloud_distance(P, Q, return_closest=True),
    "FastWindingNumber": lambda Q: gsdf.FastWindingNumber(V, F)(Q),
    "inside": lambda Q: gsdf.inside(V, F, Q),
    "FastWindingNumber.inside": lambda Q: gsdf.FastWindingNumber(V, F).inside(Q),
    "ExactWindingNumber": lambda Q: gsdf.ExactWindingNumber(V, F)(Q),
    "TriangleDistance.query": lambda Q: gsdf.TriangleDistance(V, F).query(Q),
    "TriangleDistance.query_barycentric": lambda Q: gsdf.TriangleDistance(V, F).query_barycentric(Q),
    "PointCloudDistance.query": lambda Q: gsdf.PointCloudDistance(P).query(Q),
    "GridField": lambda Q: gsdf.GridField(np.zeros((3, 3, 3)), [0, 0, 0], [1, 1, 1])(Q),
}


def _as_tuple(r):
    return r if isinstance(r, tuple) else (r,)


@pytest.mark.parametrize("name", sorted(CALLS))
def test_query_shapes_and_empty_queries(name):
    call = CALLS[name]
    Q = np.random.default_rng(1).uniform(-0.5, 1.5, size=(4, 5, 3))
    flat = _as_tuple(call(Q.reshape(-1, 3)))
    shaped = _as_tuple(call(Q))
    for a, b in zip(flat, shaped):
        assert b.shape == (4, 5) + a.shape[1:]
        np.testing.assert_array_equal(b.reshape(a.shape), a)
    for empty in (np.zeros((0, 3)), np.zeros((2, 0, 3))):
        got = _as_tuple(call(empty))
        for a, b in zip(flat, got):
            assert b.shape == empty.shape[:-1] + a.shape[1:] and b.dtype == a.dtype


def test_winding_number_2d_shapes():
    V2 = np.array([[0, 0], [1, 0], [0, 1.0]])
    E = np.array([[0, 1], [1, 2], [2, 0]])
    Q = np.full((2, 3, 2), 0.2)
    assert gsdf.winding_number_2d(V2, E, Q).shape == (2, 3)
    assert gsdf.winding_number_2d(V2, E, np.zeros((0, 2))).shape == (0,)
