"""Signed distance grid of a broken soup (exact distance, winding-number sign) and its zero level set."""

import gsdf
from gsdf.data import path
from gsdf.render._png import write_field_slice_png

V, F = gsdf.read_mesh(path("broken_soup.obj"))
field = gsdf.signed_distance_grid(V, F, resolution=32)
write_field_slice_png("sdf_grid_slice.png", field, axis=1)
Vs, Fs = field.isosurface(0.0)
print(f"grid {field.values.shape}, zero level set: {len(Fs)} triangles, closed={gsdf.mesh_topology(Vs, Fs)['closed']}")
