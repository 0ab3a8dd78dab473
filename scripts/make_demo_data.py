"""Regenerate the bundled demo inputs in src/gsdf/data/ (deterministic).

* broken_soup.obj — a sphere and a torus pushed through it (two intersecting components), ~8 % of the faces
  deleted in patches (holes), a few faces duplicated and one degenerate face: the kind of soup that breaks
  ray stabbing and pseudonormal signing but not winding numbers.
* torus_cloud.xyz — 4000 oriented points (x y z nx ny nz) on a torus with 0.5 % positional noise.
"""

import os

import numpy as np
import trimesh

rng = np.random.default_rng(2018)
here = os.path.join(os.path.dirname(__file__), "..", "src", "gsdf", "data")

sphere = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
torus = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3, major_sections=48, minor_sections=16)
R = trimesh.transformations.rotation_matrix(np.pi / 2.5, [1, 0, 0])
torus.apply_transform(R)
torus.apply_translation([0.6, 0.0, 0.0])
V = np.vstack([sphere.vertices, torus.vertices])
F = np.vstack([sphere.faces, torus.faces + len(sphere.vertices)])
# holes: delete faces whose centroid falls in a few random balls
C = V[F].mean(axis=1)
keep = np.ones(len(F), bool)
for centre in V[rng.choice(len(V), 6, replace=False)]:
    keep &= np.linalg.norm(C - centre, axis=1) > 0.22
F = F[keep]
F = np.vstack([F, F[rng.choice(len(F), 10, replace=False)], [[0, 0, 1]]])  # duplicates + a degenerate face
with open(os.path.join(here, "broken_soup.obj"), "w") as f:
    f.write("# gsdf demo: intersecting sphere + torus soup with holes, duplicates, a degenerate face\n")
    np.savetxt(f, V, fmt="v %.6f %.6f %.6f")
    np.savetxt(f, F + 1, fmt="f %d %d %d")

n = 4000
u, v = rng.uniform(0, 2 * np.pi, (2, n))
Rm, r = 1.0, 0.4
# area-uniform sampling on the torus: accept with probability (R + r cos v) / (R + r)
acc = rng.uniform(0, 1, n) < (Rm + r * np.cos(v)) / (Rm + r)
while acc.sum() < n:
    u2, v2 = rng.uniform(0, 2 * np.pi, (2, n))
    a2 = rng.uniform(0, 1, n) < (Rm + r * np.cos(v2)) / (Rm + r)
    u, v, acc = np.r_[u[acc], u2[a2]], np.r_[v[acc], v2[a2]], np.ones(acc.sum() + a2.sum(), bool)
u, v = u[:n], v[:n]
N = np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])
P = np.column_stack([(Rm + r * np.cos(v)) * np.cos(u), (Rm + r * np.cos(v)) * np.sin(u), r * np.sin(v)])
P += rng.normal(scale=0.005 * 2 * (Rm + r), size=P.shape)
np.savetxt(os.path.join(here, "torus_cloud.xyz"), np.column_stack([P, N]), fmt="%.6f")
print("wrote", os.path.abspath(here))
