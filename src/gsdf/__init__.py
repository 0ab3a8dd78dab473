"""gsdf: generalized winding numbers and generalized signed distance for broken geometry.

Re-exports only; see ``docs/architecture.md`` for the layout. Names are resolved lazily (PEP 562) so that
``import gsdf`` stays fast: numba and scipy load on first use of a function that needs them.
"""

from importlib import import_module

__version__ = "0.1.0"

_EXPORTS = {
    # I/O
    "read_mesh": "io", "write_mesh": "io", "read_points": "io", "write_points": "io",
    # winding numbers
    "winding_number": "winding", "winding_number_2d": "winding", "winding_number_points": "winding",
    "FastWindingNumber": "winding", "ExactWindingNumber": "winding", "FastWindingNumberPoints": "winding",
    "fast_winding_number": "winding", "fast_winding_number_points": "winding",
    "point_areas": "winding.point_areas", "estimate_normals": "winding.point_areas",
    # surface winding numbers (thesis ch. 6)
    "SurfaceWindingNumbers": "winding.surface", "surface_winding_number": "winding.surface",
    # distance
    "TriangleDistance": "distance", "PointCloudDistance": "distance", "unsigned_distance": "distance",
    "point_cloud_distance": "distance", "signed_distance": "distance", "signed_distance_points": "distance",
    # fields, contouring, operations
    "Field": "field", "GridField": "field",
    "extract_isosurface": "contour", "refine_on_edges": "contour", "slice_contours": "contour",
    "write_svg": "contour",
    "voxelize": "ops", "winding_grid": "ops", "save_voxels": "ops", "voxels_to_mesh": "ops",
    "mesh_boolean": "ops",
    # the signed heat method on surfaces (Feng & Crane 2024)
    "SurfaceSignedHeatSolver": "heat", "PolygonMeshSignedHeatSolver": "heat", "PointCloudSignedHeatSolver": "heat",
    "level_set_curves": "heat", "region_boundary_curves": "heat",
    "VoxelSurfaceSignedHeatSolver": "heat.domains.voxel",
    "level_set_curves": "heat", "region_boundary_curves": "heat", "Curve": "heat.sources",
    "read_curves": "io.curves", "write_curves": "io.curves",
    # the signed heat method in volumes (grids, tets) and morphology
    "signed_heat_volume": "heat.volume", "YukawaTree": "heat.volume",
    "TetField": "field", "marching_tetrahedra": "field",
    "offset_surface": "ops.morphology", "dilate_erode": "ops.morphology", "erode_dilate": "ops.morphology",
    # Points as Tori and the convolutional baselines (Feng 2026, ch. 3 and 5)
    "PointsAsTori": "tori", "SignedHopfCole": "tori", "SmoothedSignedPlanarDistance": "tori",
    "LogSumExpDistance": "tori", "WindingNumberPipeline": "tori", "render_png": "tori",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'gsdf' has no attribute {name!r}")
    value = getattr(import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
