"""The signed heat method (Feng & Crane 2024), written once and run on every discretization.

``_core`` runs steps I–III, the level-set constraints and the shift for every domain; ``_domain`` is what a
discretization supplies (operators and assembled sources, ``_sources``). One subpackage per discretization:
``triangle`` (Crouzeix–Raviart, §5; the front-end :class:`SurfaceSignedHeatSolver`, L1 integration §7.2,
sharpening §7.3), ``intrinsic`` (intrinsic Delaunay, §9.4), ``polygon`` (§8.3), ``pointcloud`` (§8.4), ``voxel``
(§8.5), ``grid`` (§8.2) and ``tet`` (§8.1); ``volume`` is the volume front-end :func:`signed_heat_volume`.
Names are imported lazily (PEP 562).
"""

from importlib import import_module

_LAZY = {
    "SurfaceSignedHeatSolver": "gsdf.heat.triangle._solver",
    "PolygonMeshSignedHeatSolver": "gsdf.heat.polygon._solver",
    "PointCloudSignedHeatSolver": "gsdf.heat.pointcloud._solver",
    "VoxelSurfaceSignedHeatSolver": "gsdf.heat.voxel._domain",
    "signed_heat_volume": "gsdf.heat.volume",
    "VolumeHeatOptions": "gsdf.heat.volume",
    "YukawaTree": "gsdf.heat._yukawa",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'gsdf.heat' has no attribute {name!r}")
    value = getattr(import_module(mod), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
