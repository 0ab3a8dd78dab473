"""The test shapes, generated in code (no downloads in CI): closed meshes and clouds with analytic answers
(cube, spheres) and procedural meshes of known topology (torus, annulus, double torus) for the DEC and
surface-winding-number tests."""

import numpy as np


def cube(half: float = 0.5):
    """Closed axis-aligned cube [-half, half]^3, 12 outward-oriented triangles."""
    V = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)], float)
    F = np.array([
        [0, 1, 3], [0, 3, 2],  # x = -h
        [4, 6, 7], [4, 7, 5],  # x = +h
        [0, 4, 5], [0, 5, 1],  # y = -h
        [2, 3, 7], [2, 7, 6],  # y = +h
        [0, 2, 6], [0, 6, 4],  # z = -h
        [1, 5, 7], [1, 7, 3],  # z = +h
    ])
    return V, F


def uv_sphere(n_lat: int = 20, n_lon: int = 40, radius: float = 1.0):
    """Closed UV sphere with outward-oriented triangles (poles are single vertices)."""
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")
    V = np.column_stack([np.sin(T).ravel() * np.cos(P).ravel(), np.sin(T).ravel() * np.sin(P).ravel(),
                         np.cos(T).ravel()])
    V = np.vstack([[0, 0, 1], V, [0, 0, -1]]) * radius
    F = []
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)  # noqa: E731
    for j in range(n_lon):
        F.append([0, idx(0, j), idx(0, j + 1)])
        F.append([len(V) - 1, idx(n_lat - 2, j + 1), idx(n_lat - 2, j)])
    for i in range(n_lat - 2):
        for j in range(n_lon):
            a, b, c, d = idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1)
            F.append([a, c, d])
            F.append([a, d, b])
    return V, np.array(F)


def fibonacci_sphere(n: int, radius: float = 1.0):
    """n nearly uniform points on a sphere (their outward normals equal P / radius)."""
    i = np.arange(n) + 0.5
    phi = np.arccos(1 - 2 * i / n)
    th = np.pi * (1 + 5**0.5) * i
    return radius * np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])


def torus(nu=24, nv=12, R=1.0, r=0.4):
    """Closed torus, outward-oriented; vertex (i, j) = i * nv + j at angles (2πi/nu around the axis, 2πj/nv
    around the tube). Returns V, F, (i, j) index grid."""
    u = 2 * np.pi * np.arange(nu) / nu
    v = 2 * np.pi * np.arange(nv) / nv
    U, W = np.meshgrid(u, v, indexing="ij")
    V = np.stack([(R + r * np.cos(W)) * np.cos(U), (R + r * np.cos(W)) * np.sin(U), r * np.sin(W)], -1)
    V = V.reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = (i * nv + j).ravel()
    b = (((i + 1) % nu) * nv + j).ravel()
    c = (((i + 1) % nu) * nv + (j + 1) % nv).ravel()
    d = (i * nv + (j + 1) % nv).ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return V, F, np.arange(nu * nv).reshape(nu, nv)


def annulus(nr=6, nt=32, r0=0.5, r1=1.0):
    """Flat annulus r0 ≤ |x| ≤ r1 in the z = 0 plane, counter-clockwise (normal +z). Vertex (i, k) at radius
    index i, angle index k is i * nt + k."""
    rr = np.linspace(r0, r1, nr + 1)
    t = 2 * np.pi * np.arange(nt) / nt
    R, T = np.meshgrid(rr, t, indexing="ij")
    V = np.stack([R * np.cos(T), R * np.sin(T), 0 * R], -1).reshape(-1, 3)
    i, k = np.meshgrid(np.arange(nr), np.arange(nt), indexing="ij")
    a = (i * nt + k).ravel()
    b = (i * nt + (k + 1) % nt).ravel()
    c = ((i + 1) * nt + (k + 1) % nt).ravel()
    d = ((i + 1) * nt + k).ravel()
    F = np.concatenate([np.stack([a, c, b], 1), np.stack([a, d, c], 1)])
    return V, F, np.arange((nr + 1) * nt).reshape(nr + 1, nt)


def double_torus(n=40):
    """Closed genus-2 surface: marching cubes of the union of two solid tori (centres x = ±0.9, R = 0.8,
    r = 0.3), faces oriented outward."""
    from skimage.measure import marching_cubes

    x = np.linspace(-2.1, 2.1, n)
    X, Y, Z = np.meshgrid(x, x * 0.6, x * 0.3, indexing="ij")

    def tor(cx):
        q = np.sqrt((X - cx) ** 2 + Y ** 2) - 0.8
        return np.sqrt(q ** 2 + Z ** 2) - 0.3

    f = np.minimum(tor(0.9), tor(-0.9))
    sp = (x[1] - x[0], (x[1] - x[0]) * 0.6, (x[1] - x[0]) * 0.3)
    V, F, _, _ = marching_cubes(f, 0.0, spacing=sp)
    V = V + np.array([x[0], 0.6 * x[0], 0.3 * x[0]])
    # marching_cubes orients faces towards increasing f (outward for an SDF): flip if the volume is negative
    vol = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6
    if vol < 0:
        F = F[:, ::-1]
    return V, np.ascontiguousarray(F, dtype=np.int64)


def polyline_chain(dec, loop, closed=True):
    """Integer edge chain (nE,) of a vertex polyline along edges of ``dec``."""
    loop = np.asarray(loop)
    a = loop if not closed else loop
    b = np.roll(loop, -1) if closed else loop[1:]
    a = a if closed else loop[:-1]
    n = dec.n_vertices
    key = dec.edges[:, 0] * n + dec.edges[:, 1]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    e = np.searchsorted(key, lo * n + hi)
    assert np.all(key[e] == lo * n + hi), "polyline leaves the edges"
    g = np.zeros(dec.n_edges)
    np.add.at(g, e, np.where(a < b, 1.0, -1.0))
    return g
