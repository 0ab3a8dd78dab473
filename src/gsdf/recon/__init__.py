"""Guaranteed simply connected reconstruction (Chen, Li & Huang 2026, seed 003) and comparison reconstructions.

Modules: :mod:`.pipeline` (``reconstruct_simply_connected``), :mod:`.steiner` (octree Steiner points),
:mod:`.orient` (normal orientation and the face chain F0), :mod:`.grow` (the guarantee layer: simple-tet
region growing), :mod:`.relocate` (the output's vertices moved onto the samples' MLS surface, faces
kept), :mod:`.topology` (closed / manifold / χ / genus checks), :mod:`.compare` (winding-number,
signed-heat and Points-as-Tori reconstructions on the same API shape).
"""

from gsdf.recon._pipeline import reconstruct_simply_connected

__all__ = ["reconstruct_simply_connected"]
