"""Type stub of the lazy public API (gsdf/__init__.py): editors and type checkers see every public name."""

from gsdf.batch import (
    BatchOptions as BatchOptions,
    SdfSamplesOptions as SdfSamplesOptions,
    run_batch as run_batch,
    sdf_samples as sdf_samples,
)
from gsdf.contour import (
    extract_isosurface as extract_isosurface,
    level_set_curves as level_set_curves,
    marching_tetrahedra as marching_tetrahedra,
    refine_on_edges as refine_on_edges,
    region_boundary_curves as region_boundary_curves,
    slice_contours as slice_contours,
    write_svg as write_svg,
)
from gsdf.curves import Curve as Curve
from gsdf.distance import (
    PointCloudDistance as PointCloudDistance,
    TriangleDistance as TriangleDistance,
    point_cloud_distance as point_cloud_distance,
    signed_distance as signed_distance,
    signed_distance_points as signed_distance_points,
    unsigned_distance as unsigned_distance,
)
from gsdf.field import (
    Field as Field,
    GridField as GridField,
    SurfaceField as SurfaceField,
    TetField as TetField,
    load_field as load_field,
)
from gsdf.grid import Grid as Grid
from gsdf.heat import (
    PointCloudSignedHeatSolver as PointCloudSignedHeatSolver,
    PolygonMeshSignedHeatSolver as PolygonMeshSignedHeatSolver,
    SurfaceSignedHeatSolver as SurfaceSignedHeatSolver,
    VoxelSurfaceSignedHeatSolver as VoxelSurfaceSignedHeatSolver,
)
from gsdf.heat.volume import (
    VolumeHeatOptions as VolumeHeatOptions,
    YukawaTree as YukawaTree,
    signed_heat_volume as signed_heat_volume,
)
from gsdf.io import (
    read_curves as read_curves,
    read_mesh as read_mesh,
    read_points as read_points,
    read_vertex_data as read_vertex_data,
    write_curves as write_curves,
    write_mesh as write_mesh,
    write_points as write_points,
)
from gsdf.mesh import mesh_topology as mesh_topology
from gsdf.ops import (
    BooleanOptions as BooleanOptions,
    dilate_erode as dilate_erode,
    erode_dilate as erode_dilate,
    mesh_boolean as mesh_boolean,
    offset_surface as offset_surface,
    save_voxels as save_voxels,
    signed_distance_grid as signed_distance_grid,
    voxelize as voxelize,
    voxels_to_mesh as voxels_to_mesh,
    winding_grid as winding_grid,
)
from gsdf.recon import (
    ReconstructionOptions as ReconstructionOptions,
    reconstruct_simply_connected as reconstruct_simply_connected,
)
from gsdf.swn import (
    SurfaceWindingNumbers as SurfaceWindingNumbers,
    SWNOptions as SWNOptions,
    surface_winding_number as surface_winding_number,
)
from gsdf.threads import get_num_threads as get_num_threads, set_num_threads as set_num_threads
from gsdf.tori import (
    LogSumExpDistance as LogSumExpDistance,
    PointsAsTori as PointsAsTori,
    PointsAsToriOptions as PointsAsToriOptions,
    SignedHopfCole as SignedHopfCole,
    SmoothedSignedPlanarDistance as SmoothedSignedPlanarDistance,
    WindingNumberPipeline as WindingNumberPipeline,
)
from gsdf.render import ViewOptions as ViewOptions, render_png as render_png, save_png as save_png, view as view
from gsdf.winding import (
    ExactWindingNumber as ExactWindingNumber,
    FastWindingNumber as FastWindingNumber,
    FastWindingNumberPoints as FastWindingNumberPoints,
    estimate_normals as estimate_normals,
    fast_winding_number as fast_winding_number,
    fast_winding_number_points as fast_winding_number_points,
    inside as inside,
    point_areas as point_areas,
    winding_number as winding_number,
    winding_number_2d as winding_number_2d,
    winding_number_points as winding_number_points,
)

__version__: str
__all__: list[str]
