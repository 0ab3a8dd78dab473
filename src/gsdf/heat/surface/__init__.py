"""The signed heat method on surface domains (Feng & Crane 2024): triangle meshes and point clouds."""

from .curves import level_set_curves, region_boundary_curves
from .pointcloud import PointCloudSignedHeatSolver
from .polygon import PolygonMeshSignedHeatSolver
from .solver import SurfaceSignedHeatSolver

__all__ = ["SurfaceSignedHeatSolver", "PointCloudSignedHeatSolver", "PolygonMeshSignedHeatSolver", "level_set_curves",
           "region_boundary_curves"]
