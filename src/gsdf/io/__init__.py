"""File input/output for meshes (OBJ, OFF, PLY, STL) and point clouds (XYZ, PWN, PLY, OBJ, PC, NPY/NPZ)."""

from .mesh_io import MESH_FORMATS, read_mesh, write_mesh
from .points_io import POINTS_READ_FORMATS, POINTS_WRITE_FORMATS, read_points, write_points

__all__ = [
    "read_mesh",
    "write_mesh",
    "read_points",
    "write_points",
    "MESH_FORMATS",
    "POINTS_READ_FORMATS",
    "POINTS_WRITE_FORMATS",
]
