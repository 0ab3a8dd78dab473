"""Domains of the signed heat core (:mod:`gsdf.heat.core`): each supplies operators and assembled sources only.

base.py       the protocol (HeatDomain, PoissonSolver) and VertexSurfaceDomain (vertex-based surfaces)
triangle.py   triangle meshes, Crouzeix–Raviart edges (§5)
intrinsic.py  intrinsic Delaunay triangulations (§9.4): flips, point location, source transfer
polygon.py    polygon meshes (§8.3)
pointcloud.py point clouds (§8.4)
grid.py       regular grids (§8.2)
tet.py        tetrahedral meshes (§8.1)
voxel.py      voxel (digital) surfaces (§8.5)
"""
