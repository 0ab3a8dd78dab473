"""Pictures: PNG writing and colour maps (``_png``), a z-buffer rasterizer of vertex functions on triangle meshes
(``_raster``) and sphere tracing of pointwise signed distance functions (``_trace``, :func:`render_png`)."""

from gsdf.view._trace import render_png, sphere_trace

__all__ = ["render_png", "sphere_trace"]
