"""The signed heat method on point clouds (Feng & Crane 2024, §8.4): the tufted-cover domain (``_domain``) and the
front-end :class:`PointCloudSignedHeatSolver` (``_solver``)."""
