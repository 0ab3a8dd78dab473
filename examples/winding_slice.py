"""Inside/outside of a broken triangle soup: the fast winding number on a slice, as a PNG (winding_slice.png)."""

import numpy as np

import gsdf
from gsdf.data import path
from gsdf.render._png import field_to_rgb, write_png

V, F = gsdf.read_mesh(path("broken_soup.obj"))        # holes, duplicated and degenerate faces
fwn = gsdf.FastWindingNumber(V, F)
lo, hi = V.min(0), V.max(0)
x, z = np.meshgrid(np.linspace(lo[0], hi[0], 128), np.linspace(lo[2], hi[2], 128))
Q = np.column_stack([x.ravel(), np.full(x.size, 0.5 * (lo[1] + hi[1])), z.ravel()])
w = fwn(Q).reshape(x.shape)
write_png("winding_slice.png", field_to_rgb(np.flipud(w), zero_level=0.5))
print(f"inside fraction {np.mean(w >= 0.5):.3f}; wrote winding_slice.png")
