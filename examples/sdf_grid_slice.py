"""Signed distance grid of a broken soup (exact distance, winding-number sign) and its zero level set."""

import gsdf
from gsdf.data import path

V, F = gsdf.read_mesh(path("broken_soup.obj"))
field = gsdf.signed_distance_grid(V, F, resolution=32)
gsdf.save_png("sdf_grid_slice.png", ("signed distance", field), size=(800, 600),
              options=gsdf.ViewOptions(slice_axis="y"))
Vs, Fs = field.isosurface(0.0)
print(f"grid {field.values.shape}, zero level set: {len(Fs)} triangles, closed={gsdf.mesh_topology(Vs, Fs)['closed']}")
