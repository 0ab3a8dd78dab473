"""Mesh connectivity and geometry helpers."""
from .geometry import face_areas, face_normals, face_area_normals, bounding_box

__all__ = ["face_areas", "face_normals", "face_area_normals", "bounding_box"]
