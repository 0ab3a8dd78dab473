"""Contouring scalar fields: isosurfaces (marching cubes + bisection) and planar slices for 3D printing.

Barill et al. 2018: Fig. 9 (bisection instead of linear interpolation for isosurfaces of winding
numbers) and Fig. 3 / §4 (slicing the 3D winding number field into stacks of polygons that a 3D
printer's toolpath software fills).
"""

from gsdf.contour._isosurface import extract_isosurface, refine_on_edges
from gsdf.contour._slicing import slice_contours, write_slices_svg, write_svg
from gsdf.contour._surface_curves import level_set_curves, region_boundary_curves
from gsdf.contour._tets import locate_in_tets, marching_tetrahedra

__all__ = ["extract_isosurface", "refine_on_edges", "slice_contours", "write_svg", "write_slices_svg",
           "level_set_curves", "region_boundary_curves", "marching_tetrahedra", "locate_in_tets"]
