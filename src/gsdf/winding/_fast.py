"""Fast generalized winding numbers for triangle soups and oriented point clouds (Barill et al. 2018, §3.2–3.3).

A tree (:mod:`gsdf.spatial._bvh`) is built once. Every node stores the Taylor expansion of the winding number
of its elements about their area-weighted centre p̃ (Eqs. 13–15 for points, 18–20 with the closed-form
triangle integrals of App. B, Eqs. 25–29 for triangles). A query walks the tree (Algorithm 1): when
|q − p̃| > β r (r = largest distance from p̃ to the node's elements) the expansion is used, otherwise the node
is opened, and leaves are summed exactly (solid angles or dipoles). For points r is the paper's; for
triangles r is the farthest corner of the node's box from p̃ (it bounds the paper's r; on the CGAL meshes it
brings the RMS error at β = 2 from ~1.3e-3 to ~7e-4, the accuracy the paper reports for β = 2). The
triangle tree splits nodes to minimise Σ n r³ (volume of the far-field balls), see :mod:`gsdf.spatial._bvh`.

Derivatives of the Green's function (App. A) with r = p̃ − q, d = |r|:
    ∇G   = r / (4π d³)                                                           (Eq. 22)
    ∇²G  = I / (4π d³) − 3 r⊗r / (4π d⁵)                                         (Eq. 23)
    ∇³G  = −3 (r_a δ_bc + r_b δ_ac + r_c δ_ab) / (4π d⁵) + 15 r_a r_b r_c / (4π d⁷)
The factor 3 in the first term of ∇³G is missing from Eq. 24 as printed in the seed text; it is what the
derivative of Eq. 23 gives, and the tests confirm order-2 converges at third order with it.

Per node we store (coefficients contracted so that evaluation needs no 27-term loop):
    c0 = Σ a n                    (3)   order 0, Eq. 13 / 25
    C1 = Σ a (x − p̃) ⊗ n          (3×3) order 1, Eq. 14 / 26
    C2 = Σ a M ⊗ n, M = (x−p̃)⊗(x−p̃) for points, M = C_t (edge-midpoint rule, Eq. 29) for triangles
         stored as u_a = Σ_b C2_abb, v_c = Σ_a C2_aac and the 6 symmetric entries of C2_··c per c.
Then
    w ≈ c0·r/d³ + (tr C1/d³ − 3 rᵀC1 r/d⁵) + ½(−3(2 r·u + r·v)/d⁵ + 15 Σ_c r_c rᵀC2_··c r / d⁷),  all / 4π,
which :func:`_compact_moments` folds into 23 numbers per node (constants and 1/4π included) evaluated by
:func:`_far_field_c` as (A + (B + C/d²)/d²)/d³.

Triangle walk (:func:`_eval_triangles_wide`): the binary tree is viewed as a 4-wide one
(:mod:`gsdf.spatial._wide`); a query pops a node and evaluates the test and the expansion of all 4 children
in one loop over lanes (data stored lane-last, (node, field, lane), so LLVM vectorises it to 4-wide SIMD),
adds the far ones and pushes the near ones (leaves: exact solid angles). A first node holding the root
alone keeps Algorithm 1's root test. This tests a node's grandchildren where the binary walk might have
accepted the child: the far-field cut is finer, never coarser, so the error is lower (RMS at β = 2 on the
CGAL meshes: 6.0e-4 vs 7.8e-4 on bunny00) at half the time per query.

Build (triangles): the volume-split tree of :mod:`gsdf.spatial._binned`; the node moments bottom-up by
:func:`_tree_moments` (leaves from their triangles, parents from their two children shifted by the
parallel-axis theorem); the compact rows folded straight into the wide lanes by :func:`_lanes`.

Cost: precompute O(m log m) (the tree; moments O(m + k)); a query O(log m) for well-distributed input.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit, prange

from gsdf._checks import as_mesh, integer, positive, query_shaped
from gsdf._memory import SECONDS_PER_QUERY, scratch
from gsdf._normalize import Frame
from gsdf.spatial._bvh import BVH, build_bvh
from gsdf.spatial._triangle_tree import PARALLEL_BUILD_FACES, WIDTH, TriangleTree, single_thread as _single_thread
from gsdf.spatial._triangle_tree import triangle_elements as _triangle_elements  # noqa: F401 (tests, bench)
from gsdf.spatial._triangle_tree import triangle_elements_root as _triangle_elements_root  # noqa: F401 (tests)
from gsdf.spatial._triangle_tree import triangle_tree
from gsdf.spatial._wide import widen
from gsdf.threads import run_ranges, run_tasks
from gsdf.winding import _inside
from gsdf.winding._query import map_queries, query_array
from gsdf.winding._exact import INV_4PI, dipole_w, oriented_area_normals, solid_angle_w

# layout of the per-node coefficient row
_CX, _R2, _C0, _C1, _U, _VV, _S = 0, 3, 4, 7, 16, 19, 22
NODE_WIDTH = 40  # 3 centre + 1 r² + 3 c0 + 9 C1 + 3 u + 3 v + 18 symmetric C2


# Reassociation and fused multiply-add speed the walk up by ~25 %; no "nnan"/"ninf", so comparisons stay exact.
_FASTMATH = {"reassoc", "contract", "arcp", "nsz"}


def _node_moments(start, end, X, AN, M, R, width):
    """Taylor coefficients per node, (k, width) (width >= NODE_WIDTH).

    X (m,3) expansion points of elements (centroids), AN (m,3) area-weighted normals, M (m,6) second
    moments about the element's own centroid (0 for points; for triangles the edge-midpoint C_t about the
    centroid), R (m,k*3) points whose distance bounds the node radius. All arrays in tree order, float64.
    Runs on the threads from :data:`SERIAL_BUILD_FACES` elements (node ranges on Python threads, the kernel
    releases the GIL: :func:`gsdf.threads.run_ranges`).
    """
    conv = [np.ascontiguousarray(a, dtype=np.float64) for a in (X, AN, M, R)]
    start = np.ascontiguousarray(start, dtype=np.int64)
    end = np.ascontiguousarray(end, dtype=np.int64)
    D = np.zeros((start.shape[0], width))
    if X.shape[0] >= SERIAL_BUILD_FACES and numba.get_num_threads() > 1:
        run_ranges(lambda i0, i1: _node_moments_range(start, end, *conv, D, i0, i1), start.shape[0], 2048)
    else:
        _node_moments_range(start, end, *conv, D, 0, start.shape[0])
    return D


@njit(cache=True, nogil=True)  # one serial, GIL-free kernel for both drivers (no parallel loop to compile)
def _node_moments_range(start, end, X, AN, M, R, D, i0, i1):
    for i in range(i0, i1):
        _node_moment(start[i], end[i], X, AN, M, R, D, i)


@njit(cache=True)
def _node_moment(s, e, X, AN, M, R, D, i):
    """Row i of :func:`_node_moments` (node of elements s..e−1)."""
    nr = R.shape[1] // 3
    A = 0.0
    cx = cy = cz = 0.0
    for j in range(s, e):
        a = np.sqrt(AN[j, 0] ** 2 + AN[j, 1] ** 2 + AN[j, 2] ** 2)
        A += a
        cx += a * X[j, 0]
        cy += a * X[j, 1]
        cz += a * X[j, 2]
    if A > 0.0:
        cx /= A
        cy /= A
        cz /= A
    else:
        cx = cy = cz = 0.0
        for j in range(s, e):
            cx += X[j, 0]
            cy += X[j, 1]
            cz += X[j, 2]
        cx /= e - s
        cy /= e - s
        cz /= e - s
    D[i, 0], D[i, 1], D[i, 2] = cx, cy, cz
    r2 = 0.0
    for j in range(s, e):
        for v in range(nr):
            dx = R[j, 3 * v] - cx
            dy = R[j, 3 * v + 1] - cy
            dz = R[j, 3 * v + 2] - cz
            r2 = max(r2, dx * dx + dy * dy + dz * dz)
        n0, n1, n2 = AN[j, 0], AN[j, 1], AN[j, 2]
        D[i, 4] += n0
        D[i, 5] += n1
        D[i, 6] += n2
        d0, d1, d2 = X[j, 0] - cx, X[j, 1] - cy, X[j, 2] - cz
        # C1[a, b] = Σ (x − p̃)_a n_b
        D[i, 7] += d0 * n0
        D[i, 8] += d0 * n1
        D[i, 9] += d0 * n2
        D[i, 10] += d1 * n0
        D[i, 11] += d1 * n1
        D[i, 12] += d1 * n2
        D[i, 13] += d2 * n0
        D[i, 14] += d2 * n1
        D[i, 15] += d2 * n2
        # second moment about p̃ = own second moment + shift (parallel-axis theorem)
        mxx = M[j, 0] + d0 * d0
        myy = M[j, 1] + d1 * d1
        mzz = M[j, 2] + d2 * d2
        mxy = M[j, 3] + d0 * d1
        mxz = M[j, 4] + d0 * d2
        myz = M[j, 5] + d1 * d2
        # u_a = Σ_b C2_abb = Σ M_ab n_b ; v_c = Σ_a C2_aac = tr(M) n_c
        D[i, 16] += mxx * n0 + mxy * n1 + mxz * n2
        D[i, 17] += mxy * n0 + myy * n1 + myz * n2
        D[i, 18] += mxz * n0 + myz * n1 + mzz * n2
        trm = mxx + myy + mzz
        D[i, 19] += trm * n0
        D[i, 20] += trm * n1
        D[i, 21] += trm * n2
        for c in range(3):
            nc = n0 if c == 0 else (n1 if c == 1 else n2)
            b = 22 + 6 * c
            D[i, b] += mxx * nc
            D[i, b + 1] += myy * nc
            D[i, b + 2] += mzz * nc
            D[i, b + 3] += mxy * nc
            D[i, b + 4] += mxz * nc
            D[i, b + 5] += myz * nc
    D[i, 3] = r2


# Compact far-field rows used by the query kernels: the 40 moments of _node_moments folded into the 20
# numbers the order-2 expansion actually needs, pre-scaled by 1/4π and the expansion's constants, so that
#     4π w = (c0·r + tr C1) / d³ + (−3 rᵀC1 r − 3/2 (2u + v)·r) / d⁵ + 15/2 Σ C2_abc r_a r_b r_c / d⁷
# is evaluated as  inv_d3 · (A + inv_d2 · (B + inv_d2 · C))  with A, B, C polynomials in r = p̃ − q.
# Columns: 0–2 c0, 3 tr C1, 4–9 symmetrised −3 C1 (xx yy zz xy xz yz), 10–12 −3/2 (2u + v),
# 13–22 symmetrised 15/2 C2 (xxx yyy zzz xxy xxz xyy yyz xzz yzz xyz), 23 padding (rows of 3 cache lines).
COMPACT_WIDTH = 24
_CUBIC = ((0, 0, 0), (1, 1, 1), (2, 2, 2), (0, 0, 1), (0, 0, 2), (0, 1, 1), (1, 1, 2), (0, 2, 2), (1, 2, 2),
          (0, 1, 2))
_PAIR = {(0, 0): 0, (1, 1): 1, (2, 2): 2, (0, 1): 3, (1, 0): 3, (0, 2): 4, (2, 0): 4, (1, 2): 5, (2, 1): 5}


def _fold_moments(D):
    """Fold the (k, NODE_WIDTH) moments of :func:`_node_moments` into (k, COMPACT_WIDTH) rows (reference form;
    :func:`_compact_moments` applies the same linear map as one matrix product)."""
    k = D.shape[0]
    C = np.zeros((k, COMPACT_WIDTH))
    C[:, 0:3] = D[:, 4:7] * INV_4PI
    C1 = D[:, 7:16].reshape(k, 3, 3)
    C[:, 3] = np.trace(C1, axis1=1, axis2=2) * INV_4PI
    S1 = -3.0 * INV_4PI * C1
    C[:, 4], C[:, 5], C[:, 6] = S1[:, 0, 0], S1[:, 1, 1], S1[:, 2, 2]
    C[:, 7] = S1[:, 0, 1] + S1[:, 1, 0]
    C[:, 8] = S1[:, 0, 2] + S1[:, 2, 0]
    C[:, 9] = S1[:, 1, 2] + S1[:, 2, 1]
    C[:, 10:13] = -1.5 * INV_4PI * (2.0 * D[:, 16:19] + D[:, 19:22])
    for col, mono in enumerate(_CUBIC):
        acc = np.zeros(k)
        seen = set()
        for perm in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
            a, b, c = (mono[perm[0]], mono[perm[1]], mono[perm[2]])
            if (a, b, c) in seen:
                continue
            seen.add((a, b, c))
            acc += D[:, 22 + 6 * c + _PAIR[(a, b)]]  # C2_abc = Σ M_ab n_c
        C[:, 13 + col] = 7.5 * INV_4PI * acc
    return C


def _compact_moments(D):
    """Fold the (k, NODE_WIDTH) moments of :func:`_node_moments` into (k, COMPACT_WIDTH) rows for _far_field_c."""
    return _apply_fold(np.ascontiguousarray(D), COMPACT_WIDTH)


@njit(cache=True)  # serial: ~20 ns per node, less than a parallel launch (and its compile)
def _apply_fold(D, width):
    C = np.zeros((D.shape[0], width))
    row = np.empty(COMPACT_WIDTH - 1)
    for i in range(D.shape[0]):
        _fold_into(D, i, row, COMPACT_WIDTH - 1)
        for j in range(COMPACT_WIDTH - 1):
            C[i, j] = row[j]
    return C


@njit(cache=True)
def _fold_into(D, i, out, keep):
    """out[0:23] (a 1-d scratch row) = the compact row of node i (the map of :func:`_fold_moments`, written
    out term by term); columns from ``keep`` on (orders not evaluated) are zero."""
    g = INV_4PI
    out[0] = g * D[i, 4]
    out[1] = g * D[i, 5]
    out[2] = g * D[i, 6]
    out[3] = g * (D[i, 7] + D[i, 11] + D[i, 15])
    h = -3.0 * g
    out[4] = h * D[i, 7]
    out[5] = h * D[i, 11]
    out[6] = h * D[i, 15]
    out[7] = h * (D[i, 8] + D[i, 10])
    out[8] = h * (D[i, 9] + D[i, 13])
    out[9] = h * (D[i, 12] + D[i, 14])
    h2 = -1.5 * g
    out[10] = h * D[i, 16] + h2 * D[i, 19]
    out[11] = h * D[i, 17] + h2 * D[i, 20]
    out[12] = h * D[i, 18] + h2 * D[i, 21]
    a = 7.5 * g
    b = 15.0 * g
    out[13] = a * D[i, 22]
    out[14] = a * D[i, 29]
    out[15] = a * D[i, 36]
    out[16] = b * D[i, 25] + a * D[i, 28]
    out[17] = b * D[i, 26] + a * D[i, 34]
    out[18] = a * D[i, 23] + b * D[i, 31]
    out[19] = b * D[i, 33] + a * D[i, 35]
    out[20] = a * D[i, 24] + b * D[i, 38]
    out[21] = a * D[i, 30] + b * D[i, 39]
    out[22] = b * (D[i, 27] + D[i, 32] + D[i, 37])
    for j in range(keep, COMPACT_WIDTH - 1):
        out[j] = 0.0


@njit(cache=True, inline="always", fastmath=_FASTMATH)
def _far_field_c(C, i, rx, ry, rz, d2, order):
    """Order-``order`` far field of node i for r = p̃ − q, d2 = |r|² (compact rows from _compact_moments)."""
    inv_d2 = 1.0 / d2
    inv_d3 = np.sqrt(inv_d2) * inv_d2
    a = C[i, 0] * rx + C[i, 1] * ry + C[i, 2] * rz
    if order >= 1:
        xx, yy, zz = rx * rx, ry * ry, rz * rz
        a += C[i, 3]
        b = (C[i, 4] * xx + C[i, 5] * yy + C[i, 6] * zz
             + C[i, 7] * (rx * ry) + C[i, 8] * (rx * rz) + C[i, 9] * (ry * rz))
        if order >= 2:
            b += C[i, 10] * rx + C[i, 11] * ry + C[i, 12] * rz
            c = (rx * (C[i, 13] * xx + C[i, 16] * (rx * ry) + C[i, 17] * (rx * rz) + C[i, 18] * yy
                       + C[i, 20] * zz + C[i, 22] * (ry * rz))
                 + ry * (C[i, 14] * yy + C[i, 19] * (ry * rz) + C[i, 21] * zz)
                 + rz * (C[i, 15] * zz))
            b += c * inv_d2
        a += b * inv_d2
    return a * inv_d3


@njit(cache=True)
def _leaf_triangles(T, s, e, qx, qy, qz):
    """Exact Σ Ω/4π over triangles s..e−1 (rows of T: 9 corner coordinates, then 1.0, or 0.0 for a zero-area
    face). The flag is needed because inside compiled loops the determinant of a degenerate triangle may be
    evaluated with fused multiply-adds and come out as a tiny non-zero number instead of exactly 0."""
    acc = 0.0
    for t in range(s, e):
        acc += T[t, 9] * solid_angle_w(T[t, 0] - qx, T[t, 1] - qy, T[t, 2] - qz,
                                       T[t, 3] - qx, T[t, 4] - qy, T[t, 5] - qz,
                                       T[t, 6] - qx, T[t, 7] - qy, T[t, 8] - qz)
    return acc


@njit(cache=True, inline="always")
def _area_normal(T, j):
    """Area-weighted normal n = ½ (b − a) × (c − a) of leaf row j of T (corners a, b, c)."""
    e1x, e1y, e1z = T[j, 3] - T[j, 0], T[j, 4] - T[j, 1], T[j, 5] - T[j, 2]
    e2x, e2y, e2z = T[j, 6] - T[j, 0], T[j, 7] - T[j, 1], T[j, 8] - T[j, 2]
    return 0.5 * (e1y * e2z - e1z * e2y), 0.5 * (e1z * e2x - e1x * e2z), 0.5 * (e1x * e2y - e1y * e2x)




def _tree_moments(V, F, order, start, end, right, lo, hi, also=None):
    """Leaf rows and Taylor moments of every node of a triangle tree, children before parents.

    Returns T (m, 10): per triangle in tree order its 9 corner coordinates, then 1.0 (0.0 for a zero-area
    face, see :func:`_leaf_triangles`); and D (k, NODE_WIDTH), the moments of :func:`_node_moments` about each
    node's area-weighted centre p̃, with r² the farthest corner of the node's box from p̃.

    A leaf sums its triangles (area-weighted normal n, centroid x, second moment C_t about x by the
    edge-midpoint rule of Eq. 29). An internal node adds its two children's moments shifted from their
    centres p_c to its own p̃ (δ = p_c − p̃, the parallel-axis theorem; Σ over the child's triangles):
        c0 += c0_c,   C1_ab += C1_c,ab + δ_a c0_c,b,
        S_ab,c += S_c,ab,c + δ_a C1_c,bc + δ_b C1_c,ac + δ_a δ_b c0_c,c      (S_ab,c = Σ (C_t + d dᵀ)_ab n_c)
    so the build costs O(m + k) instead of the O(m log m) of summing every node's triangles.

    ``also``: an optional callable of other work (the wide view of the tree) run as one more task on the
    same threads, so it costs no serial time of its own. (The evaluator's build uses the one-pass
    :func:`_moments_lanes`; this two-pass form is its reference.)
    """
    m = order.shape[0]
    k = start.shape[0]
    T = np.empty((m, 10))
    D = np.empty((k, NODE_WIDTH))  # every entry written (leaves, parents, _finish_moment): no zero pass
    W = scratch("fwn.W", (k, 7))  # Σ area, Σ area·x (3), Σ x (3): the centres of the parents
    threads = numba.get_num_threads()
    if m < PARALLEL_BUILD_FACES or threads == 1:
        if also is not None:
            also()
        _subtree_moments(V, F, order, start, end, right, lo, hi, T, D, W, 0, k)
        return T, D
    # whole subtrees on Python threads (leaves, then their parents, while the rows are in cache), then the
    # few nodes above them on this thread
    roots, above = _split_top(start, end, right, 8 * threads)

    def task(r):
        if r < 0:
            also()
        else:
            _subtree_moments(V, F, order, start, end, right, lo, hi, T, D, W, r, _subtree_end(right, r))

    run_tasks(task, ([-1] if also is not None else []) + roots, threads)
    _node_moments_list(start, end, right, lo, hi, D, W, np.array(sorted(above, reverse=True), np.int64))
    return T, D


def _split_top(start, end, right, want):
    """About ``want`` disjoint subtrees covering the tree's leaves (largest first): the root split, then the
    largest internal subtree split again; returns their roots and the nodes above them."""
    roots, above = [0], []
    while len(roots) < want:
        big = max(range(len(roots)), key=lambda j: -1 if right[roots[j]] < 0 else end[roots[j]] - start[roots[j]])
        r = roots[big]
        if right[r] < 0:
            break
        above.append(r)
        roots[big:big + 1] = [r + 1, int(right[r])]
    roots.sort(key=lambda r: start[r] - end[r])
    return roots, above


@njit(cache=True)
def _subtree_end(right, r):
    """One past the last node of node r's subtree (preorder: follow the right children down to a leaf)."""
    while right[r] >= 0:
        r = right[r]
    return r + 1


@njit(cache=True, nogil=True)  # one serial, GIL-free kernel for both drivers (no parallel loop to compile)
def _subtree_moments(V, F, order, start, end, right, lo, hi, T, D, W, i0, i1):
    """Moments of the nodes i0..i1 − 1, a whole subtree (or the tree): leaves, then parents bottom-up."""
    for i in range(i0, i1):
        if right[i] < 0:
            _leaf_moment(V, F, order, start[i], end[i], T, D, W, i)
    for i in range(i1 - 1, i0 - 1, -1):  # preorder: both children of i have larger ids
        if right[i] >= 0:
            _parent_moment(start, end, right, D, W, i)
    for i in range(i0, i1):
        _finish_moment(lo, hi, D, i)


@njit(cache=True)
def _node_moments_list(start, end, right, lo, hi, D, W, nodes):
    """Moments of the internal ``nodes`` (ids descending: children first) whose children are done."""
    for i in nodes:
        _parent_moment(start, end, right, D, W, i)
        _finish_moment(lo, hi, D, i)


@njit(cache=True)
def _leaf_moment(V, F, order, s, e, T, D, W, i):
    """Leaf i of :func:`_tree_moments` (triangles s..e−1 in tree order): its rows of T, its moments (row i
    of D) and its sums of W."""
    A = ax = ay = az = ux = uy = uz = 0.0
    for j in range(s, e):
        f = order[j]
        for c in range(3):
            v = F[f, c]
            T[j, 3 * c] = V[v, 0]
            T[j, 3 * c + 1] = V[v, 1]
            T[j, 3 * c + 2] = V[v, 2]
        nx, ny, nz = _area_normal(T, j)
        T[j, 9] = 1.0 if (nx != 0.0 or ny != 0.0 or nz != 0.0) else 0.0
        a = np.sqrt(nx * nx + ny * ny + nz * nz)
        x = (T[j, 0] + T[j, 3] + T[j, 6]) / 3.0
        y = (T[j, 1] + T[j, 4] + T[j, 7]) / 3.0
        z = (T[j, 2] + T[j, 5] + T[j, 8]) / 3.0
        A += a
        ax += a * x
        ay += a * y
        az += a * z
        ux += x
        uy += y
        uz += z
    W[i, 0], W[i, 1], W[i, 2], W[i, 3], W[i, 4], W[i, 5], W[i, 6] = A, ax, ay, az, ux, uy, uz
    if A > 0.0:
        cx, cy, cz = ax / A, ay / A, az / A
    else:
        cx, cy, cz = ux / (e - s), uy / (e - s), uz / (e - s)
    D[i, 0], D[i, 1], D[i, 2] = cx, cy, cz
    # sums in registers, written once per leaf
    c00 = c01 = c02 = 0.0
    g00 = g01 = g02 = g10 = g11 = g12 = g20 = g21 = g22 = 0.0
    sxx0 = syy0 = szz0 = sxy0 = sxz0 = syz0 = 0.0
    sxx1 = syy1 = szz1 = sxy1 = sxz1 = syz1 = 0.0
    sxx2 = syy2 = szz2 = sxy2 = sxz2 = syz2 = 0.0
    for j in range(s, e):
        n0, n1, n2 = _area_normal(T, j)
        ax_, ay_, az_ = T[j, 0], T[j, 1], T[j, 2]
        bx_, by_, bz_ = T[j, 3], T[j, 4], T[j, 5]
        qx_, qy_, qz_ = T[j, 6], T[j, 7], T[j, 8]
        x = (ax_ + bx_ + qx_) / 3.0
        y = (ay_ + by_ + qy_) / 3.0
        z = (az_ + bz_ + qz_) / 3.0
        # C_t by Eq. 29: ⅓ Σ over the edge midpoints h of (h − x)(h − x)ᵀ
        h0x, h0y, h0z = 0.5 * (ax_ + bx_) - x, 0.5 * (ay_ + by_) - y, 0.5 * (az_ + bz_) - z
        h1x, h1y, h1z = 0.5 * (bx_ + qx_) - x, 0.5 * (by_ + qy_) - y, 0.5 * (bz_ + qz_) - z
        h2x, h2y, h2z = 0.5 * (qx_ + ax_) - x, 0.5 * (qy_ + ay_) - y, 0.5 * (qz_ + az_) - z
        d0, d1, d2 = x - cx, y - cy, z - cz
        mxx = (h0x * h0x + h1x * h1x + h2x * h2x) / 3.0 + d0 * d0
        myy = (h0y * h0y + h1y * h1y + h2y * h2y) / 3.0 + d1 * d1
        mzz = (h0z * h0z + h1z * h1z + h2z * h2z) / 3.0 + d2 * d2
        mxy = (h0x * h0y + h1x * h1y + h2x * h2y) / 3.0 + d0 * d1
        mxz = (h0x * h0z + h1x * h1z + h2x * h2z) / 3.0 + d0 * d2
        myz = (h0y * h0z + h1y * h1z + h2y * h2z) / 3.0 + d1 * d2
        c00 += n0
        c01 += n1
        c02 += n2
        g00 += d0 * n0
        g01 += d0 * n1
        g02 += d0 * n2
        g10 += d1 * n0
        g11 += d1 * n1
        g12 += d1 * n2
        g20 += d2 * n0
        g21 += d2 * n1
        g22 += d2 * n2
        sxx0 += mxx * n0
        syy0 += myy * n0
        szz0 += mzz * n0
        sxy0 += mxy * n0
        sxz0 += mxz * n0
        syz0 += myz * n0
        sxx1 += mxx * n1
        syy1 += myy * n1
        szz1 += mzz * n1
        sxy1 += mxy * n1
        sxz1 += mxz * n1
        syz1 += myz * n1
        sxx2 += mxx * n2
        syy2 += myy * n2
        szz2 += mzz * n2
        sxy2 += mxy * n2
        sxz2 += mxz * n2
        syz2 += myz * n2
    D[i, 4], D[i, 5], D[i, 6] = c00, c01, c02
    D[i, 7], D[i, 8], D[i, 9] = g00, g01, g02
    D[i, 10], D[i, 11], D[i, 12] = g10, g11, g12
    D[i, 13], D[i, 14], D[i, 15] = g20, g21, g22
    D[i, 22], D[i, 23], D[i, 24], D[i, 25], D[i, 26], D[i, 27] = sxx0, syy0, szz0, sxy0, sxz0, syz0
    D[i, 28], D[i, 29], D[i, 30], D[i, 31], D[i, 32], D[i, 33] = sxx1, syy1, szz1, sxy1, sxz1, syz1
    D[i, 34], D[i, 35], D[i, 36], D[i, 37], D[i, 38], D[i, 39] = sxx2, syy2, szz2, sxy2, sxz2, syz2


@njit(cache=True)
def _parent_moment(start, end, right, D, W, i):
    """Internal node i of :func:`_tree_moments` from its two children (their rows done)."""
    _parent_rows(end[i] - start[i], D, W, i, i + 1, right[i])


@njit(cache=True, inline="always")
def _parent_rows(cnt, D, W, i, l, r):
    """Rows i of D and W: the node of ``cnt`` elements whose children's rows are l (left) and r (right)."""
    for q in range(7):
        W[i, q] = W[l, q] + W[r, q]
    if W[i, 0] > 0.0:
        cx, cy, cz = W[i, 1] / W[i, 0], W[i, 2] / W[i, 0], W[i, 3] / W[i, 0]
    else:
        cx, cy, cz = W[i, 4] / cnt, W[i, 5] / cnt, W[i, 6] / cnt
    D[i, 0], D[i, 1], D[i, 2] = cx, cy, cz
    # row i is uninitialised: the left child's terms are stored, the right child's added (no zero pass)
    for h in range(2):
        ch = l if h == 0 else r
        dl0, dl1, dl2 = D[ch, 0] - cx, D[ch, 1] - cy, D[ch, 2] - cz
        for a in range(3):
            D[i, _C0 + a] = D[i, _C0 + a] + D[ch, _C0 + a] if h else D[ch, _C0 + a]
            da = dl0 if a == 0 else (dl1 if a == 1 else dl2)
            for b in range(3):
                t = D[ch, _C1 + 3 * a + b] + da * D[ch, _C0 + b]
                D[i, _C1 + 3 * a + b] = D[i, _C1 + 3 * a + b] + t if h else t
        for pa in range(3):  # the pairs pa <= pb in the row order xx yy zz xy xz yz, q their column
            da = dl0 if pa == 0 else (dl1 if pa == 1 else dl2)
            for pb in range(pa, 3):
                q = pa if pa == pb else pa + pb + 2
                db = dl0 if pb == 0 else (dl1 if pb == 1 else dl2)
                for c in range(3):
                    t = (D[ch, _S + 6 * c + q] + da * D[ch, _C1 + 3 * pb + c]
                         + db * D[ch, _C1 + 3 * pa + c] + da * db * D[ch, _C0 + c])
                    D[i, _S + 6 * c + q] = D[i, _S + 6 * c + q] + t if h else t


@njit(cache=True)
def _finish_moment(lo, hi, D, i):
    """u, v and r² of node i (its moments done)."""
    _finish_row(lo, hi, i, D, i)


@njit(cache=True, inline="always")
def _finish_row(lo, hi, node, D, i):
    """u, v and r² in row i of D, the moments of node ``node`` (its box lo, hi)."""
    # u_a = Σ_b S_ab,b and v_c = Σ_a S_aa,c (see the module docstring)
    for c in range(3):
        D[i, _VV + c] = D[i, _S + 6 * c] + D[i, _S + 6 * c + 1] + D[i, _S + 6 * c + 2]
    D[i, _U] = D[i, _S] + D[i, _S + 6 + 3] + D[i, _S + 12 + 4]
    D[i, _U + 1] = D[i, _S + 3] + D[i, _S + 6 + 1] + D[i, _S + 12 + 5]
    D[i, _U + 2] = D[i, _S + 4] + D[i, _S + 6 + 5] + D[i, _S + 12 + 2]
    # far-field radius: the farthest corner of the node's box from p̃ (see FastWindingNumber._build)
    r2 = 0.0
    for d in range(3):
        g = max(abs(lo[node, d] - D[i, d]), abs(hi[node, d] - D[i, d]))
        r2 += g * g
    D[i, _R2] = r2


def _moments_lanes(V, F, tree, wt, beta2, order, width=WIDTH):
    """:func:`_tree_moments` and :func:`_pack_wide` in one pass, without the (k, NODE_WIDTH) moments of every
    node: the nodes are done children first (descending preorder ids: both children of i have larger ids),
    their moments kept on a stack of at most depth + 2 rows, and each node's far-field data folded into its lane
    of the wide view as soon as it is done. The same arithmetic as the two-pass form (the same rows, lanes and
    leaf rows, bit for bit); at 1.2M faces the moments array alone was 256 MB of fresh pages.

    Returns (T, W, CH, LS, LE, stack_size) as :func:`_tree_moments` (T) and :func:`_pack_wide` (the rest)."""
    order_, start, end, right, lo, hi = tree.order, tree.start, tree.end, tree.right, tree.lo, tree.hi
    m, k = order_.shape[0], start.shape[0]
    kids, child, depth = wt.kids, wt.child, wt.depth
    shift = 1 if right[0] >= 0 else 0
    if shift:  # the first wide node holds the root alone (see _pack_wide)
        top = np.full((1, width), -1, np.int64)
        top[0, 0] = 0
        kids = np.vstack([top, kids])
        top[0, :] = -2
        top[0, 0] = 1
        child = np.vstack([top, np.where(child >= 0, child + 1, child)])
        depth += 1
    keep = (3, 10, COMPACT_WIDTH - 1)[order]
    w = kids.shape[0]
    # n * width + c of each binary node's lane; −1 for a node that the wide view skipped (its children are kids)
    lane = scratch("fwn.lane", k, np.int64)
    lane.fill(-1)
    nn, cc = np.nonzero(kids >= 0)
    lane[kids[nn, cc]] = nn * width + cc
    T = np.empty((m, 10))
    WL = np.empty((w, _WF, width))
    LS = np.empty((w, width), np.int64)
    LE = np.empty((w, width), np.int64)
    empty = kids < 0  # never far (β²r² = ∞), zero centre and coefficients, empty range
    WLt = WL.transpose(0, 2, 1)
    WLt[empty] = 0.0
    WL[:, 3, :][empty] = np.inf
    LS[empty] = 0
    LE[empty] = 0
    rows = _max_depth(right) + 2
    threads = numba.get_num_threads()
    if m < PARALLEL_BUILD_FACES or threads == 1:
        RD, RW = np.empty((1, NODE_WIDTH)), np.empty((1, 7))
        _subtree_lanes(V, F, order_, start, end, right, lo, hi, T, 0, k, lane, beta2, keep, WL, LS, LE,
                       np.empty((rows, NODE_WIDTH)), np.empty((rows, 7)), RD, RW, 0)
    else:
        roots, above = _split_top(start, end, right, 8 * threads)
        nr = len(roots)
        RD, RW = np.empty((nr + len(above), NODE_WIDTH)), np.empty((nr + len(above), 7))

        def task(t):
            r = roots[t]
            _subtree_lanes(V, F, order_, start, end, right, lo, hi, T, r, _subtree_end(right, r), lane, beta2, keep,
                           WL, LS, LE, np.empty((rows, NODE_WIDTH)), np.empty((rows, 7)), RD, RW, t)

        run_tasks(task, range(nr), threads)
        ids = np.array(roots + sorted(above, reverse=True), np.int64)
        _above_lanes(start, end, right, lo, hi, ids, nr, lane, beta2, keep, WL, LS, LE, RD, RW)
    return T, WL, np.ascontiguousarray(child), LS, LE, depth * (width - 1) + 2


@njit(cache=True)
def _max_depth(right):
    """Most edges from the root to a node of the preorder tree."""
    k = right.shape[0]
    depth = np.zeros(k, np.int64)
    most = 0
    for i in range(k):
        r = right[i]
        if r >= 0:
            depth[i + 1] = depth[i] + 1
            depth[r] = depth[i] + 1
            most = max(most, depth[i] + 1)
    return most


@njit(cache=True, inline="always")
def _to_lane(start, end, i, lane, beta2, keep, WL, LS, LE, SD, j, row):
    """Node i's far-field data (row j of SD, its moments finished) into its lane, if it has one."""
    if lane[i] < 0:
        return
    width = WL.shape[2]
    n, c = lane[i] // width, lane[i] % width
    WL[n, 0, c] = SD[j, 0]
    WL[n, 1, c] = SD[j, 1]
    WL[n, 2, c] = SD[j, 2]
    WL[n, 3, c] = beta2 * SD[j, _R2]
    _fold_into(SD, j, row, keep)
    for q in range(COMPACT_WIDTH - 1):
        WL[n, 4 + q, c] = row[q]
    LS[n, c] = start[i]
    LE[n, c] = end[i]


@njit(cache=True, nogil=True)  # one serial, GIL-free kernel for both drivers (subtrees on Python threads)
def _subtree_lanes(V, F, order, start, end, right, lo, hi, T, i0, i1, lane, beta2, keep, WL, LS, LE, SD, SW, RD,
                   RW, t):
    """Nodes i1 − 1 down to i0 (a whole subtree, i0 its root): leaf rows of T, moments on the stack SD / SW
    (a child's rows wait there for its parent's), lanes; the root's moments go to row t of RD / RW."""
    row = np.empty(COMPACT_WIDTH - 1)
    sp = 0
    for i in range(i1 - 1, i0 - 1, -1):
        if right[i] < 0:
            _leaf_moment(V, F, order, start[i], end[i], T, SD, SW, sp)
        else:  # the left child (done last) on top, the right child below it
            _parent_rows(end[i] - start[i], SD, SW, sp, sp - 1, sp - 2)
            for q in range(NODE_WIDTH):
                SD[sp - 2, q] = SD[sp, q]
            for q in range(7):
                SW[sp - 2, q] = SW[sp, q]
            sp -= 2
        _finish_row(lo, hi, i, SD, sp)
        _to_lane(start, end, i, lane, beta2, keep, WL, LS, LE, SD, sp, row)
        sp += 1
    for q in range(NODE_WIDTH):
        RD[t, q] = SD[0, q]
    for q in range(7):
        RW[t, q] = SW[0, q]


@njit(cache=True)
def _above_lanes(start, end, right, lo, hi, ids, nr, lane, beta2, keep, WL, LS, LE, RD, RW):
    """The nodes above the subtrees (ids[nr:], descending) from their children's rows: row j of RD / RW holds
    node ids[j] (the subtrees' roots first)."""
    row = np.empty(COMPACT_WIDTH - 1)
    for j in range(nr, ids.shape[0]):
        i = ids[j]
        l = r = -1
        for q in range(j):
            if ids[q] == i + 1:
                l = q
            elif ids[q] == right[i]:
                r = q
        _parent_rows(end[i] - start[i], RD, RW, j, l, r)
        _finish_row(lo, hi, i, RD, j)
        _to_lane(start, end, i, lane, beta2, keep, WL, LS, LE, RD, j, row)


def _pack_nodes(D, tree):
    """(k, 8) float64 rows [centre, r², skip, right, start, end]: everything the walk touches per node, in one
    64-byte line (indices are exact in float64)."""
    N = np.empty((D.shape[0], 8))
    N[:, 0:4] = D[:, 0:4]
    N[:, 4] = tree.skip
    N[:, 5] = tree.right
    N[:, 6] = tree.start
    N[:, 7] = tree.end
    return N


# WIDTH (gsdf.spatial._triangle_tree), children per node of the wide walk: 8 measured no faster than 4 on the CGAL
# meshes (fewer visits, but 8 lanes do not fit one AVX2 register)
_WF = 4 + COMPACT_WIDTH - 1  # fields per child slot: centre (3), β²r², the 23 compact coefficients


def _pack_wide(D, tree, beta2, order, width=WIDTH, wt=None):
    """Per wide node, the far-field data of its children as (w, _WF, width) float64 (one lane per child, so
    the lane loop of :func:`_eval_triangles_wide` reads contiguous memory), plus the child links and the
    element ranges of the leaf children (w, width) int64. ``wt``: the tree's :func:`widen` view, if done."""
    if wt is None:
        wt = widen(tree, width)
    kids, child, depth = wt.kids, wt.child, wt.depth
    if tree.right[0] >= 0:
        # a first node whose one child is the root, so the root's own far field is tried too (a query far
        # from a closed mesh then gets its c0 = 0 expansion, as in Algorithm 1, not the sum of its children's)
        top = np.full((1, width), -1, np.int64)
        top[0, 0] = 0
        kids = np.vstack([top, kids])
        top[0, :] = -2
        top[0, 0] = 1
        child = np.vstack([top, np.where(child >= 0, child + 1, child)])
        depth += 1
    # compact columns kept per order (the unused orders' coefficients are zero: one kernel evaluates every order)
    keep = (3, 10, COMPACT_WIDTH - 1)[order]
    w = kids.shape[0]
    W = np.empty((w, _WF, width))  # every entry written by _lanes (empty slots too): no zero pass
    LS = np.empty((w, width), np.int64)
    LE = np.empty((w, width), np.int64)
    start, end = tree.start, tree.end
    if end[0] - start[0] >= PARALLEL_BUILD_FACES and numba.get_num_threads() > 1:
        # wide nodes cost the same: one range per thread
        run_ranges(lambda i0, i1: _lanes(D, kids, start, end, beta2, keep, W, LS, LE, i0, i1), w, 2048, 1)
    else:
        _lanes(D, kids, start, end, beta2, keep, W, LS, LE, 0, w)
    return W, np.ascontiguousarray(child), LS, LE, depth * (width - 1) + 2


@njit(cache=True, nogil=True)  # one serial, GIL-free kernel: wide nodes i0..i1 (ranges on Python threads)
def _lanes(D, kids, start, end, beta2, keep, W, LS, LE, i0, i1):
    """Fill wide nodes i0..i1 of the (w, _WF, width) lanes W (every entry; the caller need not zero them):
    lane c of wide node n holds child kids[n, c]'s centre, β²r² and its compact far-field row
    (:func:`_fold_into`, columns < ``keep``), and LS, LE (w, width) the element ranges of the children. An
    empty slot (kid −1) is never far (β²r² = ∞), has zero centre and coefficients and an empty range. ~100 ns per wide node (9 ms at 89k faces, run on
    the threads from PARALLEL_BUILD_FACES faces)."""
    width = kids.shape[1]
    row = np.empty(COMPACT_WIDTH - 1)
    for n in range(i0, i1):
        for c in range(width):
            b = kids[n, c]
            if b < 0:
                for j in range(_WF):
                    W[n, j, c] = 0.0
                W[n, 3, c] = np.inf
                LS[n, c] = 0
                LE[n, c] = 0
                continue
            W[n, 0, c] = D[b, 0]
            W[n, 1, c] = D[b, 1]
            W[n, 2, c] = D[b, 2]
            W[n, 3, c] = beta2 * D[b, _R2]
            _fold_into(D, b, row, keep)
            for j in range(COMPACT_WIDTH - 1):
                W[n, 4 + j, c] = row[j]
            LS[n, c] = start[b]
            LE[n, c] = end[b]


# The walks are one parallel kernel each, with the per-query loop inside the prange body.
@njit(parallel=True, cache=True, fastmath=_FASTMATH)
def _eval_triangles_wide(Q, T, W, CH, LS, LE, stack_size, out):
    n = Q.shape[0]
    chunk = 256
    nchunks = (n + chunk - 1) // chunk
    for ch in prange(nchunks):
        stack = np.empty(stack_size, np.int64)
        for qi in range(ch * chunk, min(n, (ch + 1) * chunk)):
            qx, qy, qz = Q[qi, 0], Q[qi, 1], Q[qi, 2]
            acc = 0.0
            stack[0] = 0
            sp = 1
            while sp > 0:
                sp -= 1
                nd = stack[sp]
                near = 0
                # the children's order-2 far fields, one SIMD lane each: Barill et al. 2018 §3.2 Eq. 13 with
                # the App. A derivatives (Eqs. 22-24) and the §3.3 / App. B triangle moments, folded into the
                # 23 per-node numbers of _compact_moments: w = (A + (B + C/d²)/d²)/d³
                for c in range(WIDTH):
                    rx = W[nd, 0, c] - qx
                    ry = W[nd, 1, c] - qy
                    rz = W[nd, 2, c] - qz
                    d2 = rx * rx + ry * ry + rz * rz
                    far = d2 > W[nd, 3, c]
                    if not far:
                        near |= 1 << c
                        d2 = 1.0
                    inv_d2 = 1.0 / d2
                    inv_d3 = np.sqrt(inv_d2) * inv_d2
                    xx, yy, zz = rx * rx, ry * ry, rz * rz
                    a = W[nd, 4, c] * rx + W[nd, 5, c] * ry + W[nd, 6, c] * rz + W[nd, 7, c]
                    b = (W[nd, 8, c] * xx + W[nd, 9, c] * yy + W[nd, 10, c] * zz
                         + W[nd, 11, c] * (rx * ry) + W[nd, 12, c] * (rx * rz) + W[nd, 13, c] * (ry * rz)
                         + W[nd, 14, c] * rx + W[nd, 15, c] * ry + W[nd, 16, c] * rz)
                    cc = (rx * (W[nd, 17, c] * xx + W[nd, 20, c] * (rx * ry) + W[nd, 21, c] * (rx * rz)
                                + W[nd, 22, c] * yy + W[nd, 24, c] * zz + W[nd, 26, c] * (ry * rz))
                          + ry * (W[nd, 18, c] * yy + W[nd, 23, c] * (ry * rz) + W[nd, 25, c] * zz)
                          + rz * (W[nd, 19, c] * zz))
                    v = (a + (b + cc * inv_d2) * inv_d2) * inv_d3
                    acc += v if far else 0.0
                if near:
                    for c in range(WIDTH - 1, -1, -1):
                        if (near >> c) & 1:
                            cw = CH[nd, c]
                            if cw >= 0:
                                stack[sp] = cw
                                sp += 1
                            elif cw == -1:
                                acc += _leaf_triangles(T, LS[nd, c], LE[nd, c], qx, qy, qz)
            out[qi] = acc


@njit(parallel=True, cache=True, fastmath=_FASTMATH)
def _eval_points(Q, P, NA, N, C, beta2, order, out):
    k = N.shape[0]
    for qi in prange(Q.shape[0]):
        qx, qy, qz = Q[qi, 0], Q[qi, 1], Q[qi, 2]
        acc = 0.0
        i = 0
        while i < k:
            rx = N[i, 0] - qx
            ry = N[i, 1] - qy
            rz = N[i, 2] - qz
            d2 = rx * rx + ry * ry + rz * rz
            if d2 > beta2 * N[i, 3]:
                acc += _far_field_c(C, i, rx, ry, rz, d2, order)
                i = int(N[i, 4])
            elif N[i, 5] < 0.0:
                for j in range(int(N[i, 6]), int(N[i, 7])):
                    acc += dipole_w(P[j, 0], P[j, 1], P[j, 2], NA[j, 0], NA[j, 1], NA[j, 2], 1.0, qx, qy, qz)
                i = int(N[i, 4])
            else:
                i += 1
        out[qi] = acc


#: Largest accuracy parameter β: β² multiplies node radii² in the walk, and beyond 1e150 it overflows (every node
#: would be opened anyway).
BETA_MAX = 1e150


def _check_params(beta, order):
    beta = positive(beta, "beta", most=BETA_MAX)
    if isinstance(order, (bool, np.bool_)) or np.ndim(order) != 0 or order not in (0, 1, 2):
        raise ValueError(f"order: must be 0, 1 or 2, got {order!r}")
    return beta, int(order)


# Below these sizes the build kernels / the walk run on the calling thread: a numba parallel launch waits
# for its worker threads, which on a loaded machine can take longer than the work.
SERIAL_BUILD_FACES = 100_000  # points (clouds)
# Triangle builds use the threads from PARALLEL_BUILD_FACES (gsdf.spatial._triangle_tree) on: three parallel
# launches (the tree's lower subtrees, the leaf moments, the lanes) against ~60 ms of serial work at 75k faces.
SERIAL_QUERIES = 16_384


class _FastWindingBase:
    tree: BVH
    _seconds_per_point = SECONDS_PER_QUERY  # cost of one query, for the size guard of contouring callers

    @query_shaped()
    def __call__(self, Q, progress=None) -> np.ndarray:
        """Winding numbers at the query points ``Q``, evaluated in parallel chunks (the same as :meth:`query`).

        Parameters
        ----------
        Q : (q, 3) float
            Query points, in the input's units.
        progress : callable, optional
            ``progress(stage, fraction)``, called after each chunk of queries with ``fraction`` in (0, 1].

        Returns
        -------
        (q,) float64
            Generalized winding numbers: about 1 inside a closed outward-oriented surface, 0 outside.

        Raises
        ------
        ValueError
            ``Q`` is not an (q, 3) array of finite numbers, or ``progress`` is not callable.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> gsdf.FastWindingNumber(V, F).query([[0.1, 0.1, 0.1]]).round(3)
        array([1.])
        """
        return map_queries(self._kernel, Q, progress=progress, coherent=True, frame=self._frame)

    query = __call__

    @property
    def n_nodes(self) -> int:
        """Number of nodes of the tree."""
        return self.tree.n_nodes


class FastWindingNumber(_FastWindingBase):
    """Reusable fast winding number of a triangle soup: precompute once, query many times.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles; soups, holes, self-intersections and flipped components are all fine. Zero-area faces
        contribute nothing.
    beta : float, default 2.0
        Accuracy parameter β of Algorithm 1 (Barill et al. 2018): a tree node is approximated by its expansion
        when the query is farther than β times the node's radius. Larger is more accurate and slower (β = 2:
        RMS error ~1e-3 in the paper).
    order : {0, 1, 2}, default 2
        Taylor order of the far-field expansion (§3.2, Eqs. 8–10).
    leaf_size : int, default 4
        Triangles per tree leaf (>= 1); changes speed only.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range, ``beta <= 0``, ``order`` not 0, 1 or
        2.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> fwn = gsdf.FastWindingNumber(V, F)
    >>> fwn([[0.1, 0.1, 0.1], [5, 5, 5]]).round(3) + 0.0
    array([1., 0.])
    """

    def __init__(self, V, F, beta: float = 2.0, order: int = 2, leaf_size: int = 4):
        V, F = as_mesh(V, F)
        self.beta, self.order = _check_params(beta, order)
        self._build(triangle_tree(V, F, integer(leaf_size, "leaf_size", 1)))

    @classmethod
    def _of_tree(cls, tt: TriangleTree, beta: float = 2.0, order: int = 2) -> "FastWindingNumber":
        """The evaluator on an already built :class:`gsdf.spatial._triangle_tree.TriangleTree` (shared with
        :class:`gsdf.TriangleDistance` by :func:`gsdf.signed_distance`)."""
        self = cls.__new__(cls)
        self.beta, self.order = _check_params(beta, order)
        self._build(tt)
        return self

    def _build(self, tt: TriangleTree):
        """Leaf rows, node moments and the wide walk's lane data of the tree ``tt`` (in its normalised frame).

        Far-field radius for triangles (set as in _tree_moments): the farthest corner of the node's box from p̃.
        It bounds the paper's r (farthest element point) and, measured on the CGAL meshes, brings the RMS error
        at β = 2 from ~1.3e-3 to ~7e-4 — the paper's "β = 2 gives ~1e-3". Each node's (40) moments are folded
        into its lane as soon as they are done (:func:`_moments_lanes`); the (k, 40) moments of every node are
        never stored (18 MB at 89k faces; tests build them with _tree_moments).
        """
        self._frame = tt.frame  # scale invariance: the tree lives in the normalised frame
        self._mesh = (tt.Vf, tt.F)  # for inside(): closed or not (computed on first use), cell grids by size
        self._closed, self._grids = None, {}
        self._pending = None
        self.tree = t = tt.bvh
        with _single_thread(tt.F.shape[0] < PARALLEL_BUILD_FACES):
            self._T, self._W, self._CH, self._LS, self._LE, self._stack = _moments_lanes(
                tt.Vf, tt.F, t, tt.wide, self.beta ** 2, self.order)

    @classmethod
    def _deferred(cls, V, F, beta: float = 2.0, order: int = 2) -> FastWindingNumber:
        """The evaluator of the validated mesh (V, F) whose tree and moments are built at the first walk (for
        :func:`inside`, whose queries on a closed mesh may need none)."""
        self = cls.__new__(cls)
        self.beta, self.order = _check_params(beta, order)
        self._frame = Frame.of_mesh(V, F)
        self._mesh = (np.ascontiguousarray(self._frame.geometry(V)), F)
        self._closed, self._grids = None, {}
        self._pending = V
        return self

    def _kernel(self, q, out):
        if self._pending is not None:
            V, self._pending = self._pending, None
            self._build(triangle_tree(V, self._mesh[1], 4, frame=self._frame))
        with _single_thread(q.shape[0] < SERIAL_QUERIES):
            _eval_triangles_wide(q, self._T, self._W, self._CH, self._LS, self._LE, self._stack, out)

    @query_shaped()
    def inside(self, Q, progress=None) -> np.ndarray:
        """Inside / outside at the query points ``Q``: winding number > 1/2, the answer of ``self(Q) > 0.5``.

        For a closed oriented mesh (every directed edge used as often as its reverse: also several, nested or
        intersecting components) the winding number is an integer, constant off the surface: the queries are
        settled by the cells of a grid that no triangle touches (one value per connected component of them)
        and by signed crossing counts along x to such a cell, and only the queries whose count cannot be
        decided (on the surface, or a crossing within a relative 1e-12 of a face's edge) walk the tree (see
        :mod:`gsdf.winding._inside`). Meshes with a boundary (holes, soups) walk the tree for every query.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, in the input's units.
        progress : callable, optional
            ``progress(stage, fraction)``, called after each chunk of queries with ``fraction`` in (0, 1].

        Returns
        -------
        (q,) bool
            True inside (winding number > 1/2).

        Raises
        ------
        ValueError
            ``Q`` is not an (q, 3) array of finite numbers, or ``progress`` is not callable.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> gsdf.FastWindingNumber(V, F).inside([[0.1, 0.1, 0.1], [1, 1, 1]])
        array([ True, False])
        """
        if self._closed is None:
            Vf, F = self._mesh
            self._closed = _inside.is_closed(F, Vf.shape[0])
        if not self._closed:  # w is not constant off the surface: the walk
            return self(Q, progress=progress) > 0.5
        return map_queries(self._inside_kernel, Q, progress=progress, frame=self._frame) > 0.5

    def _inside_kernel(self, q, out):
        Vf, F = self._mesh
        n = q.shape[0]
        if n < 2048:  # the grid would cost more than the walks
            self._kernel(q, out)
            out[:] = out > 0.5
            return
        cells = int(n * _inside.CELLS_PER_QUERY)
        key = round(cells ** (1.0 / 3.0))
        grid = self._grids.get(key)
        if grid is None:  # one grid kept (the last size): repeated calls of one size reuse it
            grid = _inside.build_grid(Vf, F, cells, self._values)
            self._grids = {key: grid}
        _inside.classify(grid, q, out, self._kernel, Vf, F)

    def _values(self, P):
        w = np.empty(P.shape[0])
        if P.shape[0]:
            self._kernel(np.ascontiguousarray(P, dtype=np.float64), w)
        return w


class FastWindingNumberPoints(_FastWindingBase):
    """Reusable fast winding number of an oriented point cloud (Eq. 5 approximated by Eqs. 13–15).

    Parameters
    ----------
    P, N : (m, 3) float
        Points and outward normals (normalized internally; their length does not matter).
    areas : (m,) float, optional
        Point areas a_i (Eq. 5; square input units); estimated by :func:`gsdf.point_areas` (k = 20) when omitted.
    beta : float, default 2.3
        Accuracy parameter β (the paper's value for clouds: RMS error ~1e-2); larger is more accurate and slower.
    order : {0, 1, 2}, default 2
        Taylor order of the far-field expansion (Eqs. 13–15).
    leaf_size : int, default 8
        Points per tree leaf (>= 1); changes speed only.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite values, negative areas, ``beta <= 0``, ``order`` not 0, 1 or 2.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> i = np.arange(4000) + 0.5
    >>> phi, th = np.arccos(1 - 2 * i / 4000), np.pi * (1 + 5 ** 0.5) * i
    >>> P = np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])
    >>> fwn = gsdf.FastWindingNumberPoints(P, P, areas=np.full(4000, 4 * np.pi / 4000))
    >>> fwn([[0, 0, 0], [3, 0, 0]]).round(2)
    array([1., 0.])
    """

    def __init__(self, P, N, areas=None, beta: float = 2.3, order: int = 2, leaf_size: int = 8):
        self._frame, P, NA = oriented_area_normals(P, N, areas)  # normalised frame (gsdf._normalize)
        self.beta, self.order = _check_params(beta, order)
        leaf_size = integer(leaf_size, "leaf_size", 1)
        with _single_thread(len(P) < SERIAL_BUILD_FACES):
            self.tree = build_bvh(P, P, P, leaf_size)
            o = self.tree.order
            self._P = np.ascontiguousarray(P[o])
            self._NA = np.ascontiguousarray(NA[o])
            self._D = _node_moments(self.tree.start, self.tree.end, self._P, self._NA,
                                    np.zeros((len(P), 6)), self._P, NODE_WIDTH)
            self._N = _pack_nodes(self._D, self.tree)
            self._C = _compact_moments(self._D)

    def _kernel(self, q, out):
        with _single_thread(q.shape[0] < SERIAL_QUERIES):
            _eval_points(q, self._P, self._NA, self._N, self._C, self.beta ** 2, self.order, out)


@query_shaped()
def fast_winding_number(V, F, Q, beta: float = 2.0, order: int = 2) -> np.ndarray:
    """Fast generalized winding number of a triangle soup at ``Q`` (one call: build the tree, query).

    Barill et al. 2018, Algorithm 1; see :class:`FastWindingNumber` to reuse the tree across calls.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles; soups, holes, self-intersections and flipped components are all fine.
    Q : (q, 3) float
        Query points.
    beta : float, default 2.0
        Accuracy parameter β: larger is more accurate and slower (see :class:`FastWindingNumber`).
    order : {0, 1, 2}, default 2
        Taylor order of the far-field expansion.

    Returns
    -------
    (q,) float64
        Winding numbers: about 1 inside a closed outward-oriented surface, 0 outside, in between near holes.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range, ``beta <= 0``, a bad ``order``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])          # outward tetrahedron
    >>> w = gsdf.fast_winding_number(V, F, [[0.1, 0.1, 0.1], [2.0, 2.0, 2.0]])
    >>> (np.round(w, 6) + 0.0).tolist()
    [1.0, 0.0]
    """
    query_array(Q)  # the size guard before the tree is built
    return FastWindingNumber(V, F, beta=beta, order=order)(Q)


@query_shaped()
def inside(V, F, Q, beta: float = 2.0) -> np.ndarray:
    """Inside / outside of a triangle mesh or soup at ``Q``: the generalized winding number > 1/2, in one call.

    The answer of ``FastWindingNumber(V, F).inside(Q)`` (see :meth:`FastWindingNumber.inside`); for a closed
    oriented mesh the queries are settled by free grid cells and signed crossing counts, and the tree of the
    fast winding number (Barill et al. 2018, Algorithm 1) is built only if some query needs it (a query on
    the surface, or a crossing too close to an edge to be decided).

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles; soups, holes, self-intersections and flipped components are all fine.
    Q : (q, 3) float
        Query points.
    beta : float, default 2.0
        Accuracy parameter β of the fast winding number where it is used (see :class:`FastWindingNumber`).

    Returns
    -------
    (q,) bool
        True where the winding number exceeds 1/2.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite coordinates, face indices out of range, ``beta <= 0``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])          # outward tetrahedron
    >>> gsdf.inside(V, F, [[0.1, 0.1, 0.1], [2.0, 2.0, 2.0]])
    array([ True, False])
    """
    query_array(Q)  # the size guard before anything is built
    V, F = as_mesh(V, F)
    return FastWindingNumber._deferred(V, F, beta=beta).inside(Q)


@query_shaped()
def fast_winding_number_points(P, N, Q, areas=None, beta: float = 2.3, order: int = 2) -> np.ndarray:
    """Fast winding number of an oriented point cloud at ``Q``; ``areas=None`` estimates point areas.

    Barill et al. 2018, Eq. 5 approximated by Eqs. 13–15; see :class:`FastWindingNumberPoints` to reuse the tree
    across calls.

    Parameters
    ----------
    P : (m, 3) float
        Points.
    N : (m, 3) float
        Outward normals (normalized internally).
    Q : (q, 3) float
        Query points.
    areas : (m,) float, optional
        Point areas (square input units); default: estimated by :func:`gsdf.point_areas` with k = 20.
    beta : float, default 2.3
        Accuracy parameter β: larger is more accurate and slower.
    order : {0, 1, 2}, default 2
        Taylor order of the far-field expansion.

    Returns
    -------
    (q,) float64
        Winding numbers: about 1 inside, 0 outside.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite values, negative areas, ``beta <= 0``, a bad ``order``.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> rng = np.random.default_rng(0)
    >>> P = rng.normal(size=(2000, 3)); P /= np.linalg.norm(P, axis=1, keepdims=True)   # unit sphere
    >>> w = gsdf.fast_winding_number_points(P, P, [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])   # normals = P
    >>> bool(abs(w[0] - 1) < 0.05 and abs(w[1]) < 0.05)
    True
    """
    query_array(Q)  # the size guard before the tree is built
    return FastWindingNumberPoints(P, N, areas=areas, beta=beta, order=order)(Q)
