"""Step 1 of the grid signed heat method: the Yukawa potential of vector sources, summed with a tree.

Feng & Crane 2024, §8.2: on a grid the short-time heat flow is not solved for; the diffused field at a node x
is the convolution of the source with the fundamental solution of ``id − tΔ``, the Yukawa potential
``G_t(x, y) = e^{−λ|x−y|} / (4π|x−y|)`` with ``λ = 1/√t``, by midpoint quadrature at the source points b_f:

    X(x) = Σ_f |f| N_f G_t(x, b_f).

(The seed prints G_t with a minus sign; we use the positive kernel so that X points along the source normals,
i.e. along ∇φ with φ negative inside — only the direction of X is used, Step II.) The seed notes the sum "could
be accelerated via the method of Barnes and Hut"; this module does that with the flat preorder BVH of
:mod:`gsdf.spatial._bvh`:

* every tree node stores moments of its vector charges ``w_f = |f| N_f`` about its centre c:
  ``S0 = Σ w``, ``S1 = Σ δ ⊗ w``, ``S2 = Σ δδᵀ ⊗ w`` (6 symmetric entries per component), ``T = Σ |δ|² w``,
  ``δ = b_f − c``; and its radius ρ = max |δ|;
* a node is used as a cluster when its second-order Taylor expansion in δ is accurate *relative to what
  matters*: with r = |x − c| > 2ρ the expansion of ``e^{−λ|x−c−δ|}/|x−c−δ|`` converges like powers of
  ``E = ρ (λ + 1/r)`` with remainder ≲ E³ e^{λρ}/6 of the node's sum, and the node's sum itself weighs
  ``e^{−λ(r − d*)}`` relative to the nearest source (d* = nearest source distance). The node is accepted when
  ``E³ e^{λρ} e^{−λ(r − d*)} < θ³`` (``theta``, the error tolerance) — so clusters far behind the
  nearest sources may be large, which keeps the walk short at nodes far from the input;
* **pruning by exponential decay**: every value is computed relative to d*(x) (so nothing underflows far
  from the input), and a node whose box is farther than ``d* + τ/λ`` is skipped, ``τ = ln(1/ε)``.

For the radial kernel g(r) = e^{−λ(r−d*)}/(4πr): g' = −g (1 + λr)/r and g'' = g (λ²r² + 2λr + 2)/r², and with
u = (c − x)/r the second-order expansion of Σ w g(|x − c − δ|) is

    g S0 + g' uᵀS1 + ½ [ (g'' − g'/r) Σ_ab u_a u_b S2_ab + (g'/r) T ].

Cost: O(m log m) precompute, and per node O(log m + number of clusters in the band d* ≤ d ≤ d* + τ/λ).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from scipy.spatial import cKDTree

from gsdf._checks import as_points, as_values, integer, nonnegative, positive, progress_callback
from gsdf._memory import SECONDS_PER_PAIR, SECONDS_PER_QUERY
from gsdf.spatial._bvh import build_bvh

INV_4PI = 1.0 / (4.0 * np.pi)
_W = 37  # c(3) rho(1) S0(3) S1(9) S2(18) T(3)


@njit(cache=True)
def _moments(start, end, B, W):
    # serial: O(m log m) flops, well under a millisecond for 10⁵ sources (a parallel launch can wait for a
    # descheduled thread on a loaded machine, docs/decisions.md)
    k = start.shape[0]
    D = np.zeros((k, _W))
    for i in range(k):
        s, e = start[i], end[i]
        A = 0.0
        cx = cy = cz = 0.0
        for j in range(s, e):
            a = np.sqrt(W[j, 0] ** 2 + W[j, 1] ** 2 + W[j, 2] ** 2) + 1e-300
            A += a
            cx += a * B[j, 0]
            cy += a * B[j, 1]
            cz += a * B[j, 2]
        cx /= A
        cy /= A
        cz /= A
        D[i, 0], D[i, 1], D[i, 2] = cx, cy, cz
        r2 = 0.0
        for j in range(s, e):
            d0, d1, d2 = B[j, 0] - cx, B[j, 1] - cy, B[j, 2] - cz
            r2 = max(r2, d0 * d0 + d1 * d1 + d2 * d2)
            dd = d0 * d0 + d1 * d1 + d2 * d2
            for c in range(3):
                w = W[j, c]
                D[i, 4 + c] += w
                D[i, 7 + c] += d0 * w  # S1[a, c] at 7 + 3a + c
                D[i, 10 + c] += d1 * w
                D[i, 13 + c] += d2 * w
                b = 16 + 6 * c  # xx yy zz xy xz yz
                D[i, b] += d0 * d0 * w
                D[i, b + 1] += d1 * d1 * w
                D[i, b + 2] += d2 * d2 * w
                D[i, b + 3] += d0 * d1 * w
                D[i, b + 4] += d0 * d2 * w
                D[i, b + 5] += d1 * d2 * w
                D[i, 34 + c] += dd * w
        D[i, 3] = np.sqrt(r2)
    return D


@njit(parallel=True, cache=True, fastmath=True)
def _tree_kernel(Q, dref, B, W, D, erho, lo, hi, right, skip, start, end, lam, theta, band, rmin, out):
    k = D.shape[0]
    theta3 = theta * theta * theta
    for qi in prange(Q.shape[0]):
        qx, qy, qz = Q[qi, 0], Q[qi, 1], Q[qi, 2]
        d0 = dref[qi]
        cut = d0 + band
        cut2 = cut * cut
        ax = ay = az = 0.0
        i = 0
        while i < k:
            # squared distance from the query to the node's box: prune by exponential decay
            ex = max(lo[i, 0] - qx, 0.0, qx - hi[i, 0])
            ey = max(lo[i, 1] - qy, 0.0, qy - hi[i, 1])
            ez = max(lo[i, 2] - qz, 0.0, qz - hi[i, 2])
            if ex * ex + ey * ey + ez * ez > cut2:
                i = skip[i]
                continue
            ux = D[i, 0] - qx
            uy = D[i, 1] - qy
            uz = D[i, 2] - qz
            r = np.sqrt(ux * ux + uy * uy + uz * uz)
            rho = D[i, 3]
            # accept the cluster when its Taylor remainder, ~E³ e^{λρ}/6 times the cluster's weight
            # e^{−λ(r − d*)} relative to the nearest source, is below θ³/6 (E = ρ(λ + 1/r)): written as
            # E³ e^{−λ(r − d*)} < θ³ e^{−λρ}, so the one exponential serves the test and the expansion
            # (erho = e^{−λρ} per tree node; no logarithm per visited node)
            accept = False
            decay = 0.0
            if r > 2.0 * rho and theta > 0.0:
                E = rho * (lam + 1.0 / r)
                decay = np.exp(-lam * (r - d0))
                if E == 0.0 or E * E * E * decay < theta3 * erho[i]:
                    accept = True
            if accept:
                ux /= r
                uy /= r
                uz /= r
                g = decay * INV_4PI / r
                g1 = -g * (1.0 + lam * r) / r
                g2 = g * (lam * lam * r * r + 2.0 * lam * r + 2.0) / (r * r)
                a2 = 0.5 * (g2 - g1 / r)
                a3 = 0.5 * g1 / r
                for c in range(3):
                    v = g * D[i, 4 + c]
                    v += g1 * (ux * D[i, 7 + c] + uy * D[i, 10 + c] + uz * D[i, 13 + c])
                    b = 16 + 6 * c
                    quad = (D[i, b] * ux * ux + D[i, b + 1] * uy * uy + D[i, b + 2] * uz * uz
                            + 2.0 * (D[i, b + 3] * ux * uy + D[i, b + 4] * ux * uz + D[i, b + 5] * uy * uz))
                    v += a2 * quad + a3 * D[i, 34 + c]
                    if c == 0:
                        ax += v
                    elif c == 1:
                        ay += v
                    else:
                        az += v
                i = skip[i]
            elif right[i] < 0:
                for j in range(start[i], end[i]):
                    dx = B[j, 0] - qx
                    dy = B[j, 1] - qy
                    dz = B[j, 2] - qz
                    rj = max(np.sqrt(dx * dx + dy * dy + dz * dz), rmin)
                    g = np.exp(-lam * (rj - d0)) * INV_4PI / rj
                    ax += g * W[j, 0]
                    ay += g * W[j, 1]
                    az += g * W[j, 2]
                i = skip[i]
            else:
                i += 1
        out[qi, 0] = ax
        out[qi, 1] = ay
        out[qi, 2] = az


@njit(parallel=True, cache=True)
def _direct_kernel(Q, dref, B, W, lam, rmin, out):
    for qi in prange(Q.shape[0]):
        ax = ay = az = 0.0
        for j in range(B.shape[0]):
            dx = B[j, 0] - Q[qi, 0]
            dy = B[j, 1] - Q[qi, 1]
            dz = B[j, 2] - Q[qi, 2]
            r = max(np.sqrt(dx * dx + dy * dy + dz * dz), rmin)
            g = np.exp(-lam * (r - dref[qi])) * INV_4PI / r
            ax += g * W[j, 0]
            ay += g * W[j, 1]
            az += g * W[j, 2]
        out[qi, 0] = ax
        out[qi, 1] = ay
        out[qi, 2] = az


class YukawaTree:
    """Hierarchical (Barnes–Hut) evaluation of the vector Yukawa potential X(x) = Σ w_f G_t(x, b_f) (§8.2).

    Parameters
    ----------
    B : (m, 3) float
        Source points (triangle barycenters, or cloud points).
    W : (m, 3) float
        Vector charges ``|f| N_f`` (area-weighted normals, or normals × point areas).
    t : float
        Diffusion time (square model units, > 0); λ = 1/√t.
    theta : float >= 0, default 0.5
        Cluster acceptance tolerance: a tree node of radius ρ at distance r is used through its second-order
        expansion when ``E³ exp(λρ − λ(r − d*)) < theta³``, E = ρ (λ + 1/r). Smaller is more accurate and
        slower; 0 disables clustering.
    eps : float, default 1e-6
        Relative pruning tolerance of the exponential decay, in (0, 1/2]: sources whose weight has decayed
        below ``eps`` times the nearest one's are skipped.
    leaf_size : int >= 1, default 8
        Sources per tree leaf; changes speed only.

    Raises
    ------
    ValueError
        ``t <= 0``, ``theta < 0``, ``eps`` outside (0, 1/2], ``leaf_size`` not an integer >= 1.

    Notes
    -----
    Results are returned *scaled* by ``exp(λ d*(x))``, d* the distance from x to the nearest source, so that
    they never underflow; the scale is positive and only the direction of X is used by the method. Calling the
    tree, ``tree(Q, dref=None, slack=0.0, chunk=65536, progress=None)``, returns the scaled X (q, 3) at the
    query points; ``dref`` is an estimate of d* within ``slack`` (computed exactly when omitted).

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> B = np.array([[0.0, 0, 0], [1.0, 0, 0]]); W = np.array([[0, 0, 1.0], [0, 0, 1.0]])
    >>> X = gsdf.YukawaTree(B, W, t=0.01)([[0.5, 0, 0.2]])
    >>> bool(X[0, 2] > 0 and abs(X[0, 0]) < 1e-12)
    True
    """

    def __init__(self, B, W, t: float, theta: float = 0.5, eps: float = 1e-6, leaf_size: int = 8):
        B = as_points(B, "B")
        W = as_points(W, "W")
        if len(W) != len(B):
            raise ValueError(f"W: has {len(W)} rows but there are {len(B)} source points B")
        self.m = len(B)
        self.lam = 1.0 / np.sqrt(positive(t, "t"))
        self.theta = nonnegative(theta, "theta")
        self.tau = float(np.log(1.0 / positive(eps, "eps", most=0.5)))  # eps in (0, 1/2]: a relative tolerance
        self.tree = build_bvh(B, B, B, integer(leaf_size, "leaf_size", lo=1))
        o = self.tree.order
        self._B = np.ascontiguousarray(B[o])
        self._W = np.ascontiguousarray(W[o])
        self._D = _moments(self.tree.start, self.tree.end, self._B, self._W)
        self._erho = np.exp(-self.lam * self._D[:, 3])  # e^{−λρ} of every tree node (the acceptance test)
        self._src = B
        self._kd = None  # built on first exact nearest-distance query (grids pass their own estimate)
        ext = B.max(axis=0) - B.min(axis=0)
        self._rmin = 1e-9 * max(float(ext.max()), 1e-300)

    def nearest_distance(self, Q) -> np.ndarray:
        """Distance from each query to the nearest source point (the reference distance d*).

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        (q,) float64

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> tree = gsdf.YukawaTree(np.eye(3), np.eye(3), t=0.01)
        >>> tree.nearest_distance([[0.0, 0.0, 0.0]]).round(3).tolist()
        [1.0]
        """
        Q = as_points(Q, "Q", allow_empty=True, seconds_per_row=SECONDS_PER_QUERY)
        if self._kd is None:
            self._kd = cKDTree(self._src)
        return self._kd.query(Q, workers=-1)[0]

    def __call__(self, Q, dref=None, slack: float = 0.0, chunk: int = 1 << 16, progress=None) -> np.ndarray:
        """Scaled X at queries ``Q`` (q, 3) → (q, 3).

        ``progress(stage, fraction)`` is called after each chunk when given. ``dref`` (q,) is an estimate of the
        nearest source distance with ``|dref − d*| ≤ slack`` (computed
        exactly with a k-d tree when omitted); :func:`grid_nearest_distance` gives one for grids.
        """
        Q = as_points(Q, "Q", allow_empty=True, seconds_per_row=SECONDS_PER_QUERY)
        if dref is not None:
            dref = as_values(dref, "dref", (len(Q),), allow_empty=True)
        slack = nonnegative(slack, "slack")
        chunk = integer(chunk, "chunk", 1)
        progress = progress_callback(progress)
        out = np.empty((len(Q), 3))
        t = self.tree
        band = self.tau / self.lam + 2.0 * float(slack)
        for s in range(0, len(Q), chunk):
            q = Q[s:s + chunk]
            d = self.nearest_distance(q) if dref is None else dref[s:s + chunk]
            _tree_kernel(q, d, self._B, self._W, self._D, self._erho, t.lo, t.hi, t.right, t.skip, t.start, t.end,
                         self.lam, self.theta, band, self._rmin, out[s:s + chunk])
            progress("Yukawa sums", (s + len(q)) / len(Q))
        return out

    def direct(self, Q) -> np.ndarray:
        """The O(q × m) direct sum with the same scaling (signedheat3d's Step I), for testing the tree.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        (q, 3) float64
            X scaled by ``exp(λ d*)``, as the tree returns it.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> B = np.array([[0.0, 0, 0], [1.0, 0, 0]]); W = np.array([[0, 0, 1.0], [0, 0, 1.0]])
        >>> tree = gsdf.YukawaTree(B, W, t=0.01)
        >>> bool(np.allclose(tree([[0.5, 0, 0.2]]), tree.direct([[0.5, 0, 0.2]]), rtol=1e-6))
        True
        """
        Q = as_points(Q, "Q", allow_empty=True, seconds_per_row=self.m * SECONDS_PER_PAIR)
        out = np.empty((len(Q), 3))
        _direct_kernel(Q, self.nearest_distance(Q), self._B, self._W, self.lam, self._rmin, out)
        return out


def grid_nearest_distance(B, bbox_min, spacing, shape):
    """Approximate distance from every grid node to the nearest source point, and its error bound.

    Marks the node nearest to each source and takes the Euclidean distance transform
    (:func:`scipy.ndimage.distance_transform_edt`); the result is within ``slack = |spacing|/2`` of the exact
    nearest source distance (sources outside the box are clamped to it, which only adds to the slack bound
    the clamping distance — the caller guarantees the box contains the sources).

    Returns
    -------
    d : (nx*ny*nz,) float, C order
    slack : float
    """
    from scipy.ndimage import distance_transform_edt

    shape = tuple(int(s) for s in shape)
    idx = np.rint((np.asarray(B) - bbox_min) / spacing).astype(np.int64)
    idx = np.clip(idx, 0, np.array(shape) - 1)
    free = np.ones(shape, dtype=bool)
    free[idx[:, 0], idx[:, 1], idx[:, 2]] = False
    d = distance_transform_edt(free, sampling=tuple(float(h) for h in spacing))
    return d.ravel(), 0.5 * float(np.linalg.norm(spacing))
