"""Generalized winding numbers: exact direct sums, fast tree-based approximations, point areas."""
from gsdf.winding._exact import winding_number, winding_number_2d, winding_number_points
from gsdf.winding._hierarchical import ExactWindingNumber
from gsdf.winding._point_areas import estimate_normals, point_areas
from gsdf.winding._fast import (
    FastWindingNumber,
    FastWindingNumberPoints,
    fast_winding_number,
    fast_winding_number_points,
    inside,
)

__all__ = [
    "winding_number",
    "ExactWindingNumber",
    "winding_number_2d",
    "winding_number_points",
    "FastWindingNumber",
    "FastWindingNumberPoints",
    "fast_winding_number",
    "fast_winding_number_points",
    "inside",
    "point_areas",
    "estimate_normals",
]
