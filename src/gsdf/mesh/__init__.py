"""Mesh connectivity and geometry helpers."""
from .geometry import face_areas, face_normals, face_area_normals, bounding_box
from .connectivity import MeshTopology, unique_edges

__all__ = ["face_areas", "face_normals", "face_area_normals", "bounding_box", "MeshTopology", "unique_edges"]
