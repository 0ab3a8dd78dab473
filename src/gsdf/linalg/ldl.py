"""Sparse LDLᴴ factorization of small and mid-size Hermitian / symmetric positive definite matrices (numba).

Why it exists: on the heat method's systems of a few thousand unknowns SuperLU spends most of its time in
fixed costs (its supernode and panel machinery, minimum-degree ordering, L *and* U), not in arithmetic: the
vector heat operator of a 2.8k-vertex scan (7.4k unknowns, L with 47k entries) took 11 ms to factorize while
the arithmetic is ~10⁵ multiply-adds (issue 17: first solves on small meshes were slower than potpourri3d,
whose Eigen ``SimplicialLDLT`` does exactly this). Here:

* **ordering** — nested dissection by breadth-first level structures (George 1973): a pseudo-peripheral node
  of the subgraph, its BFS levels, and the smallest level near the median as the vertex separator (thinned:
  separator nodes without a neighbour on the far side move to the near side); the two sides recurse, the
  separator is numbered last. Graph-only (no coordinates), O(nnz log n); disconnected subgraphs split into
  components for free;
* **symbolic** — elimination tree and column counts of L (Davis, "Algorithm 849: LDL", 2005);
* **numeric** — up-looking LDLᴴ: row k of L from a sparse triangular solve along the elimination tree,
  ``l_k = conj(y) / D``, ``D_k = a_kk − Σ l_ki y_i`` (no pivoting: the matrix must be positive definite;
  a pivot ≤ 0 raises ValueError and callers fall back to SuperLU).

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

__all__ = ["LDLFactorization", "nested_dissection"]


# ------------------------------------------------------------------------------------------ ordering
@njit(cache=True)
def _bfs(indptr, indices, part, label, root, level, queue):
    """BFS from ``root`` inside the nodes with ``part == label``; fills ``level`` (-1 elsewhere must be preset
    by the caller for the subset) and ``queue`` (visit order); returns the number of nodes reached."""
    head, tail = 0, 1
    queue[0] = root
    level[root] = 0
    while head < tail:
        u = queue[head]
        head += 1
        for q in range(indptr[u], indptr[u + 1]):
            w = indices[q]
            if part[w] == label and level[w] < 0:
                level[w] = level[u] + 1
                queue[tail] = w
                tail += 1
    return tail


@njit(cache=True)
def _nested_dissection(indptr, indices, n, leaf):
    perm = np.arange(n)                      # perm[lo:hi] = the nodes of one subset; output order at the end
    part = np.zeros(n, np.int64)             # subset label of every node (labels = range start lo)
    level = np.full(n, -1, np.int64)
    queue = np.empty(n, np.int64)
    tmp = np.empty(n, np.int64)
    stack = np.empty((2 * n + 2, 2), np.int64)
    top = 0
    stack[0, 0], stack[0, 1] = 0, n
    top = 1
    while top > 0:
        top -= 1
        lo, hi = stack[top, 0], stack[top, 1]
        size = hi - lo
        if size <= leaf:
            continue
        # pseudo-peripheral node: two BFS sweeps from the first node
        root = perm[lo]
        for s in range(2):
            reached = _bfs(indptr, indices, part, lo, root, level, queue)
            last = queue[reached - 1]
            if s == 0:
                for r in range(reached):
                    level[queue[r]] = -1
                root = last
        if reached < size:
            # disconnected: the reached component first, the rest after; no separator
            k = 0
            m = reached
            for r in range(lo, hi):
                v = perm[r]
                if level[v] >= 0:
                    tmp[k] = v
                    k += 1
                else:
                    tmp[m] = v
                    m += 1
            for r in range(size):
                perm[lo + r] = tmp[r]
                level[tmp[r]] = -1
            for r in range(reached, size):
                part[perm[lo + r]] = lo + reached
            stack[top, 0], stack[top, 1] = lo, lo + reached
            top += 1
            stack[top, 0], stack[top, 1] = lo + reached, hi
            top += 1
            continue
        nlev = level[queue[reached - 1]] + 1
        if nlev < 3:                          # (nearly) a clique: nothing to dissect
            for r in range(reached):
                level[queue[r]] = -1
            continue
        counts = np.zeros(nlev, np.int64)
        for r in range(reached):
            counts[level[queue[r]]] += 1
        # the smallest level whose cumulative count lies in the middle 60 % of the subset (ties: nearest half)
        best, best_score = -1, 1e300
        below = 0
        for L in range(nlev):
            if L > 0 and L < nlev - 1:
                frac = (below + 0.5 * counts[L]) / size
                if 0.2 <= frac <= 0.8:
                    score = counts[L] * (1.0 + 2.0 * abs(frac - 0.5))
                    if score < best_score:
                        best, best_score = L, score
            below += counts[L]
        if best < 0:                          # no level in the middle band: the one closest to the half
            below = 0
            for L in range(1, nlev - 1):
                frac = (below + counts[0] + 0.5 * counts[L]) / size
                score = abs(frac - 0.5)
                if score < best_score:
                    best, best_score = L, score
                below += counts[L]
        # sides: 0 = near (level < best), 1 = far (level > best), 2 = separator; thin the separator
        for r in range(reached):
            v = queue[r]
            lv = level[v]
            if lv < best:
                tmp[v] = 0
            elif lv > best:
                tmp[v] = 1
            else:
                tmp[v] = 2
        for r in range(reached):
            v = queue[r]
            if tmp[v] == 2:
                far = False
                for q in range(indptr[v], indptr[v + 1]):
                    w = indices[q]
                    if part[w] == lo and level[w] >= 0 and tmp[w] == 1:
                        far = True
                        break
                if not far:
                    tmp[v] = 0
        n0 = 0
        n1 = 0
        for r in range(lo, hi):
            sd = tmp[perm[r]]
            if sd == 0:
                n0 += 1
            elif sd == 1:
                n1 += 1
        a, b, c = 0, n0, n0 + n1
        for r in range(lo, hi):
            v = perm[r]
            sd = tmp[v]
            if sd == 0:
                queue[a] = v
                a += 1
            elif sd == 1:
                queue[b] = v
                b += 1
            else:
                queue[c] = v
                c += 1
        for r in range(size):
            v = queue[r]
            perm[lo + r] = v
            level[v] = -1
            if r < n0:
                part[v] = lo
            elif r < n0 + n1:
                part[v] = lo + n0
            else:
                part[v] = -1                  # numbered: out of every later subset
        if n0 > 0:
            stack[top, 0], stack[top, 1] = lo, lo + n0
            top += 1
        if n1 > 0:
            stack[top, 0], stack[top, 1] = lo + n0, lo + n0 + n1
            top += 1
    return perm


def nested_dissection(A, leaf: int = 8) -> np.ndarray:
    """Fill-reducing ordering of the symmetric sparsity pattern of ``A`` (n, n): ``perm[k]`` = the node
    eliminated k-th (module docs). Subgraphs of at most ``leaf`` nodes keep their order.

    Example
    -------
    >>> import scipy.sparse as sp
    >>> P = sp.diags([1, 1, 1], [-1, 0, 1], shape=(7, 7)).tocsr()   # a path: the middle node goes last
    >>> int(nested_dissection(P, leaf=1)[-1])
    3
    """
    A = sp.csr_matrix(A)
    n = A.shape[0]
    if n == 0:
        return np.zeros(0, np.int64)
    return _nested_dissection(A.indptr.astype(np.int64), A.indices.astype(np.int64), n, int(leaf))


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
    li = np.empty(nnz, np.int64)
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


class LDLFactorization:
    """LDLᴴ of a sparse Hermitian (or real symmetric) positive definite matrix, nested-dissection ordered.

    Parameters
    ----------
    A : scipy.sparse matrix (n, n), float64 or complex128
        Only the pattern's symmetry and the values of the upper triangle of the reordered matrix are used (A is
        assumed Hermitian; nothing checks it).

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

    def __init__(self, A):
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
        self.perm = _nested_dissection(indptr, indices, n, 8) if n else np.zeros(0, np.int64)
        pinv = np.empty(n, np.int64)
        pinv[self.perm] = np.arange(n)
        colptr, rows, src = _upper_csc(indptr, indices, n, pinv)
        parent, self._lp = _symbolic(colptr, rows, n)
        self._li, self._lx, self._d, bad = _numeric(colptr, rows, data[src], n, parent, self._lp)
        if bad >= 0:
            raise ValueError(f"matrix: not positive definite (pivot {int(bad)} of the LDL factorization ≤ 0)")

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
