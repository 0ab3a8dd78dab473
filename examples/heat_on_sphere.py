"""Signed heat method: signed geodesic distance to a broken latitude curve on a sphere (heat_on_sphere.png)."""

import numpy as np
import trimesh

import gsdf

mesh = trimesh.creation.icosphere(subdivisions=3)
V, F = np.asarray(mesh.vertices), np.asarray(mesh.faces)
ring = gsdf.level_set_curves(V, F, V[:, 2], 0.0)[0]          # the equator as (face, barycentric) points
n = len(ring)
arcs = [ring[: n // 3], ring[n // 2: 5 * n // 6]]               # two arcs with gaps between them
phi = gsdf.SurfaceSignedHeatSolver(V, F).compute_distance(arcs, level_set_constraint="none")
gsdf.save_png("heat_on_sphere.png", ("signed distance", (V, F, phi)), ("arcs", arcs), size=(800, 600))
print(f"phi at the poles: {phi[np.argmax(V[:, 2])]:.2f} (north), {phi[np.argmin(V[:, 2])]:.2f} (south)")
