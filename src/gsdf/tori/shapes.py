"""Analytic shapes, uniform oriented samplings and the corruptions of thesis §7.2.

Used by the tests and by ``bench/bench_tori.py``: spheres and capped cylinders of height 1 centred at the
origin (axis z), sampled uniformly by area, with exact signed distance functions; corruption by Gaussian noise
on positions and normals, uniform outliers in [-1, 1]³ with random normals, and flipped normals (§7.2).
"""

from __future__ import annotations

import numpy as np


def sphere_sdf(X, radius: float) -> np.ndarray:
    """Exact SDF of the sphere of ``radius`` at the origin."""
    return np.linalg.norm(X, axis=1) - radius


def cylinder_sdf(X, radius: float, height: float = 1.0) -> np.ndarray:
    """Exact SDF of the closed cylinder (axis z, centred at the origin)."""
    X = np.asarray(X, dtype=np.float64)
    dx = np.hypot(X[:, 0], X[:, 1]) - radius
    dz = np.abs(X[:, 2]) - 0.5 * height
    out = np.hypot(np.maximum(dx, 0), np.maximum(dz, 0))
    return out + np.minimum(np.maximum(dx, dz), 0.0)


def sample_sphere(n: int, radius: float, rng) -> tuple[np.ndarray, np.ndarray]:
    """``n`` uniform random points and outward normals on a sphere."""
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    return radius * N, N


def sample_cylinder(n: int, radius: float, rng, height: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points uniform by area on a closed cylinder (side and both caps), with outward normals."""
    side, cap = 2 * np.pi * radius * height, np.pi * radius ** 2
    which = rng.choice(3, size=n, p=np.array([side, cap, cap]) / (side + 2 * cap))
    th = rng.uniform(0, 2 * np.pi, n)
    P, N = np.zeros((n, 3)), np.zeros((n, 3))
    s = which == 0
    P[s] = np.column_stack([radius * np.cos(th[s]), radius * np.sin(th[s]), rng.uniform(-height / 2, height / 2, s.sum())])
    N[s] = np.column_stack([np.cos(th[s]), np.sin(th[s]), np.zeros(s.sum())])
    for c, z in ((1, height / 2), (2, -height / 2)):
        m = which == c
        rr = radius * np.sqrt(rng.uniform(0, 1, m.sum()))
        P[m] = np.column_stack([rr * np.cos(th[m]), rr * np.sin(th[m]), np.full(m.sum(), z)])
        N[m] = [0, 0, np.sign(z)]
    return P, N


def corrupt(P, N, rng, noise: float = 0.0, outliers: float = 0.0, flips: float = 0.0):
    """Corruptions of §7.2.

    ``noise``: Gaussian perturbation (std) added to positions and to normals (then renormalized);
    ``outliers``: floor(fraction × n) extra points uniform in [-1, 1]³ with random unit normals;
    ``flips``: fraction of normals, chosen at random, flipped.
    """
    P, N = P.copy(), N.copy()
    n = len(P)
    if flips > 0:
        idx = rng.choice(n, size=int(flips * n), replace=False)
        N[idx] *= -1
    if noise > 0:
        P += rng.normal(scale=noise, size=P.shape)
        N += rng.normal(scale=noise, size=N.shape)
        N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-12)
    m = int(np.floor(outliers * n))
    if m > 0:
        Po = rng.uniform(-1, 1, size=(m, 3))
        No = rng.normal(size=(m, 3))
        No /= np.linalg.norm(No, axis=1, keepdims=True)
        P, N = np.vstack([P, Po]), np.vstack([N, No])
    return P, N


def grid(resolution: int = 64, lo: float = -1.0, hi: float = 1.0) -> np.ndarray:
    """Nodes of a regular ``resolution``³ grid over [lo, hi]³, (resolution³, 3), x fastest... C order (i, j, k)."""
    t = np.linspace(lo, hi, resolution)
    X, Y, Z = np.meshgrid(t, t, t, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
