"""Points as Tori: sphere-traced picture of the signed distance of an oriented point cloud (tori_render.png)."""

import gsdf
from gsdf.data import path

P, N = gsdf.read_points(path("torus_cloud.xyz"))
pat = gsdf.PointsAsTori(P, N)
gsdf.render_png(pat, "tori_render.png", width=320, height=240)     # only pointwise queries: no grid, no mesh
print(f"{len(P)} points; distance at the centre {pat.signed_distance([P.mean(0)])[0]:.3f} (the torus hole: > 0)")
