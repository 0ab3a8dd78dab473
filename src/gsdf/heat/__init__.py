"""Heat methods for generalized signed distance (Feng & Crane 2024).

``core.py`` runs the signed heat method once for every discretization; ``domains/`` supply operators and
sources; ``surface/`` and ``volume/`` hold the public front-ends (SurfaceSignedHeatSolver,
PolygonMeshSignedHeatSolver, PointCloudSignedHeatSolver, signed_heat_volume); ``sources.py`` the typed
:class:`Curve` and the assembled :class:`Sources`.
"""

from .sources import Curve
from .surface import (PointCloudSignedHeatSolver, PolygonMeshSignedHeatSolver, SurfaceSignedHeatSolver,
                      level_set_curves, region_boundary_curves)

__all__ = ["Curve", "SurfaceSignedHeatSolver", "PointCloudSignedHeatSolver", "PolygonMeshSignedHeatSolver", "level_set_curves",
           "region_boundary_curves"]
