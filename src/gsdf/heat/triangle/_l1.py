"""Piecewise-continuous integration of the signed heat field by an L1 linear program (Feng & Crane 2024, §7.2).

When the curves do not bound a region (or are inconsistently oriented) the unit field Y of step II need not be a
gradient. Instead of the L2 Poisson fit, integrate Y exactly inside every face and allow jumps across edges,
minimizing their weighted L1 norm (Eq. 16) with weights ``|ij| exp(-|curl Y|_ij)`` (Eq. 15).

Reduction to |F| unknowns (as the paper does, following Feng et al. 2023 §3.4): inside face f the function is
``φ_f(x) = c_f + Y_f · (x - x_f)`` (x_f its first corner), so only the offsets c_f are free; the jump across an
interior edge ij between faces f and g is measured at the edge midpoint m,
``J_ij = c_f - c_g + Y_f·(m - x_f) - Y_g·(m - x_g)``, and ``min Σ w_ij |J_ij|`` is the linear program
``min Σ w (s⁺ + s⁻)  s.t.  c_f - c_g - s⁺ + s⁻ = -(Y_f·(m - x_f) - Y_g·(m - x_g)),  s± ≥ 0``, solved by HiGHS
through the dual-graph LP of :mod:`gsdf.linalg._dual_l1`.
Nonmanifold edges contribute every pair of their faces (consecutive in face order).
"""

from __future__ import annotations

import numpy as np

from gsdf.linalg._dual_l1 import dual_graph_l1


def edge_face_pairs(ops):
    """Pairs (edge, face f, slot in f, face g, slot in g) of faces sharing an edge (consecutive pairs)."""
    fe = ops.face_edges.ravel()
    order = np.argsort(fe, kind="stable")
    e_sorted = fe[order]
    same = e_sorted[1:] == e_sorted[:-1]
    a, b = order[:-1][same], order[1:][same]
    return e_sorted[1:][same], a // 3, a % 3, b // 3, b % 3


def integrate_l1(ops, Y: np.ndarray) -> np.ndarray:
    """Corner values (m, 3) of the piecewise-linear function that integrates the face field ``Y`` (m, 3) exactly
    per face and has the least weighted L1 jump across edges (Eqs. 15–16). Defined up to one constant per
    connected piece of the jump-free region; HiGHS picks one."""
    V, F = ops.V, ops.F
    m = len(F)
    e, f, a, g, b = edge_face_pairs(ops)
    base = V[F[:, 0]]
    i, j = ops.edges[e, 0], ops.edges[e, 1]
    mid = 0.5 * (V[i] + V[j])
    t = (V[j] - V[i]) / ops.edge_len[e][:, None]
    off = np.einsum("kj,kj->k", Y[f], mid - base[f]) - np.einsum("kj,kj->k", Y[g], mid - base[g])
    curl = np.abs(np.einsum("kj,kj->k", Y[f] - Y[g], t))    # Eq. 15: difference of projections on the edge
    w = ops.edge_len[e] * np.exp(-curl)
    if len(e) == 0:
        c = np.zeros(m)
    else:
        c = dual_graph_l1(m, np.stack([f, g], axis=1), off, w, gauge="none").shifts
    return c[:, None] + np.einsum("fkj,fj->fk", V[F] - base[:, None, :], Y)
