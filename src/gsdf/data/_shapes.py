"""Analytic test shapes: small triangle meshes (a grid square, an icosphere, an anisotropic strip), uniform oriented
samplings of spheres and capped cylinders with their exact signed distance functions, the point-cloud corruptions
of thesis §7.2 (Gaussian noise on positions and normals, uniform outliers with random normals, flipped normals),
and the 2D polygon signed distance used to check surface results on planar domains.
"""

from __future__ import annotations

import numpy as np


def grid_mesh(n: int, size: float = 1.0, jitter: float = 0.0, seed: int = 0, delaunay: bool = False):
    """Triangulated square ``[-size, size]²`` (z = 0) with ``n`` cells per side.

    ``jitter`` moves interior vertices by up to ``jitter`` cell widths (uniform), ``delaunay`` re-triangulates
    (scipy.spatial.Delaunay) instead of splitting every cell along its diagonal. Faces are counter-clockwise
    (normals +z). Returns ``V (N, 3), F (M, 3)``.

    Example
    -------
    >>> V, F = grid_mesh(4)
    >>> V.shape, F.shape
    ((25, 3), (32, 3))
    """
    x = np.linspace(-size, size, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    if jitter:
        rng = np.random.default_rng(seed)
        inner = (np.abs(V[:, :2]) < size * (1 - 1e-9)).all(1)
        V[inner, :2] += rng.uniform(-jitter, jitter, (int(inner.sum()), 2)) * (2 * size / n)
    if delaunay:
        from scipy.spatial import Delaunay

        F = Delaunay(V[:, :2]).simplices.astype(np.int64)
    else:
        idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
        a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
        F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    e1, e2 = V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]
    cw = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    F[cw] = F[cw][:, ::-1]
    return V, F


def sphere_mesh(subdivisions: int = 3, radius: float = 1.0):
    """Icosphere (outward normals) with vertices on the sphere of ``radius``; 20·4^s faces.

    Example
    -------
    >>> V, F = sphere_mesh(1)
    >>> len(F)
    80
    """
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=np.float64)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], dtype=np.int64)
    for _ in range(subdivisions):
        E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(E, axis=0, return_inverse=True)
        inv = inv.ravel()
        mid = len(V) + inv.reshape(3, -1).T                    # (m, 3): midpoints of edges 01, 12, 20
        V = np.concatenate([V, 0.5 * (V[uniq[:, 0]] + V[uniq[:, 1]])])
        a, b, c = F.T
        ab, bc, ca = mid.T
        F = np.concatenate([np.stack([a, ab, ca], 1), np.stack([b, bc, ab], 1), np.stack([c, ca, bc], 1),
                            np.stack([ab, bc, ca], 1)])
    V = V / np.linalg.norm(V, axis=1, keepdims=True) * radius
    return V, F


def anisotropic_mesh(n: int, stretch: float = 8.0, jitter: float = 0.3, seed: int = 0):
    """A sliver mesh of ``[-1, 1]²``: a jittered (n+1)² grid triangulated by Delaunay *after* shrinking x by
    ``stretch``, so in the true metric the triangles are long, very obtuse slivers spanning several columns
    (far from Delaunay). Used to exercise intrinsic Delaunay flipping (§9.4, Fig. 22).

    Example
    -------
    >>> V, F = anisotropic_mesh(8)
    >>> V.shape
    (81, 3)
    """
    from scipy.spatial import Delaunay

    x = np.linspace(-1, 1, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    rng = np.random.default_rng(seed)
    inner = (np.abs(V[:, :2]) < 1 - 1e-9).all(1)
    V[inner, :2] += rng.uniform(-jitter, jitter, (int(inner.sum()), 2)) * (2 / n)
    F = Delaunay(V[:, :2] * [1 / stretch, 1]).simplices.astype(np.int64)
    e1, e2 = V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]
    cw = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    F[cw] = F[cw][:, ::-1]
    return V, F


def polygon_sdf_2d(P, loop_xy, chunk: int = 256):
    """Exact signed distance (negative inside, winding number test) of 2D points P (n, 2) to the closed polygon
    ``loop_xy`` (k, 2) (first point repeated at the end or not).

    Example
    -------
    >>> sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1], [0, 0]])
    >>> [round(float(v), 3) for v in polygon_sdf_2d(np.array([[0.5, 0.5], [2, 0.5]]), sq)]
    [-0.5, 1.0]
    """
    P = np.asarray(P, np.float64)[:, :2]
    Q = np.asarray(loop_xy, np.float64)[:, :2]
    if not np.allclose(Q[0], Q[-1]):
        Q = np.concatenate([Q, Q[:1]])
    A, B = Q[:-1], Q[1:]
    d = np.full(len(P), np.inf)
    wn = np.zeros(len(P))
    for s in range(0, len(A), chunk):
        a, b = A[s:s + chunk], B[s:s + chunk]
        ab = b - a
        ap = P[:, None, :] - a[None]
        t = np.clip((ap * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
        d = np.minimum(d, np.linalg.norm(ap - t[..., None] * ab[None], axis=-1).min(1))
        bp = P[:, None, :] - b[None]
        wn += np.arctan2(ap[..., 0] * bp[..., 1] - ap[..., 1] * bp[..., 0], (ap * bp).sum(-1)).sum(1)
    return np.where(np.abs(wn) > np.pi, -d, d)

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
