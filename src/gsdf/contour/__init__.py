"""Contouring scalar fields: isosurfaces (marching cubes + bisection) and planar slices for 3D printing.

Barill et al. 2018: Fig. 9 (bisection instead of linear interpolation for isosurfaces of winding
numbers) and Fig. 3 / §4 (slicing the 3D winding number field into stacks of polygons that a 3D
printer's toolpath software fills).
"""

from .isosurface import extract_isosurface, refine_on_edges
from .slicing import slice_contours, write_slices_svg, write_svg

__all__ = ["extract_isosurface", "refine_on_edges", "slice_contours", "write_svg", "write_slices_svg"]
