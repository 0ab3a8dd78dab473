"""Inputs shared by the conformance tests and ../record_refs.py (plain numpy/scipy; no gsdf, no peer)."""

from __future__ import annotations

import numpy as np

# potpourri3d test/sample.py: curves and points on bunny_small.ply / bunny_poly.ply (vertex indices)
PP3D_BROKEN = [[809, 808, 830, 783, 843, 181, 696, 781, 302, 937, 793],
               [1088, 487, 981, 1239, 1238, 402, 57, 1189],
               [529, 560, 316, 766, 833]]
PP3D_POINTS = [1085, 1000]
PP3D_SP_CURVE = [(603, [0.3, 0.3, 0.4]), (726, []), (1660, [0.3, 0.3, 0.4]), (718, []), (2058, [0.3, 0.3, 0.4]),
                 (162, []), (583, []), (88, []), (26, []), (1025, []), (600, []), (1394, [0.3, 0.3]), (1101, []),
                 (1517, [0.3, 0.3]), (919, []), (62, [])]
PP3D_POLY_CURVE = [96, 1037, 1238, 1239, 851, 487, 1088, 601, 217, 942, 702, 631, 805, 793, 937, 1237, 302, 781, 185,
                   923, 908, 843, 909, 910, 889, 809, 833, 766, 317, 267, 296, 345, 289, 484, 465, 985, 1168, 1099,
                   17, 212]
PP3D_CLOUD_CURVE = [809, 808, 830, 783, 843, 181, 696, 781, 302, 937, 793, 26, 1025, 704, 1047, 1088, 487, 981, 1239,
                    1238, 402, 57, 1189, 161, 471, 529, 560, 316, 766, 832]


def consistent_normals(V, polys, N):
    """Flip each normal to agree with the polygon mesh's area-weighted outward vertex normal."""
    vn = np.zeros_like(V)
    for p in polys:
        p = list(p)
        a = V[p]
        n = np.cross(a - a.mean(0), np.roll(a, -1, axis=0) - a.mean(0)).sum(0)
        vn[p] += n
    s = np.sign((vn * N).sum(1))
    s[s == 0] = 1
    return N * s[:, None]


def uv_sphere_polygons(nu=64, nv=32):
    """(V, polygons, source vertex, loop): unit UV sphere, quads between rings, triangles at the poles; the source
    is on the ring just above the equator, the loop is that ring (counter-clockwise seen from +z, closed)."""
    th = np.linspace(0, np.pi, nv + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    V = np.array([[0, 0, 1]] + [[np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)] for t in th for p in ph]
                 + [[0, 0, -1]], dtype=np.float64)
    S = len(V) - 1

    def idx(i, j):
        return 1 + i * nu + (j % nu)

    P = [[0, idx(0, j), idx(0, j + 1)] for j in range(nu)]
    P += [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)] for i in range(nv - 2) for j in range(nu)]
    P += [[S, idx(nv - 2, j + 1), idx(nv - 2, j)] for j in range(nu)]
    i = nv // 2 - 1
    loop = [idx(i, j) for j in range(nu)] + [idx(i, 0)]
    return V, P, idx(i, 0), loop


def fibonacci_sphere_case(n=4000, m=120):
    """(P (n, 3), curve): unit-sphere Fibonacci cloud and a closed polyline of point indices along the equator."""
    from scipy.spatial import cKDTree

    i = np.arange(n) + 0.5
    ph = np.arccos(1 - 2 * i / n)
    th = np.pi * (1 + 5 ** 0.5) * i
    P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    ang = np.linspace(0, 2 * np.pi, m, endpoint=False)
    E = np.column_stack([np.cos(ang), np.sin(ang), 0 * ang])
    idx = list(dict.fromkeys(cKDTree(P).query(E)[1].tolist()))
    return P, idx + [idx[0]]


def sample_on_mesh(V, F, n, seed=0):
    """n area-uniform random points on (V, F) and their unit face normals (numpy's generator, seeded)."""
    rng = np.random.default_rng(seed)
    e = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    A = 0.5 * np.linalg.norm(e, axis=1)
    I = rng.choice(len(F), n, p=A / A.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    X = V[F[I, 0]] + u[:, None] * (V[F[I, 1]] - V[F[I, 0]]) + v[:, None] * (V[F[I, 2]] - V[F[I, 0]])
    return X, e[I] / np.linalg.norm(e[I], axis=1, keepdims=True)

