"""The surface winding number demo's curve files: read by :func:`gsdf.io._curves.read_curves` (one reader for
the three curve formats); the nodes-and-segments form the surface winding numbers use is
:class:`gsdf.io._curves.SWNCurves`."""

from gsdf.io._curves import SWNCurves, read_swn_curves

__all__ = ["SWNCurves", "read_swn_curves"]
