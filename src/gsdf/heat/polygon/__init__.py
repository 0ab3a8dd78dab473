"""The signed heat method on polygon meshes (Feng & Crane 2024, §8.3): the domain (``_domain``), its numba kernels
(``_kernels``) and the front-end :class:`PolygonMeshSignedHeatSolver` (``_solver``)."""
