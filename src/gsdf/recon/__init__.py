"""Guaranteed simply connected reconstruction (Chen, Li & Huang 2026, seed 003) and comparison reconstructions.

Modules: ``_pipeline`` (:func:`reconstruct_simply_connected`, :class:`ReconstructionOptions`, the pipeline's
stages), ``_cloud`` (pre-filter, rescues of dropped points, PCA normals), ``_steiner`` (octree Steiner points),
``_orient`` (normal orientation and the face chain F0), ``_grow`` (the guarantee layer: simple-tet region
growing and carving), ``_relocate`` (the output's vertices moved onto the samples' MLS surface, faces kept),
``_globalfit`` (the global least-squares fit of all vertices), ``_remesh`` (edge flips onto the samples'
surface), ``_compare`` (winding-number, signed-heat and Points-as-Tori reconstructions on the same API shape).
"""

from gsdf.recon._pipeline import ReconstructionOptions, reconstruct_simply_connected

__all__ = ["reconstruct_simply_connected", "ReconstructionOptions"]
