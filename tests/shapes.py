"""Small analytic test shapes generated in code (no downloads in CI)."""

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
