"""gsdf: generalized winding numbers and generalized signed distance for broken geometry.

Re-exports only; see ``docs/architecture.md`` for the layout.
"""

from .field import Field, GridField
from .winding import (
    FastWindingNumber,
    FastWindingNumberPoints,
    fast_winding_number,
    fast_winding_number_points,
    winding_number,
    winding_number_2d,
    winding_number_points,
)

__version__ = "0.1.0"

__all__ = [
    "Field",
    "GridField",
    "FastWindingNumber",
    "FastWindingNumberPoints",
    "fast_winding_number",
    "fast_winding_number_points",
    "winding_number",
    "winding_number_2d",
    "winding_number_points",
]
