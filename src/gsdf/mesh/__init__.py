"""Mesh connectivity and geometry helpers.

The operator sets that discrete exterior calculus and the signed heat method share live in the private modules
``_triangle_ops`` (:class:`~gsdf.mesh._triangle_ops.TriangleOperators`) and ``_tet_ops``
(:class:`~gsdf.mesh._tet_ops.TetOperators`); they are imported where used, not here.
"""
from gsdf.mesh._geometry import face_areas, face_normals, face_area_normals, bounding_box
from gsdf.mesh._connectivity import MeshTopology, unique_edges
from gsdf.mesh._topology import is_sphere, mesh_topology

__all__ = ["face_areas", "face_normals", "face_area_normals", "bounding_box", "MeshTopology", "unique_edges", "mesh_topology", "is_sphere"]
