"""gsdf: generalized winding numbers and generalized signed distance for broken geometry.

Re-exports only; see ``docs/architecture.md`` for the layout. Names are resolved lazily (PEP 562) so that
``import gsdf`` stays fast: numba and scipy load on first use of a function that needs them.
"""

from importlib import import_module

from gsdf._jit import configure_cache as _configure_cache

__version__ = "0.1.0"

_configure_cache()  # numba's cache dir when the install dir and the user cache are read-only (cheap)

_EXPORTS = {
    # I/O
    "read_mesh": "io", "write_mesh": "io", "read_points": "io", "write_points": "io",
    "read_vertex_data": "io",
    # winding numbers
    "winding_number": "winding", "winding_number_2d": "winding", "winding_number_points": "winding",
    "FastWindingNumber": "winding", "ExactWindingNumber": "winding", "FastWindingNumberPoints": "winding",
    "fast_winding_number": "winding", "fast_winding_number_points": "winding", "inside": "winding",
    "point_areas": "winding", "estimate_normals": "winding",
    # surface winding numbers (thesis ch. 6)
    "SurfaceWindingNumbers": "swn", "surface_winding_number": "swn", "SWNOptions": "swn",
    # distance
    "TriangleDistance": "distance", "PointCloudDistance": "distance", "unsigned_distance": "distance",
    "point_cloud_distance": "distance", "signed_distance": "distance", "signed_distance_points": "distance",
    # fields, contouring, operations
    "Field": "field", "GridField": "field", "SurfaceField": "field", "load_field": "field",
    "Grid": "grid", "signed_distance_grid": "ops",
    "extract_isosurface": "contour", "refine_on_edges": "contour", "slice_contours": "contour",
    "write_svg": "contour",
    "voxelize": "ops", "winding_grid": "ops", "save_voxels": "ops", "voxels_to_mesh": "ops",
    "mesh_boolean": "ops", "BooleanOptions": "ops",
    # the signed heat method on surfaces (Feng & Crane 2024)
    "SurfaceSignedHeatSolver": "heat", "PolygonMeshSignedHeatSolver": "heat", "PointCloudSignedHeatSolver": "heat",
    "level_set_curves": "contour", "region_boundary_curves": "contour",
    "VoxelSurfaceSignedHeatSolver": "heat",
    "Curve": "curves", "read_curves": "io", "write_curves": "io",
    # the signed heat method in volumes (grids, tets) and morphology
    "signed_heat_volume": "heat.volume", "VolumeHeatOptions": "heat.volume", "YukawaTree": "heat.volume",
    "TetField": "field", "marching_tetrahedra": "contour",
    "offset_surface": "ops", "dilate_erode": "ops", "erode_dilate": "ops",
    # Points as Tori and the convolutional baselines (Feng 2026, ch. 3 and 5)
    "PointsAsTori": "tori", "PointsAsToriOptions": "tori", "SignedHopfCole": "tori",
    "SmoothedSignedPlanarDistance": "tori", "LogSumExpDistance": "tori", "WindingNumberPipeline": "tori",
    # pictures and the viewer (polyscope: the extra gsdf[view])
    "view": "render", "ViewOptions": "render", "render_png": "render", "save_png": "render",
    # guaranteed simply connected reconstruction (Chen, Li & Huang 2026) and comparison reconstructions
    "reconstruct_simply_connected": "recon", "ReconstructionOptions": "recon", "mesh_topology": "mesh",
    # dataset batches
    "run_batch": "batch", "BatchOptions": "batch", "sdf_samples": "batch", "SdfSamplesOptions": "batch",
    # one thread setting for numba kernels and BLAS (gsdf.threads)
    "set_num_threads": "threads", "get_num_threads": "threads",
}
_SUBMODULES = {"threads"}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _SUBMODULES:
        return import_module(f".{name}", __name__)
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'gsdf' has no attribute {name!r}")
    value = getattr(import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS) | _SUBMODULES)
