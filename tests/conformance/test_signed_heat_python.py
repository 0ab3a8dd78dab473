"""signed-heat-python's own tests (test/test.py: the `signedheat3d` package), re-expressed to call gsdf.

Source (read, not copied): github.com/nzfeng/signed-heat-python @ f5a9d04c (MIT). Assets vendored under
data/signed_heat_python/ with its LICENSE: bunny_small.obj.gz, spot.obj.gz, bunny.pc.gz.

The peer's TET_RESOLUTION is ``[8, 8, 8] if platform.system != 'linux' else [2, 2, 2]``; ``platform.system`` is
a function, never equal to a string, so its tests always run at [8, 8, 8] — so do these. Its residual checks are
``np.mean(residual) < 2e-2`` on the *signed* residual, as written.
"""

from __future__ import annotations

import numpy as np
import pytest

import gsdf

P = "signed_heat_python"
TET_RESOLUTION = np.array([8, 8, 8])


def area_weighted_vertex_normals(V, F):
    """test.py::area_weighted_vertex_normals (polygons: first three corners of each face, as the peer does)."""
    F = np.asarray(F)
    tri = V[F]
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    vn = np.zeros_like(V)
    np.add.at(vn, F.ravel(), np.repeat(fn, F.shape[1], axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        return vn / np.linalg.norm(vn, axis=1, keepdims=True)


def approximate_signed_distance(Q, Pp, N):
    """test.py::approximate_signed_distance: distance to the nearest point of Pp, with the sign of N . (q - p)
    at that point (the peer's argmin over the full |Q| x |P| array; the nearest point by a k-d tree here)."""
    from scipy.spatial import cKDTree

    d, i = cKDTree(Pp).query(Q)
    return np.sign(np.sum(N[i] * (Q - Pp[i]), axis=1)) * d


def average_squared_distance(V1, F1, V2, F2):
    """test.py::TestTetSolver.average_squared_distance (np.sum, as the peer: a NaN normal makes it NaN)."""
    N1 = area_weighted_vertex_normals(V1, F1)
    N2 = area_weighted_vertex_normals(V2, F2)
    D2_1 = np.square(approximate_signed_distance(V1, V2, N2))
    D2_2 = np.square(approximate_signed_distance(V2, V1, N1))
    return (np.sum(D2_1) + np.sum(D2_2)) / (V1.shape[0] + V2.shape[0])


def residual_mean(phi, approx):
    span = np.amax(approx) - np.amin(approx)
    residual = (phi - approx) / span
    residual[np.isnan(residual)] = 0.0
    return float(np.mean(residual))


@pytest.fixture(scope="module")
def bunny(unpacked):
    return gsdf.read_mesh(unpacked(P, "bunny_small.obj"))


@pytest.fixture(scope="module")
def cloud(unpacked):
    return gsdf.read_points(unpacked(P, "bunny.pc"))


@pytest.fixture(scope="module")
def tet_mesh_field(bunny):
    return gsdf.signed_heat_volume(mesh=bunny, domain="tet", resolution=TET_RESOLUTION)


# ---------------------------------------------------------------------------------------------------------------
# reading / writing
# ---------------------------------------------------------------------------------------------------------------


def test_read_polygon_mesh(unpacked):
    """test.py::test_read_polygon_mesh — bunny_small.obj: (n, 3) vertices, all faces triangles, indices in
    range; spot.obj: all faces quads, indices in [0, n)."""
    V, F = gsdf.read_mesh(unpacked(P, "bunny_small.obj"), triangulate=False)
    assert V.ndim == 2 and V.shape[1] == 3
    assert all(len(p) == 3 for p in F)
    assert max(max(p) for p in F) < V.shape[0]
    V, F = gsdf.read_mesh(unpacked(P, "spot.obj"), triangulate=False)
    assert V.ndim == 2 and V.shape[1] == 3
    assert all(len(p) == 4 for p in F)
    assert np.amax(F) < V.shape[0] and np.amin(F) >= 0


def test_write_surface_mesh(unpacked, tmp_path):
    """test.py::test_write_surface_mesh — write bunny_small as OBJ and read it back: max |V - V_new| < 1e-6, the
    face lists equal."""
    V, F = gsdf.read_mesh(unpacked(P, "bunny_small.obj"), triangulate=False)
    p = str(tmp_path / "test_mesh.obj")
    gsdf.write_mesh(p, V, F)
    V_new, F_new = gsdf.read_mesh(p, triangulate=False)
    assert np.amax(np.abs(V - V_new)) < 1e-6
    assert np.array_equal(np.asarray(F), np.asarray(F_new))


def test_read_point_cloud(cloud):
    """test.py::test_read_point_cloud — bunny.pc ('v' / 'vn' lines): P and N both (n, 3)."""
    Pp, N = cloud
    assert Pp.ndim == 2 and Pp.shape[1] == 3
    assert N is not None and N.ndim == 2 and N.shape[1] == 3
    assert Pp.shape == N.shape


# ---------------------------------------------------------------------------------------------------------------
# TestTetSolver
# ---------------------------------------------------------------------------------------------------------------


def test_tet_get_vertices(tet_mesh_field):
    """test.py::TestTetSolver::test_get_vertices — tet-mesh vertices (n, 3), one φ per vertex."""
    f = tet_mesh_field
    assert f.vertices.ndim == 2 and f.vertices.shape[1] == 3
    assert f.vertices.shape[0] == len(f.values)


def test_tet_get_tets(tet_mesh_field):
    """test.py::TestTetSolver::test_get_tets — tets (m, 4), indices in [0, n)."""
    f = tet_mesh_field
    assert f.tets.ndim == 2 and f.tets.shape[1] == 4
    assert np.amax(f.tets) < f.vertices.shape[0] and np.amin(f.tets) >= 0


def test_tet_compute_distance_to_mesh(bunny, tet_mesh_field):
    """test.py::TestTetSolver::test_compute_distance_to_mesh — φ is 1-D; mean signed residual against the
    nearest-vertex pseudo signed distance, over its span, < 2e-2."""
    V, F = bunny
    phi = tet_mesh_field.values
    assert phi.ndim == 1
    approx = approximate_signed_distance(tet_mesh_field.vertices, V, area_weighted_vertex_normals(V, F))
    assert residual_mean(phi, approx) < 2e-2


def test_tet_compute_distance_to_point_cloud(cloud):
    """test.py::TestTetSolver::test_compute_distance_to_point_cloud — the same for the bunny point cloud."""
    Pp, N = cloud
    f = gsdf.signed_heat_volume(points=(Pp, N), domain="tet", resolution=TET_RESOLUTION)
    assert f.values.ndim == 1
    approx = approximate_signed_distance(f.vertices, Pp, N)
    approx[np.isnan(approx)] = 0.0
    assert residual_mean(f.values, approx) < 2e-2


@pytest.fixture(scope="module")
def tet_iso(bunny):
    f = gsdf.signed_heat_volume(mesh=bunny, domain="tet", resolution=TET_RESOLUTION,
                                options=gsdf.VolumeHeatOptions(level_set_constraint="zero"))
    return f.isosurface(0.0)


def test_tet_isosurface(bunny, tet_iso):
    """test.py::TestTetSolver::test_isosurface — ZeroSet constraint, isosurface(φ, 0): average squared
    (pseudo-)distance between the input and the isosurface < 1e-2."""
    V, F = bunny
    Vi, Fi = tet_iso
    assert average_squared_distance(V, F, Vi, Fi) < 1e-2


def test_tet_isosurface_closed(tet_iso):
    """The 0-isosurface of a closed input's tet field is closed (no boundary edge), as signedheat3d's is.
    Regression: φ = 0 on every input point leaves whole tets at the level; counting the level as above gave 24
    boundary edges at [8, 8, 8] (76 / 210 at 16 / 32) and NaN in the peer's error (2.75e-2 without the NaN
    terms); counted as below (libigl's marching_tets): 0 / 0 / 0 and 8.0e-4 / 3.0e-4 / 1.5e-3."""
    Vi, Fi = tet_iso
    E = np.sort(np.concatenate([Fi[:, [0, 1]], Fi[:, [1, 2]], Fi[:, [2, 0]]]), axis=1)
    _, c = np.unique(E, axis=0, return_counts=True)
    assert (c == 1).sum() == 0


# ---------------------------------------------------------------------------------------------------------------
# TestGridSolver
# ---------------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def grid_default(bunny):
    return gsdf.signed_heat_volume(mesh=bunny)


def test_grid_get_grid_resolution(grid_default):
    """test.py::TestGridSolver::test_get_grid_resolution — default options: 3 node counts, all > 0."""
    res = grid_default.values.shape
    assert len(res) == 3 and all(r > 0 for r in res)


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): signed_heat_volume refuses a box "
                          "that does not contain the input (bunny_small reaches x = ±1.0014, the peer's box is "
                          "[-1, 1]^3); signedheat3d accepts it and leaves the input's tips outside", strict=True,
                   raises=ValueError)
def test_grid_get_bbox(bunny):
    """test.py::TestGridSolver::test_get_bbox — bbox_min = (-1,-1,-1), bbox_max = (1,1,1) are returned as set
    (1e-8), ordered min -> max."""
    f = gsdf.signed_heat_volume(mesh=bunny, bbox_min=[-1, -1, -1], bbox_max=[1, 1, 1])
    assert np.linalg.norm(f.bbox_min - [-1, -1, -1]) < 1e-8 and np.linalg.norm(f.bbox_max - [1, 1, 1]) < 1e-8


def test_grid_get_bbox_error_in_user_units(bunny):
    """The refusal of test_get_bbox's box names the boxes in the caller's units (the given ±1). Regression: it
    printed gsdf's internal frame (±0.5)."""
    with pytest.raises(ValueError) as e:
        gsdf.signed_heat_volume(mesh=bunny, bbox_min=[-1, -1, -1], bbox_max=[1, 1, 1], resolution=8)
    msg = str(e.value)
    assert "[[-1. -1. -1.], [1. 1. 1.]]" in msg and "-1.00139" in msg  # the given box, the bunny's x reach


def test_grid_to_grid_array(grid_default):
    """test.py::TestGridSolver::test_to_grid_array — the field on the grid is a 3-D array."""
    assert grid_default.values.ndim == 3


@pytest.mark.parametrize("kind", ["mesh", "points"])
def test_grid_compute_distance(bunny, cloud, kind):
    """test.py::TestGridSolver::test_compute_distance_to_mesh / _to_point_cloud — resolution [32, 32, 32]; mean
    signed residual against the nearest-vertex (nearest-point) pseudo signed distance at the grid nodes, over
    its span, < 2e-2."""
    if kind == "mesh":
        V, F = bunny
        f = gsdf.signed_heat_volume(mesh=bunny, resolution=np.array([32, 32, 32]))
        Pp, N = V, area_weighted_vertex_normals(V, F)
    else:
        Pp, N = cloud
        f = gsdf.signed_heat_volume(points=cloud, resolution=np.array([32, 32, 32]))
    phi = f.values.ravel()
    Q = f.grid_points().reshape(-1, 3)
    approx = approximate_signed_distance(Q, Pp, N)
    assert residual_mean(phi, approx) < 2e-2
