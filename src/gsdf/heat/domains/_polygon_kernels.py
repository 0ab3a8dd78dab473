"""numba kernels of the polygon Laplacian of Bunge, Herholz, Kazhdan & Botsch 2020 ("Polygon Laplacian made
simple"), one pass over the polygons each:

* :func:`polygon_weights` — the affine weights of the virtual vertices (§3): per polygon a 3×3 least-squares
  problem for the point x minimizing the squared fan-triangle areas, then the minimum-norm affine weights
  reproducing x (the same decisions and cut-offs as :func:`numpy.linalg.pinv` with ``rcond=1e-10``);
* :func:`polygon_assembly` — per polygon the fan's cotan stiffness (s + 1)², prolonged to the s corners by
  ``Wᵀ K W`` (W = [w; I], §4: ``L = Pᵀ C_fan P`` restricted to one polygon), its lumped mass ``Wᵀ a`` (§4.2)
  and its area-weighted fan normals at the corners (§8.3 of Feng & Crane 2024), emitted as COO triplets and
  vertex sums: the refined sparse matrices are never built.

Used by :mod:`gsdf.heat.domains.polygon` (which owns the formulas' description); measured in
bench/bench_heat_surface.py --speed (polygon rows).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _jacobi3(S):
    """Eigenvalues (3,) and eigenvectors (columns of a 3×3) of a symmetric 3×3 matrix by cyclic Jacobi
    rotations (accurate to a few ulps of the largest eigenvalue, also for repeated and zero eigenvalues)."""
    A = S.copy()
    U = np.eye(3)
    for _ in range(30):
        off = A[0, 1] * A[0, 1] + A[0, 2] * A[0, 2] + A[1, 2] * A[1, 2]
        diag = A[0, 0] * A[0, 0] + A[1, 1] * A[1, 1] + A[2, 2] * A[2, 2]
        if off <= 1e-36 * diag or off == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = A[p, q]
            if apq == 0.0:
                continue
            theta = (A[q, q] - A[p, p]) / (2.0 * apq)
            t = (1.0 if theta >= 0 else -1.0) / (abs(theta) + np.sqrt(theta * theta + 1.0))
            c = 1.0 / np.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):                       # A <- Jᵀ A J (columns, then rows)
                akp, akq = A[k, p], A[k, q]
                A[k, p] = c * akp - s * akq
                A[k, q] = s * akp + c * akq
            for k in range(3):
                apk, aqk = A[p, k], A[q, k]
                A[p, k] = c * apk - s * aqk
                A[q, k] = s * apk + c * aqk
            A[p, q] = 0.0
            A[q, p] = 0.0
            for k in range(3):
                ukp, ukq = U[k, p], U[k, q]
                U[k, p] = c * ukp - s * ukq
                U[k, q] = s * ukp + c * ukq
    lam = np.empty(3)
    for k in range(3):
        lam[k] = A[k, k]
    return lam, U


@njit(cache=True)
def _right_svd(A0, s):
    """Singular values (3,) and right singular vectors (columns of a 3×3) of the s×3 matrix ``A0[:s]``, by
    one-sided (Hestenes) Jacobi rotations of its columns."""
    A = A0[:s].copy()
    V = np.eye(3)
    for _ in range(30):
        rotated = False
        for p, q in ((0, 1), (0, 2), (1, 2)):
            al = 0.0
            be = 0.0
            ga = 0.0
            for i in range(s):
                al += A[i, p] * A[i, p]
                be += A[i, q] * A[i, q]
                ga += A[i, p] * A[i, q]
            if ga == 0.0 or abs(ga) <= 1e-17 * np.sqrt(al * be):
                continue
            rotated = True
            zeta = (be - al) / (2.0 * ga)
            t = (1.0 if zeta >= 0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
            c = 1.0 / np.sqrt(1.0 + t * t)
            sn = c * t
            for i in range(s):
                aip, aiq = A[i, p], A[i, q]
                A[i, p] = c * aip - sn * aiq
                A[i, q] = sn * aip + c * aiq
            for i in range(3):
                vip, viq = V[i, p], V[i, q]
                V[i, p] = c * vip - sn * viq
                V[i, q] = sn * vip + c * viq
        if not rotated:
            break
    sig = np.empty(3)
    for k in range(3):
        acc = 0.0
        for i in range(s):
            acc += A[i, k] * A[i, k]
        sig[k] = np.sqrt(acc)
    return sig, V


@njit(cache=True)
def _min_eig3(H):
    """Smallest eigenvalue of a symmetric 3×3 matrix, closed form (trigonometric); only used to choose between
    a direct solve and a pseudo-inverse."""
    q3 = (H[0, 0] + H[1, 1] + H[2, 2]) / 3.0
    p1 = H[0, 1] ** 2 + H[0, 2] ** 2 + H[1, 2] ** 2
    p2 = (H[0, 0] - q3) ** 2 + (H[1, 1] - q3) ** 2 + (H[2, 2] - q3) ** 2 + 2.0 * p1
    p = np.sqrt(p2 / 6.0)
    if p == 0:
        return q3
    B = (H - q3 * np.eye(3)) / p
    r = 0.5 * (B[0, 0] * (B[1, 1] * B[2, 2] - B[1, 2] * B[2, 1]) - B[0, 1] * (B[1, 0] * B[2, 2] - B[1, 2] * B[2, 0])
               + B[0, 2] * (B[1, 0] * B[2, 1] - B[1, 1] * B[2, 0]))
    r = min(1.0, max(-1.0, r))
    return q3 + 2.0 * p * np.cos(np.arccos(r) / 3.0 + 2.0 * np.pi / 3.0)


@njit(cache=True)
def _solve3(H, b):
    """x = H⁻¹ b for a well-conditioned symmetric 3×3 H, by the adjugate."""
    a, bb, c = H[0, 0], H[0, 1], H[0, 2]
    d, e, f = H[1, 1], H[1, 2], H[2, 2]
    A00, A01, A02 = d * f - e * e, c * e - bb * f, bb * e - c * d
    A11, A12, A22 = a * f - c * c, bb * c - a * e, a * d - bb * bb
    det = a * A00 + bb * A01 + c * A02
    x = np.empty(3)
    x[0] = (A00 * b[0] + A01 * b[1] + A02 * b[2]) / det
    x[1] = (A01 * b[0] + A11 * b[1] + A12 * b[2]) / det
    x[2] = (A02 * b[0] + A12 * b[1] + A22 * b[2]) / det
    return x


@njit(cache=True)
def _pinv_apply(S, b, keep_ratio, floor):
    """Σ_k (u_k · b) / λ_k u_k over the eigenpairs of S with λ_k > keep_ratio · floor; also whether all kept."""
    lam, U = _jacobi3(S)
    x = np.zeros(3)
    allkept = True
    for k in range(3):
        if lam[k] > keep_ratio * floor:
            ub = U[0, k] * b[0] + U[1, k] * b[1] + U[2, k] * b[2]
            for j in range(3):
                x[j] += ub / lam[k] * U[j, k]
        else:
            allkept = False
    return x, allkept, lam


@njit(cache=True)
def polygon_weights(X):
    """Virtual-vertex weights (q, s) of q polygons with s corners ``X`` (q, s, 3) (module docs; Bunge et al.
    2020 §3). Degenerate polygons (no unique minimizer, or weights that do not reproduce it) get 1/s."""
    q, s, _ = X.shape
    W = np.empty((q, s))
    A = np.empty((s, 3))
    for p in range(q):
        for j in range(3):
            c = 0.0
            for i in range(s):
                c += X[p, i, j]
            c /= s
            for i in range(s):
                A[i, j] = X[p, i, j] - c
        # (a - x) × (b - x) = a × b + [d]_× x with d = b - a: normal equations H x = rhs,
        # H = Σ (|d|² I − d dᵀ), rhs = Σ d × (a × b)
        H = np.zeros((3, 3))
        rhs = np.zeros(3)
        for i in range(s):
            i1 = (i + 1) % s
            d0, d1, d2 = A[i1, 0] - A[i, 0], A[i1, 1] - A[i, 1], A[i1, 2] - A[i, 2]
            dd = d0 * d0 + d1 * d1 + d2 * d2
            dv = (d0, d1, d2)
            for r in range(3):
                for cc in range(3):
                    H[r, cc] -= dv[r] * dv[cc]
                H[r, r] += dd
            c0 = A[i, 1] * A[i1, 2] - A[i, 2] * A[i1, 1]
            c1 = A[i, 2] * A[i1, 0] - A[i, 0] * A[i1, 2]
            c2 = A[i, 0] * A[i1, 1] - A[i, 1] * A[i1, 0]
            rhs[0] += d1 * c2 - d2 * c1
            rhs[1] += d2 * c0 - d0 * c2
            rhs[2] += d0 * c1 - d1 * c0
        scale = H[0, 0] + H[1, 1] + H[2, 2]
        ok = scale > 0
        floor = max(scale, 1e-300)
        if _min_eig3(H) > 1e-6 * floor:
            x = _solve3(H, rhs)
        else:                                   # collinear corners: the pseudo-inverse (no unique minimizer)
            x, allkept, _ = _pinv_apply(H, rhs, 1e-10, floor)
            ok = ok and allkept
        # minimum-norm affine weights w = K⁺ [x; 1], K = [Aᵀ; 1ᵀ]: A is centred, so K Kᵀ = diag(AᵀA, s) and
        # w = A (AᵀA)⁺ x + 1/s, with pinv's cut-off on the singular values √λ(AᵀA) and √s of K
        G = np.zeros((3, 3))
        for i in range(s):
            for r in range(3):
                for cc in range(3):
                    G[r, cc] += A[i, r] * A[i, cc]
        gtr = G[0, 0] + G[1, 1] + G[2, 2]
        gmin = _min_eig3(G)
        cut = 1e-10 * np.sqrt(max(s, gtr))
        if gmin > 1e-6 * gtr and gmin > (1e4 * cut) ** 2:
            y = _solve3(G, x)
        else:                                   # planar and nearly planar polygons
            # singular values of A by one-sided Jacobi on A itself (accurate down to eps·|A|; those of AᵀA
            # would lose the small ones), cut like pinv: σ_k ≤ 1e-10 · max(σ_max(A), √s) count as zero
            sig, Vt = _right_svd(A, s)
            smax = max(max(sig[0], max(sig[1], sig[2])), np.sqrt(float(s)))
            y = np.zeros(3)
            for k in range(3):
                if sig[k] > 1e-10 * smax:
                    vx = Vt[0, k] * x[0] + Vt[1, k] * x[1] + Vt[2, k] * x[2]
                    for j in range(3):
                        y[j] += vx / (sig[k] * sig[k]) * Vt[j, k]
        tot = 0.0
        for i in range(s):
            W[p, i] = A[i, 0] * y[0] + A[i, 1] * y[1] + A[i, 2] * y[2] + 1.0 / s
            tot += W[p, i]
            ok = ok and np.isfinite(W[p, i])
        if not ok or abs(tot - 1.0) >= 1e-6:
            for i in range(s):
                W[p, i] = 1.0 / s
    return W


@njit(cache=True)
def polygon_assembly(Vr, start, corners, vid, wflat, n, thresh):
    """Per-polygon Laplacian, mass and normals (module docs).

    Parameters
    ----------
    Vr : (n + #virtual, 3) refined vertex positions; start : (m + 1,) offsets into ``corners`` (flat corner
    indices); vid : (m,) the virtual vertex of every polygon (-1: a triangle, not refined); wflat : weights
    aligned with ``corners`` (ignored for triangles); n : number of original vertices; thresh : fan triangles
    with twice their area ≤ thresh carry nothing (degenerate fans).

    Returns
    -------
    rows, cols, vals : the Σ s² COO triplets of L; mass : (n,); An : (n, 3) area-weighted normal sums.
    """
    m = len(start) - 1
    tot = 0
    for p in range(m):
        s = start[p + 1] - start[p]
        tot += s * s
    rows = np.empty(tot, np.int64)
    cols = np.empty(tot, np.int64)
    vals = np.empty(tot)
    mass = np.zeros(n)
    An = np.zeros((n, 3))
    smax = 0
    for p in range(m):
        smax = max(smax, start[p + 1] - start[p])
    K = np.zeros((smax + 1, smax + 1))
    a = np.zeros(smax + 1)
    T = np.zeros((3, 3))
    node = np.empty(3, np.int64)
    out = 0
    for p in range(m):
        b0 = start[p]
        s = start[p + 1] - b0
        refined = vid[p] >= 0
        base = 1 if refined else 0            # local node 0 = the virtual vertex when refined
        nl = s + base
        for i in range(nl):
            a[i] = 0.0
            for j in range(nl):
                K[i, j] = 0.0
        ntri = s if refined else 1
        for t in range(ntri):
            if refined:
                node[0], node[1], node[2] = 0, 1 + t, 1 + (t + 1) % s
            else:
                node[0], node[1], node[2] = 0, 1, 2
            for k in range(3):
                loc = node[k]
                g = vid[p] if (refined and loc == 0) else corners[b0 + loc - base]
                for j in range(3):
                    T[k, j] = Vr[g, j]
            # slot k: edge (k, k+1); the corner angle at k has cot (|e_{k-1}|² + |e_k|² − |e_{k+1}|²) / (4 area)
            e0 = T[1] - T[0]
            e1 = T[2] - T[1]
            e2 = T[0] - T[2]
            cx = e0[1] * (-e2[2]) - e0[2] * (-e2[1])
            cy = e0[2] * (-e2[0]) - e0[0] * (-e2[2])
            cz = e0[0] * (-e2[1]) - e0[1] * (-e2[0])
            dbl = np.sqrt(cx * cx + cy * cy + cz * cz)
            if dbl <= thresh:
                continue
            area = 0.5 * dbl
            l0 = e0[0] * e0[0] + e0[1] * e0[1] + e0[2] * e0[2]
            l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]
            l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]
            L2 = (l0, l1, l2)
            for k in range(3):
                cot = (L2[(k + 2) % 3] + L2[k] - L2[(k + 1) % 3]) / (4.0 * area)
                w = 0.5 * cot                     # cotan weight of the edge opposite corner k
                i, j = node[(k + 1) % 3], node[(k + 2) % 3]
                K[i, j] -= w
                K[j, i] -= w
                K[i, i] += w
                K[j, j] += w
                a[node[k]] += area / 3.0
            # area-weighted unit normal = half the cross product, at the original corners
            for k in range(3):
                loc = node[k]
                if refined and loc == 0:
                    continue
                v = corners[b0 + loc - base]
                An[v, 0] += 0.5 * cx
                An[v, 1] += 0.5 * cy
                An[v, 2] += 0.5 * cz
        # prolong to the corners: Wᵀ K W with W = [w; I] (exactly symmetric: the mixed terms are summed as
        # S_ij + S_ji and the virtual-virtual term as K00 (w_i w_j))
        for i in range(s):
            vi = corners[b0 + i]
            if refined:
                wi = wflat[b0 + i]
                mass[vi] += a[1 + i] + wi * a[0]
            else:
                mass[vi] += a[i]
            for j in range(s):
                if refined:
                    wj = wflat[b0 + j]
                    val = K[1 + i, 1 + j] + (wi * K[0, 1 + j] + wj * K[0, 1 + i]) + K[0, 0] * (wi * wj)
                else:
                    val = K[i, j]
                rows[out] = vi
                cols[out] = corners[b0 + j]
                vals[out] = val
                out += 1
    return rows, cols, vals, mass, An
