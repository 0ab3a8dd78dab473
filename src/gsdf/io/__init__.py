"""File input/output: meshes (OBJ, OFF, PLY, STL parsed by gsdf; GLB/GLTF/3MF through trimesh; VTK, VTU, Gmsh,
Medit, Abaqus, Nastran, SU2 through meshio), point clouds (XYZ, PWN, PLY, OBJ, PC, NPY/NPZ), curves, PNG images,
and the safe, atomic writing every writer uses (:mod:`gsdf.io._safe_write`)."""

from gsdf.io._mesh import MESH_FORMATS, MESH_READ_FORMATS, MESH_WRITE_FORMATS, read_mesh, read_vertex_data, write_mesh
from gsdf.io._curves import read_curves, write_curves
from gsdf.io._points import POINTS_READ_FORMATS, POINTS_WRITE_FORMATS, read_points, write_points

__all__ = [
    "read_mesh",
    "write_mesh",
    "read_vertex_data",
    "read_points",
    "read_curves",
    "write_curves",
    "write_points",
    "MESH_FORMATS",
    "MESH_READ_FORMATS",
    "MESH_WRITE_FORMATS",
    "POINTS_READ_FORMATS",
    "POINTS_WRITE_FORMATS",
]
