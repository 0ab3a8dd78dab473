"""Inside / outside (winding number > 1/2) of many query points, settled per grid cell where the winding number
cannot change, the tree walk of :class:`gsdf.FastWindingNumber` only for the rest.

The generalized winding number w of a triangle mesh (Barill et al. 2018, §2, Eq. 2: w(q) = Σ Ω_t(q)/4π) is
harmonic off the surface, and its gradient depends on the mesh's boundary only: the solid angle of a surface
S seen from q has ∇Ω(q) = −∮_∂S dl × (y − q)/|y − q|³ (the Biot–Savart law of the boundary curve; faces sharing
an edge with opposite orientations cancel it), so

    |∇w(q)| ≤ (1/4π) Σ_e |k_e| ℓ_e / dist(q, e)²

over the edges e of the boundary chain ∂F (edge multiplicity k_e, length ℓ_e). Hence:

- a mesh without boundary (every directed edge (a, b) used as often as (b, a): closed, oriented, also with
  several or nested components) has an integer w constant on every connected region free of triangles; the
  grid cells touched by no triangle are grouped into 6-connected components (the union of two face-adjacent
  free cells is a free box), w is evaluated at a few cell centres of each component, and every query in a
  free cell takes its component's value;
- a mesh with a short boundary (holes): a free cell C of half-diagonal h is settled when |w(c) − ½| > h G_C
  + δ at its centre c, G_C the bound above over C (from clusters of boundary edges), δ = :data:`MARGIN` the
  allowance for the far-field error of w(c);
- every other query (in a cell touched by a triangle, in a component whose samples disagree, or when the
  boundary has too many edges for the bound to pay, as in triangle soups) gets the tree walk.

The answer is the exact winding number rounded wherever the evaluations at the cell centres are within
δ of it (the far-field error at β = 2 is ~1e-3 half a cell away from the surface); the walked queries get the
answer of ``FastWindingNumber(V, F)(Q) > 0.5``.

Cost: O(m) to mark the cells, O(cells) to label them, a few walks per component; O(1) per settled query.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit

from gsdf.spatial._morton import cell_order, gather_rows
from gsdf.threads import run_ranges

#: Allowance for the error of the fast winding number at a cell centre (which is at least half a cell away
#: from every triangle): a centre value within this of 1/2 never settles its cell.
MARGIN = 0.05
#: Cells per query point of the grid for a mesh without boundary (labelling costs ~10 ns per cell).
CELLS_PER_QUERY = 1.0
#: Query points per cell of the grid for a mesh with boundary (each settled cell costs one walk).
QUERIES_PER_CELL = 6.0
#: Most boundary-edge clusters for which the gradient bound is computed (beyond: every query is walked).
MAX_CLUSTERS = 2048
#: Sample cells evaluated per component of free cells.
SAMPLES = 8


def boundary_chain(F, n_vertices):
    """Edges (b, 2) int64 and multiplicities (b,) of the boundary chain ∂F (non-zero net count of (a, b)
    minus (b, a)); empty for a closed oriented mesh."""
    F = np.ascontiguousarray(F, dtype=np.int64)
    return _boundary(F, int(n_vertices))


@njit(cache=True)
def _boundary(F, nv):
    m = F.shape[0]
    cnt = np.zeros(nv + 1, np.int64)
    for t in range(m):
        for j in range(3):
            a, b = F[t, j], F[t, (j + 1) % 3]
            if a != b:
                cnt[min(a, b) + 1] += 1
    for v in range(nv):
        cnt[v + 1] += cnt[v]
    pos = cnt[:-1].copy()
    other = np.empty(cnt[nv], np.int64)
    sign = np.empty(cnt[nv], np.int64)
    for t in range(m):
        for j in range(3):
            a, b = F[t, j], F[t, (j + 1) % 3]
            if a != b:
                lo = min(a, b)
                other[pos[lo]] = max(a, b)
                sign[pos[lo]] = 1 if a < b else -1
                pos[lo] += 1
    E = np.empty((cnt[nv], 2), np.int64)
    K = np.empty(cnt[nv], np.int64)
    nb = 0
    for v in range(nv):
        s, e = cnt[v], cnt[v + 1]
        for i in range(s, e):
            if sign[i] == 0:  # already summed into an earlier entry
                continue
            net = sign[i]
            for j in range(i + 1, e):
                if other[j] == other[i] and sign[j] != 0:
                    net += sign[j]
                    sign[j] = 0
            if net != 0:
                E[nb, 0], E[nb, 1] = v, other[i]
                K[nb] = net
                nb += 1
    return E[:nb].copy(), K[:nb].copy()


class CellGrid:
    """Per cell of a cubic-celled grid over the mesh's box: 1 (inside), 0 (outside) or −1 (not settled); the
    value beyond the grid (0 for a mesh without boundary, else −1); for a mesh without boundary also the
    triangles that may touch each cell (CSR: ``ctri[cstart[c]:cstart[c + 1]]``)."""

    def __init__(self, lo, size, dims, value, outside, cstart=None, ctri=None):
        self.lo, self.size, self.dims, self.value, self.outside = lo, size, dims, value, outside
        self.cstart, self.ctri = cstart, ctri


def build_grid(Vf, F, B, n_cells, evaluate, box=None):
    """The :class:`CellGrid` of the mesh (Vf, F) (frame coordinates) with boundary chain B = (edges,
    multiplicities) and about ``n_cells`` cells; ``evaluate(P)`` returns the winding numbers at points P
    (m, 3). The grid covers the mesh's box (with a free layer of cells around it), and for a mesh with
    boundary also ``box`` (lo, hi) within 3 times the mesh's size."""
    lo, hi = _box(Vf, F)
    if box is not None and B[0].shape[0]:
        c, r = 0.5 * (lo + hi), 1.5 * float((hi - lo).max())
        lo = np.minimum(lo, np.maximum(box[0], c - r))
        hi = np.maximum(hi, np.minimum(box[1], c + r))
    ext = hi - lo
    big = float(ext.max()) or 1.0
    s = big / max(1.0, n_cells ** (1.0 / 3.0))
    dims = np.ceil(ext / s).astype(np.int64) + 3  # at least 1.5 cells of margin: the outer layer is free
    if int(np.prod(dims)) > 4 * n_cells + 64:  # a flat box: cells of the same count
        s *= (np.prod(dims) / n_cells) ** (1.0 / 3.0)
        dims = np.ceil(ext / s).astype(np.int64) + 3
    g0 = lo - 0.5 * (dims * s - ext)
    eps = 1e-9 * big
    ncell = int(np.prod(dims))
    cstart = np.zeros(ncell + 1, np.int64)
    _mark(Vf, F, g0, s, dims, eps, cstart, cstart[:0], False)
    occ = (cstart[1:] > 0).astype(np.uint8)
    E, K = B
    value = np.full(ncell, -1, np.int8)
    if E.shape[0] == 0:
        np.cumsum(cstart, out=cstart)
        ctri = np.empty(cstart[-1], np.int64)
        _mark(Vf, F, g0, s, dims, eps, cstart[:-1].copy(), ctri, True)
        grid = CellGrid(g0, s, dims, value, 0, cstart, ctri)
        label, queue, starts = _label(occ, dims)
        ncomp = starts.shape[0] - 1
        val = np.full(ncomp, -1, np.int8)
        if ncomp:
            val[label[0]] = 0  # the component of the grid's corner is outside the mesh's box: w = 0
            pick = _samples(queue, starts, SAMPLES)
            _assign(label, val, value)
            _component_crossings(grid, Vf, F, pick, starts, SAMPLES, val)
            if (val < 0).any():  # samples without a clean crossing count: the fast winding number
                w = evaluate(_centres(pick, g0, s, dims))
                fall = _component_values(w, pick, starts, SAMPLES)
                val = np.where(val < 0, fall, val).astype(np.int8)
            _assign(label, val, value)
        return grid
    clusters, parent, finest = _cluster_levels(Vf, E, K, g0, s, dims)
    if finest <= 2:  # else the bound is too coarse to settle cells near the surface: walk every query
        free = np.flatnonzero(occ == 0)
        h = 0.5 * np.sqrt(3.0) * s
        C = _centres(free, g0, s, dims)
        G = _gradient_bound(C, clusters, parent, h + eps)
        ok = h * G < 0.5 - MARGIN
        if ok.any():
            w = evaluate(np.ascontiguousarray(C[ok]))
            settle = np.abs(w - 0.5) > h * G[ok] + MARGIN
            value[free[ok][settle]] = (w[settle] > 0.5).astype(np.int8)
    return CellGrid(g0, s, dims, value, -1)


@njit(cache=True)
def _box(V, F):
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for t in range(F.shape[0]):
        for c in range(3):
            v = F[t, c]
            for d in range(3):
                lo[d] = min(lo[d], V[v, d])
                hi[d] = max(hi[d], V[v, d])
    return lo, hi


@njit(cache=True)
def _mark(V, F, g0, s, dims, eps, pos, ctri, fill):
    """The cells (closed, grown by eps) that each triangle may touch: those of the triangle's box, less those
    its plane misses when the box spans more than two cells. ``fill`` False: pos[c + 1] += 1 per (triangle,
    cell c); True: ctri[pos[c]] = triangle, pos[c] += 1."""
    nx, ny, nz = dims[0], dims[1], dims[2]
    inv = 1.0 / s
    half = 0.5 * s + eps
    for t in range(F.shape[0]):
        ax, ay, az = V[F[t, 0], 0], V[F[t, 0], 1], V[F[t, 0], 2]
        bx, by, bz = V[F[t, 1], 0], V[F[t, 1], 1], V[F[t, 1], 2]
        cx, cy, cz = V[F[t, 2], 0], V[F[t, 2], 1], V[F[t, 2], 2]
        i0 = max(0, int(np.floor((min(ax, min(bx, cx)) - g0[0] - eps) * inv)))
        j0 = max(0, int(np.floor((min(ay, min(by, cy)) - g0[1] - eps) * inv)))
        k0 = max(0, int(np.floor((min(az, min(bz, cz)) - g0[2] - eps) * inv)))
        i1 = min(nx - 1, int(np.floor((max(ax, max(bx, cx)) - g0[0] + eps) * inv)))
        j1 = min(ny - 1, int(np.floor((max(ay, max(by, cy)) - g0[1] + eps) * inv)))
        k1 = min(nz - 1, int(np.floor((max(az, max(bz, cz)) - g0[2] + eps) * inv)))
        many = (i1 - i0 + 1) * (j1 - j0 + 1) * (k1 - k0 + 1) > 2
        e1x, e1y, e1z = bx - ax, by - ay, bz - az
        e2x, e2y, e2z = cx - ax, cy - ay, cz - az
        nx_ = e1y * e2z - e1z * e2y
        ny_ = e1z * e2x - e1x * e2z
        nz_ = e1x * e2y - e1y * e2x
        nn = nx_ * nx_ + ny_ * ny_ + nz_ * nz_
        ll = max(e1x * e1x + e1y * e1y + e1z * e1z, e2x * e2x + e2y * e2y + e2z * e2z)
        plane = many and nn > 1e-12 * ll * ll  # the plane test only for well-shaped triangles
        an = abs(nx_) + abs(ny_) + abs(nz_)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(k0, k1 + 1):
                    if plane:
                        px = g0[0] + (i + 0.5) * s - ax
                        py = g0[1] + (j + 0.5) * s - ay
                        pz = g0[2] + (k + 0.5) * s - az
                        if abs(nx_ * px + ny_ * py + nz_ * pz) > half * an * (1.0 + 1e-9):
                            continue
                    c = (i * ny + j) * nz + k
                    if fill:
                        ctri[pos[c]] = t
                        pos[c] += 1
                    else:
                        pos[c + 1] += 1


@njit(cache=True)
def _crossings(px, py, pz, step, g0, s, dims, value, outside, cstart, ctri, V, F):
    """Winding number at p of a mesh without boundary, by counting the signed crossings of the segment from p
    along ``step`` · x (±1) to the first cell with a known value (or out of the grid): crossing a face with
    area normal n changes w by −sign(n · direction) (w of a closed oriented surface counts how often it winds
    around p). Each crossing is counted in the cell that owns its x (the floor of the point lookup), so a
    triangle listed in several cells counts once. Returns −99 when a crossing is too close to an edge of a
    face (in the projection along x) or to p to be decided."""
    nx, ny, nz = dims[0], dims[1], dims[2]
    inv = 1.0 / s
    fi = (px - g0[0]) * inv
    fj = (py - g0[1]) * inv
    fk = (pz - g0[2]) * inv
    if fj < 0.0 or fk < 0.0 or fj >= ny or fk >= nz:
        return outside if outside >= 0 else -99
    j, k = int(fj), int(fk)
    i = int(min(max(fi, -1.0), float(nx)))
    if fi < 0.0:
        i = -1
    tolx = 1e-9 * s
    acc = 0
    while True:
        if i < 0 or i >= nx:
            if (i < 0 and step > 0) or (i >= nx and step < 0):
                i += step
                continue
            return outside + acc if outside >= 0 else -99
        c = (i * ny + j) * nz + k
        for q in range(cstart[c], cstart[c + 1]):
            t = ctri[q]
            a, b, d = F[t, 0], F[t, 1], F[t, 2]
            ay, az = V[a, 1] - py, V[a, 2] - pz
            by, bz = V[b, 1] - py, V[b, 2] - pz
            cy, cz = V[d, 1] - py, V[d, 2] - pz
            # edge functions of p in the yz-projection (p at the origin)
            e0 = ay * bz - az * by
            e1 = by * cz - bz * cy
            e2 = cy * az - cz * ay
            t0 = 1e-12 * (abs(ay * bz) + abs(az * by))
            t1 = 1e-12 * (abs(by * cz) + abs(bz * cy))
            t2 = 1e-12 * (abs(cy * az) + abs(cz * ay))
            if (e0 > t0 and e1 > t1 and e2 > t2) or (e0 < -t0 and e1 < -t1 and e2 < -t2):
                ax_ = V[a, 0]
                e1x, e1y, e1z = V[b, 0] - ax_, by - ay, bz - az
                e2x, e2y, e2z = V[d, 0] - ax_, cy - ay, cz - az
                n0 = e1y * e2z - e1z * e2y
                n1 = e1z * e2x - e1x * e2z
                n2 = e1x * e2y - e1y * e2x
                if n0 == 0.0:
                    return -99
                xh = ax_ + (n1 * ay + n2 * az) / n0  # plane n·(x − a) = 0 on the line through p along x
                if abs(xh - px) <= tolx:
                    return -99
                if (xh - px) * step < 0.0:
                    continue
                fh = (xh - g0[0]) * inv
                ih = -1 if fh < 0.0 else (nx if fh >= nx else int(fh))
                if ih != i:
                    continue
                acc += 1 if n0 * step > 0.0 else -1
            elif not ((e0 > t0 or e1 > t1 or e2 > t2) and (e0 < -t0 or e1 < -t1 or e2 < -t2)):
                return -99  # neither clearly inside nor clearly outside the projected face
        i += step
        if 0 <= i < nx:
            v = value[(i * ny + j) * nz + k]
            if v >= 0:
                return v + acc


def _component_crossings(grid, Vf, F, pick, starts, k, val):
    """val[c] = 1 / 0 for the components whose sample cells all get the same clean crossing count."""
    nc = starts.shape[0] - 1
    C = _centres(pick, grid.lo, grid.size, grid.dims)
    for c in range(nc):
        if val[c] >= 0:
            continue
        got = -1
        for j in range(k):
            if pick[c * k + j] < 0:
                break
            w = _crossings(C[c * k + j, 0], C[c * k + j, 1], C[c * k + j, 2], -1, grid.lo, grid.size, grid.dims,
                           grid.value, grid.outside, grid.cstart, grid.ctri, Vf, F)
            if w == -99:
                continue
            r = 1 if w > 0 else 0
            if got >= 0 and r != got:
                got = -2
                break
            got = r
        if got >= 0:
            val[c] = got


@njit(cache=True)
def _label(occ, dims):
    """6-connected components of the free cells (occ == 0): label per cell (−1 on marked cells), the cells in
    visiting order (components contiguous) and the components' starts in it."""
    nx, ny, nz = dims[0], dims[1], dims[2]
    n = occ.shape[0]
    label = np.full(n, -1, np.int32)
    queue = np.empty(n, np.int64)
    starts = np.empty(n + 1, np.int64)
    nq = 0
    nc = 0
    for seed in range(n):
        if occ[seed] != 0 or label[seed] >= 0:
            continue
        starts[nc] = nq
        label[seed] = nc
        queue[nq] = seed
        nq += 1
        head = nq - 1
        while head < nq:
            c = queue[head]
            head += 1
            k = c % nz
            j = (c // nz) % ny
            i = c // (ny * nz)
            for d in range(6):
                if d == 0:
                    if i == 0:
                        continue
                    o = c - ny * nz
                elif d == 1:
                    if i == nx - 1:
                        continue
                    o = c + ny * nz
                elif d == 2:
                    if j == 0:
                        continue
                    o = c - nz
                elif d == 3:
                    if j == ny - 1:
                        continue
                    o = c + nz
                elif d == 4:
                    if k == 0:
                        continue
                    o = c - 1
                else:
                    if k == nz - 1:
                        continue
                    o = c + 1
                if occ[o] == 0 and label[o] < 0:
                    label[o] = nc
                    queue[nq] = o
                    nq += 1
        nc += 1
    starts[nc] = nq
    return label, queue[:nq], starts[:nc + 1].copy()


@njit(cache=True)
def _samples(queue, starts, k):
    """Up to k cells of each component, spread over its visiting order (−1 pads short components)."""
    nc = starts.shape[0] - 1
    pick = np.full(nc * k, -1, np.int64)
    for c in range(nc):
        s, e = starts[c], starts[c + 1]
        m = min(k, e - s)
        for j in range(m):
            pick[c * k + j] = queue[s + (j * (e - s)) // m]
    return pick


def _centres(cells, g0, s, dims):
    cells = np.asarray(cells)
    c = np.where(cells < 0, 0, cells)
    k = c % dims[2]
    j = (c // dims[2]) % dims[1]
    i = c // (dims[1] * dims[2])
    return np.ascontiguousarray(g0 + (np.column_stack([i, j, k]) + 0.5) * s)


def _component_values(w, pick, starts, k):
    """1 / 0 for a component whose samples all round to the same integer (within 1/4), else −1."""
    nc = starts.shape[0] - 1
    W = w.reshape(nc, k)
    valid = pick.reshape(nc, k) >= 0
    R = np.round(W)
    good = np.where(valid, np.abs(W - R) < 0.25, True).all(axis=1)
    first = R[:, 0]
    same = np.where(valid, R == first[:, None], True).all(axis=1)
    return np.where(good & same, (first > 0.5).astype(np.int8), np.int8(-1)).astype(np.int8)


@njit(cache=True)
def _assign(label, val, value):
    for c in range(label.shape[0]):
        if label[c] >= 0:
            value[c] = val[label[c]]


def _cluster_levels(Vf, E, K, g0, s, dims):
    """The clusters of :func:`_clusters` for blocks of 1, 2, 4, ... cells (up to one block), all levels in one
    array (finest first), with each cluster's parent (the cluster of the next level holding its edges; −1 at
    the top), and the finest block size kept: levels of more than :data:`MAX_CLUSTERS` clusters are left out."""
    rows, keys = [], []
    blocks = 1
    finest = 0
    while True:
        R, inv = _clusters(Vf, E, K, g0, s, dims, blocks)
        if R.shape[0] <= MAX_CLUSTERS or blocks >= dims.max():
            rows.append(R)
            keys.append(inv)
            finest = finest or blocks
        if R.shape[0] == 1 or blocks >= dims.max():
            break
        blocks *= 2
    off = np.cumsum([0] + [r.shape[0] for r in rows])
    parent = np.full(off[-1], -1, np.int64)
    for l in range(len(rows) - 1):
        parent[off[l] + keys[l]] = off[l + 1] + keys[l + 1]
    return np.ascontiguousarray(np.vstack(rows)), parent, finest


def _clusters(Vf, E, K, g0, s, dims, blocks):
    """Boundary edges grouped by their midpoints' blocks of ``blocks``³ cells. Rows per cluster about its
    centre p (the mean of its edge midpoints): p (3), ρ (largest |y − p| over its edges), L = Σ |k| ℓ,
    |S| with S = Σ k (b − a), ‖M‖_F with M = Σ k ((a + b)/2 − p) ⊗ (b − a) (edges a → b, multiplicity k)."""
    a, b = Vf[E[:, 0]], Vf[E[:, 1]]
    mid = 0.5 * (a + b)
    dl = (b - a) * K[:, None]
    ln = np.sqrt(((b - a) ** 2).sum(axis=1)) * np.abs(K)
    bs = blocks * s
    key = np.floor((mid - g0) / bs).astype(np.int64)
    kd = np.maximum(1, (dims + blocks - 1) // blocks + 1)
    flat = (key[:, 0] * kd[1] + key[:, 1]) * kd[2] + key[:, 2]
    u, inv = np.unique(flat, return_inverse=True)
    nc = u.shape[0]
    cnt = np.bincount(inv, minlength=nc).astype(np.float64)
    p = np.column_stack([np.bincount(inv, weights=mid[:, d], minlength=nc) for d in range(3)]) / cnt[:, None]
    ra = np.sqrt(((a - p[inv]) ** 2).sum(axis=1))
    rb = np.sqrt(((b - p[inv]) ** 2).sum(axis=1))
    rho = np.zeros(nc)
    np.maximum.at(rho, inv, np.maximum(ra, rb))
    L = np.bincount(inv, weights=ln, minlength=nc)
    S = np.column_stack([np.bincount(inv, weights=dl[:, d], minlength=nc) for d in range(3)])
    rel = mid - p[inv]
    M = np.column_stack([np.bincount(inv, weights=rel[:, i] * dl[:, j], minlength=nc)
                         for i in range(3) for j in range(3)])
    rho *= 1.0 + 1e-12
    return np.ascontiguousarray(np.column_stack([p, rho, L, np.sqrt((S ** 2).sum(axis=1)),
                                                 np.sqrt((M ** 2).sum(axis=1))])), inv


def _gradient_bound(C, clusters, parent, h):
    G = np.empty(C.shape[0])
    run_ranges(lambda i0, i1: _gradient_range(C, clusters, parent, h, G, i0, i1), C.shape[0], 2048, 1)
    return G


@njit(cache=True, nogil=True)
def _gradient_range(C, K, parent, h, G, i0, i1):
    """G[i] ≥ sup |∇w| over the ball of radius h about C[i]. Per cluster (rows of :func:`_clusters`), with
    d = |c − p| − h the least distance from the ball to p, the smaller of
        L / (d − ρ)²                                     (each edge: ∫ dl / |y − q|²)
        |S| / d² + 2 √3 ‖M‖_F / d³ + 12 L ρ² / (d − ρ)⁴   (f(y) = (y − q)/|y − q|³ expanded about p to first
                                                          order: |f(p)| = 1/d², ‖∇f‖ ≤ 2/d³, ‖∇²f‖ ≤ 24/d⁴)
    all / 4π; infinite when the ball reaches a cluster's ball (d ≤ ρ). A cluster with a parent takes the smaller
    of its own bound and the sum of its children's (both bound its edges' part), the top clusters are summed."""
    inv4pi = 1.0 / (4.0 * np.pi)
    nk = K.shape[0]
    child = np.empty(nk)
    for i in range(i0, i1):
        child[:] = -1.0  # −1: no child seen (the finest level)
        acc = 0.0
        for k in range(nk):
            dx, dy, dz = C[i, 0] - K[k, 0], C[i, 1] - K[k, 1], C[i, 2] - K[k, 2]
            d = np.sqrt(dx * dx + dy * dy + dz * dz) - h
            rho = K[k, 3]
            g = d - rho
            own = np.inf
            if g > 0.0:
                g2 = g * g
                d2 = d * d
                own = min(K[k, 4] / g2, K[k, 5] / d2 + 3.4641016151377544 * K[k, 6] / (d2 * d)
                          + 12.0 * K[k, 4] * rho * rho / (g2 * g2))
            v = own if child[k] < 0.0 else min(own, child[k])
            p = parent[k]
            if p >= 0:
                child[p] = v if child[p] < 0.0 else child[p] + v
            else:
                acc += v
        G[i] = acc * inv4pi


def classify(grid, Q, out, walk, Vf=None, F=None):
    """out[i] = 1.0 / 0.0 for queries Q (frame coordinates) inside / outside. Queries in unsettled cells: for a
    mesh without boundary (the grid has cell lists; Vf, F given) the crossing count of :func:`_crossings`
    along −x, else +x; the rest go to ``walk(P, w)`` (winding numbers w at points P), grouped by cells."""
    n = Q.shape[0]
    run_ranges(lambda i0, i1: _lookup(Q, grid.lo, grid.size, grid.dims, grid.value, grid.outside, out, i0, i1),
               n, 16384, 1)
    rest = np.flatnonzero(out < 0.0)
    if rest.shape[0] and grid.ctri is not None:
        run_ranges(lambda i0, i1: _cross_range(Q, rest, grid.lo, grid.size, grid.dims, grid.value, grid.outside,
                                               grid.cstart, grid.ctri, Vf, F, out, i0, i1), rest.shape[0], 4096, 4)
        rest = rest[out[rest] < 0.0]
    if rest.shape[0]:
        P = gather_rows(Q, rest)
        if rest.shape[0] > 4096:
            o = cell_order(P)
            P = gather_rows(P, o)
            rest = rest[o]
        w = np.empty(rest.shape[0])
        walk(P, w)
        out[rest] = (w > 0.5).astype(np.float64)


@njit(cache=True, nogil=True)
def _cross_range(Q, rest, g0, s, dims, value, outside, cstart, ctri, V, F, out, i0, i1):
    for r in range(i0, i1):
        q = rest[r]
        for step in (-1, 1):
            w = _crossings(Q[q, 0], Q[q, 1], Q[q, 2], step, g0, s, dims, value, outside, cstart, ctri, V, F)
            if w != -99:
                out[q] = 1.0 if w > 0 else 0.0
                break


@njit(cache=True, nogil=True)
def _lookup(Q, g0, s, dims, value, outside, out, i0, i1):
    inv = 1.0 / s
    nx, ny, nz = dims[0], dims[1], dims[2]
    for q in range(i0, i1):
        fi = (Q[q, 0] - g0[0]) * inv
        fj = (Q[q, 1] - g0[1]) * inv
        fk = (Q[q, 2] - g0[2]) * inv
        if fi < 0.0 or fj < 0.0 or fk < 0.0 or fi >= nx or fj >= ny or fk >= nz:
            out[q] = outside if outside >= 0 else -1.0
            continue
        v = value[(int(fi) * ny + int(fj)) * nz + int(fk)]
        out[q] = v if v >= 0 else -1.0
