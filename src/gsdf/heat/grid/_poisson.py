"""Operators and Poisson solvers of the grid signed-heat domain (Feng & Crane 2024, §8.2). The steps run in
:mod:`gsdf.heat._core` over :class:`gsdf.heat.grid._domain.GridDomain`; ``solve_grid`` is in
:mod:`gsdf.heat.volume._solve`.

Step I   X_t(x) = Σ_f |f| N_f G_t(x, b_f), the Yukawa potential of the sources (the fundamental solution of
         id − tΔ, λ = 1/√t), by a tree walk (:mod:`gsdf.heat._yukawa`) or by one screened solve on the grid
         itself (:mod:`gsdf.heat.grid._screened`), as :class:`~gsdf.heat.grid._domain.GridDomain` chooses.
Step II  Y = X / |X| (Eq. 3 of the seed: only the direction is kept).
Step III Δφ = ∇·Y with the seven-point Laplacian, Neumann boundary and forward differences: we minimise
         Σ_edges (φ_j − φ_i − h Ŷ_ij)² over the grid edges, Ŷ_ij the edge component of Y averaged over the
         edge's two nodes. Its normal equations are the 7-point graph Laplacian (natural Neumann boundary) against
         the forward-difference divergence of Y (the transpose of the forward-difference gradient).
Level set: "none": φ is shifted so that its area-weighted mean over the source points is 0 (as signedheat3d
         does). ``soft_weight=c``: the zero level set is pulled through the sources by a penalty on the
         trilinear values φ(b_f), then the same shift. "zero" (hard): the seed's constrained solve with
         trilinear rows (§8.2), one row per grid cell holding sources (the area-weighted mean of their trilinear
         rows — one row per source would force φ ≡ 0 on every cell crossed by a dense input), imposed exactly by
         the augmented Lagrangian (:func:`solve_constrained`); "multiple": the same rows made equal per input
         component.

Linear algebra: the Neumann 7-point Laplacian on a box is diagonal in the DCT-II basis, so Step III is solved
*exactly* by two fast cosine transforms, O(N log N) at every size (128³ in well under a second). With the soft
level-set constraint the system becomes L + P and is solved by CG preconditioned with that fast solver between
Gauss–Seidel sweeps over the penalized nodes and a coarse block-aggregate correction. The
exact constraint factorizes L + ρCᵀWC once (CHOLMOD / SuperLU, grids up to 50k nodes) and reuses it for every
multiplier update; larger grids use the preconditioned CG per update, which is slow (minutes at 64³).
"""

from __future__ import annotations

import functools

import numpy as np
import scipy.sparse as sp
from numba import njit

from gsdf.linalg import Factorization, pcg



def neumann_laplacian(shape, spacing) -> sp.csr_matrix:
    """The 7-point Laplacian with Neumann boundary, positive semidefinite: Σ_a K_a / h_a², K_a = D_aᵀ D_a.

    K_a is the path Laplacian along axis a (2 on the diagonal, 1 at both ends, −1 off it). Assembled directly in
    CSR by :func:`_laplacian_csr` — entry for entry what ``kron(K_x, I, I) + kron(I, K_y, I) + kron(I, I, K_z)``
    gives (:func:`_neumann_laplacian_kron`, kept for the test).
    """
    shape = tuple(int(s) for s in shape)
    w = np.array([float(spacing[a]) ** 2 for a in range(3)])
    n = shape[0] * shape[1] * shape[2]
    itype = np.int32 if 7 * n < 2 ** 31 else np.int64  # scipy's own index type for this size
    indptr, indices, data = np.zeros(n + 1, itype), np.empty(7 * n, itype), np.empty(7 * n)
    p = _laplacian_csr(shape[0], shape[1], shape[2], w, indptr, indices, data)
    return sp.csr_matrix((data[:p], indices[:p], indptr), shape=(n, n))


@njit(cache=True)
def _laplacian_csr(n0, n1, n2, w, indptr, indices, data):
    """Fill the CSR arrays of :func:`neumann_laplacian` (returns the entry count): row-major nodes, columns
    ascending (x−1, y−1, z−1, self, z+1, y+1, x+1); the diagonal summed x, y, z in that order (so it equals the
    Kronecker assembly bit for bit)."""
    dims = (n0, n1, n2)
    s1, s0 = n2, n1 * n2
    p = 0
    for i in range(n0):
        for j in range(n1):
            for k in range(n2):
                r = (i * n1 + j) * n2 + k
                diag = 0.0
                for a in range(3):
                    c = i if a == 0 else (j if a == 1 else k)
                    m = dims[a]
                    main = 1.0 if (c == 0 or c == m - 1) else 2.0
                    diag = main / w[a] if a == 0 else diag + main / w[a]
                if i > 0:
                    indices[p] = r - s0
                    data[p] = -1.0 / w[0]
                    p += 1
                if j > 0:
                    indices[p] = r - s1
                    data[p] = -1.0 / w[1]
                    p += 1
                if k > 0:
                    indices[p] = r - 1
                    data[p] = -1.0 / w[2]
                    p += 1
                indices[p] = r
                data[p] = diag
                p += 1
                if k < n2 - 1:
                    indices[p] = r + 1
                    data[p] = -1.0 / w[2]
                    p += 1
                if j < n1 - 1:
                    indices[p] = r + s1
                    data[p] = -1.0 / w[1]
                    p += 1
                if i < n0 - 1:
                    indices[p] = r + s0
                    data[p] = -1.0 / w[0]
                    p += 1
                indptr[r + 1] = p
    return p


def _neumann_laplacian_kron(shape, spacing) -> sp.csr_matrix:
    """The Kronecker-product assembly of :func:`neumann_laplacian` (reference for the test)."""
    shape = tuple(int(s) for s in shape)
    mats = []
    for a in range(3):
        n = shape[a]
        main = np.full(n, 2.0)
        main[0] = main[-1] = 1.0
        K = sp.diags([main, -np.ones(n - 1), -np.ones(n - 1)], [0, -1, 1], format="csr") / spacing[a] ** 2
        eye = [sp.identity(shape[b], format="csr") for b in range(3)]
        eye[a] = K
        mats.append(sp.kron(sp.kron(eye[0], eye[1]), eye[2], format="csr"))
    return (mats[0] + mats[1] + mats[2]).tocsr()


def divergence_rhs(Y, spacing) -> np.ndarray:
    """Right-hand side Gᵀ Ŷ / h of the edge least-squares problem (forward-difference divergence of Y)."""
    rhs = np.zeros(Y.shape[:3])
    for a in range(3):
        sl_hi = [slice(None)] * 3
        sl_lo = [slice(None)] * 3
        sl_hi[a] = slice(1, None)
        sl_lo[a] = slice(0, -1)
        Ya = Y[..., a]
        E = 0.5 * (Ya[tuple(sl_hi)] + Ya[tuple(sl_lo)]) / spacing[a]  # slices, not np.take (a copy per call)
        rhs[tuple(sl_hi)] += E
        rhs[tuple(sl_lo)] -= E
    return rhs.ravel()


def trilinear_matrix(P, bbox_min, spacing, shape) -> sp.csr_matrix:
    """Sparse (len(P), nodes) matrix of trilinear interpolation weights at points ``P`` inside the grid.

    Every row holds the 8 corners of the point's cell; listed with dx, then dy, then dz as the slow index, the
    corners' node numbers ascend, so the CSR arrays are written directly (canonical: sorted, no duplicates)."""
    n = np.array(shape)
    t = np.clip((P - bbox_min) / spacing, 0.0, n - 1.0)
    i0 = np.minimum(np.floor(t).astype(np.int64), n - 2)
    f = t - i0
    m = len(P)
    base = (i0[:, 0] * n[1] + i0[:, 1]) * n[2] + i0[:, 2]
    cols = np.empty((m, 8), np.int64)
    vals = np.empty((m, 8))
    c = 0
    for dx in (0, 1):
        fx = f[:, 0] if dx else 1 - f[:, 0]
        for dy in (0, 1):
            fy = fx * (f[:, 1] if dy else 1 - f[:, 1])
            for dz in (0, 1):
                vals[:, c] = fy * (f[:, 2] if dz else 1 - f[:, 2])
                cols[:, c] = base + (dx * n[1] + dy) * n[2] + dz
                c += 1
    N = int(np.prod(n))
    itype = np.int32 if N < 2 ** 31 and 8 * m < 2 ** 31 else np.int64
    T = sp.csr_matrix((vals.ravel(), cols.ravel().astype(itype), np.arange(0, 8 * m + 1, 8, dtype=itype)),
                      shape=(m, N))
    T.has_sorted_indices = True
    return T


def penalty_matrix(A, w, shape) -> sp.csr_matrix:
    """P = Aᵀ diag(w) A, CSR, for the soft level-set penalty. Rows of ``A`` whose entries all lie in one grid cell
    (trilinear rows) are summed by a numba kernel straight into P's 27-point rows; any other row set (the
    differences of the "multiple" constraint) by SciPy's products."""
    A = sp.csr_matrix(A)
    dims = np.array(shape, np.int64)
    if dims.shape != (3,) or (dims < 1).any() or A.shape[1] != int(np.prod(dims)):
        raise ValueError(f"penalty_matrix: A has {A.shape[1]} columns, expected one per node of the grid {tuple(shape)}")
    w = np.ascontiguousarray(np.broadcast_to(np.asarray(w, np.float64), (A.shape[0],)))
    out = _cell_penalty(A.indptr.astype(np.int64), A.indices.astype(np.int64), A.data.astype(np.float64), w, dims)
    if out is None:
        return (A.T @ sp.diags(w) @ A).tocsr()
    indptr, indices, data = out
    return sp.csr_matrix((data, indices, indptr), shape=(A.shape[1], A.shape[1]))


@njit(cache=True)
def _cell_penalty(Ap, Ai, Av, w, dims):
    """CSR (indptr, indices, data) of Aᵀ diag(w) A when every row of A lies in one cell, else None."""
    n1, n2 = dims[1], dims[2]
    s0 = n1 * n2
    N = dims[0] * s0
    m = Ap.shape[0] - 1
    slot = np.full(N, -1, np.int64)          # node -> its row of the accumulator (the nodes A touches)
    nodes = np.empty(min(N, Ai.shape[0]) + 1, np.int64)
    # per entry: 9 i + 3 j + k relative to its row's first entry (so two entries' code difference is their
    # offset in the 27-point stencil); two integer divisions per entry, the kernel's main cost
    code = np.empty(Ai.shape[0], np.int64)
    nb = 0
    for r in range(m):
        s, e = Ap[r], Ap[r + 1]
        if e == s:
            continue
        if e - s > 8:                        # a cell has 8 nodes: duplicates, not a trilinear row
            return None
        lo0 = lo1 = lo2 = N
        hi0 = hi1 = hi2 = -N
        i0 = j0 = k0 = 0
        for p in range(s, e):                # the row's nodes must span at most one cell on every axis
            c = Ai[p]
            q = c // n2
            k = c - q * n2
            i = q // n1
            j = q - i * n1
            if p == s:
                i0, j0, k0 = i, j, k
            code[p] = (i - i0) * 9 + (j - j0) * 3 + (k - k0)
            lo0, hi0 = min(lo0, i), max(hi0, i)
            lo1, hi1 = min(lo1, j), max(hi1, j)
            lo2, hi2 = min(lo2, k), max(hi2, k)
        if hi0 - lo0 > 1 or hi1 - lo1 > 1 or hi2 - lo2 > 1:
            return None
        for p in range(s, e):
            c = Ai[p]
            if slot[c] < 0:
                slot[c] = nb
                nodes[nb] = c
                nb += 1
    acc = np.zeros((nb, 27))                 # offset (di + 1) * 9 + (dj + 1) * 3 + (dk + 1)
    for r in range(m):
        s, e = Ap[r], Ap[r + 1]
        if e == s:
            continue
        wr = w[r]
        for p in range(s, e):
            va = wr * Av[p]
            row = slot[Ai[p]]
            ca = code[p]
            for q in range(s, e):
                acc[row, code[q] - ca + 13] += va * Av[q]
    cnt = np.zeros(N + 1, np.int64)
    for t in range(nb):
        c = nodes[t]
        for o in range(27):
            if acc[t, o] != 0.0:
                cnt[c + 1] += 1
    for c in range(N):
        cnt[c + 1] += cnt[c]
    indices = np.empty(cnt[N], np.int64)
    data = np.empty(cnt[N])
    for t in range(nb):
        c = nodes[t]
        q = cnt[c]
        for o in range(27):                  # lexicographic offsets: columns ascending
            v = acc[t, o]
            if v != 0.0:
                indices[q] = c + (o // 9 - 1) * s0 + ((o // 3) % 3 - 1) * n2 + (o % 3 - 1)
                data[q] = v
                q += 1
    return cnt, indices, data


def _dct_eigenvalues(shape, spacing, shift: float = 0.0) -> np.ndarray:
    """Eigenvalues of :func:`neumann_laplacian` in the DCT-II basis: Σ_a (2 − 2 cos(π k_a / n_a)) / h_a²."""
    lam = np.full(tuple(shape), float(shift))
    for a in range(3):
        n = shape[a]
        ev = (2.0 - 2.0 * np.cos(np.pi * np.arange(n) / n)) / spacing[a] ** 2
        lam = lam + ev.reshape([-1 if i == a else 1 for i in range(3)])
    return lam


def dct_poisson(rhs, shape, spacing, shift: float = 0.0, lam=None) -> np.ndarray:
    """Exact solve of (L + shift·I) φ = rhs for the Neumann 7-point Laplacian by the fast cosine transform.

    The Neumann matrix K = DᵀD of a path is diagonalised by the DCT-II, so the 3D Laplacian is diagonal in
    the separable DCT-II basis: one forward and one inverse transform, O(N log N). With ``shift = 0`` the
    constant mode is dropped (φ has zero mean; rhs must be orthogonal to constants).
    """
    if lam is None:
        lam = _dct_eigenvalues(shape, spacing, shift)
    c = dct3(np.asarray(rhs, float).reshape(shape))
    if shift == 0.0:
        c[0, 0, 0] = 0.0
        lam = lam.copy()
        lam[0, 0, 0] = 1.0
    c /= lam
    return dct3(c, inverse=True).ravel()


#: Grids whose three node counts sum to at most this are transformed by dense DCT matrices (below).
DCT_MATRIX_MAX_SUM = 100


@functools.lru_cache(maxsize=16)
def _dct_matrix(n: int) -> np.ndarray:
    """The orthonormal DCT-II matrix of size n: C[k, j] = s_k cos(π k (2j + 1) / 2n), s_0 = √(1/n), else √(2/n)."""
    k = np.arange(n)[:, None]
    C = np.cos(np.pi * k * (2 * np.arange(n)[None, :] + 1) / (2 * n)) * np.sqrt(2.0 / n)
    C[0] /= np.sqrt(2.0)
    C.setflags(write=False)
    return C


def dct3(X, inverse: bool = False) -> np.ndarray:
    """Orthonormal 3D DCT-II of X (n0, n1, n2) (``inverse``: its inverse, the DCT-III), as scipy's
    ``dctn(X, type=2, norm="ortho")`` / ``idctn``.

    Small grids (n0 + n1 + n2 ≤ :data:`DCT_MATRIX_MAX_SUM`) apply the dense n_a × n_a DCT matrix along each axis
    (three matrix products, 2 N Σ n_a flops, in BLAS); larger ones scipy.fft (pocketfft). The two agree to
    ~3e-14 of the values.
    """
    X = np.asarray(X, np.float64)
    shape = X.shape
    if sum(shape) > DCT_MATRIX_MAX_SUM:
        from scipy.fft import dctn, idctn

        workers = _fft_workers(int(np.prod(shape)))
        return (idctn if inverse else dctn)(X, type=2, norm="ortho", workers=workers)
    from gsdf.threads import blas_region

    n0, n1, n2 = shape
    C0, C1, C2 = (_dct_matrix(n) for n in shape)
    if inverse:
        C0, C1, C2 = C0.T, C1.T, C2.T
    with blas_region():   # one BLAS thread (or gsdf's setting): these products take a tenth of a millisecond
        Y = (C0 @ X.reshape(n0, n1 * n2)).reshape(n0, n1, n2)
        Y = np.matmul(C1, Y)
        return (Y.reshape(n0 * n1, n2) @ C2.T).reshape(n0, n1, n2)


def _fft_workers(n: int) -> int:
    """Threads of scipy.fft for an n-node transform: one below 2¹⁸ nodes, else gsdf's thread setting
    (:func:`gsdf.threads.get_num_threads`). The result is the same for any count."""
    if n < 1 << 18:
        return 1
    from gsdf.threads import get_num_threads

    return get_num_threads()


def _aggregation(shape, block: int) -> sp.csr_matrix:
    """Restriction R summing the nodes of each block³ of the grid into one coarse unknown (piecewise constants)."""
    n = int(np.prod(shape))
    coarse = [(s + block - 1) // block for s in shape]
    agg = np.ravel_multi_index(tuple(np.indices(shape).reshape(3, -1) // block), coarse)
    return sp.csr_matrix((np.ones(n), (agg, np.arange(n))), shape=(int(np.prod(coarse)), n))


def solve_poisson(rhs, shape, spacing, penalty=None, tol: float = 1e-5, maxiter: int = 300,
                  coarse_size: int = 4096, min_block: int = 4) -> np.ndarray:
    """Solve the Step III system.

    Without ``penalty`` the system is the singular Neumann Laplacian L φ = rhs, solved exactly by
    :func:`dct_poisson` (a direct solver, any size). With a penalty matrix P (the soft level-set
    constraint), A φ = rhs with A = L + P is solved by conjugate gradients with a symmetric multiplicative
    preconditioner whose stages each handle what the others miss:

    1. a coarse correction on piecewise-constant block aggregates (Galerkin Rᵀ(RARᵀ)⁻¹R, blocks of
       ``max(min_block, ∛(N / coarse_size))`` nodes a side, sparse LU) — the smooth error modes the penalty
       couples globally, the constant among them;
    2. a forward Gauss–Seidel sweep over the "band" (the nodes P touches, next to the sources) — the stiff
       penalty rows;
    3. an exact fast-Poisson (DCT) solve with L + δI, δ = tr(P)/N — everything away from the sources;
    4. the backward band sweep and the coarse correction again (so the preconditioner is symmetric).

    The residual is carried through the stages instead of recomputed: after the coarse step it is
    r − A Rᵀc, a band sweep changes it only through the band's columns of A, and after the DCT step y solves
    (L + δI) y = r exactly, so r − A y = δ y − P y, which differs from δ y only on the band. One
    application therefore costs one DCT pair, two tiny coarse solves and O(N) vector work — no full product
    with A (the same operator as recomputing r − A x after each stage, in fewer flops). The stages are numba
    kernels on the grid (:class:`PenalizedPoisson`: L applied as its stencil, never assembled), so a CG
    iteration makes a dozen calls.

    The start is the unconstrained DCT solution plus the best constant. ``tol`` is CG's relative residual.
    """
    shape = tuple(shape)
    if penalty is None:
        return dct_poisson(rhs, shape, spacing)
    from gsdf.linalg._iterative import cg_loop

    system = PenalizedPoisson(shape, spacing, penalty, coarse_size=coarse_size, min_block=min_block)
    rhs = np.ascontiguousarray(rhs, dtype=np.float64)
    x0 = dct_poisson(rhs - rhs.mean(), shape, spacing)
    if abs(system.penalty_sum) > 1e-12 * system.delta * int(np.prod(shape)):   # |P·1| against tr(P)
        # best constant (L annihilates constants); a penalty of differences only (P·1 = 0) leaves it free
        x0 += (rhs.sum() - system.matvec(x0).sum()) / system.penalty_sum
    from gsdf.threads import blas_region

    with blas_region():   # once around the loop: the DCT stage's own blas_region blocks then set nothing
        x, _ = cg_loop(system.matvec, system.precondition, rhs, x0, rtol=tol, maxiter=maxiter, warn="step III")
    return x


class PenalizedPoisson:
    """A = L + P on a grid (L the Neumann 7-point Laplacian, P a sparse symmetric penalty) with the preconditioner
    of :func:`solve_poisson`: ``matvec(x)`` = A x, ``precondition(r)`` = M r, in numba kernels over the grid
    (L as its stencil; P as CSR). Attributes: ``band`` (the nodes P touches), ``block`` (aggregate size),
    ``coarse`` (the factorized R A Rᵀ), ``delta`` (the DCT stage's shift tr(P)/N)."""

    def __init__(self, shape, spacing, penalty, coarse_size: int = 4096, min_block: int = 4):
        self.shape = tuple(int(s) for s in shape)
        self.spacing = np.asarray(spacing, float)
        n = int(np.prod(self.shape))
        P = sp.csr_matrix(penalty)
        if P.shape != (n, n):
            raise ValueError(f"penalty: expected a ({n}, {n}) matrix for the grid {self.shape}, got {P.shape}")
        P.sum_duplicates()
        self.Pp, self.Pi, self.Pv = P.indptr.astype(np.int64), P.indices.astype(np.int64), P.data.astype(np.float64)
        self.w = 1.0 / self.spacing ** 2                       # the Laplacian's edge weights per axis
        self.dims = np.array(self.shape, np.int64)
        self.block = max(int(min_block), int(np.ceil((n / coarse_size) ** (1.0 / 3.0))))
        self.cdims = (self.dims + self.block - 1) // self.block
        self.band = np.flatnonzero(np.diff(self.Pp) > 0).astype(np.int64)
        self.band_nbrs = _neighbour_mask(self.band, self.dims)
        self.kblock = np.arange(self.shape[2], dtype=np.int64) // self.block   # k // block per z index
        diagP = P.diagonal()
        if not diagP.sum() > 0 or not np.isfinite(self.Pv).all():
            raise ValueError("penalty: expected a finite positive semi-definite matrix with a positive trace "
                             "(an all-zero penalty leaves the Neumann problem without a unique solution)")
        self.delta = float(diagP.sum()) / n
        self.penalty_sum = float(self.Pv.sum())
        self.lam = _dct_eigenvalues(self.shape, self.spacing, self.delta)
        self.adiag = _laplacian_diagonal(self.dims, self.w, self.band) + diagP[self.band]
        ip, ix, val, local = _coarse_matrix(self.dims, self.w, self.block, self.cdims, self.Pp, self.Pi, self.Pv,
                                            self.band)
        nc = int(np.prod(self.cdims))
        if local:
            C = sp.csc_matrix((val, ix, ip), shape=(nc, nc))   # CSR of a symmetric matrix = its CSC
        else:  # P couples nodes more than one cell apart (difference rows): the Galerkin product by SciPy
            R = _aggregation(self.shape, self.block)
            C = (R @ (neumann_laplacian(self.shape, self.spacing) + P) @ R.T).tocsc()
        self.coarse = Factorization(C)
        self._d = np.zeros(n)

    def matvec(self, x):
        out = np.empty(len(x))
        _apply_system(np.ascontiguousarray(x, dtype=np.float64), self.dims, self.w, self.Pp, self.Pi, self.Pv,
                      self.band, out)
        return out

    def _coarse_solve(self, r):
        rc = np.zeros(int(np.prod(self.cdims)))
        _restrict(r, self.dims, self.block, self.kblock, self.cdims, rc)
        return self.coarse.solve(rc)

    def precondition(self, r):
        r = np.ascontiguousarray(r, dtype=np.float64)
        dims, w, Pp, Pi, Pv, band, nbrs = self.dims, self.w, self.Pp, self.Pi, self.Pv, self.band, self.band_nbrs
        x = np.empty(len(r))
        res = np.empty(len(r))
        _prolong_residual(self._coarse_solve(r), r, dims, self.block, self.kblock, self.cdims, w, Pp, Pi, Pv, band,
                          x, res)
        d = self._d
        _band_sweep(res, d, x, band, nbrs, dims, w, Pp, Pi, Pv, self.adiag, True)
        y = dct_poisson(res, self.shape, self.spacing, self.delta, self.lam)
        _after_dct(y, self.delta, band, Pp, Pi, Pv, x, res)
        _band_sweep(res, d, x, band, nbrs, dims, w, Pp, Pi, Pv, self.adiag, False)
        _prolong_add(self._coarse_solve(res), dims, self.block, self.kblock, self.cdims, x)
        return x


@njit(cache=True)
def _laplacian_diagonal(dims, w, nodes):
    """The Neumann Laplacian's diagonal at ``nodes``: Σ_a w_a × (neighbours along axis a)."""
    n1, n2 = dims[1], dims[2]
    out = np.empty(nodes.shape[0])
    for t in range(nodes.shape[0]):
        r = nodes[t]
        c = (r // (n1 * n2), (r // n2) % n1, r % n2)
        acc = 0.0
        for a in range(3):
            if c[a] > 0:
                acc += w[a]
            if c[a] < dims[a] - 1:
                acc += w[a]
        out[t] = acc
    return out


@njit(cache=True)
def _apply_system(x, dims, w, Pp, Pi, Pv, band, out):
    """out = (L + P) x: the 7-point stencil of every node, then P's rows (those of ``band``)."""
    n0, n1, n2 = dims[0], dims[1], dims[2]
    s0, s1 = n1 * n2, n2
    w0, w1, w2 = w[0], w[1], w[2]
    for i in range(n0):
        for j in range(n1):
            base = (i * n1 + j) * n2
            for k in range(n2):
                r = base + k
                xr = x[r]
                acc = 0.0
                if i > 0:
                    acc += w0 * (xr - x[r - s0])
                if i < n0 - 1:
                    acc += w0 * (xr - x[r + s0])
                if j > 0:
                    acc += w1 * (xr - x[r - s1])
                if j < n1 - 1:
                    acc += w1 * (xr - x[r + s1])
                if k > 0:
                    acc += w2 * (xr - x[r - 1])
                if k < n2 - 1:
                    acc += w2 * (xr - x[r + 1])
                out[r] = acc
    for t in range(band.shape[0]):
        r = band[t]
        acc = 0.0
        for p in range(Pp[r], Pp[r + 1]):
            acc += Pv[p] * x[Pi[p]]
        out[r] += acc


@njit(cache=True)
def _neighbour_mask(nodes, dims):
    """Per node, which of its six grid neighbours exist: bits 1, 2 (x−1, x+1), 4, 8 (y−1, y+1), 16, 32 (z−1, z+1).
    Computed once per solve so that the band kernels need no integer divisions per node (three of them per node
    and sweep were most of a sweep's time)."""
    n0, n1, n2 = dims[0], dims[1], dims[2]
    out = np.empty(nodes.shape[0], np.int64)
    for t in range(nodes.shape[0]):
        r = nodes[t]
        i, j, k = r // (n1 * n2), (r // n2) % n1, r % n2
        out[t] = ((i > 0) * 1 | (i < n0 - 1) * 2 | (j > 0) * 4 | (j < n1 - 1) * 8 | (k > 0) * 16
                  | (k < n2 - 1) * 32)
    return out


@njit(cache=True)
def _subtract_columns(res, d, band, nbrs, dims, w, Pp, Pi, Pv):
    """res −= A d for d supported on ``band`` (A's band columns: the stencil's and P's, P symmetric); ``nbrs``
    the band's :func:`_neighbour_mask`."""
    n1, n2 = dims[1], dims[2]
    s0, s1 = n1 * n2, n2
    for t in range(band.shape[0]):
        r = band[t]
        v = d[r]
        if v == 0.0:
            continue
        nb = nbrs[t]
        if nb & 1:
            res[r - s0] += w[0] * v
            res[r] -= w[0] * v
        if nb & 2:
            res[r + s0] += w[0] * v
            res[r] -= w[0] * v
        if nb & 4:
            res[r - s1] += w[1] * v
            res[r] -= w[1] * v
        if nb & 8:
            res[r + s1] += w[1] * v
            res[r] -= w[1] * v
        if nb & 16:
            res[r - 1] += w[2] * v
            res[r] -= w[2] * v
        if nb & 32:
            res[r + 1] += w[2] * v
            res[r] -= w[2] * v
        for p in range(Pp[r], Pp[r + 1]):
            res[Pi[p]] -= Pv[p] * v


@njit(cache=True)
def _band_sweep(res, d, x, band, nbrs, dims, w, Pp, Pi, Pv, adiag, forward):
    """One Gauss–Seidel sweep of A over the band nodes against ``res`` (forward: ascending nodes, the lower
    triangle of A's band block; else descending, the upper), then x += d and res −= A d. ``d`` is a zero
    scratch vector of the grid's size on entry and is left zero; ``nbrs`` the band's :func:`_neighbour_mask`."""
    n1, n2 = dims[1], dims[2]
    s0, s1 = n1 * n2, n2
    nb = band.shape[0]
    for q in range(nb):
        t = q if forward else nb - 1 - q
        r = band[t]
        m = nbrs[t]
        acc = res[r]
        # d is zero off the band and on the rows not swept yet: the sums run over the triangle only
        if m & 1:
            acc += w[0] * d[r - s0]
        if m & 2:
            acc += w[0] * d[r + s0]
        if m & 4:
            acc += w[1] * d[r - s1]
        if m & 8:
            acc += w[1] * d[r + s1]
        if m & 16:
            acc += w[2] * d[r - 1]
        if m & 32:
            acc += w[2] * d[r + 1]
        for p in range(Pp[r], Pp[r + 1]):
            c = Pi[p]
            if c != r:
                acc -= Pv[p] * d[c]
        d[r] = acc / adiag[t]
    _subtract_columns(res, d, band, nbrs, dims, w, Pp, Pi, Pv)
    for t in range(nb):
        r = band[t]
        x[r] += d[r]
        d[r] = 0.0


@njit(cache=True)
def _after_dct(y, delta, band, Pp, Pi, Pv, x, res):
    """After the DCT stage: x += y and res = r − A y = δ y − P y (y solves (L + δI) y = r exactly)."""
    for r in range(y.shape[0]):
        x[r] += y[r]
        res[r] = delta * y[r]
    for t in range(band.shape[0]):
        r = band[t]
        acc = 0.0
        for p in range(Pp[r], Pp[r + 1]):
            acc += Pv[p] * y[Pi[p]]
        res[r] -= acc


@njit(cache=True)
def _restrict(r, dims, block, kblock, cdims, out):
    """out += R r: the sums of r over the block aggregates (``kblock[k]`` = k // block)."""
    n0, n1, n2 = dims[0], dims[1], dims[2]
    for i in range(n0):
        for j in range(n1):
            cb = ((i // block) * cdims[1] + j // block) * cdims[2]
            base = (i * n1 + j) * n2
            for k in range(n2):
                out[cb + kblock[k]] += r[base + k]


@njit(cache=True)
def _prolong_add(c, dims, block, kblock, cdims, x):
    """x += Rᵀ c: every node gets its aggregate's value (``kblock[k]`` = k // block)."""
    n0, n1, n2 = dims[0], dims[1], dims[2]
    for i in range(n0):
        for j in range(n1):
            cb = ((i // block) * cdims[1] + j // block) * cdims[2]
            base = (i * n1 + j) * n2
            for k in range(n2):
                x[base + k] += c[cb + kblock[k]]


@njit(cache=True)
def _prolong_residual(c, r, dims, block, kblock, cdims, w, Pp, Pi, Pv, band, x, res):
    """The first coarse stage: x = Rᵀ c and res = r − A x (``kblock[k]`` = k // block)."""
    n0, n1, n2 = dims[0], dims[1], dims[2]
    for i in range(n0):
        for j in range(n1):
            cb = ((i // block) * cdims[1] + j // block) * cdims[2]
            base = (i * n1 + j) * n2
            for k in range(n2):
                x[base + k] = c[cb + kblock[k]]
    _apply_system(x, dims, w, Pp, Pi, Pv, band, res)
    for q in range(r.shape[0]):
        res[q] = r[q] - res[q]


@njit(cache=True)
def _coarse_matrix(dims, w, block, cdims, Pp, Pi, Pv, band):
    """CSR (indptr, indices, data) of the Galerkin coarse matrix R (L + P) Rᵀ on the block aggregates, and
    whether P only couples nodes of one cell (else the 27-entry coarse rows cannot hold it: the caller forms
    the product with SciPy). L's part: every grid edge between two blocks adds w_a to both diagonals and −w_a
    between them."""
    n0, n1, n2 = dims[0], dims[1], dims[2]
    c0, c1, c2 = cdims[0], cdims[1], cdims[2]
    nc = c0 * c1 * c2
    C = np.zeros((nc, 27))     # coarse row, offset (dI + 1) * 9 + (dJ + 1) * 3 + (dK + 1)
    q = np.arange(max(n0, n1, n2) + 1) // block   # the aggregate index along an axis (no division per node)
    for i in range(n0):
        for j in range(n1):
            for k in range(n2):
                I = (q[i] * c1 + q[j]) * c2 + q[k]
                for a in range(3):
                    ii, jj, kk = i + (a == 0), j + (a == 1), k + (a == 2)
                    if ii >= n0 or jj >= n1 or kk >= n2:
                        continue
                    J = (q[ii] * c1 + q[jj]) * c2 + q[kk]
                    if J == I:
                        continue
                    C[I, 13] += w[a]
                    C[J, 13] += w[a]
                    up = 13 + (9 if a == 0 else (3 if a == 1 else 1))
                    C[I, up] -= w[a]
                    C[J, 26 - up] -= w[a]
    s0, s1 = n1 * n2, n2
    local = True
    for t in range(band.shape[0]):
        r = band[t]
        ri, rj, rk = r // s0, (r // s1) % n1, r % n2
        I0, I1, I2 = ri // block, rj // block, rk // block
        I = (I0 * c1 + I1) * c2 + I2
        for p in range(Pp[r], Pp[r + 1]):
            c = Pi[p]
            ci, cj, ck = c // s0, (c // s1) % n1, c % n2
            d0, d1, d2 = ci // block - I0, cj // block - I1, ck // block - I2
            if abs(d0) > 1 or abs(d1) > 1 or abs(d2) > 1:
                local = False
                continue
            C[I, (d0 + 1) * 9 + (d1 + 1) * 3 + (d2 + 1)] += Pv[p]
    indptr = np.zeros(nc + 1, np.int64)
    cnt = 0
    for I in range(nc):
        for o in range(27):
            if C[I, o] != 0.0:
                cnt += 1
        indptr[I + 1] = cnt
    indices = np.empty(cnt, np.int64)
    data = np.empty(cnt)
    q = 0
    for I in range(nc):
        for o in range(27):   # offsets in lexicographic order: columns ascending
            if C[I, o] != 0.0:
                d0, d1, d2 = o // 9 - 1, (o // 3) % 3 - 1, o % 3 - 1
                indices[q] = I + (d0 * c1 + d1) * c2 + d2
                data[q] = C[I, o]
                q += 1
    return indptr, indices, data, local


def _solve_poisson_reference(rhs, shape, spacing, penalty, tol: float = 1e-5, maxiter: int = 300,
                             block: int = 2) -> np.ndarray:
    """The same preconditioned CG with every stage's residual recomputed as r − A x (reference for the test)."""
    from scipy.sparse.linalg import LinearOperator

    shape = tuple(shape)
    n = int(np.prod(shape))
    A = (neumann_laplacian(shape, spacing) + penalty).tocsr()
    delta = float(penalty.diagonal().sum()) / n
    lam = _dct_eigenvalues(shape, spacing, delta)
    band = np.flatnonzero(np.diff(sp.csr_matrix(penalty).indptr) > 0)
    A_bb = A[band][:, band]
    lower, upper = sp.tril(A_bb, format="csr"), sp.triu(A_bb, format="csr")
    lower.sort_indices()
    upper.sort_indices()
    R = _aggregation(shape, block)
    coarse = Factorization((R @ A @ R.T).tocsc())

    def precondition(r):
        x = R.T @ coarse.solve(R @ r)
        x[band] += _triangular_solve(lower.indptr, lower.indices, lower.data, (r - A @ x)[band], True)
        x += dct_poisson(r - A @ x, shape, spacing, delta, lam)
        x[band] += _triangular_solve(upper.indptr, upper.indices, upper.data, (r - A @ x)[band], False)
        x += R.T @ coarse.solve(R @ (r - A @ x))
        return x

    M = LinearOperator((n, n), matvec=precondition)
    x0 = dct_poisson(rhs - rhs.mean(), shape, spacing)
    x0 += (rhs.sum() - (A @ x0).sum()) / penalty.sum()
    return pcg(A, rhs, M=M, x0=x0, rtol=tol, maxiter=maxiter)[0]


@njit(cache=True)
def _triangular_solve(indptr, indices, data, b, lower):
    """Solve T x = b, T the lower (``lower``) or upper triangle of a CSR matrix — entries of the other triangle
    are skipped, so the whole matrix can be passed (the Gauss–Seidel sweeps of :func:`solve_poisson`):
    forward substitution when ``lower``, else backward. Serial by nature."""
    n = b.shape[0]
    x = np.empty(n)
    for k in range(n):
        i = k if lower else n - 1 - k
        acc = b[i]
        diag = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            if j == i:
                diag = data[p]
            elif (j < i) == lower:
                acc -= data[p] * x[j]
        x[i] = acc / diag
    return x


def cell_constraint_matrix(B, a, bbox_min, spacing, shape):
    """One constraint row per grid cell holding sources: the area-weighted mean of their trilinear rows.

    Row c is Σ_{f in c} a_f T(b_f) / Σ a_f, T the trilinear weights, i.e. the least-squares fit of a zero level
    through the sources of the cell; returns ``(C, w)``, w the source area of each row.
    """
    n = np.array(shape)
    T = trilinear_matrix(B, bbox_min, spacing, shape)
    t = np.clip((B - bbox_min) / spacing, 0.0, n - 1.0)
    i0 = np.minimum(np.floor(t).astype(np.int64), n - 2)
    cell = (i0[:, 0] * n[1] + i0[:, 1]) * n[2] + i0[:, 2]
    cells, row = np.unique(cell, return_inverse=True)
    row = row.ravel()
    w = np.bincount(row, weights=a, minlength=len(cells))
    R = sp.csr_matrix((a / w[row], (row, np.arange(len(B)))), shape=(len(cells), len(B)))
    return (R @ T).tocsr(), w


def solve_constrained(rhs, shape, spacing, C, w, rho: float, tol: float, max_outer: int = 200,
                      inner_tol: float = 1e-8, direct_below: int = 50_000, regularize: bool = False):
    """min ½φᵀLφ − rhsᵀφ subject to Cφ = 0, by the augmented Lagrangian (method of multipliers).

    Each outer step solves (L + ρ CᵀWC) φ = rhs − Cᵀμ by CG preconditioned with the exact DCT solve of
    L + δI (warm-started), then updates μ ← μ + ρ W Cφ; stops when max |Cφ| ≤ ``tol``. W = diag(w).
    ``regularize``: add 1e-10 · mean diag to the matrix, for constraints that leave the constant free
    (differences, "multiple"). Returns φ, the final max |Cφ| and the number of outer steps.
    """
    from scipy.sparse.linalg import LinearOperator

    shape = tuple(shape)
    n = int(np.prod(shape))
    L = neumann_laplacian(shape, spacing)
    Wd = rho * w
    A = (L + C.T @ sp.diags(Wd) @ C).tocsr()
    if regularize:
        A = (A + sp.identity(n) * (1e-10 * float(A.diagonal().mean()))).tocsr()
    direct = None
    if n <= direct_below:
        try:  # factorize once (CHOLMOD), every outer step is then two triangular solves
            from gsdf.linalg import SPDSolver

            direct = SPDSolver(A, direct_max=direct_below)  # many outer steps: factorize, never CG
        except Exception:  # pragma: no cover - fall back to the iterative inner solver
            direct = None
    if direct is None:
        delta = float(A.diagonal().sum() - L.diagonal().sum()) / n
        lam = _dct_eigenvalues(shape, spacing, delta)
        M = LinearOperator((n, n), matvec=lambda r: dct_poisson(r, shape, spacing, delta, lam),
                           dtype=np.float64)
    mu = np.zeros(C.shape[0])
    phi = dct_poisson(rhs - rhs.mean(), shape, spacing)
    res = np.inf
    k = 0
    for k in range(1, max_outer + 1):
        if direct is not None:
            phi = direct.solve(rhs - C.T @ mu)
        else:
            phi, _ = pcg(A, rhs - C.T @ mu, M=M, x0=phi, rtol=inner_tol, maxiter=500)
        r = C @ phi
        res = float(np.abs(r).max())
        if res <= tol:
            break
        mu += Wd * r
    return phi, res, k
