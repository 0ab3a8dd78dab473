"""The signed heat method on voxel (digital) surfaces (Feng & Crane 2024, §8.5): the digital surface (``_digital``),
de Goes et al. 2020 operators (``_degoes``) and the domain with its front-end :class:`VoxelSurfaceSignedHeatSolver`
(``_domain``)."""
