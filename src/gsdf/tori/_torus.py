"""Torus geometry of Points as Tori (thesis ch. 5, §5.1.1, Eqs. 5.2–5.4).

Each point p_i with unit normal n_i carries a local frame (s_i, t_i, n_i) and a quadratic height field
(Eq. 5.2)

    Q_i*(s, t) = p_i + s s_i + t t_i + Q_i(s, t) n_i,   Q_i = a00 + a10 s + a01 t + a20 s² + a11 s t + a02 t².

Monge patch at (0, 0) (standard; Feng et al. 2026 App. C): tangents X_s = (1, 0, a10), X_t = (0, 1, a01),
normal n* = (−a10, −a01, 1)/W with W = sqrt(1 + a10² + a01²); first fundamental form
I = [[1 + a10², a10 a01], [a10 a01, 1 + a01²]], second II = [[2 a20, a11], [a11, 2 a02]] / W. The principal
curvatures κ solve det(II − κ I) = 0, the principal directions are the matching eigenvectors pushed forward
by (X_s, X_t).

We use *convex-positive* curvatures c = −κ (a sphere of radius ρ with outward normals has c = +1/ρ). Let
c_max be the principal curvature of larger magnitude, k1 = |c_max| ≥ k2 = |c_min|, s = sign(c_max) and
e = sign(c_max c_min) (e = +1: same signs, e = −1: saddle). The torus (Fig. 5.4) has

* tube (minor) radius r = 1/k1 and axis u = principal direction of c_max (at an equator point the meridian
  circle runs along the axis);
* the shifted point p* = p_i + a00 n_i on its *outer* equator (e = +1, then R + r = 1/k2) or *inner* equator
  (e = −1, saddle, then R − r = 1/k2), i.e. ring (major) radius R = 1/k2 − e r;
* tube centre m = p* − s r n*, torus centre c = m − s e R n*;
* sign(T_i) = s: the tube lies on the side towards which the surface bends most (Fig. 5.4, right), so the
  local SDF is g_i = s φ_T (Eq. 5.4) with φ_T(x) = ‖(‖(x−c)×u‖ − R, ⟨x−c, u⟩)‖ − r (Eq. 5.3).

Limits without overflow. Write z = x − p*, (z_n, z_u, z_b) its coordinates along n*, u and b = u × n*, and
t_w = r + s z_n. Then the radial term q = ‖(x−c)×u‖ − R is

    q = sqrt((e t_w + R)² + z_b²) − R                                                  (R ≤ 4 r)
    q = (2 e t_w + κ (t_w² + z_b²)) / (1 + sqrt((1 + e κ t_w)² + (κ z_b)²)),  κ = 1/R   (R > 4 r)

(the two are algebraically equal; the second form is finite for κ → 0, the *cylindrical* limit c_min → 0,
where it tends to q = e t_w, the SDF of a cylinder of radius r). When k1 ≤ k_floor (both curvatures
vanish: the *planar* limit) g = ⟨x − p*, n*⟩ exactly; below k_floor the torus and plane differ by
O(k_floor ‖z‖²), and above it the tube radius 1/k1 stays bounded so φ_T = ‖(q, z_u)‖ − r loses at most
ε/k_floor to rounding.

Gradients are analytic: ∇q = ((e t_w + R) s e n* + z_b b)/ρ (resp. ((1 + e κ t_w) s e n* + κ z_b b)/S),
∇g = s (q ∇q + z_u u)/‖(q, z_u)‖.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# column layout of a fitted torus row
T_P, T_N, T_U, T_K1, T_K2, T_S, T_E = 0, 3, 6, 9, 10, 11, 12
TORUS_WIDTH = 13

__all__ = ["local_frames", "coefficients_to_tori", "torus_sdf", "torus_eval", "TORUS_WIDTH"]


def local_frames(N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal tangents (s_i, t_i) completing unit normals n_i to a right-handed frame (Eq. 5.2).

    Uses the branch-free construction of Duff et al. (2017), continuous except at n_z = −1 (handled).

    Examples
    --------
    >>> import numpy as np
    >>> S, T = local_frames(np.array([[0.0, 0.0, 1.0]]))
    >>> (S.round(3) + 0.0).tolist(), (T.round(3) + 0.0).tolist()
    ([[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    """
    N = np.asarray(N, dtype=np.float64)
    x, y, z = N[:, 0], N[:, 1], N[:, 2]
    sgn = np.where(z >= 0, 1.0, -1.0)
    a = -1.0 / (sgn + z)
    b = x * y * a
    S = np.column_stack([1.0 + sgn * x * x * a, sgn * b, -sgn * x])
    T = np.column_stack([b, sgn + y * y * a, -y])
    return S, T


@njit(cache=True, inline="always")
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True)
def _coeffs_to_torus(p, n, sv, tv, a, k_floor, k_cap, out):
    """One torus from six coefficients a = (a00, a10, a01, a20, a11, a02) in the frame (sv, tv, n)."""
    a00, a10, a01, a20, a11, a02 = a[0], a[1], a[2], a[3], a[4], a[5]
    W = np.sqrt(1.0 + a10 * a10 + a01 * a01)
    # Monge patch normal n* in world coordinates
    nl0, nl1, nl2 = -a10 / W, -a01 / W, 1.0 / W
    ns0 = nl0 * sv[0] + nl1 * tv[0] + nl2 * n[0]
    ns1 = nl0 * sv[1] + nl1 * tv[1] + nl2 * n[1]
    ns2 = nl0 * sv[2] + nl1 * tv[2] + nl2 * n[2]
    E, F, G = 1.0 + a10 * a10, a10 * a01, 1.0 + a01 * a01
    L, M, Nn = 2.0 * a20 / W, a11 / W, 2.0 * a02 / W
    detI = E * G - F * F
    H = (E * Nn - 2.0 * F * M + G * L) / (2.0 * detI)  # mean curvature (w.r.t. n*)
    K = (L * Nn - M * M) / detI  # Gaussian curvature
    disc = np.sqrt(max(H * H - K, 0.0))
    ka, kb = H + disc, H - disc  # normal curvatures κ; convex-positive c = −κ
    if abs(ka) >= abs(kb):
        kmax, kmin = ka, kb
    else:
        kmax, kmin = kb, ka
    # principal direction of kmax: (II − κ I) v = 0
    v0a, v1a = M - kmax * F, -(L - kmax * E)
    v0b, v1b = Nn - kmax * G, -(M - kmax * F)
    if v0a * v0a + v1a * v1a >= v0b * v0b + v1b * v1b:
        v0, v1 = v0a, v1a
    else:
        v0, v1 = v0b, v1b
    if v0 * v0 + v1 * v1 < 1e-24 * (1.0 + L * L + M * M + Nn * Nn):
        v0, v1 = 1.0, 0.0  # umbilic: any tangent direction is principal
    # push forward: v0 X_s + v1 X_t with X_s = (1, 0, a10), X_t = (0, 1, a01) in the local frame
    l0, l1, l2 = v0, v1, v0 * a10 + v1 * a01
    u0 = l0 * sv[0] + l1 * tv[0] + l2 * n[0]
    u1 = l0 * sv[1] + l1 * tv[1] + l2 * n[1]
    u2 = l0 * sv[2] + l1 * tv[2] + l2 * n[2]
    d = u0 * ns0 + u1 * ns1 + u2 * ns2  # remove rounding drift off the tangent plane
    u0, u1, u2 = u0 - d * ns0, u1 - d * ns1, u2 - d * ns2
    un = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    u0, u1, u2 = u0 / un, u1 / un, u2 / un
    cmax, cmin = -kmax, -kmin
    k1 = min(abs(cmax), k_cap)
    k2 = min(abs(cmin), k1)
    out[0] = p[0] + a00 * n[0]
    out[1] = p[1] + a00 * n[1]
    out[2] = p[2] + a00 * n[2]
    out[3], out[4], out[5] = ns0, ns1, ns2
    out[6], out[7], out[8] = u0, u1, u2
    out[9] = k1 if k1 > k_floor else 0.0
    out[10] = k2 if k1 > k_floor else 0.0
    out[11] = 1.0 if cmax >= 0.0 else -1.0
    out[12] = 1.0 if cmax * cmin >= 0.0 else -1.0


@njit(parallel=True, cache=True)
def _coeffs_to_tori(P, N, S, T, A, k_floor, k_cap, out):
    for i in prange(P.shape[0]):
        _coeffs_to_torus(P[i], N[i], S[i], T[i], A[i], k_floor, k_cap, out[i])


def coefficients_to_tori(P, N, A, k_floor: float = 0.0, k_cap: float = np.inf) -> np.ndarray:
    """Fit one torus per point from its six height-field coefficients (§5.1.1, Eqs. 5.2–5.4).

    Parameters
    ----------
    P, N : (n, 3) float
        Points and unit normals (the frame of Eq. 5.2 is ``local_frames(N)``).
    A : (n, 6) float
        Coefficients (a00, a10, a01, a20, a11, a02) of Q_i(s, t).
    k_floor : float
        Curvature magnitude below which a point is treated as planar (g = ⟨x − p*, n*⟩).
    k_cap : float
        Largest allowed curvature magnitude (smallest tube radius 1/k_cap).

    Returns
    -------
    (n, 13) float64
        Rows (p*, n*, u, k1, k2, s, e): shifted point, Monge normal, torus axis, |c_max|, |c_min| (0 when
        planar), sign(c_max), sign(c_max c_min); see the module notes.

    Examples
    --------
    >>> import numpy as np
    >>> T = coefficients_to_tori([[0, 0, 1.0]], [[0, 0, 1.0]], [[0, 0, 0, -0.5, 0, -0.5]])  # unit sphere
    >>> float(torus_sdf(T, np.array([[0, 0, 2.0]]))[0])
    1.0
    """
    P = np.ascontiguousarray(P, dtype=np.float64)
    N = np.ascontiguousarray(N, dtype=np.float64)
    A = np.ascontiguousarray(A, dtype=np.float64)
    N = N / np.linalg.norm(N, axis=1, keepdims=True)
    S, T = local_frames(N)
    out = np.empty((P.shape[0], TORUS_WIDTH))
    _coeffs_to_tori(P, N, np.ascontiguousarray(S), np.ascontiguousarray(T), A, float(k_floor), float(k_cap), out)
    return out


@njit(cache=True, inline="always")
def torus_eval(T, i, x0, x1, x2):
    """Signed torus distance g_i(x) (Eq. 5.4) and its gradient; returns (g, gx, gy, gz)."""
    z0, z1, z2 = x0 - T[i, 0], x1 - T[i, 1], x2 - T[i, 2]
    n0, n1, n2 = T[i, 3], T[i, 4], T[i, 5]
    zn = z0 * n0 + z1 * n1 + z2 * n2
    k1 = T[i, 9]
    if k1 <= 0.0:  # planar limit
        return zn, n0, n1, n2
    u0, u1, u2 = T[i, 6], T[i, 7], T[i, 8]
    b0, b1, b2 = _cross(u0, u1, u2, n0, n1, n2)
    zu = z0 * u0 + z1 * u1 + z2 * u2
    zb = z0 * b0 + z1 * b1 + z2 * b2
    k2, s, e = T[i, 10], T[i, 11], T[i, 12]
    r = 1.0 / k1
    tw = r + s * zn
    se = s * e
    if k1 <= (4.0 + e) * k2:  # R <= 4 r: direct form
        R = (k1 - e * k2) / (k1 * k2)
        a = e * tw + R
        rho = np.sqrt(a * a + zb * zb)
        q = rho - R
        if rho > 0.0:
            gn, gb = a * se / rho, zb / rho
        else:
            gn, gb = se, 0.0
    else:  # cylindrical side, κ = 1/R -> 0 without overflow
        kap = k1 * k2 / (k1 - e * k2)
        a = 1.0 + e * kap * tw
        S = np.sqrt(a * a + kap * kap * zb * zb)
        q = (2.0 * e * tw + kap * (tw * tw + zb * zb)) / (1.0 + S)
        gn, gb = a * se / S, kap * zb / S
    Aq = np.sqrt(q * q + zu * zu)
    g = s * (Aq - r)
    if Aq > 0.0:
        c_n, c_u = s * q / Aq, s * zu / Aq
    else:
        c_n, c_u = 0.0, 0.0
    gx = c_n * (gn * n0 + gb * b0) + c_u * u0
    gy = c_n * (gn * n1 + gb * b1) + c_u * u1
    gz = c_n * (gn * n2 + gb * b2) + c_u * u2
    return g, gx, gy, gz


@njit(parallel=True, cache=True)
def _torus_sdf_kernel(T, idx, X, out, grad):
    for j in prange(X.shape[0]):
        g, gx, gy, gz = torus_eval(T, idx[j], X[j, 0], X[j, 1], X[j, 2])
        out[j] = g
        grad[j, 0], grad[j, 1], grad[j, 2] = gx, gy, gz


def torus_sdf(T, X, index=None, return_gradient: bool = False):
    """Evaluate the signed torus distance g_i (Eq. 5.4) of torus ``index[j]`` at ``X[j]``.

    Parameters
    ----------
    T : (n, 13) float
        Tori from :func:`coefficients_to_tori`.
    X : (q, 3) float
        Evaluation points.
    index : (q,) int, optional
        Torus of each point (default: torus 0 for all).
    return_gradient : bool
        Also return the analytic gradient (q, 3).

    Examples
    --------
    >>> import numpy as np
    >>> T = coefficients_to_tori([[0, 0, 0.0]], [[0, 0, 1.0]], [[0, 0, 0, 0, 0, 0]])  # a plane
    >>> torus_sdf(T, np.array([[3.0, 4.0, -0.5]])).tolist()
    [-0.5]
    """
    T = np.ascontiguousarray(T, dtype=np.float64)
    X = np.ascontiguousarray(X, dtype=np.float64).reshape(-1, 3)
    idx = np.zeros(len(X), np.int64) if index is None else np.ascontiguousarray(index, dtype=np.int64)
    out, grad = np.empty(len(X)), np.empty((len(X), 3))
    _torus_sdf_kernel(T, idx, X, out, grad)
    return (out, grad) if return_gradient else out
