"""Open3D's own tests of RaycastingScene (python/test/t/geometry/test_raycasting_scene.py) and of the triangle
mesh (test_trianglemesh.py: isosurfaces, booleans), re-expressed to call gsdf.

Source (read, not copied, except the 6 x 6 x 6 expected occupancy of test_sphere_wrong_occupancy, data of an MIT
test): github.com/isl-org/Open3D @ 22a6a307 (MIT). Open3D's primitives (create_box, create_sphere(0.8) in the
legacy and tensor versions) and its boolean answers are recorded from open3d 0.20.0 by ../record_refs.py into
data/refs/open3d.npz. Ray casting (cast_rays, test_occlusions, count/list_intersections) has no gsdf counterpart.

gsdf counterparts: compute_closest_points -> unsigned_distance(return_closest=True); compute_distance ->
unsigned_distance; compute_signed_distance -> signed_distance; compute_occupancy -> winding_number(...) >= 1/2;
create_isosurfaces -> GridField(...).isosurface; boolean_* -> mesh_boolean.
"""

from __future__ import annotations

import numpy as np
import pytest

import gsdf
from tests.conformance.helpers import enclosed_volume, euler_characteristic, exterior_edge_count, ref

TRI_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]], dtype=np.float32)
TRI_F = np.array([[0, 1, 2]], dtype=np.uint32)


@pytest.fixture(scope="module")
def o3d():
    return ref("open3d")


def test_compute_closest_points():
    """test_raycasting_scene.py::test_compute_closest_points — one triangle, queries (0.2, 0.1, 1), (10, 10, 10):
    primitive 0, points (0.2, 0.1, 0) and (1, 1, 0) (rtol = atol = 1e-6)."""
    q = np.array([[0.2, 0.1, 1], [10, 10, 10]], dtype=np.float32)
    d, face, C = gsdf.unsigned_distance(TRI_V, TRI_F, q, return_closest=True)
    assert (face == 0).all()
    np.testing.assert_allclose(C, [[0.2, 0.1, 0.0], [1, 1, 0]], rtol=1e-6, atol=1e-6)


QUERIES = np.array([[0.5, 0.5, 0.5], [-0.5, -0.5, -0.5], [0, 0, 0]], dtype=np.float32)


def test_compute_distance(o3d):
    """test_raycasting_scene.py::test_compute_distance — unit box (create_box), queries centre, (-.5,-.5,-.5),
    corner: [0.5, sqrt(3 * 0.25), 0] (assert_allclose defaults, rtol 1e-7)."""
    d = gsdf.unsigned_distance(o3d["box_V"], o3d["box_F"], QUERIES)
    np.testing.assert_allclose(d, [0.5, np.sqrt(3 * 0.5 ** 2), 0.0])


def test_compute_signed_distance(o3d):
    """test_raycasting_scene.py::test_compute_signed_distance — [-0.5, sqrt(3 * 0.25), 0] (negative inside in
    both)."""
    s = gsdf.signed_distance(o3d["box_V"], o3d["box_F"], QUERIES)
    np.testing.assert_allclose(s, [-0.5, np.sqrt(3 * 0.5 ** 2), 0.0])


def test_compute_occupancy(o3d):
    """test_raycasting_scene.py::test_compute_occupancy — centre 1, outside point 0."""
    w = gsdf.winding_number(o3d["box_V"], o3d["box_F"], QUERIES[:2])
    np.testing.assert_allclose((w >= 0.5).astype(float), [1.0, 0.0])
    assert gsdf.inside(o3d["box_V"], o3d["box_F"], QUERIES[:2]).tolist() == [True, False]


@pytest.mark.parametrize("shape", [[11], [1, 2, 3], [32, 14], [0]])
def test_output_shapes(shape):
    """test_raycasting_scene.py::test_output_shapes — distance, signed distance and occupancy of queries shaped
    shape + [3] have shape ``shape``; closest points shape + [3]. (Ray outputs: no gsdf counterpart.) [0]: an
    empty query array gives empty results. Regression: (..., 3) and (0, 3) queries were refused."""
    rs = np.random.RandomState(123)
    rs.uniform(size=shape + [6])                      # the rays drawn first, as the peer does
    q = rs.uniform(size=shape + [3]).astype(np.float32)
    assert list(gsdf.unsigned_distance(TRI_V, TRI_F, q).shape) == shape
    assert list(gsdf.signed_distance(TRI_V, TRI_F, q).shape) == shape
    assert list(gsdf.winding_number(TRI_V, TRI_F, q).shape) == shape
    d, face, C = gsdf.unsigned_distance(TRI_V, TRI_F, q, return_closest=True)
    assert list(face.shape) == shape and list(C.shape) == shape + [3]


# test_sphere_wrong_occupancy's expected occupancy (Open3D, MIT): 6 x 6 x 6, meshgrid's default 'xy' indexing
_RING = [[0, 0, 0, 0, 0, 0], [0, 0, 1, 1, 0, 0], [0, 1, 1, 1, 1, 0], [0, 1, 1, 1, 1, 0], [0, 0, 1, 1, 0, 0],
         [0, 0, 0, 0, 0, 0]]
_FULL = [[0, 0, 0, 0, 0, 0], [0, 1, 1, 1, 1, 0], [0, 1, 1, 1, 1, 0], [0, 1, 1, 1, 1, 0], [0, 1, 1, 1, 1, 0],
         [0, 0, 0, 0, 0, 0]]
_ZERO = [[0] * 6] * 6
EXPECTED = np.array([_ZERO, _RING, _FULL, _FULL, _RING, _ZERO], dtype=np.float32)


def test_sphere_wrong_occupancy(o3d):
    """test_raycasting_scene.py::test_sphere_wrong_occupancy — t.geometry.TriangleMesh.create_sphere(0.8), a 6^3
    grid from 1.1 x min to 1.1 x max: occupancy equals the expected array exactly (with nsamples=3 too; gsdf
    has no sampling, one answer)."""
    V, F = o3d["tsphere_V"], o3d["tsphere_F"]
    xyz_range = np.linspace(V.min(0) * 1.1, V.max(0) * 1.1, num=6)
    q = np.stack(np.meshgrid(*xyz_range.T), axis=-1).astype(np.float32)
    occ = (gsdf.winding_number(V, F, q) >= 0.5).astype(np.float32)  # (6, 6, 6, 3) queries -> (6, 6, 6)
    np.testing.assert_equal(occ, EXPECTED)
    np.testing.assert_equal(gsdf.inside(V, F, q).astype(np.float32), EXPECTED)
    # the same grid refined to 48^3 (the grid-cell path of gsdf.inside): the fast winding number's answers
    fine = np.linspace(V.min(0) * 1.1, V.max(0) * 1.1, num=48)
    qf = np.stack(np.meshgrid(*fine.T), axis=-1).reshape(-1, 3)
    np.testing.assert_equal(gsdf.inside(V, F, qf), gsdf.FastWindingNumber(V, F)(qf) > 0.5)


def test_create_isosurfaces():
    """test_trianglemesh.py::test_create_isosurfaces — |x| - 0.5 on a 64^3 grid over [-1, 1]^3 ('ij'): 4728
    vertices, 9452 triangles."""
    coords = np.stack(np.meshgrid(*3 * [np.linspace(-1, 1, num=64)], indexing="ij"), axis=-1)
    vol = np.linalg.norm(coords, axis=-1) - 0.5
    V, F = gsdf.GridField(vol, [-1, -1, -1], [1, 1, 1]).isosurface(0.0)
    assert V.shape[0] == 4728
    assert F.shape[0] == 9452


OPS = [("union", (730, 1384)), ("intersection", (154, 232)), ("difference", (160, 244))]


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): the vertex / triangle counts are "
                          "those of Open3D's Manifold back end's triangulation; gsdf's arrangement keeps the input "
                          "triangles whole where nothing cuts them (716 / 1428, 159 / 314, 165 / 326). The geometry "
                          "agrees: closed, volumes within 3e-9 (next test)", strict=True)
@pytest.mark.parametrize("op,counts", OPS)
def test_boolean_operations__counts(o3d, op, counts):
    """test_trianglemesh.py::test_boolean_operations — box (create_box) with sphere (create_sphere(0.8)): union
    730 / 1384, intersection 154 / 232, difference 160 / 244 vertices / triangles."""
    V, F = gsdf.mesh_boolean(o3d["box_V"], o3d["box_F"], o3d["sphere_V"], o3d["sphere_F"], op)
    assert (V.shape[0], F.shape[0]) == counts


@pytest.mark.parametrize("op,counts", OPS)
def test_boolean_operations__geometry(o3d, op, counts):
    """test_trianglemesh.py::test_boolean_operations on the geometry: gsdf's result is closed, has Euler
    characteristic 2 and encloses Open3D's volume within 1e-8 (relative; both cut exactly)."""
    V, F = gsdf.mesh_boolean(o3d["box_V"], o3d["box_F"], o3d["sphere_V"], o3d["sphere_F"], op)
    ref_vol = enclosed_volume(o3d[f"{op}_V"], o3d[f"{op}_F"])
    assert exterior_edge_count(F) == 0
    assert euler_characteristic(V, F) == 2
    assert abs(enclosed_volume(V, F) / ref_vol - 1) < 1e-8
