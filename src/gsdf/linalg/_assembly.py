"""Sparse matrix assembly from COO triplets (one serial numba pass, no sort), for operators built per element,
and principal submatrices plus a diagonal (:func:`principal_submatrix`).

``scipy.sparse.csr_matrix((vals, (rows, cols)))`` converts, then sorts every row and sums duplicates in
separate passes with Python-level checks around each (~1 ms per operator on small meshes). :func:`coo_to_csr`
computes the canonical CSR pattern once (bucket by row, duplicates merged through a column marker, each short
row insertion-sorted) together with the output slot of every triplet, and sums the values with ``np.bincount``
in input order — so real and complex values share one compiled kernel.

:func:`principal_submatrix` forms ``s · A[keep][:, keep] + diag(d)`` of a canonical CSR (or CSC) matrix in one
pass, the same matrix as scipy's indexing, scaling and addition (entries whose sum is exactly zero dropped, as
scipy's addition does), without scipy's index checks and intermediate matrices.

Example
-------
>>> import numpy as np
>>> A = coo_to_csr(np.array([0, 1, 0]), np.array([1, 0, 1]), np.array([1.0, 2.0, 3.0]), (2, 2))
>>> A.toarray().tolist()
[[0.0, 4.0], [2.0, 0.0]]
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

__all__ = ["coo_to_csr", "csr_pattern", "principal_submatrix"]


@njit(cache=True)
def sort_row(indices, first, out, mark):
    """Sort the column indices ``indices[first:out]`` of one CSR row in place (insertion sort: rows are short)
    and record each column's final position in ``mark``."""
    for a in range(first + 1, out):
        c = indices[a]
        b = a - 1
        while b >= first and indices[b] > c:
            indices[b + 1] = indices[b]
            b -= 1
        indices[b + 1] = c
    for a in range(first, out):
        mark[indices[a]] = a


@njit(cache=True)
def _csr_pattern(rows, cols, n_rows, n_cols):
    k = len(rows)
    start = np.zeros(n_rows + 1, np.int64)
    for t in range(k):
        start[rows[t] + 1] += 1
    for i in range(n_rows):
        start[i + 1] += start[i]
    pos = start[:-1].copy()
    order = np.empty(k, np.int64)
    for t in range(k):
        order[pos[rows[t]]] = t
        pos[rows[t]] += 1
    indptr = np.zeros(n_rows + 1, np.int32)
    indices = np.empty(k, np.int32)
    slot = np.empty(k, np.int64)
    mark = np.full(n_cols, -1, np.int64)
    out = np.int64(0)                      # not a literal 0: sort_row would compile once more for it
    for i in range(n_rows):
        first = out
        for q in range(start[i], start[i + 1]):
            j = cols[order[q]]
            if mark[j] < first:
                mark[j] = out
                indices[out] = j
                out += 1
        sort_row(indices, first, out, mark)
        for q in range(start[i], start[i + 1]):
            t = order[q]
            slot[t] = mark[cols[t]]
        indptr[i + 1] = out
    return indptr, indices[:out].copy(), slot


def csr_pattern(rows, cols, shape):
    """Canonical CSR pattern of COO indices: ``(indptr, indices, slot)`` with ``slot[t]`` the position of
    triplet t in the CSR data (int32 indices; indices must be in range — callers pass their own)."""
    return _csr_pattern(np.asarray(rows, np.int64), np.asarray(cols, np.int64), int(shape[0]), int(shape[1]))


def coo_to_csr(rows, cols, vals, shape) -> sp.csr_matrix:
    """``scipy.sparse.csr_matrix((vals, (rows, cols)), shape)`` with sorted indices and duplicates summed
    (in input order), built in one pass (module docs); real or complex ``vals``."""
    indptr, indices, slot = csr_pattern(rows, cols, shape)
    vals = np.asarray(vals)
    nnz = len(indices)
    if np.iscomplexobj(vals):
        data = np.bincount(slot, weights=vals.real, minlength=nnz) \
            + 1j * np.bincount(slot, weights=vals.imag, minlength=nnz)
    else:
        data = np.bincount(slot, weights=vals, minlength=nnz)
    A = sp.csr_matrix((data, indices, indptr), shape=shape)
    A.has_sorted_indices = True
    A.has_canonical_format = True
    return A


@njit(cache=True)
def _principal_submatrix(indptr, indices, data, rank, m, scale, diag, add_diag):
    n = len(indptr) - 1
    cnt = 0
    for i in range(n):
        if rank[i] >= 0:
            cnt += indptr[i + 1] - indptr[i] + 1
    out_ptr = np.zeros(m + 1, np.int32)
    out_idx = np.empty(cnt, np.int32)
    out_val = np.empty(cnt, data.dtype)
    q = 0
    for i in range(n):
        r = rank[i]
        if r < 0:
            continue
        placed = not add_diag
        for p in range(indptr[i], indptr[i + 1]):
            c = rank[indices[p]]
            if c < 0:
                continue
            if not placed and c >= r:             # the diagonal, added in column order (inserted if missing)
                placed = True
                if c > r:
                    if diag[r] != 0:
                        out_idx[q] = r
                        out_val[q] = diag[r]
                        q += 1
                else:
                    v = data[p] * scale + diag[r]
                    if v != 0:
                        out_idx[q] = c
                        out_val[q] = v
                        q += 1
                    continue
            v = data[p] * scale
            if add_diag and v == 0:
                continue
            out_idx[q] = c
            out_val[q] = v
            q += 1
        if not placed and diag[r] != 0:
            out_idx[q] = r
            out_val[q] = diag[r]
            q += 1
        out_ptr[r + 1] = q
    return out_ptr, out_idx[:q].copy(), out_val[:q].copy()


def principal_submatrix(A, keep=None, scale: float = 1.0, diag=None):
    """``scale · A[keep][:, keep] + diag(diag)`` (module docs) for a CSR or CSC ``A`` with sorted indices, in A's
    format; ``keep`` an ascending index array (None: all rows), ``diag`` (len(keep),) or None. Entries whose
    value is exactly zero are dropped when a diagonal is added (scipy's addition drops them), kept otherwise
    (scipy's indexing keeps them).

    Example
    -------
    >>> A = sp.csr_matrix(np.array([[2.0, -1, 0], [-1, 2, -1], [0, -1, 2]]))
    >>> principal_submatrix(A, np.array([0, 2]), 0.5, np.array([1.0, 1.0])).toarray().tolist()
    [[2.0, 0.0], [0.0, 2.0]]
    """
    if A.format not in ("csr", "csc") or not A.has_sorted_indices:
        raise ValueError(f"A: expected a CSR or CSC matrix with sorted indices, got format {A.format!r}")
    n = A.shape[0]
    if A.shape[1] != n:
        raise ValueError(f"A: expected a square matrix, got shape {A.shape}")
    rank = np.full(n, -1, np.int64)
    if keep is None:
        rank[:] = np.arange(n)
        m = n
    else:
        keep = np.asarray(keep)
        if keep.ndim != 1 or (keep.size and keep.dtype.kind not in "iu"):
            raise ValueError(f"keep: expected a 1-D array of integer indices, got shape {keep.shape} "
                             f"dtype {keep.dtype}")
        keep = keep.astype(np.int64)
        if keep.size and (keep[0] < 0 or keep[-1] >= n or (np.diff(keep) <= 0).any()):
            raise ValueError(f"keep: expected strictly increasing indices in [0, {n}), got "
                             f"{keep.min()}..{keep.max()} ({'not ' if (np.diff(keep) <= 0).any() else ''}increasing)")
        rank[keep] = np.arange(len(keep))
        m = len(keep)
    if A.nnz + m >= 2 ** 31:
        raise ValueError(f"A: {A.nnz} stored entries, beyond the 32-bit indices of the submatrix")
    add = diag is not None
    d = np.asarray(diag, np.float64) if add else np.zeros(0)
    if add and d.shape != (m,):
        raise ValueError(f"diag: expected shape ({m},), got {d.shape}")
    ptr, idx, val = _principal_submatrix(A.indptr, A.indices, A.data, rank, m, float(scale), d, add)
    out = (sp.csr_matrix if A.format == "csr" else sp.csc_matrix)((val, idx, ptr), shape=(m, m))
    out.has_sorted_indices = True
    return out
