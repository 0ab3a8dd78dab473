"""Heat methods for generalized signed distance (Feng & Crane 2024)."""

from .surface import (PointCloudSignedHeatSolver, PolygonMeshSignedHeatSolver, SurfaceSignedHeatSolver,
                      level_set_curves, region_boundary_curves)

__all__ = ["SurfaceSignedHeatSolver", "PointCloudSignedHeatSolver", "PolygonMeshSignedHeatSolver", "level_set_curves",
           "region_boundary_curves"]
