"""Eigen-decomposition of a symmetric 3 × 3 matrix inside numba kernels (no allocation, no LAPACK call).

Used per point or per polygon in hot loops (moving-least-squares frames of the reconstruction, polygon
Laplacian frames), where ``np.linalg.eigh`` would allocate and call LAPACK once per matrix.

Example
-------
>>> import numpy as np
>>> from gsdf.linalg._eig3 import jacobi_eig3
>>> A = np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]])
>>> U = np.empty((3, 3))
>>> jacobi_eig3(A, U)
>>> np.round(np.sort(np.diag(A)), 12).tolist()
[1.0, 3.0, 5.0]
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def jacobi_eig3(A, U):
    """Diagonalise the symmetric 3 × 3 matrix ``A`` in place by cyclic Jacobi rotations (to rounding; also
    for repeated and zero eigenvalues): on return ``A``'s diagonal holds the eigenvalues (unsorted) and the
    columns of ``U`` (3 × 3, overwritten) the matching unit eigenvectors, so that A_in = U diag(A) Uᵀ."""
    for r in range(3):
        for s in range(3):
            U[r, s] = 1.0 if r == s else 0.0
    for _sweep in range(50):
        off = A[0, 1] * A[0, 1] + A[0, 2] * A[0, 2] + A[1, 2] * A[1, 2]
        dia = A[0, 0] * A[0, 0] + A[1, 1] * A[1, 1] + A[2, 2] * A[2, 2]
        if off <= 1e-36 * dia or off == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = A[p, q]
            if apq == 0.0:
                continue
            # the rotation J in the (p, q) plane that zeroes A[p, q]: tan of its angle, the smaller root
            theta = (A[q, q] - A[p, p]) / (2.0 * apq)
            t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
            if theta < 0.0:
                t = -t
            cs = 1.0 / np.sqrt(t * t + 1.0)
            sn = t * cs
            for r in range(3):                   # A <- A J (columns p, q)
                arp, arq = A[r, p], A[r, q]
                A[r, p] = cs * arp - sn * arq
                A[r, q] = sn * arp + cs * arq
            for r in range(3):                   # A <- Jᵀ A (rows p, q)
                apr, aqr = A[p, r], A[q, r]
                A[p, r] = cs * apr - sn * aqr
                A[q, r] = sn * apr + cs * aqr
            A[p, q] = A[q, p] = 0.0
            for r in range(3):                   # U <- U J
                urp, urq = U[r, p], U[r, q]
                U[r, p] = cs * urp - sn * urq
                U[r, q] = sn * urp + cs * urq
