"""Inside / outside (winding number > 1/2) of many query points of a closed oriented triangle mesh, settled
per grid cell and by signed crossing counts; the tree walk of :class:`gsdf.FastWindingNumber` only where
those cannot decide.

A mesh whose boundary chain is empty (every directed edge (a, b) used as often as (b, a): closed and
oriented, also with several, nested or intersecting components) has an integer generalized winding number
(Barill et al. 2018, §2, Eq. 2: w(q) = Σ Ω_t(q)/4π) that is constant on every connected region free of
triangles, 0 on the unbounded one, and changes by −sign(n · d) where a path in direction d crosses a face of
area normal n. So:

- the grid cells that no triangle touches (conservatively: the cells of a triangle's box that its plane
  reaches, every cell grown by a relative 1e-9) are grouped into 6-connected components (the union of two
  face-adjacent free cells is a free box); the component of the grid's corner is outside (w = 0), every other
  one takes the signed crossing count from a few of its cell centres along −x to the grid's border (the fast
  winding number at those centres if no count is clean);
- a query in a free cell takes its component's value; a query in a cell touched by triangles counts the
  signed crossings of the segment along −x (else +x) to the first settled cell, testing the triangles listed
  in the cells it passes (each crossing counted once, in the cell that owns its x);
- a crossing too close to an edge of a face (in the projection along x, relative 1e-12) or to the query
  (1e-9 of a cell) is not decided: those queries, and queries of a component whose samples disagree, get
  the tree walk (``FastWindingNumber(V, F)(Q) > 0.5``).

Meshes with a boundary (holes, soups) are left to the tree walk: w is not constant off their surface.

The answer is the exact winding number rounded (an integer here) everywhere the counts decide; measured equal
to ``FastWindingNumber(V, F)(Q) > 0.5`` at every query on the closed CGAL meshes.

Cost: O(m) to list the triangles per cell, O(cells) to label the free cells; O(1) per query in a free cell,
the triangles of ~1.5 cells per query in a cell touched by triangles.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gsdf.spatial._morton import cell_order, gather_rows
from gsdf.threads import run_ranges

#: Cells per query point of the grid (labelling costs ~10 ns per cell; the queries in cells touched by
#: triangles, which count crossings, are ~4 % at one cell per query on the CGAL meshes).
CELLS_PER_QUERY = 1.0
#: Sample cells per component of free cells whose crossing counts must agree.
SAMPLES = 8
#: Cell value of a cell not settled (and the crossing count's "undecided").
UNKNOWN = -(2 ** 31)


def is_closed(F, n_vertices) -> bool:
    """True when the boundary chain of the faces F is empty: every directed edge (a, b) is used as often as
    (b, a) (edges with a = b do not count)."""
    return bool(_closed(np.ascontiguousarray(F, dtype=np.int64), int(n_vertices)))


@njit(cache=True)
def _closed(F, nv):
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
    other = np.empty(cnt[nv], np.int64)  # per smaller end: the larger end, + for a < b, − (as ~b) for a > b
    for t in range(m):
        for j in range(3):
            a, b = F[t, j], F[t, (j + 1) % 3]
            if a != b:
                lo = min(a, b)
                other[pos[lo]] = b if a < b else ~a
                pos[lo] += 1
    for v in range(nv):
        s, e = cnt[v], cnt[v + 1]
        for i in range(s, e):
            x = other[i]
            if x == np.iinfo(np.int64).min:  # already paired
                continue
            u = x if x >= 0 else ~x
            net = 1 if x >= 0 else -1
            for j in range(i + 1, e):
                y = other[j]
                if y != np.iinfo(np.int64).min and (y if y >= 0 else ~y) == u:
                    net += 1 if y >= 0 else -1
                    other[j] = np.iinfo(np.int64).min
            if net != 0:
                return False
    return True


class CellGrid:
    """Per cell of a cubic-celled grid over the mesh's box: its winding number (an integer) or :data:`UNKNOWN`
    (touched by triangles, or not settled), and the triangles that may touch each cell (CSR:
    ``ctri[cstart[c]:cstart[c + 1]]``)."""

    def __init__(self, lo, size, dims, value, cstart, ctri):
        self.lo, self.size, self.dims, self.value, self.cstart, self.ctri = lo, size, dims, value, cstart, ctri
        self.inside = None  # int8 per cell: 1 / 0 / −1 (not settled), for the lookups (a quarter of the memory)


def build_grid(Vf, F, n_cells, evaluate):
    """The :class:`CellGrid` of the closed oriented mesh (Vf, F) with about ``n_cells`` cells over its box
    (and a free layer of cells around it); ``evaluate(P)`` returns the winding numbers at points P (m, 3),
    used only for components whose samples have no clean crossing count."""
    lo, hi = _box(Vf, F)
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
    np.cumsum(cstart, out=cstart)
    ctri = np.empty(cstart[-1], np.int64)
    _mark(Vf, F, g0, s, dims, eps, cstart[:-1].copy(), ctri, True)
    value = np.full(ncell, UNKNOWN, np.int32)
    grid = CellGrid(g0, s, dims, value, cstart, ctri)
    label, queue, starts = _label(occ, dims)
    ncomp = starts.shape[0] - 1
    val = np.full(ncomp, UNKNOWN, np.int32)
    val[label[0]] = 0  # the component of the grid's corner is outside the mesh's box: w = 0
    pick = _samples(queue, starts, SAMPLES)
    _assign(label, val, value)
    _component_crossings(grid, Vf, F, pick, starts, SAMPLES, val)
    if (val == UNKNOWN).any():  # samples without a clean crossing count: the fast winding number
        w = evaluate(_centres(pick, g0, s, dims))
        val = np.where(val == UNKNOWN, _component_values(w, pick, starts, SAMPLES), val).astype(np.int32)
    _assign(label, val, value)
    grid.inside = np.where(value == UNKNOWN, -1, value > 0).astype(np.int8)
    return grid


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
def _crossings(px, py, pz, step, g0, s, dims, value, cstart, ctri, V, F):
    """Winding number at p of a mesh without boundary, by counting the signed crossings of the segment from p
    along ``step`` · x (±1) to the first cell with a known value (or out of the grid): crossing a face with
    area normal n changes w by −sign(n · direction) (w of a closed oriented surface counts how often it winds
    around p). Each crossing is counted in the cell that owns its x (the floor of the point lookup), so a
    triangle listed in several cells counts once. Returns :data:`UNKNOWN` when a crossing is too close to an
    edge of a face (in the projection along x) or to p to be decided."""
    nx, ny, nz = dims[0], dims[1], dims[2]
    inv = 1.0 / s
    fi = (px - g0[0]) * inv
    fj = (py - g0[1]) * inv
    fk = (pz - g0[2]) * inv
    if fj < 0.0 or fk < 0.0 or fj >= ny or fk >= nz:
        return 0
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
            return acc
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
                    return UNKNOWN
                xh = ax_ + (n1 * ay + n2 * az) / n0  # plane n·(x − a) = 0 on the line through p along x
                if abs(xh - px) <= tolx:
                    return UNKNOWN
                if (xh - px) * step < 0.0:
                    continue
                fh = (xh - g0[0]) * inv
                ih = -1 if fh < 0.0 else (nx if fh >= nx else int(fh))
                if ih != i:
                    continue
                acc += 1 if n0 * step > 0.0 else -1
            elif not ((e0 > t0 or e1 > t1 or e2 > t2) and (e0 < -t0 or e1 < -t1 or e2 < -t2)):
                return UNKNOWN  # neither clearly inside nor clearly outside the projected face
        i += step
        if 0 <= i < nx:
            v = value[(i * ny + j) * nz + k]
            if v != UNKNOWN:
                return v + acc


def _component_crossings(grid, Vf, F, pick, starts, k, val):
    """val[c] = the winding number of the components whose sample cells all get the same clean crossing
    count."""
    nc = starts.shape[0] - 1
    C = _centres(pick, grid.lo, grid.size, grid.dims)
    for c in range(nc):
        if val[c] != UNKNOWN:
            continue
        got = UNKNOWN
        for j in range(k):
            if pick[c * k + j] < 0:
                break
            w = _crossings(C[c * k + j, 0], C[c * k + j, 1], C[c * k + j, 2], -1, grid.lo, grid.size, grid.dims,
                           grid.value, grid.cstart, grid.ctri, Vf, F)
            if w == UNKNOWN:
                continue
            if got != UNKNOWN and w != got:
                got = UNKNOWN
                break
            got = w
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
    """The winding number of a component whose samples all round to the same integer (within 1/4), else
    :data:`UNKNOWN`."""
    nc = starts.shape[0] - 1
    W = w.reshape(nc, k)
    valid = pick.reshape(nc, k) >= 0
    R = np.round(W)
    good = np.where(valid, np.abs(W - R) < 0.25, True).all(axis=1)
    first = R[:, 0]
    same = np.where(valid, R == first[:, None], True).all(axis=1)
    return np.where(good & same, first, UNKNOWN).astype(np.int32)


@njit(cache=True)
def _assign(label, val, value):
    for c in range(label.shape[0]):
        if label[c] >= 0:
            value[c] = val[label[c]]


def classify(grid, Q, out, walk, Vf, F):
    """out[i] = 1.0 / 0.0 for the queries Q (frame coordinates) inside / outside: the cell's value, else the
    crossing count of :func:`_crossings` along −x, else +x; the rest go to ``walk(P, w)`` (winding numbers w
    at points P), grouped by cells."""
    n = Q.shape[0]
    run_ranges(lambda i0, i1: _lookup(Q, grid.lo, grid.size, grid.dims, grid.inside, out, i0, i1), n, 16384, 1)
    rest = np.flatnonzero(out < 0.0)
    if rest.shape[0]:
        rest = rest[np.argsort(_cell_of(Q, rest, grid.lo, grid.size, grid.dims), kind="stable")]  # cell by cell
        run_ranges(lambda i0, i1: _cross_range(Q, rest, grid.lo, grid.size, grid.dims, grid.value, grid.cstart,
                                               grid.ctri, Vf, F, out, i0, i1), rest.shape[0], 4096, 4)
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


@njit(cache=True)
def _cell_of(Q, rows, g0, s, dims):
    """Cell index of the queries Q[rows] (clamped to the grid: only an order)."""
    out = np.empty(rows.shape[0], np.int64)
    inv = 1.0 / s
    for r in range(rows.shape[0]):
        q = rows[r]
        i = min(max(int((Q[q, 0] - g0[0]) * inv), 0), dims[0] - 1)
        j = min(max(int((Q[q, 1] - g0[1]) * inv), 0), dims[1] - 1)
        k = min(max(int((Q[q, 2] - g0[2]) * inv), 0), dims[2] - 1)
        out[r] = (i * dims[1] + j) * dims[2] + k
    return out


@njit(cache=True, nogil=True)
def _cross_range(Q, rest, g0, s, dims, value, cstart, ctri, V, F, out, i0, i1):
    for r in range(i0, i1):
        q = rest[r]
        for step in (-1, 1):
            w = _crossings(Q[q, 0], Q[q, 1], Q[q, 2], step, g0, s, dims, value, cstart, ctri, V, F)
            if w != UNKNOWN:
                out[q] = 1.0 if w > 0 else 0.0
                break


@njit(cache=True, nogil=True)
def _lookup(Q, g0, s, dims, inside, out, i0, i1):
    """out[q] = the value of q's cell (0 beyond the grid, outside the mesh's box), −1.0 when not settled."""
    inv = 1.0 / s
    nx, ny, nz = dims[0], dims[1], dims[2]
    for q in range(i0, i1):
        fi = (Q[q, 0] - g0[0]) * inv
        fj = (Q[q, 1] - g0[1]) * inv
        fk = (Q[q, 2] - g0[2]) * inv
        if fi < 0.0 or fj < 0.0 or fk < 0.0 or fi >= nx or fj >= ny or fk >= nz:
            out[q] = 0.0
            continue
        out[q] = inside[(int(fi) * ny + int(fj)) * nz + int(fk)]
