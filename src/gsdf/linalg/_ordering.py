"""Fill-reducing orderings of sparse symmetric matrices for :mod:`gsdf.linalg._ldl` (numba, graph only).

``perm[k]`` is the node eliminated k-th; the factor of ``A[perm][:, perm]`` is what :mod:`.ldl` computes.

* :func:`approximate_minimum_degree` — AMD (Amestoy, Davis & Duff, "An approximate minimum degree ordering
  algorithm", SIAM J. Matrix Anal. Appl. 17, 1996): eliminate, one at a time, the node of least degree in the
  graph of the remaining Schur complement, but never form that graph. It is kept as a *quotient graph*: each
  eliminated node becomes an *element* standing for the clique its elimination creates, so a node's
  neighbourhood is its remaining variable neighbours plus the union of its elements' variable lists. Memory
  stays within the original graph's size because an element absorbs every element adjacent to its pivot
  (their cliques are contained in the new one), and, aggressively, every element whose list the new one
  covers. Exact degrees (size of that union) cost too much; the approximate degree bounds them from above by
  ``|A_i ∖ i| + |Lme ∖ i| + Σ_e |Le ∖ Lme|`` (paper eq. 4; also by the previous bound plus |Lme ∖ i|), the
  set differences for all elements e next to the new element me counted in one sweep over Lme. Nodes whose neighbourhoods became identical (found by a hash of their lists) merge into
  *supervariables* eliminated together, and a node adjacent only to the new element is eliminated with it
  (mass elimination). No dense-row removal: the systems here are mesh Laplacians.
* :func:`nested_dissection` — nested dissection by breadth-first level structures (George 1973): a
  pseudo-peripheral node of the subgraph, its BFS levels, and the smallest level near the median as the
  vertex separator (thinned: separator nodes without a neighbour on the far side move to the near side); the
  two sides recurse, the separator is numbered last. O(nnz log n); disconnected subgraphs split into
  components for free.
* :func:`fill_reducing_ordering` — either, by name (:class:`~gsdf.linalg._ldl.LDLFactorization` chooses
  between them by its ``ordering="auto"`` rule).

Example
-------
>>> import scipy.sparse as sp
>>> P = sp.diags([1, 1, 1], [-1, 0, 1], shape=(5, 5)).tocsr()  # a path: minimum degree takes ends first
>>> sorted(approximate_minimum_degree(P).tolist()) == list(range(5))
True
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

__all__ = ["approximate_minimum_degree", "nested_dissection", "fill_reducing_ordering", "order_csr", "ORDERING_NAMES"]

#: The orderings :func:`fill_reducing_ordering` knows.
ORDERING_NAMES = ("amd", "nd")


# ------------------------------------------------------------------------------------------ minimum degree
@njit(cache=True)
def _flip(x):
    """Encode "absorbed into x" in ``pe`` (≤ -2; -1 means an empty/dead list)."""
    return -x - 2


@njit(cache=True, inline="always")
def _unlink(i, lst, nxt, head, degree):
    """Take variable i out of the doubly linked list of the variables of its degree."""
    ilast, inext = lst[i], nxt[i]
    if inext >= 0:
        lst[inext] = ilast
    if ilast >= 0:
        nxt[ilast] = inext
    else:
        head[degree[i]] = inext


@njit(cache=True)
def _amd(indptr, indices, n):
    """Approximate minimum degree (Amestoy, Davis & Duff 1996) on the quotient graph of the symmetric pattern
    of the CSR (indptr, indices) (diagonal and duplicates ignored, an unsymmetric pattern symmetrized).

    Node lists live in one array ``iw``: a variable's list is its elements (``elen`` of them) then its
    variables, an element's list is its variables. ``nv[i]`` is the supervariable weight (0: absorbed),
    ``degree`` the approximate external degree, ``w`` the |Le ∖ Lme| workspace. Returns the order."""
    # ---- symmetrized adjacency without diagonal or duplicates: both directions of every entry, then
    # duplicates dropped row by row (the lists compact towards the front)
    cnt = np.zeros(n, np.int64)
    for i in range(n):
        for q in range(indptr[i], indptr[i + 1]):
            j = indices[q]
            if j != i:
                cnt[i] += 1
                cnt[j] += 1
    nnz2 = 0
    for i in range(n):
        nnz2 += cnt[i]
    iwlen = nnz2 + nnz2 // 5 + 2 * n + 16
    iw = np.empty(iwlen, np.int64)
    pe = np.empty(n, np.int64)
    ln = np.zeros(n, np.int64)               # list lengths
    p = 0
    for i in range(n):
        pe[i] = p
        p += cnt[i]
    for i in range(n):
        for q in range(indptr[i], indptr[i + 1]):
            j = indices[q]
            if j != i:
                iw[pe[i] + ln[i]] = j
                ln[i] += 1
                iw[pe[j] + ln[j]] = i
                ln[j] += 1
    mark = np.full(n, -1)
    pfree = 0
    for i in range(n):
        start = pe[i]
        k = 0
        for t in range(start, start + ln[i]):
            j = iw[t]
            if mark[j] != i:
                mark[j] = i
                iw[pfree + k] = j
                k += 1
        pe[i] = pfree
        ln[i] = k
        pfree += k
    # ---- state
    elen = np.zeros(n, np.int64)
    nv = np.ones(n, np.int64)
    degree = np.empty(n, np.int64)
    for i in range(n):
        degree[i] = ln[i]
    w = np.ones(n, np.int64)
    rank = np.full(n, -1)
    head = np.full(n, -1)          # degree lists
    nxt = np.full(n, -1)
    lst = np.full(n, -1)
    hhead = np.full(n, -1)         # hash buckets of the current step
    hnext = np.full(n, -1)
    hashv = np.zeros(n, np.int64)
    for i in range(n):
        d = degree[i]
        nxt[i] = head[d]
        if head[d] >= 0:
            lst[head[d]] = i
        head[d] = i
    mindeg = 0
    nel = 0
    wflg = 2
    lemax = 0
    npiv = 0
    while nel < n:
        # ---- pivot: a supervariable of least approximate degree
        while head[mindeg] < 0:
            mindeg += 1
        me = head[mindeg]
        inext = nxt[me]
        if inext >= 0:
            lst[inext] = -1
        head[mindeg] = inext
        rank[me] = npiv
        npiv += 1
        elenme = elen[me]
        nvpiv = nv[me]
        nel += nvpiv
        nv[me] = -nvpiv
        degme = 0
        # ---- the new element Lme: me's variables and the variables of its elements (which it absorbs)
        if elenme == 0:                       # in place: me's list holds only variables
            pme1 = pe[me]
            pme2 = pme1
            for t in range(pme1, pme1 + ln[me]):
                i = iw[t]
                nvi = nv[i]
                if nvi > 0:
                    degme += nvi
                    nv[i] = -nvi
                    iw[pme2] = i
                    pme2 += 1
                    _unlink(i, lst, nxt, head, degree)
        else:
            if pfree + (n - nel) + 1 > iwlen:     # room for the new list: copy the live lists to a fresh array
                used = 0
                for i in range(n):
                    if pe[i] >= 0:
                        used += ln[i]
                iwlen = max(iwlen, 2 * used + 2 * n + 16)
                fresh = np.empty(iwlen, np.int64)
                pos = 0
                for i in range(n):
                    if pe[i] >= 0:
                        for t in range(ln[i]):
                            fresh[pos + t] = iw[pe[i] + t]
                        pe[i] = pos
                        pos += ln[i]
                iw = fresh
                pfree = pos
            pme1 = pfree
            pme2 = pme1
            pm = pe[me]
            for knt in range(elenme + 1):
                if knt < elenme:
                    e = iw[pm + knt]
                    pj, lj = pe[e], ln[e]
                else:
                    e = me
                    pj, lj = pm + elenme, ln[me] - elenme
                for t in range(pj, pj + lj):
                    i = iw[t]
                    nvi = nv[i]
                    if nvi > 0:
                        degme += nvi
                        nv[i] = -nvi
                        iw[pme2] = i
                        pme2 += 1
                        _unlink(i, lst, nxt, head, degree)
                if e != me:                   # element e absorbed into me
                    pe[e] = _flip(me)
                    w[e] = 0
            pfree = pme2
        degree[me] = degme
        pe[me] = pme1
        ln[me] = pme2 - pme1
        elen[me] = 0
        # ---- |Le ∖ Lme| for every element e next to Lme: w[e] - wflg
        for t in range(pme1, pme2):
            i = iw[t]
            nvi = -nv[i]
            wnvi = wflg - nvi
            for q in range(pe[i], pe[i] + elen[i]):
                e = iw[q]
                we = w[e]
                if we >= wflg:
                    we -= nvi
                elif we != 0:
                    we = degree[e] + wnvi
                w[e] = we
        # ---- degree update, element absorption (aggressive), mass elimination; hash of each list
        for t in range(pme1, pme2):
            i = iw[t]
            p1 = pe[i]
            p2 = p1 + elen[i]
            pn = p1
            hsh = 0
            deg = 0
            for q in range(p1, p2):
                e = iw[q]
                we = w[e]
                if we != 0:
                    dext = we - wflg
                    if dext > 0:
                        deg += dext
                        iw[pn] = e
                        pn += 1
                        hsh += e
                    else:                     # Le ⊆ Lme: absorbed
                        pe[e] = _flip(me)
                        w[e] = 0
            elen[i] = pn - p1 + 1
            p3 = pn
            for q in range(p2, p1 + ln[i]):
                j = iw[q]
                nvj = nv[j]
                if nvj > 0:                   # a variable outside Lme (Lme and me itself are negative)
                    deg += nvj
                    iw[pn] = j
                    pn += 1
                    hsh += j
            if elen[i] == 1 and p3 == pn:     # only adjacent to me: eliminated with it
                pe[i] = _flip(me)
                nvi = -nv[i]
                degme -= nvi
                nvpiv += nvi
                nel += nvi
                nv[i] = 0
                elen[i] = -1
            else:
                if deg < degree[i]:
                    degree[i] = deg
                iw[pn] = iw[p3]               # me first: the first variable to the end, the first element
                iw[p3] = iw[p1]               # to the end of the elements
                iw[p1] = me
                ln[i] = pn - p1 + 1
                h = hsh % n
                hashv[i] = h
                hnext[i] = hhead[h]
                hhead[h] = i
        degree[me] = degme
        if degme > lemax:
            lemax = degme
        wflg += lemax + 1
        # ---- indistinguishable supervariables of Lme (same hash, same list) merge
        for t in range(pme1, pme2):
            i = iw[t]
            if nv[i] >= 0:
                continue
            h = hashv[i]
            if hhead[h] < 0:
                continue
            a = hhead[h]
            hhead[h] = -1
            while a >= 0:
                if nv[a] < 0:
                    for q in range(pe[a], pe[a] + ln[a]):
                        w[iw[q]] = wflg
                    prev = a
                    b = hnext[a]
                    while b >= 0:
                        same = ln[b] == ln[a] and elen[b] == elen[a] and nv[b] < 0
                        if same:
                            for q in range(pe[b], pe[b] + ln[b]):
                                if w[iw[q]] != wflg:
                                    same = False
                                    break
                        if same:
                            pe[b] = _flip(a)
                            nv[a] += nv[b]
                            nv[b] = 0
                            elen[b] = -1
                            hnext[prev] = hnext[b]
                        else:
                            prev = b
                        b = hnext[b]
                    wflg += 1
                a = hnext[a]
        # ---- back into the degree lists; Lme keeps its principal variables
        pn = pme1
        for t in range(pme1, pme2):
            i = iw[t]
            nvi = -nv[i]
            if nvi > 0:
                nv[i] = nvi
                deg = degree[i] + degme - nvi
                cap = n - nel - nvi
                if deg > cap:
                    deg = cap
                if deg < 0:
                    deg = 0
                inext = head[deg]
                if inext >= 0:
                    lst[inext] = i
                nxt[i] = inext
                lst[i] = -1
                head[deg] = i
                if deg < mindeg:
                    mindeg = deg
                degree[i] = deg
                iw[pn] = i
                pn += 1
        nv[me] = nvpiv
        ln[me] = pn - pme1
        if ln[me] == 0:
            pe[me] = -1
            w[me] = 0
        if elenme != 0:
            pfree = pn
    # ---- the order: pivots by rank, each followed by the variables absorbed into it
    rep = np.empty(n, np.int64)
    for v in range(n):
        if rank[v] >= 0:
            rep[v] = v
            continue
        x = v
        while rank[x] < 0:
            x = _flip(pe[x])
        rep[v] = x
        y = v                                 # path compression: later chains stop here
        while rank[y] < 0 and pe[y] != _flip(x):
            z = _flip(pe[y])
            pe[y] = _flip(x)
            y = z
    start = np.zeros(npiv + 1, np.int64)
    for v in range(n):
        start[rank[rep[v]] + 1] += 1
    for k in range(npiv):
        start[k + 1] += start[k]
    perm = np.empty(n, np.int64)
    for v in range(n):                        # the pivot itself first in its group
        if rank[v] >= 0:
            perm[start[rank[v]]] = v
            start[rank[v]] += 1
    for v in range(n):
        if rank[v] < 0:
            k = rank[rep[v]]
            perm[start[k]] = v
            start[k] += 1
    return perm


# ------------------------------------------------------------------------------------------ nested dissection
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
    level = np.full(n, -1)
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
    indptr, indices, n = _csr_arrays(A)
    if n == 0:
        return np.zeros(0, np.int64)
    return _nested_dissection(indptr, indices, n, int(leaf))


def _csr_arrays(A):
    A = A if sp.issparse(A) and A.format == "csr" else sp.csr_matrix(A)
    if A.shape[0] != A.shape[1]:
        raise ValueError(f"A: expected a square matrix, got shape {A.shape}")
    return A.indptr.astype(np.int64), A.indices.astype(np.int64), A.shape[0]


def approximate_minimum_degree(A) -> np.ndarray:
    """Approximate minimum degree ordering of the symmetric pattern of ``A`` (n, n) (module docs): ``perm``
    (n,) int64 with ``perm[k]`` the node eliminated k-th. The pattern of A + Aᵀ is used; values are ignored.

    Example
    -------
    >>> import scipy.sparse as sp
    >>> star = sp.csr_matrix(([1.0] * 8, ([0, 0, 0, 0, 1, 2, 3, 4], [1, 2, 3, 4, 0, 0, 0, 0])), shape=(5, 5))
    >>> int(approximate_minimum_degree(star)[0]) != 0  # a leaf first (the hub first would fill a clique)
    True
    """
    indptr, indices, n = _csr_arrays(A)
    if n == 0:
        return np.zeros(0, np.int64)
    return _amd(indptr, indices, n)


def fill_reducing_ordering(A, method: str = "amd") -> np.ndarray:
    """The ordering ``method`` (one of :data:`ORDERING_NAMES`) of the symmetric pattern of ``A`` (n, n).

    Example
    -------
    >>> import scipy.sparse as sp
    >>> fill_reducing_ordering(sp.identity(3, format="csr"), "nd").tolist()
    [0, 1, 2]
    """
    indptr, indices, n = _csr_arrays(A)
    return order_csr(indptr, indices, n, method)


def order_csr(indptr, indices, n: int, method: str = "amd") -> np.ndarray:
    """:func:`fill_reducing_ordering` from the int64 CSR (or CSC) index arrays of a symmetric pattern (no
    conversion: the entry point of :class:`~gsdf.linalg._ldl.LDLFactorization`)."""
    if not isinstance(method, str) or method not in ORDERING_NAMES:
        raise ValueError(f"ordering: expected one of {ORDERING_NAMES}, got {method!r}")
    if n == 0:
        return np.zeros(0, np.int64)
    if method == "nd":
        return _nested_dissection(indptr, indices, n, 8)
    return _amd(indptr, indices, n)
