"""Mesh connectivity and geometry helpers."""
from gsdf.mesh._geometry import face_areas, face_normals, face_area_normals, bounding_box
from gsdf.mesh._connectivity import MeshTopology, unique_edges
from gsdf.mesh._topology import is_sphere, mesh_topology

__all__ = ["face_areas", "face_normals", "face_area_normals", "bounding_box", "MeshTopology", "unique_edges", "mesh_topology", "is_sphere"]
