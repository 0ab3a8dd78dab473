"""Generalized winding numbers: exact direct sums, fast tree-based approximations, point areas."""
from .exact import winding_number, winding_number_2d, winding_number_points
from .hierarchical import ExactWindingNumber
from .fast import (
    FastWindingNumber,
    FastWindingNumberPoints,
    fast_winding_number,
    fast_winding_number_points,
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
]
