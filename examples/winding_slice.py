"""Inside/outside of a broken triangle soup: the fast winding number on a grid, as a PNG (winding_slice.png)."""

import numpy as np

import gsdf
from gsdf.data import path

V, F = gsdf.read_mesh(path("broken_soup.obj"))        # holes, duplicated and degenerate faces
fwn = gsdf.FastWindingNumber(V, F)
grid = gsdf.Grid.around(V, resolution=48)
w = fwn(grid.points()).reshape(grid.shape)
gsdf.save_png("winding_slice.png", ("winding number", gsdf.GridField(w, *grid.box)), (V, F), size=(800, 600))
print(f"inside fraction {np.mean(w >= 0.5):.3f}; wrote winding_slice.png")
