"""numba kernels of the polygon Laplacian of Bunge, Herholz, Kazhdan & Botsch 2020 ("Polygon Laplacian made
simple"), one pass over the polygons each:

* :func:`polygon_weights` — the affine weights of the virtual vertices (§3): per polygon a 3×3 least-squares
  problem for the point x minimizing the squared fan-triangle areas, then the minimum-norm affine weights
  reproducing x (the same decisions and cut-offs as :func:`numpy.linalg.pinv` with ``rcond=1e-10``);
* :func:`polygon_assembly` — per polygon the fan's cotan stiffness (s + 1)², prolonged to the s corners by
  ``Wᵀ K W`` (W = [w; I], §4: ``L = Pᵀ C_fan P`` restricted to one polygon), its lumped mass ``Wᵀ a`` (§4.2)
  and its area-weighted fan normals at the corners (§8.3 of Feng & Crane 2024), emitted as triplet values and
  vertex sums: the refined sparse matrices are never built;
* :func:`refine_polygons` — the weights, virtual vertices, fans and prolongation of all polygons at once;
* :func:`polygon_csr_pattern` — L's CSR pattern from the polygons' incidence and the slot of every triplet.

Used by :mod:`gsdf.heat.polygon._domain` (which owns the formulas' description).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gsdf.linalg._assembly import sort_row
from gsdf.linalg._eig3 import jacobi_eig3


@njit(cache=True)
def _jacobi3(S):
    """Eigenvalues (3,) and eigenvectors (columns of a 3×3) of a symmetric 3×3 matrix by cyclic Jacobi
    rotations (accurate to a few ulps of the largest eigenvalue, also for repeated and zero eigenvalues)."""
    A = S.copy()
    U = np.empty((3, 3))
    jacobi_eig3(A, U)
    lam = np.empty(3)
    for k in range(3):
        lam[k] = A[k, k]
    return lam, U


@njit(cache=True)
def _right_svd(A, s, V, sig):
    """Singular values ``sig`` (3,) and right singular vectors (columns of ``V``, 3×3) of the s×3 matrix
    ``A[:s]``, by one-sided (Hestenes) Jacobi rotations of its columns; ``A[:s]`` is overwritten by A V."""
    for i in range(3):
        for j in range(3):
            V[i, j] = 1.0 if i == j else 0.0
    tot = 0.0
    for i in range(s):
        for j in range(3):
            tot += A[i, j] * A[i, j]
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
            # converged pair: orthogonal to rounding, or one column negligible (σ < 1e-15 |A|, far below the
            # 1e-10 cut-off of the callers)
            if abs(ga) <= 1e-15 * np.sqrt(al * be) or min(al, be) <= 1e-30 * tot:
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
    for k in range(3):
        acc = 0.0
        for i in range(s):
            acc += A[i, k] * A[i, k]
        sig[k] = np.sqrt(acc)


@njit(cache=True)
def _min_eig3(a, b, c, d, e, f):
    """Smallest eigenvalue of the symmetric 3×3 matrix [[a, b, c], [b, d, e], [c, e, f]], closed form
    (trigonometric); only used to choose between a direct solve and a pseudo-inverse."""
    q3 = (a + d + f) / 3.0
    p1 = b * b + c * c + e * e
    p2 = (a - q3) ** 2 + (d - q3) ** 2 + (f - q3) ** 2 + 2.0 * p1
    p = np.sqrt(p2 / 6.0)
    if p == 0:
        return q3
    a, d, f, b, c, e = (a - q3) / p, (d - q3) / p, (f - q3) / p, b / p, c / p, e / p
    r = 0.5 * (a * (d * f - e * e) - b * (b * f - e * c) + c * (b * e - d * c))
    r = min(1.0, max(-1.0, r))
    return q3 + 2.0 * p * np.cos(np.arccos(r) / 3.0 + 2.0 * np.pi / 3.0)


@njit(cache=True)
def _solve3(a, bb, c, d, e, f, b0, b1, b2):
    """x = H⁻¹ b for a well-conditioned symmetric 3×3 H = [[a, bb, c], [bb, d, e], [c, e, f]], by the
    adjugate."""
    A00, A01, A02 = d * f - e * e, c * e - bb * f, bb * e - c * d
    A11, A12, A22 = a * f - c * c, bb * c - a * e, a * d - bb * bb
    det = a * A00 + bb * A01 + c * A02
    return ((A00 * b0 + A01 * b1 + A02 * b2) / det, (A01 * b0 + A11 * b1 + A12 * b2) / det,
            (A02 * b0 + A12 * b1 + A22 * b2) / det)


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
def _centred_weights(A, s, Asv, Vsv, sig, out, o):
    """The weights of one polygon with s corners ``A[:s]`` (centred on their mean) into ``out[o:o + s]``
    (:func:`polygon_weights`; ``Asv``, ``Vsv``, ``sig``: work arrays)."""
    # (a - x) × (b - x) = a × b + [d]_× x with d = b - a: normal equations H x = rhs,
    # H = Σ (|d|² I − d dᵀ), rhs = Σ d × (a × b)
    h00 = h01 = h02 = h11 = h12 = h22 = 0.0
    r0 = r1 = r2 = 0.0
    g00 = g01 = g02 = g11 = g12 = g22 = 0.0
    for i in range(s):
        i1 = (i + 1) % s
        a0, a1, a2 = A[i, 0], A[i, 1], A[i, 2]
        b0, b1, b2 = A[i1, 0], A[i1, 1], A[i1, 2]
        d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
        dd = d0 * d0 + d1 * d1 + d2 * d2
        h00 += dd - d0 * d0
        h11 += dd - d1 * d1
        h22 += dd - d2 * d2
        h01 -= d0 * d1
        h02 -= d0 * d2
        h12 -= d1 * d2
        c0 = a1 * b2 - a2 * b1
        c1 = a2 * b0 - a0 * b2
        c2 = a0 * b1 - a1 * b0
        r0 += d1 * c2 - d2 * c1
        r1 += d2 * c0 - d0 * c2
        r2 += d0 * c1 - d1 * c0
        g00 += a0 * a0
        g01 += a0 * a1
        g02 += a0 * a2
        g11 += a1 * a1
        g12 += a1 * a2
        g22 += a2 * a2
    scale = h00 + h11 + h22
    ok = scale > 0
    floor = max(scale, 1e-300)
    if _min_eig3(h00, h01, h02, h11, h12, h22) > 1e-6 * floor:
        x0, x1, x2 = _solve3(h00, h01, h02, h11, h12, h22, r0, r1, r2)
    else:                                   # collinear corners: the pseudo-inverse (no unique minimizer)
        H = np.array([[h00, h01, h02], [h01, h11, h12], [h02, h12, h22]])
        xv, allkept, _ = _pinv_apply(H, np.array([r0, r1, r2]), 1e-10, floor)
        x0, x1, x2 = xv[0], xv[1], xv[2]
        ok = ok and allkept
    # minimum-norm affine weights w = K⁺ [x; 1], K = [Aᵀ; 1ᵀ]: A is centred, so K Kᵀ = diag(AᵀA, s) and
    # w = A (AᵀA)⁺ x + 1/s, with pinv's cut-off on the singular values of K (those of A, and √s)
    gtr = g00 + g11 + g22
    gmin = _min_eig3(g00, g01, g02, g11, g12, g22)
    cut = 1e-10 * np.sqrt(max(s, gtr))
    if gmin > 1e-6 * gtr and gmin > (1e4 * cut) ** 2:
        y0, y1, y2 = _solve3(g00, g01, g02, g11, g12, g22, x0, x1, x2)
    else:                                   # planar and nearly planar polygons
        # singular values of A by one-sided Jacobi on A itself (accurate down to eps·|A|; those of AᵀA
        # would lose the small ones), cut like pinv: σ_k ≤ 1e-10 · max(σ_max(A), √s) count as zero
        for i in range(s):
            for j in range(3):
                Asv[i, j] = A[i, j]
        _right_svd(Asv, s, Vsv, sig)
        smax = max(max(sig[0], max(sig[1], sig[2])), np.sqrt(float(s)))
        y0 = y1 = y2 = 0.0
        for k in range(3):
            if sig[k] > 1e-10 * smax:
                f = (Vsv[0, k] * x0 + Vsv[1, k] * x1 + Vsv[2, k] * x2) / (sig[k] * sig[k])
                y0 += f * Vsv[0, k]
                y1 += f * Vsv[1, k]
                y2 += f * Vsv[2, k]
    tot = 0.0
    for i in range(s):
        out[o + i] = A[i, 0] * y0 + A[i, 1] * y1 + A[i, 2] * y2 + 1.0 / s
        tot += out[o + i]
        ok = ok and np.isfinite(out[o + i])
    if not ok or abs(tot - 1.0) >= 1e-6:
        for i in range(s):
            out[o + i] = 1.0 / s


@njit(cache=True)
def polygon_weights(X):
    """Virtual-vertex weights (q, s) of q polygons with s corners ``X`` (q, s, 3) (module docs; Bunge et al.
    2020 §3). Degenerate polygons (no unique minimizer, or weights that do not reproduce it) get 1/s."""
    q, s, _ = X.shape
    W = np.empty(q * s)
    A = np.empty((s, 3))
    Asv = np.empty((s, 3))
    Vsv = np.empty((3, 3))
    sig = np.empty(3)
    for p in range(q):
        for j in range(3):
            c = 0.0
            for i in range(s):
                c += X[p, i, j]
            c /= s
            for i in range(s):
                A[i, j] = X[p, i, j] - c
        _centred_weights(A, s, Asv, Vsv, sig, W, p * s)
    return W.reshape(q, s)


@njit(cache=True)
def refine_polygons(V, start, corners):
    """The virtual-vertex refinement of polygons in the flat layout (``corners[start[p]:start[p + 1]]`` = the
    corners of polygon p, ascending degree): weights ``wflat`` aligned with ``corners`` (0 for triangles), the
    virtual vertex ``vid`` of every polygon (-1 for triangles; numbered n, n + 1, … in polygon order), the
    virtual positions ``Σ w_i x_i`` (#virtual, 3), the refined triangles (a triangle as it is, a polygon as the
    fan (virtual, c_i, c_{i+1})) and the prolongation in canonical CSR (identity rows, then per virtual vertex
    its weights by ascending column): ``(wflat, vid, newV, F, p_indptr, p_indices, p_data)``."""
    n = len(V)
    m = len(start) - 1
    nv = 0
    nf = 0
    smax = 3
    for p in range(m):
        s = start[p + 1] - start[p]
        smax = max(smax, s)
        if s > 3:
            nv += 1
            nf += s
        else:
            nf += 1
    wflat = np.zeros(len(corners))
    vid = np.full(m, -1, np.int64)
    newV = np.zeros((nv, 3))
    F = np.empty((nf, 3), np.int64)
    pnz = n + (start[m] - 0)
    p_indptr = np.empty(n + nv + 1, np.int64)
    p_indices = np.empty(pnz, np.int64)
    p_data = np.empty(pnz)
    for i in range(n):
        p_indptr[i] = i
        p_indices[i] = i
        p_data[i] = 1.0
    p_indptr[n] = n
    A = np.empty((smax, 3))
    Asv = np.empty((smax, 3))
    Vsv = np.empty((3, 3))
    sig = np.empty(3)
    srt = np.empty(smax, np.int64)
    q = n
    f = 0
    k = 0
    for p in range(m):
        b0 = start[p]
        s = start[p + 1] - b0
        if s == 3:
            F[f, 0], F[f, 1], F[f, 2] = corners[b0], corners[b0 + 1], corners[b0 + 2]
            f += 1
            continue
        for j in range(3):
            c = 0.0
            for i in range(s):
                c += V[corners[b0 + i], j]
            c /= s
            for i in range(s):
                A[i, j] = V[corners[b0 + i], j] - c
        _centred_weights(A, s, Asv, Vsv, sig, wflat, b0)
        v = n + k
        vid[p] = v
        for i in range(s):
            w = wflat[b0 + i]
            for j in range(3):
                newV[k, j] += w * V[corners[b0 + i], j]
            F[f, 0], F[f, 1], F[f, 2] = v, corners[b0 + i], corners[b0 + (i + 1) % s]
            f += 1
        for i in range(s):                        # the row of P: columns ascending (insertion sort)
            srt[i] = i
            a = i
            while a > 0 and corners[b0 + srt[a - 1]] > corners[b0 + srt[a]]:
                srt[a - 1], srt[a] = srt[a], srt[a - 1]
                a -= 1
        for i in range(s):
            p_indices[q] = corners[b0 + srt[i]]
            p_data[q] = wflat[b0 + srt[i]]
            q += 1
        k += 1
        p_indptr[n + k] = q
    return wflat, vid, newV, F, p_indptr, p_indices[:q].copy(), p_data[:q].copy()


@njit(cache=True)
def first_repeat(start, corners):
    """The first polygon (in order) with a repeated corner, or -1."""
    for p in range(len(start) - 1):
        for a in range(start[p], start[p + 1]):
            for b in range(a + 1, start[p + 1]):
                if corners[a] == corners[b]:
                    return p
    return -1


@njit(cache=True)
def polygon_assembly(Vr, start, corners, vid, wflat, n, thresh):
    """Per-polygon Laplacian, mass and normals (module docs), and the fine triangles' data of steps II–III.

    Parameters
    ----------
    Vr : (n + #virtual, 3) refined vertex positions; start : (m + 1,) offsets into ``corners`` (flat corner
    indices); vid : (m,) the virtual vertex of every polygon (-1: a triangle, not refined); wflat : weights
    aligned with ``corners`` (ignored for triangles); n : number of original vertices; thresh : fan triangles
    with twice their area ≤ thresh carry nothing (degenerate fans).

    Returns
    -------
    vals : the Σ s² values of L's triplets (polygon p, row corner i, column corner j; CSR slots from
    :func:`polygon_csr_pattern`); mass : (n,); An : (n, 3) area-weighted normal sums;
    good : (k,) bool, the fine triangles (triangles, then the fans polygon by polygon) that are kept;
    fn : (k, 3) their unit normals; fG : (k, 3, 3) ``|f| ∇λ_c = ½ n × (v_{c+2} − v_{c+1})`` per corner c
    (the divergence weights of :meth:`gsdf.mesh._triangle_ops.TriangleOperators.divergence`).
    """
    m = len(start) - 1
    tot = 0
    nfine = 0
    for p in range(m):
        s = start[p + 1] - start[p]
        tot += s * s
        nfine += s if vid[p] >= 0 else 1
    good = np.zeros(nfine, np.bool_)
    fn = np.zeros((nfine, 3))
    fG = np.zeros((nfine, 3, 3))
    ft = -1
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
            ft += 1
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
            e00, e01, e02 = T[1, 0] - T[0, 0], T[1, 1] - T[0, 1], T[1, 2] - T[0, 2]
            e10, e11, e12 = T[2, 0] - T[1, 0], T[2, 1] - T[1, 1], T[2, 2] - T[1, 2]
            e20, e21, e22 = T[0, 0] - T[2, 0], T[0, 1] - T[2, 1], T[0, 2] - T[2, 2]
            cx = e01 * (-e22) - e02 * (-e21)
            cy = e02 * (-e20) - e00 * (-e22)
            cz = e00 * (-e21) - e01 * (-e20)
            dbl = np.sqrt(cx * cx + cy * cy + cz * cz)
            if dbl <= thresh:
                continue
            area = 0.5 * dbl
            good[ft] = True
            nx, ny, nz = cx / dbl, cy / dbl, cz / dbl
            fn[ft, 0], fn[ft, 1], fn[ft, 2] = nx, ny, nz
            # corner c: ½ n × e_{c+1} (e_{c+1} = the edge opposite c)
            fG[ft, 0, 0] = 0.5 * (ny * e12 - nz * e11)
            fG[ft, 0, 1] = 0.5 * (nz * e10 - nx * e12)
            fG[ft, 0, 2] = 0.5 * (nx * e11 - ny * e10)
            fG[ft, 1, 0] = 0.5 * (ny * e22 - nz * e21)
            fG[ft, 1, 1] = 0.5 * (nz * e20 - nx * e22)
            fG[ft, 1, 2] = 0.5 * (nx * e21 - ny * e20)
            fG[ft, 2, 0] = 0.5 * (ny * e02 - nz * e01)
            fG[ft, 2, 1] = 0.5 * (nz * e00 - nx * e02)
            fG[ft, 2, 2] = 0.5 * (nx * e01 - ny * e00)
            l0 = e00 * e00 + e01 * e01 + e02 * e02
            l1 = e10 * e10 + e11 * e11 + e12 * e12
            l2 = e20 * e20 + e21 * e21 + e22 * e22
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
                vals[out] = val
                out += 1
    return vals, mass, An, good, fn, fG


@njit(cache=True)
def connection_values(indptr, indices, data, N, e1, e2):
    """Values of the vertex connection Laplacian on the pattern of a symmetric CSR Laplacian (sorted
    columns and a symmetric pattern): for i < j, L_ij times the unit complex r_ij expressing e1_j in frame i
    after the smallest rotation taking N_j to N_i (Rodrigues; antiparallel normals: no rotation) and, at (j, i),
    L_ij times conj(r_ij) — exactly Hermitian; the diagonal unchanged."""
    n = len(indptr) - 1
    out = np.empty(len(data), np.complex128)
    for i in range(n):
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            if j == i:
                out[p] = data[p]
                continue
            if j < i:
                continue
            a0, a1, a2 = N[j, 0], N[j, 1], N[j, 2]
            b0, b1, b2 = N[i, 0], N[i, 1], N[i, 2]
            v0, v1, v2 = e1[j, 0], e1[j, 1], e1[j, 2]
            c = a0 * b0 + a1 * b1 + a2 * b2
            w0, w1, w2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
            wv0, wv1, wv2 = w1 * v2 - w2 * v1, w2 * v0 - w0 * v2, w0 * v1 - w1 * v0
            # R v = v + w × v + w × (w × v) / (1 + c)
            if 1.0 + c > 1e-12:
                inv = 1.0 / (1.0 + c)
                r0 = v0 + wv0 + (w1 * wv2 - w2 * wv1) * inv
                r1 = v1 + wv1 + (w2 * wv0 - w0 * wv2) * inv
                r2 = v2 + wv2 + (w0 * wv1 - w1 * wv0) * inv
            else:
                r0, r1, r2 = v0 + wv0, v1 + wv1, v2 + wv2
            zr = r0 * e1[i, 0] + r1 * e1[i, 1] + r2 * e1[i, 2]
            zi = r0 * e2[i, 0] + r1 * e2[i, 1] + r2 * e2[i, 2]
            mag = np.sqrt(zr * zr + zi * zi)
            z = complex(zr / mag, zi / mag) if mag > 0 else complex(1.0, 0.0)
            out[p] = data[p] * z
            # the mirrored entry (j, i): binary search in row j
            lo, hi = indptr[j], indptr[j + 1]
            while lo < hi:
                mid = (lo + hi) // 2
                if indices[mid] < i:
                    lo = mid + 1
                else:
                    hi = mid
            out[lo] = data[p] * np.conj(z)
    return out


@njit(cache=True)
def polygon_csr_pattern(start, corners, n):
    """Canonical CSR pattern of the polygon Laplacian (vertex pairs sharing a polygon, diagonal included) from
    the polygons' incidence, and the CSR slot of each of the Σ s² triplets in :func:`polygon_assembly`'s order
    (polygon p, row corner a, column corner b): ``(indptr, indices, slot)``. The triplets of one entry come from
    distinct polygons, so summing them by slot in triplet order adds them in polygon order, as
    :func:`gsdf.linalg._assembly.coo_to_csr` does."""
    m = len(start) - 1
    nc = len(corners)
    toff = np.empty(m + 1, np.int64)                 # first triplet of each polygon
    toff[0] = 0
    for p in range(m):
        s = start[p + 1] - start[p]
        toff[p + 1] = toff[p] + s * s
    head = np.zeros(n + 1, np.int64)                 # corners by vertex, in polygon order (counting sort)
    for c in range(nc):
        head[corners[c] + 1] += 1
    for i in range(n):
        head[i + 1] += head[i]
    pos = head[:-1].copy()
    inc = np.empty(nc, np.int64)
    owner = np.empty(nc, np.int64)
    for p in range(m):
        for c in range(start[p], start[p + 1]):
            v = corners[c]
            inc[pos[v]] = c
            owner[pos[v]] = p
            pos[v] += 1
    cap = toff[m]
    indptr = np.zeros(n + 1, np.int32)
    indices = np.empty(cap, np.int32)
    slot = np.empty(cap, np.int64)
    mark = np.full(n, -1, np.int64)
    out = np.int64(0)                      # not a literal 0: sort_row would compile once more for it
    for i in range(n):
        first = out
        for q in range(head[i], head[i + 1]):
            p = owner[q]
            for c in range(start[p], start[p + 1]):
                j = corners[c]
                if mark[j] < first:
                    mark[j] = out
                    indices[out] = j
                    out += 1
        sort_row(indices, first, out, mark)
        for q in range(head[i], head[i + 1]):
            p = owner[q]
            b0 = start[p]
            s = start[p + 1] - b0
            t = toff[p] + (inc[q] - b0) * s
            for c in range(b0, start[p + 1]):
                slot[t] = mark[corners[c]]
                t += 1
        indptr[i + 1] = out
    return indptr, indices[:out].copy(), slot


@njit(cache=True)
def fine_vectors(X, e1, e2, p_indptr, p_indices, p_data, F, Nf):
    """Step II on the refined mesh in one pass: the complex vertex vectors X (n,) as 3D vectors in the frames
    (e1, e2), prolonged by P (CSR; virtual vertex = Σ w_i X_i), summed over every fine triangle F (k, 3) and
    projected into its plane (unit normals Nf): (k, 3), not normalized. The same sums, in the same order, as
    ``P @ X3``, ``(X_a + X_b) + X_c`` and ``Y - N (Y · N)``."""
    nr = len(p_indptr) - 1
    Xf = np.zeros((nr, 3))
    for r in range(nr):
        for q in range(p_indptr[r], p_indptr[r + 1]):
            v = p_indices[q]
            w = p_data[q]
            xr, xi = X[v].real, X[v].imag
            for j in range(3):
                Xf[r, j] += w * (xr * e1[v, j] + xi * e2[v, j])
    k = len(F)
    Y = np.empty((k, 3))
    for f in range(k):
        a, b, c = F[f, 0], F[f, 1], F[f, 2]
        y0 = (Xf[a, 0] + Xf[b, 0]) + Xf[c, 0]
        y1 = (Xf[a, 1] + Xf[b, 1]) + Xf[c, 1]
        y2 = (Xf[a, 2] + Xf[b, 2]) + Xf[c, 2]
        d = y0 * Nf[f, 0] + y1 * Nf[f, 1] + y2 * Nf[f, 2]
        Y[f, 0] = y0 - Nf[f, 0] * d
        Y[f, 1] = y1 - Nf[f, 1] * d
        Y[f, 2] = y2 - Nf[f, 2] * d
    return Y


@njit(cache=True)
def fine_divergence(G, Y, F, p_indptr, p_indices, p_data, n):
    """Step III's right-hand side in one pass: b_i = Σ_f |f| ∇λ_i · Y_f on the fine vertices (G (k, 3, 3) the
    divergence weights per corner), restricted by Pᵀ to the n original vertices; the same sums, in the same
    order, as ``bincount(F, einsum(G, Y))`` and ``P.T @ b``."""
    nr = len(p_indptr) - 1
    bf = np.zeros(nr)
    for f in range(len(F)):
        y0, y1, y2 = Y[f, 0], Y[f, 1], Y[f, 2]
        for c in range(3):
            bf[F[f, c]] += G[f, c, 0] * y0 + G[f, c, 1] * y1 + G[f, c, 2] * y2
    out = np.zeros(n)
    for r in range(nr):
        for q in range(p_indptr[r], p_indptr[r + 1]):
            out[p_indices[q]] += p_data[q] * bf[r]
    return out
