"""Surface winding numbers (Feng 2026, thesis ch. 6): inside / outside of broken curves on any surface.

``_solver`` (:class:`SurfaceWindingNumbers`, :func:`surface_winding_number`), ``_gaps`` (labels of the faces at
the curves' gaps), ``_insert`` (curves through faces inserted into the mesh by cutting).
"""

from gsdf.swn._solver import SurfaceWindingNumbers, surface_winding_number

__all__ = ["SurfaceWindingNumbers", "surface_winding_number"]
