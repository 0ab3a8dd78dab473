"""The signed heat method on triangle meshes (Feng & Crane 2024, §5): Crouzeix–Raviart domain (``_domain``),
operators (``_operators``: the Crouzeix–Raviart vector heat operators, on :mod:`gsdf.mesh._triangle_ops`), sources (``_sources``, App. A), the front-end :class:`SurfaceSignedHeatSolver` (``_solver``),
L1 integration (``_l1``, §7.2) and sharpening (``_sharpen``, §7.3)."""
