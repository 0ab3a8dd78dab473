"""Surface winding numbers (Feng 2026, thesis ch. 6): inside / outside of broken curves on any surface.

``_solver`` (:class:`SurfaceWindingNumbers`, :func:`surface_winding_number`, :class:`SWNOptions`), ``_gaps`` (labels of the faces at
the curves' gaps), ``_insert`` (curves through faces inserted into the mesh by cutting).
"""

from gsdf.swn._insert import insert_surface_points
from gsdf.swn._solver import SurfaceWindingNumbers, SWNOptions, surface_winding_number

__all__ = ["SurfaceWindingNumbers", "SWNOptions", "surface_winding_number", "insert_surface_points"]
