"""The signed heat method on tetrahedral meshes (Feng & Crane 2024, §8.1): the domain (``_domain``, operators from
:class:`gsdf.mesh._tet_ops.TetOperators`) and the graded Delaunay / TetGen meshes (``_mesh``)."""
