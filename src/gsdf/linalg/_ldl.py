"""Sparse LDLᴴ factorization of small and mid-size Hermitian / symmetric positive definite matrices (numba).

Why it exists: on the heat method's systems of a few thousand unknowns SuperLU spends most of its time in
fixed costs (its supernode and panel machinery, minimum-degree ordering, L *and* U), not in arithmetic. Like
Eigen's ``SimplicialLDLT``:

* **ordering** — a fill-reducing permutation from :mod:`.ordering`: by default approximate minimum degree,
  and on small systems whose AMD factor is flop-heavy also nested dissection, keeping the one with fewer
  flops (:data:`AUTO_ND_MAX_N`, :data:`AUTO_ND_FLOPS`); or one named or given by the caller;
* **symbolic** — elimination tree and column counts of L (Davis, "Algorithm 849: LDL", 2005);
* **numeric** — up-looking LDLᴴ: row k of L from a sparse triangular solve along the elimination tree,
  ``l_k = conj(y) / D``, ``D_k = a_kk − Σ l_ki y_i`` (no pivoting: the matrix must be positive definite;
  a pivot ≤ 0 raises ValueError and callers fall back to SuperLU); or, for complex flop-heavy factors with
  wide supernodes (:data:`SUPERNODAL_FLOPS`), left-looking supernodal: dense blocks per fundamental supernode
  (:func:`_supernodal_numeric`), the same L and D up to rounding.

L's row indices and column pointers are int32 (``int64`` for the symbolic work arrays only): L takes 12 bytes
per entry instead of 16 for real factors (20 instead of 24 complex).

All kernels are serial: their sizes are the ones where thread wake-up would cost more than the work (and a
parallel region waits for a descheduled thread under contention).

Example
-------
>>> import numpy as np, scipy.sparse as sp
>>> A = sp.csr_matrix(np.array([[4.0, 1, 0], [1, 3, 1], [0, 1, 2]]))
>>> x = LDLFactorization(A).solve(np.array([1.0, 2.0, 3.0]))
>>> bool(np.allclose(A @ x, [1.0, 2.0, 3.0]))
True
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

from gsdf.linalg._ordering import ORDERING_NAMES, nested_dissection, order_csr

INDEX_MAX = 2**31 - 1     # entries of L addressable by its int32 indices (larger systems: SuperLU)

__all__ = ["LDLFactorization", "nested_dissection", "fill_count", "AUTO_ND_MAX_N", "AUTO_ND_FLOPS",
           "HINT_AMD_FLOPS"]

#: The ``ordering="auto"`` rule: approximate minimum degree (AMD); up to AUTO_ND_MAX_N unknowns, when the AMD
#: factor is flop-heavy, Σ_j c_j² ≥ AUTO_ND_FLOPS · nnz(A) · log2 n (c_j = entries of column j of L), nested
#: dissection is computed too and kept when its flop count is below AUTO_ND_GAIN × AMD's.
AUTO_ND_MAX_N = 10_000
AUTO_ND_FLOPS = 12.0
AUTO_ND_GAIN = 0.9

#: An ordering ``hint`` (:class:`LDLFactorization`) is taken as it is unless its factor is flop-heavy, Σ_j c_j² ≥
#: HINT_AMD_FLOPS · nnz(A) · log2 n; then AMD is computed too and the fewer-flop one kept. (A hint such as step
#: I's order restricted to the free vertices of step III: the induced order's fill is at most that of the factor
#: it came from.)
HINT_AMD_FLOPS = 60.0

#: Complex (Hermitian) factors with at least SUPERNODAL_FLOPS flops (Σ_j c_j², :func:`_flops`), a fundamental
#: supernode of at least SUPERNODAL_WIDTH columns and at least SUPERNODAL_MEAN columns per supernode on average
#: are computed by the supernodal kernel (:func:`_supernodal_numeric`), the others by the up-looking one.
SUPERNODAL_FLOPS = 4e6
SUPERNODAL_WIDTH = 100
SUPERNODAL_MEAN = 1.8

#: The orderings :class:`LDLFactorization` takes by name.
LDL_ORDERINGS = ("auto",) + ORDERING_NAMES


# ------------------------------------------------------------------------------------------ factorization
@njit(cache=True)
def _upper_csc(indptr, indices, n, pinv):
    """Pattern of the upper triangle (i ≤ j) of P A Pᵀ in CSC, from the CSR of A: (colptr, rows, src) with
    ``src`` the position of each entry in A's data (duplicates kept: the numeric step sums them)."""
    cnt = np.zeros(n + 1, np.int64)
    for r in range(n):
        i = pinv[r]
        for q in range(indptr[r], indptr[r + 1]):
            j = pinv[indices[q]]
            if i <= j:
                cnt[j + 1] += 1
    for j in range(n):
        cnt[j + 1] += cnt[j]
    pos = cnt[:-1].copy()
    rows = np.empty(cnt[n], np.int64)
    src = np.empty(cnt[n], np.int64)
    for r in range(n):
        i = pinv[r]
        for q in range(indptr[r], indptr[r + 1]):
            j = pinv[indices[q]]
            if i <= j:
                rows[pos[j]] = i
                src[pos[j]] = q
                pos[j] += 1
    return cnt, rows, src


@njit(cache=True)
def _symbolic(colptr, rows, n):
    """Elimination tree and column counts of L (Davis' LDL, ldl_symbolic)."""
    parent = np.full(n, -1, np.int64)
    flag = np.empty(n, np.int64)
    lnz = np.zeros(n, np.int64)
    for k in range(n):
        flag[k] = k
        for p in range(colptr[k], colptr[k + 1]):
            i = rows[p]
            while i < k and flag[i] != k:
                if parent[i] == -1:
                    parent[i] = k
                lnz[i] += 1
                flag[i] = k
                i = parent[i]
    lp = np.zeros(n + 1, np.int64)
    for k in range(n):
        lp[k + 1] = lp[k] + lnz[k]
    return parent, lp


@njit(cache=True)
def _numeric(colptr, rows, vals, n, parent, lp):
    """Up-looking LDLᴴ (ldl_numeric, conjugated for Hermitian matrices). Returns (Li, Lx, D, k_bad) with k_bad
    the first column whose pivot is not positive (-1 if none)."""
    nnz = lp[n]
    li = np.empty(nnz, np.int32)             # int32 rows of L: a third less memory traffic in the solves
    lx = np.empty(nnz, vals.dtype)
    d = np.empty(n, np.float64)
    y = np.zeros(n, vals.dtype)
    pattern = np.empty(n, np.int64)
    flag = np.empty(n, np.int64)
    lnz = np.zeros(n, np.int64)
    for k in range(n):
        top = n
        flag[k] = k
        dk = 0.0
        for p in range(colptr[k], colptr[k + 1]):
            i = rows[p]
            if i == k:
                dk += vals[p].real
                continue
            y[i] += vals[p]
            ln = 0
            while flag[i] != k:
                pattern[ln] = i
                ln += 1
                flag[i] = k
                i = parent[i]
            while ln > 0:
                top -= 1
                ln -= 1
                pattern[top] = pattern[ln]
        for t in range(top, n):
            i = pattern[t]
            yi = y[i]
            y[i] = 0.0
            p2 = lp[i] + lnz[i]
            for p in range(lp[i], p2):
                y[li[p]] -= lx[p] * yi
            lki = np.conj(yi) / d[i]
            dk -= (lki * yi).real
            li[p2] = k
            lx[p2] = lki
            lnz[i] += 1
        if not dk > 0.0:
            return li, lx, d, k
        d[k] = dk
    return li, lx, d, -1


@njit(cache=True)
def _solve(lp, li, lx, d, b):
    """x = (L D Lᴴ)⁻¹ b in place on a copy (b already permuted)."""
    n = len(d)
    x = b.copy()
    for j in range(n):
        xj = x[j]
        for p in range(lp[j], lp[j + 1]):
            x[li[p]] -= lx[p] * xj
    for j in range(n):
        x[j] /= d[j]
    for j in range(n - 1, -1, -1):
        s = x[j]
        for p in range(lp[j], lp[j + 1]):
            s -= np.conj(lx[p]) * x[li[p]]
        x[j] = s
    return x


def _check_perm(perm, n):
    """``perm`` as an int64 permutation of range(n), or ValueError."""
    p = np.asarray(perm)
    if p.shape != (n,) or p.dtype.kind not in "iu":
        raise ValueError(f"ordering: expected a name in {LDL_ORDERINGS} or an integer permutation of shape ({n},), "
                         f"got {p.dtype} array of shape {p.shape}")
    p = p.astype(np.int64)
    seen = np.zeros(n, bool)
    if n and (p.min() < 0 or p.max() >= n):
        raise ValueError("ordering: permutation entries out of range")
    seen[p] = True
    if not seen.all():
        raise ValueError("ordering: not a permutation (repeated entries)")
    return p


def _pattern(indptr, indices, n, perm):
    """(colptr, rows, src, parent, lp): the upper pattern of P A Pᵀ (A's int64 CSR arrays) and its symbolic
    factor."""
    pinv = np.empty(n, np.int64)
    pinv[perm] = np.arange(n)
    colptr, rows, src = _upper_csc(indptr, indices, n, pinv)
    parent, lp = _symbolic(colptr, rows, n)
    return colptr, rows, src, parent, lp


@njit(cache=True)
def _supernode_widths(parent, lp):
    """(widest, mean) columns of the fundamental supernodes of L (:func:`_supernodes`' rule, without their
    patterns): one pass over the columns."""
    n = len(parent)
    if n < 2:
        return n, float(n)
    count, widest, w = 1, 1, 1
    for j in range(1, n):
        if parent[j - 1] == j and lp[j] - lp[j - 1] == lp[j + 1] - lp[j] + 1:
            w += 1
        else:
            count += 1
            w = 1
        if w > widest:
            widest = w
    return widest, n / count


def _use_supernodal(cplx, parent, lp) -> bool:
    """The :data:`SUPERNODAL_FLOPS` rule."""
    if not cplx or _flops(lp) < SUPERNODAL_FLOPS:
        return False
    widest, mean = _supernode_widths(parent, lp)
    return widest >= SUPERNODAL_WIDTH and mean >= SUPERNODAL_MEAN


def _flops(lp) -> float:
    """Σ_j c_j² over the column counts c_j of L (the multiply-adds of the factorization, up to a factor)."""
    c = np.diff(lp).astype(np.float64)
    return float(c @ c)


def _auto_pattern(indptr, indices, n, hint=None):
    """The ``ordering="auto"`` rule (:data:`AUTO_ND_MAX_N`): (perm, pattern). With a ``hint`` permutation: the
    hint, unless its factor is flop-heavy (:data:`HINT_AMD_FLOPS`); then the fewer-flop one of the hint and AMD
    (no nested dissection: the hint's maker has weighed it already)."""
    if hint is not None:
        pat_h = _pattern(indptr, indices, n, hint)
        f_h = _flops(pat_h[4])
        if n <= 2 or f_h < HINT_AMD_FLOPS * len(indices) * np.log2(n):
            return hint, pat_h
        perm = order_csr(indptr, indices, n, "amd")
        pat = _pattern(indptr, indices, n, perm)
        return (hint, pat_h) if f_h <= _flops(pat[4]) else (perm, pat)
    perm = order_csr(indptr, indices, n, "amd")
    pat = _pattern(indptr, indices, n, perm)
    if 2 < n <= AUTO_ND_MAX_N:
        f_amd = _flops(pat[4])
        if f_amd >= AUTO_ND_FLOPS * len(indices) * np.log2(n):
            perm_nd = order_csr(indptr, indices, n, "nd")
            pat_nd = _pattern(indptr, indices, n, perm_nd)
            if _flops(pat_nd[4]) < AUTO_ND_GAIN * f_amd:
                return perm_nd, pat_nd
    return perm, pat


def fill_count(A, perm) -> int:
    """Entries of L below the diagonal in the LDLᴴ of ``A[perm][:, perm]`` (symbolic only; ``A`` (n, n) with
    a symmetric pattern, ``perm`` (n,) with ``perm[k]`` the node eliminated k-th).

    Example
    -------
    >>> import numpy as np, scipy.sparse as sp
    >>> star = sp.csr_matrix(np.array([[4.0, 1, 1], [1, 4, 0], [1, 0, 4]]))
    >>> fill_count(star, [0, 1, 2]), fill_count(star, [1, 2, 0])   # hub first: one fill entry
    (3, 2)
    """
    A = sp.csr_matrix(A)
    n = A.shape[0]
    return int(_pattern(A.indptr.astype(np.int64), A.indices.astype(np.int64), n, _check_perm(perm, n))[4][-1])


class LDLFactorization:
    """LDLᴴ of a sparse Hermitian (or real symmetric) positive definite matrix, fill-reducing ordered.

    Parameters
    ----------
    A : scipy.sparse matrix (n, n), float64 or complex128
        Only the pattern's symmetry and the values of the upper triangle of the reordered matrix are used (A is
        assumed Hermitian; nothing checks it).
    ordering : {"auto", "amd", "nd"} or int array (n,)
        The fill-reducing ordering: ``"auto"`` the rule of :data:`AUTO_ND_MAX_N` (module docs), a
        name of :func:`gsdf.linalg._ordering.fill_reducing_ordering`, or a permutation (``ordering[k]`` = the
        unknown eliminated k-th). The factors are those of ``A``, whatever the ordering.
    hint : int array (n,), optional
        With ``ordering="auto"``: a permutation known to suit A (e.g. a related system's ordering restricted
        to A's unknowns), used in place of AMD; only when its factor is flop-heavy (:data:`HINT_AMD_FLOPS`) is
        AMD computed too and the fewer-flop one kept (no nested-dissection candidate).

    Raises
    ------
    ValueError
        A pivot is not positive (A is not positive definite, or too ill-conditioned for an unpivoted
        factorization); callers fall back to a pivoting LU.

    Example
    -------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.csr_matrix(np.array([[2.0, 1j], [-1j, 2.0]]))
    >>> x = LDLFactorization(A).solve(np.array([1.0, 0.0]))
    >>> bool(np.allclose(A @ x, [1.0, 0.0]))
    True
    """

    def __init__(self, A, ordering="auto", hint=None):
        if not sp.issparse(A) or A.format not in ("csr", "csc"):
            A = sp.csr_matrix(A)
        n = A.shape[0]
        if A.shape != (n, n):
            raise ValueError(f"matrix: expected a square matrix, got shape {A.shape}")
        cplx = np.iscomplexobj(A.data)
        data = np.ascontiguousarray(A.data, dtype=np.complex128 if cplx else np.float64)
        if A.format == "csc" and cplx:
            data = np.conj(data)             # CSC arrays read as CSR are Aᵀ = conj(A) for a Hermitian A
        indptr, indices = A.indptr.astype(np.int64), A.indices.astype(np.int64)
        self.n, self.dtype = n, data.dtype
        if isinstance(ordering, str) and ordering == "auto":
            self.perm, pat = _auto_pattern(indptr, indices, n, None if hint is None else _check_perm(hint, n))
        else:
            if isinstance(ordering, str):
                if ordering not in LDL_ORDERINGS:
                    raise ValueError(f"ordering: expected one of {LDL_ORDERINGS} or a permutation, got {ordering!r}")
                self.perm = order_csr(indptr, indices, n, ordering)
            else:
                self.perm = _check_perm(ordering, n)
            pat = _pattern(indptr, indices, n, self.perm)
        colptr, rows, src, parent, self._lp = pat
        if self._lp[-1] > INDEX_MAX:
            raise ValueError(f"matrix: L would have {int(self._lp[-1])} entries, more than int32 indices address")
        if _use_supernodal(cplx, parent, self._lp):
            pinv = np.empty(n, np.int64)
            pinv[self.perm] = np.arange(n)
            lcol, lrows, lsrc = _lower_csc(indptr, indices, n, pinv)
            sn = _supernodes(colptr, rows, n, parent, self._lp)
            self._li, self._lx, self._d, bad = _supernodal_numeric(lcol, lrows, data[lsrc], n, self._lp, *sn)
        else:
            self._li, self._lx, self._d, bad = _numeric(colptr, rows, data[src], n, parent, self._lp)
        if bad >= 0:
            raise ValueError(f"matrix: not positive definite (pivot {int(bad)} of the LDL factorization ≤ 0)")
        self._lp = self._lp.astype(np.int32)   # with int32 rows: the solve reads 4-byte indices only

    @property
    def nnz(self) -> int:
        """Entries of L below the diagonal."""
        return int(self._lp[-1])

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for one right-hand side (n,) or several (n, k)."""
        b = np.asarray(b)
        dt = np.result_type(b.dtype, self.dtype, np.float64)
        if b.ndim == 2:
            return np.stack([self.solve(b[:, j]) for j in range(b.shape[1])], axis=1)
        if b.shape != (self.n,):
            raise ValueError(f"b: expected shape ({self.n},), got {b.shape}")
        if dt != self.dtype:                 # a complex right-hand side of a real matrix: two real solves
            return self.solve(np.ascontiguousarray(b.real)) + 1j * self.solve(np.ascontiguousarray(b.imag))
        x = np.empty(self.n, dt)
        x[self.perm] = _solve(self._lp, self._li, self._lx, self._d, np.ascontiguousarray(b[self.perm], dt))
        return x


# ------------------------------------------------------------------------------------ supernodal numeric
@njit(cache=True)
def _lower_csc(indptr, indices, n, pinv):
    """Pattern of the lower triangle (i ≥ j) of P A Pᵀ in CSC, from the CSR of A: (colptr, rows, src), ``src``
    the position of each entry in A's data (value A[i, j]; duplicates kept, the numeric step sums them)."""
    cnt = np.zeros(n + 1, np.int64)
    for r in range(n):
        i = pinv[r]
        for q in range(indptr[r], indptr[r + 1]):
            j = pinv[indices[q]]
            if i >= j:
                cnt[j + 1] += 1
    for j in range(n):
        cnt[j + 1] += cnt[j]
    pos = cnt[:-1].copy()
    rows = np.empty(cnt[n], np.int64)
    src = np.empty(cnt[n], np.int64)
    for r in range(n):
        i = pinv[r]
        for q in range(indptr[r], indptr[r + 1]):
            j = pinv[indices[q]]
            if i >= j:
                rows[pos[j]] = i
                src[pos[j]] = q
                pos[j] += 1
    return cnt, rows, src


@njit(cache=True)
def _supernodes(colptr, rows, n, parent, lp):
    """Fundamental supernodes of L (columns j, j+1 share one when parent[j] = j+1 and column j's pattern is
    column j+1's plus j+1, i.e. c_j = c_{j+1} + 1) and the row pattern of each: (first, snode, rptr, srow) with
    ``first`` (S+1,) the first column of each supernode, ``snode`` the supernode of each column and
    ``srow[rptr[s]:rptr[s+1]]`` its rows, ascending (its own columns first). The patterns come from the
    elimination-tree reach of each row of the upper pattern (colptr, rows), as in the up-looking factorization."""
    cnt = np.empty(n, np.int64)
    for j in range(n):
        cnt[j] = lp[j + 1] - lp[j]
    snode = np.empty(n, np.int64)
    first = np.empty(n + 1, np.int64)
    ns = 0
    for j in range(n):
        if j == 0 or not (parent[j - 1] == j and cnt[j - 1] == cnt[j] + 1):
            first[ns] = j
            ns += 1
        snode[j] = ns - 1
    first[ns] = n
    first = first[:ns + 1].copy()
    rptr = np.zeros(ns + 1, np.int64)
    for s in range(ns):
        rptr[s + 1] = rptr[s] + 1 + cnt[first[s]]
    srow = np.empty(rptr[ns], np.int64)
    fill = np.empty(ns, np.int64)
    for s in range(ns):
        srow[rptr[s]] = first[s]
        fill[s] = rptr[s] + 1
    flag = np.empty(n, np.int64)
    for k in range(n):
        flag[k] = k
        for p in range(colptr[k], colptr[k + 1]):
            i = rows[p]
            while i < k and flag[i] != k:
                s = snode[i]
                if first[s] == i:
                    srow[fill[s]] = k
                    fill[s] += 1
                flag[i] = k
                i = parent[i]
    return first, snode, rptr, srow


@njit(cache=True)
def _supernodal_numeric(colptr, rows, vals, n, lp, first, snode, rptr, srow):
    """Left-looking supernodal LDLᴴ (the scheme of CHOLMOD's supernodal factorization, without BLAS): each
    supernode is a dense block (its rows × its columns, row-major); it receives the updates
    ``L_d[r, :] D_d L_d[c, :]ᴴ`` of every earlier supernode d whose pattern meets its columns (scattered through a
    row map), then is factorized densely, ``D_j = a_jj − Σ_k |l_jk|² D_k``, ``l_ij = (a_ij − Σ_k l_ik D_k
    conj(l_jk)) / D_j``; the update of a descendant is applied two target columns per pass over its rows (each
    sum formed as with one column: the same L, D, fewer passes). (colptr, rows, vals): the lower triangle of the
    reordered matrix in CSC. Returns (Li, Lx, D, k_bad) in the simplicial layout of :func:`_numeric` (column
    pointers ``lp``)."""
    ns_tot = len(first) - 1
    off = np.zeros(ns_tot + 1, np.int64)
    wmax = 1
    for s in range(ns_tot):
        w = first[s + 1] - first[s]
        off[s + 1] = off[s] + (rptr[s + 1] - rptr[s]) * w
        if w > wmax:
            wmax = w
    X = np.zeros(off[ns_tot], vals.dtype)
    d = np.empty(n, np.float64)
    wk = np.empty(wmax, vals.dtype)
    wk2 = np.empty(wmax, vals.dtype)
    rmap = np.empty(n, np.int64)
    rel = np.empty(n + 1, np.int64)
    head = np.full(ns_tot, -1, np.int64)
    nxt = np.full(ns_tot, -1, np.int64)
    ptr = np.zeros(ns_tot, np.int64)
    li = np.empty(lp[n], np.int32)
    lx = np.empty(lp[n], vals.dtype)
    for s in range(ns_tot):
        f = first[s]
        w = first[s + 1] - f
        r0 = rptr[s]
        nr = rptr[s + 1] - r0
        o = off[s]
        for i in range(nr):
            rmap[srow[r0 + i]] = i
        for c in range(w):
            for p in range(colptr[f + c], colptr[f + c + 1]):
                X[o + rmap[rows[p]] * w + c] += vals[p]
        dd = head[s]
        while dd != -1:
            dnext = nxt[dd]
            fd = first[dd]
            wd = first[dd + 1] - fd
            rd = rptr[dd]
            nrd = rptr[dd + 1] - rd
            od = off[dd]
            p1 = ptr[dd]
            p2 = p1
            while p2 < nrd and srow[rd + p2] < f + w:
                p2 += 1
            for ii in range(p1, nrd):
                rel[ii] = o + rmap[srow[rd + ii]] * w
            jj = p1
            while jj < p2:
                c = srow[rd + jj] - f
                bj = od + jj * wd
                for k in range(wd):
                    wk[k] = d[fd + k] * np.conj(X[bj + k])
                if jj + 1 == p2:
                    for ii in range(jj, nrd):
                        bi = od + ii * wd
                        t = X[bi] * wk[0]
                        for k in range(1, wd):
                            t += X[bi + k] * wk[k]
                        X[rel[ii] + c] -= t
                    break
                # two target columns per pass over the rows of d (each sum as in the one-column loop)
                c2 = srow[rd + jj + 1] - f
                for k in range(wd):
                    wk2[k] = d[fd + k] * np.conj(X[bj + wd + k])
                t = X[bj] * wk[0]
                for k in range(1, wd):
                    t += X[bj + k] * wk[k]
                X[rel[jj] + c] -= t
                for ii in range(jj + 1, nrd):
                    bi = od + ii * wd
                    x = X[bi]
                    t = x * wk[0]
                    t2 = x * wk2[0]
                    for k in range(1, wd):
                        x = X[bi + k]
                        t += x * wk[k]
                        t2 += x * wk2[k]
                    r = rel[ii]
                    X[r + c] -= t
                    X[r + c2] -= t2
                jj += 2
            ptr[dd] = p2
            if p2 < nrd:
                tg = snode[srow[rd + p2]]
                nxt[dd] = head[tg]
                head[tg] = dd
            dd = dnext
        for j in range(w):
            bj = o + j * w
            for k in range(j):
                wk[k] = d[f + k] * np.conj(X[bj + k])
            for i in range(j, nr):
                bi = o + i * w
                t = X[bi + j] * 0.0
                for k in range(j):
                    t += X[bi + k] * wk[k]
                X[bi + j] -= t
            dj = X[bj + j].real
            if not dj > 0.0:
                return li, lx, d, f + j
            d[f + j] = dj
            for i in range(j + 1, nr):
                X[o + i * w + j] /= dj
        ptr[s] = w
        if w < nr:
            tg = snode[srow[r0 + w]]
            nxt[s] = head[tg]
            head[tg] = s
        for c in range(w):
            q = lp[f + c]
            for i in range(c + 1, nr):
                li[q] = srow[r0 + i]
                lx[q] = X[o + i * w + c]
                q += 1
    return li, lx, d, -1
