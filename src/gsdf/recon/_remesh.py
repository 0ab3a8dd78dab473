"""Edge flips that make a closed triangle mesh follow the local surface of its samples (connectivity only).

The guarantee layer (:mod:`gsdf.recon._grow`) outputs the boundary of a tet region: its edges are Delaunay edges of the
samples and Steiner points, chosen for the topology, not for the fit — a face may cut across a bend of the
sampled surface although a flip of one of its edges would follow it.  This pass flips the edge (a, b) of the
faces (a, b, c), (b, a, d) into (c, d) when the two new faces lie closer to the samples' surface: the error
of a face is its area × the mean offset of its centroid and edge midpoints from the moving-least-squares
quadric (:func:`gsdf.recon._relocate.local_surface`'s fit, with ``k`` samples) of the sample nearest to each point.

The topology is kept by construction: a flip is taken only when (c, d) is not already an edge, so a closed,
edge-manifold, oriented mesh stays one, with the same vertices, edge and face counts — hence the same Euler
characteristic and components — and both new faces must keep the orientation of the pair.  Vertices never
move.  Greedy sweeps over the faces run in one numba kernel over vertex → face incidence lists; after the
first sweep only edges next to a flipped face are looked at again.

Example
-------
>>> import numpy as np
>>> from gsdf.recon._remesh import flip_to_samples
>>> V = np.array([[0, 0, 0.5], [1, 0, 0], [1, 1, 0.5], [0, 1, 0], [0.5, 0.5, -1.0]])   # a square on a ridge
>>> F = np.array([[0, 1, 3], [1, 2, 3], [0, 4, 1], [1, 4, 2], [2, 4, 3], [3, 4, 0]])   # + a cone below
>>> g = np.linspace(0, 1, 21)
>>> S = np.array([[x, y, 0.5 * (1 - (x - y) ** 2)] for x in g for y in g])             # ridge along x = y
>>> F2 = flip_to_samples(V, F, S, spacing=0.05)
>>> sorted(map(sorted, F2[:2].tolist()))             # the diagonal (1, 3) cut the ridge; (0, 2) follows it
[[0, 1, 2], [0, 2, 3]]
"""

from __future__ import annotations

import numba as nb
import numpy as np
from scipy.spatial import cKDTree

from gsdf._checks import as_faces, as_points, integer, nonnegative, positive
from gsdf.mesh._connectivity import MeshTopology

__all__ = ["flip_to_samples"]


@nb.njit(cache=True)
def _normal(V, i, j, k):
    a, b = V[j] - V[i], V[k] - V[i]
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@nb.njit(cache=True)
def _drop(vf, off, deg, v, f):
    """Remove face f from vertex v's incidence list (its faces are vf[off[v] : off[v] + deg[v]])."""
    o = off[v]
    for t in range(deg[v]):
        if vf[o + t] == f:
            deg[v] -= 1
            vf[o + t] = vf[o + deg[v]]
            return


@nb.njit(cache=True)
def _has_edge(F, vf, off, deg, a, b):
    for t in range(deg[a]):
        f = vf[off[a] + t]
        if F[f, 0] == b or F[f, 1] == b or F[f, 2] == b:
            return True
    return False


@nb.njit(cache=True)
def _point_error(px, py, pz, S, cen, frame, h, coef, near, i, j, k):
    """|offset| of point p from the quadric fitted around the sample nearest to p among the nearest samples
    of vertices i, j, k (frame rows t1, t2, n; the fit of :func:`gsdf.recon._relocate.local_surface`)."""
    best, bd = -1, 1e300
    for v in (i, j, k):
        q = near[v]
        d = (px - S[q, 0]) ** 2 + (py - S[q, 1]) ** 2 + (pz - S[q, 2]) ** 2
        if d < bd:
            bd, best = d, q
    rx, ry, rz = px - cen[best, 0], py - cen[best, 1], pz - cen[best, 2]
    fr = frame[best]
    x = (rx * fr[0, 0] + ry * fr[0, 1] + rz * fr[0, 2]) / h[best]
    y = (rx * fr[1, 0] + ry * fr[1, 1] + rz * fr[1, 2]) / h[best]
    z = rx * fr[2, 0] + ry * fr[2, 1] + rz * fr[2, 2]
    c = coef[best]
    return abs(z - (c[0] + c[1] * x + c[2] * y + c[3] * x * x + c[4] * x * y + c[5] * y * y))


@nb.njit(cache=True)
def _face_error(V, S, cen, frame, h, coef, near, i, j, k):
    """Area × mean fit height at the centroid and the three edge midpoints of triangle (i, j, k)."""
    ax, ay, az = V[j, 0] - V[i, 0], V[j, 1] - V[i, 1], V[j, 2] - V[i, 2]
    bx, by, bz = V[k, 0] - V[i, 0], V[k, 1] - V[i, 1], V[k, 2] - V[i, 2]
    area = 0.5 * np.sqrt((ay * bz - az * by) ** 2 + (az * bx - ax * bz) ** 2 + (ax * by - ay * bx) ** 2)
    e = 0.0
    for wi, wj, wk in ((1.0 / 3, 1.0 / 3, 1.0 / 3), (0.5, 0.5, 0.0), (0.0, 0.5, 0.5), (0.5, 0.0, 0.5)):
        e += _point_error(wi * V[i, 0] + wj * V[j, 0] + wk * V[k, 0], wi * V[i, 1] + wj * V[j, 1] + wk * V[k, 1],
                          wi * V[i, 2] + wj * V[j, 2] + wk * V[k, 2], S, cen, frame, h, coef, near, i, j, k)
    return 0.25 * area * e


@nb.njit(cache=True)
def _side(V, i, j, k, nx, ny, nz):
    """(normal of triangle i, j, k) · n."""
    ax, ay, az = V[j, 0] - V[i, 0], V[j, 1] - V[i, 1], V[j, 2] - V[i, 2]
    bx, by, bz = V[k, 0] - V[i, 0], V[k, 1] - V[i, 1], V[k, 2] - V[i, 2]
    return (ay * bz - az * by) * nx + (az * bx - ax * bz) * ny + (ax * by - ay * bx) * nz


@nb.njit(cache=True)
def _fit_flips(V, F, S, cen, frame, h, coef, near, slack, sweeps, margin):
    """Greedy flips in place on F; returns the number of flips.

    The flip (a, b) → (c, d) is taken when (c, d) is not an edge yet, both new faces keep the orientation of
    the pair (positive dot product with the pair's summed normal), and the summed face error
    (:func:`_face_error`) drops below (1 − ``margin``) × its value.  A vertex may gain at most ``slack`` faces
    over its starting count (its incidence list has that much room)."""
    nv, nf = V.shape[0], F.shape[0]
    deg = np.zeros(nv, np.int64)
    for f in range(nf):
        for c in range(3):
            deg[F[f, c]] += 1
    off = np.zeros(nv + 1, np.int64)       # vertex v's faces: vf[off[v] : off[v] + deg[v]]
    for v in range(nv):
        off[v + 1] = off[v] + deg[v] + slack
    vf = np.full(off[nv], -1, np.int64)
    deg[:] = 0
    for f in range(nf):
        for c in range(3):
            v = F[f, c]
            vf[off[v] + deg[v]] = f
            deg[v] += 1
    err = np.empty(nf)
    for f in range(nf):
        err[f] = _face_error(V, S, cen, frame, h, coef, near, F[f, 0], F[f, 1], F[f, 2])
    total = 0
    dirty = np.ones(nf, np.bool_)          # faces flipped in the previous sweep (all, at first)
    for _ in range(sweeps):
        changed = 0
        now = np.zeros(nf, np.bool_)
        for f1 in range(nf):
            for c in range(3):
                a, b, cc = F[f1, c], F[f1, (c + 1) % 3], F[f1, (c + 2) % 3]
                f2 = np.int64(-1)          # the other face on edge (a, b) traverses b → a
                d = np.int64(-1)           # (not literal -1s: each callee would compile once more for them)
                for t in range(deg[b]):
                    g = vf[off[b] + t]
                    for c2 in range(3):
                        if g != f1 and F[g, c2] == b and F[g, (c2 + 1) % 3] == a:
                            f2 = g
                            d = F[g, (c2 + 2) % 3]
                if f2 < f1 or not (dirty[f1] or dirty[f2]):
                    continue               # each edge once per sweep, and only next to a change
                if d == cc or deg[cc] >= off[cc + 1] - off[cc] or deg[d] >= off[d + 1] - off[d] \
                        or _has_edge(F, vf, off, deg, cc, d):
                    continue
                e1 = _face_error(V, S, cen, frame, h, coef, near, cc, a, d)
                e2 = _face_error(V, S, cen, frame, h, coef, near, d, b, cc)
                if e1 + e2 >= (1.0 - margin) * (err[f1] + err[f2]):
                    continue
                na = _normal(V, a, b, cc) + _normal(V, b, a, d)
                if _side(V, cc, a, d, na[0], na[1], na[2]) <= 0.0 or _side(V, d, b, cc, na[0], na[1], na[2]) <= 0.0:
                    continue
                F[f1, 0], F[f1, 1], F[f1, 2] = cc, a, d
                F[f2, 0], F[f2, 1], F[f2, 2] = d, b, cc
                err[f1], err[f2] = e1, e2
                _drop(vf, off, deg, a, f2)
                _drop(vf, off, deg, b, f1)
                vf[off[cc] + deg[cc]] = f2
                deg[cc] += 1
                vf[off[d] + deg[d]] = f1
                deg[d] += 1
                now[f1] = now[f2] = True
                changed += 1
                break                      # f1 has changed: its other edges wait for the next sweep
        dirty = now
        total += changed
        if changed == 0:
            break
    return total


def flip_to_samples(V, F, S, spacing: float, *, k: int = 8, sweeps: int = 10, margin: float = 0.0, tree=None,
                    check: bool = True, return_report: bool = False):
    """Flip edges of a closed mesh so that its faces follow the local surface of the samples ``S``.

    Parameters
    ----------
    V : (v, 3) float; F : (f, 3) int — a closed, edge-manifold, consistently oriented triangle mesh (every
        undirected edge in exactly two faces, traversed in opposite directions).
    S : (s, 3) float — samples of the surface (s ≥ 3); spacing : float > 0 — their typical spacing.
    k : int ≥ 3 — samples in each local quadric fit (clipped to s); sweeps : int ≥ 0 — greedy passes (stops
        early when one flips nothing); margin : float in [0, 1) — a flip must lower the error of its two faces
        by at least this fraction.
    tree : cKDTree of ``S`` or None (built here).  check : bool — verify that F is closed, edge-manifold and
        consistently oriented (False only for a mesh known to be one, say the 1-to-4 split of a checked one:
        the check is a fifth of the call on 80K faces).  return_report : bool — also return
        ``{"flipped": n, "error_before": e0, "error_after": e1}`` (summed face errors, see the module text).

    Returns
    -------
    F2 : (f, 3) int64 — the flipped faces (same count, same vertices; V is not changed).  (F2, report) with
    ``return_report``.

    Raises
    ------
    ValueError : bad shapes, NaN / inf, out-of-range faces, a mesh that is not closed, edge-manifold and
        consistently oriented, fewer than 3 samples, bad option values.
    """
    V = as_points(V, "V")
    F = as_faces(F, len(V), "F")
    S = as_points(S, "S")
    spacing = positive(spacing, "spacing")
    k = integer(k, "k", lo=3)
    sweeps = integer(sweeps, "sweeps", lo=0)
    margin = nonnegative(margin, "margin")
    if margin >= 1.0:
        raise ValueError(f"margin: must be in [0, 1) (a flip must lower its faces' error by this fraction), "
                         f"got {margin!r}")
    if len(S) < 3:
        raise ValueError(f"S: needs at least 3 samples for a local surface, got {len(S)}")
    F = F.astype(np.int64, copy=True)
    if check and len(F):
        if (F[:, 0] == F[:, 1]).any() or (F[:, 1] == F[:, 2]).any() or (F[:, 2] == F[:, 0]).any():
            raise ValueError("F: expected a closed, edge-manifold, consistently oriented mesh; some faces repeat "
                             "a vertex")
        topo = MeshTopology(F, len(V))
        if not topo.is_closed:
            raise ValueError(f"F: expected a closed mesh, got {int(topo.boundary_edges.sum())} boundary edges")
        if len(topo.nonmanifold_edges):
            e = int(topo.nonmanifold_edges[0])
            raise ValueError(f"F: expected an edge-manifold mesh: edge {tuple(topo.edges[e].tolist())} has "
                             f"{int(topo.edge_face_count[e])} faces")
        topo.require_oriented("F")
    from gsdf.recon._relocate import _fit_quadrics
    if tree is None:
        tree = cKDTree(S)
    elif not isinstance(tree, cKDTree) or tree.n != len(S) or tree.m != 3:
        raise ValueError(f"tree: expected a cKDTree of the {len(S)} samples S, got "
                         f"{type(tree).__name__} of {getattr(tree, 'n', '?')} points")
    cen, frame, h, coef, _ = _fit_quadrics(S, S, spacing, int(min(k, len(S))), 0, tree)
    near = tree.query(V)[1].astype(np.int64)
    frame = np.ascontiguousarray(frame)
    report = {}
    if return_report:
        report["error_before"] = _total_error(V, F, S, cen, frame, h, coef, near)
    n = _fit_flips(V, F, S, cen, frame, h, coef, near, 16, sweeps, margin) if len(F) else 0
    if not return_report:
        return F
    report.update(flipped=int(n), error_after=_total_error(V, F, S, cen, frame, h, coef, near))
    return F, report


@nb.njit(cache=True)
def _total_error(V, F, S, cen, frame, h, coef, near):
    e = 0.0
    for f in range(F.shape[0]):
        e += _face_error(V, S, cen, frame, h, coef, near, F[f, 0], F[f, 1], F[f, 2])
    return e
