"""Operations on winding fields: voxelization and booleans of broken geometry.

Barill et al. 2018, *Fast Winding Numbers for Soups and Clouds*, §4: voxelization by thresholding the fast
winding number at voxel centers (Fig. 11) and booleans that trim each operand against the winding field of
the other instead of intersecting triangles (Figs. 12-15).
"""

from gsdf.ops._boolean import BooleanOptions, mesh_boolean, trim_mesh
from gsdf.ops._distance_grid import signed_distance_grid
from gsdf.ops._morphology import dilate_erode, erode_dilate, offset_surface
from gsdf.ops._voxelize import (
    load_voxels,
    save_voxels,
    voxelize,
    voxels_to_mesh,
    winding_grid,
)

__all__ = [
    "voxelize",
    "winding_grid",
    "save_voxels",
    "load_voxels",
    "voxels_to_mesh",
    "mesh_boolean",
    "BooleanOptions",
    "trim_mesh",
    "signed_distance_grid",
    "offset_surface",
    "dilate_erode",
    "erode_dilate",
]
