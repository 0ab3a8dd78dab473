"""Unsigned and signed distance to triangle meshes/soups and point clouds."""

from gsdf.distance._points import PointCloudDistance, point_cloud_distance
from gsdf.distance._signed import SIGN_MODES, signed_distance, signed_distance_points
from gsdf.distance._triangles import TriangleDistance, brute_force_distance, closest_point_triangle, unsigned_distance

__all__ = [
    "TriangleDistance",
    "unsigned_distance",
    "closest_point_triangle",
    "brute_force_distance",
    "PointCloudDistance",
    "point_cloud_distance",
    "signed_distance",
    "signed_distance_points",
    "SIGN_MODES",
]
