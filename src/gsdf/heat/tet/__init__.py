"""The signed heat method on tetrahedral meshes (Feng & Crane 2024, §8.1): the domain (``_domain``) and the graded
Delaunay / TetGen meshes with their P1 and Crouzeix–Raviart operators (``_mesh``)."""
