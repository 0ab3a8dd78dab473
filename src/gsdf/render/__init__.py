"""Pictures and the viewer.

:func:`gsdf.view` shows meshes, clouds, curves and gsdf's results in polyscope, or renders them headless to a PNG
(``_view``: the function and :class:`ViewOptions`; ``_scene``: what the items become and the camera, without
polyscope; ``_polyscope``: every polyscope call). :func:`save_png` is the picture of a result that the command
line writes: polyscope's when it can render here, else gsdf's own renderers: PNG writing and colour maps
(``_png``), a z-buffer rasterizer of vertex functions on triangle meshes (``_raster``) and sphere tracing of
pointwise signed distance functions (``_trace``, :func:`render_png`).
"""

from gsdf.render._picture import save_png
from gsdf.render._trace import render_png, sphere_trace
from gsdf.render._view import ViewOptions, view

__all__ = ["view", "ViewOptions", "save_png", "render_png", "sphere_trace"]
