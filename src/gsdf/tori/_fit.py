"""Per-point height-field coefficients by weighted least-squares jet fitting (the classical estimator, §5.1.2).

For each point p_i and its k nearest neighbours (k = 64 as in the thesis) we express the neighbours in the
frame (s_i, t_i, n_i) of Eq. 5.2, scale by the neighbourhood radius h_i (distance to the k-th neighbour), and
fit Q_i(s, t) = a00 + a10 s + a01 t + a20 s² + a11 s t + a02 t² by weighted least squares using

* position rows   Q_i(s_j, t_j) = h_j                       (heights of the neighbours), and
* normal rows     ∂Q_i/∂s(s_j, t_j) = −n_j·s_i / n_j·n_i,   ∂Q_i/∂t(s_j, t_j) = −n_j·t_i / n_j·n_i
  (slopes implied by the neighbours' normals; they make curvature estimates stable on sparse clouds),

with Gaussian weights exp(−2 (d_ij/h_i)²) times max(n_i·n_j, 0)² (neighbours on the far side of a thin
sheet, whose normals disagree, are ignored; cf. the brittleness discussed around Fig. 5.17), and a small
ridge penalty on the second-order coefficients. Curvatures are finally capped at ``curvature_cap / h_i``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from gsdf.tori._torus import local_frames


@njit(cache=True)
def _solve6(M, rhs):
    """Solve the small dense system M c = rhs in place by Gaussian elimination with partial pivoting (the
    algorithm of LAPACK's dgesv; hand-written because numba's np.linalg.solve costs ~7 s of compilation)."""
    n = rhs.shape[0]
    for col in range(n):
        piv = col
        for r in range(col + 1, n):
            if abs(M[r, col]) > abs(M[piv, col]):
                piv = r
        if M[piv, col] == 0.0:
            raise ValueError("jet fit: singular normal equations")
        if piv != col:
            for b in range(n):
                M[col, b], M[piv, b] = M[piv, b], M[col, b]
            rhs[col], rhs[piv] = rhs[piv], rhs[col]
        inv = 1.0 / M[col, col]
        for r in range(col + 1, n):
            f = M[r, col] * inv
            if f != 0.0:
                for b in range(col, n):
                    M[r, b] -= f * M[col, b]
                rhs[r] -= f * rhs[col]
    for r in range(n - 1, -1, -1):
        acc = rhs[r]
        for b in range(r + 1, n):
            acc -= M[r, b] * rhs[b]
        rhs[r] = acc / M[r, r]
    return rhs


@njit(parallel=True, cache=True)
def _jet_kernel(P, N, S, T, idx, dist, normal_weight, ridge, out):
    n, k = idx.shape
    for i in prange(n):
        h = dist[i, k - 1]
        if not h > 0.0:
            h = 1.0
        M = np.zeros((6, 6))
        rhs = np.zeros(6)
        row = np.zeros(6)
        wsum = 0.0
        for jj in range(k):
            j = idx[i, jj]
            d0, d1, d2 = P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2]
            cn = N[j, 0] * N[i, 0] + N[j, 1] * N[i, 1] + N[j, 2] * N[i, 2]
            if cn <= 0.0:
                continue
            dd = dist[i, jj] / h
            w = np.exp(-2.0 * dd * dd) * cn * cn
            U = (d0 * S[i, 0] + d1 * S[i, 1] + d2 * S[i, 2]) / h
            V = (d0 * T[i, 0] + d1 * T[i, 1] + d2 * T[i, 2]) / h
            Hh = (d0 * N[i, 0] + d1 * N[i, 1] + d2 * N[i, 2]) / h
            # position row
            row[0], row[1], row[2], row[3], row[4], row[5] = 1.0, U, V, U * U, U * V, V * V
            for a in range(6):
                rhs[a] += w * row[a] * Hh
                for b in range(6):
                    M[a, b] += w * row[a] * row[b]
            wsum += w
            if normal_weight > 0.0 and cn > 0.3:
                ns = N[j, 0] * S[i, 0] + N[j, 1] * S[i, 1] + N[j, 2] * S[i, 2]
                nt = N[j, 0] * T[i, 0] + N[j, 1] * T[i, 1] + N[j, 2] * T[i, 2]
                wn = w * normal_weight
                # slope rows (dimensionless in scaled coordinates)
                row[0], row[1], row[2], row[3], row[4], row[5] = 0.0, 1.0, 0.0, 2.0 * U, V, 0.0
                y = -ns / cn
                for a in range(6):
                    rhs[a] += wn * row[a] * y
                    for b in range(6):
                        M[a, b] += wn * row[a] * row[b]
                row[0], row[1], row[2], row[3], row[4], row[5] = 0.0, 0.0, 1.0, 0.0, U, 2.0 * V
                y = -nt / cn
                for a in range(6):
                    rhs[a] += wn * row[a] * y
                    for b in range(6):
                        M[a, b] += wn * row[a] * row[b]
        reg = ridge * (wsum + 1e-12)
        for a in range(6):
            M[a, a] += reg if a >= 3 else 1e-9 * (wsum + 1e-12)
        c = _solve6(M, rhs)
        # back to unscaled coordinates: a00 = h b00, a10 = b10, a20 = b20 / h
        out[i, 0] = c[0] * h
        out[i, 1] = c[1]
        out[i, 2] = c[2]
        out[i, 3] = c[3] / h
        out[i, 4] = c[4] / h
        out[i, 5] = c[5] / h


def jet_coefficients(P, N, idx, dist, normal_weight: float = 1.0, ridge: float = 1e-3) -> np.ndarray:
    """Six height-field coefficients per point (Eq. 5.2) by weighted least squares on its neighbours.

    Parameters
    ----------
    P, N : (n, 3) float64
        Points and unit normals.
    idx, dist : (n, k) int64 / float64
        k nearest neighbours of every point (including itself) and their distances, ascending.
    normal_weight : float
        Weight of the slope rows from the neighbours' normals (0: heights only, classical jet fitting).
    ridge : float
        Tikhonov weight on (a20, a11, a02), relative to the total weight.

    Returns
    -------
    (n, 6) float64
        (a00, a10, a01, a20, a11, a02) per point.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.spatial import cKDTree
    >>> g = np.linspace(-0.2, 0.2, 9)
    >>> X, Y = np.meshgrid(g, g)
    >>> P = np.column_stack([X.ravel(), Y.ravel(), -0.5 * X.ravel() ** 2])  # curvature 1 along x
    >>> N = np.column_stack([X.ravel(), 0 * X.ravel(), np.ones(81)]); N /= np.linalg.norm(N, axis=1)[:, None]
    >>> d, i = cKDTree(P).query(P, k=20)
    >>> (jet_coefficients(P, N, i, d)[40].round(2) + 0.0).tolist()
    [0.0, 0.0, 0.0, -0.5, 0.0, 0.0]
    """
    S, T = local_frames(N)
    out = np.empty((P.shape[0], 6))
    _jet_kernel(P, N, np.ascontiguousarray(S), np.ascontiguousarray(T), np.ascontiguousarray(idx, dtype=np.int64),
                np.ascontiguousarray(dist, dtype=np.float64), float(normal_weight), float(ridge), out)
    return out
