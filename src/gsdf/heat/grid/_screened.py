"""Step I of the grid signed heat method on the grid itself: one screened solve (id − tΔ) X = X⁰ by fast cosine
transforms, in place of the Yukawa sum of :mod:`gsdf.heat._yukawa` (Feng & Crane 2024, §8.2 "the diffused field
is the convolution with the fundamental solution of id − tΔ"; the seed solves Step I on the domain's own mesh on
tets, §8.1, and so does signedheat3d on its grid).

X⁰ is the source vector field splatted onto the nodes: every source point b_f gives its charge w_f = |f| N_f to
the 8 nodes of its cell with trilinear weights, divided by the cell volume (a density). The screened operator is
diagonal in the separable DCT-II basis, so X is three forward and three inverse 3D transforms — O(N log N),
independent of the number of sources.

Two choices bring it to the accuracy of the continuous sum:

* **an isotropic Laplacian.** The 7-point Laplacian's Green's function decays faster along the axes than along
  the diagonals, which tilts the direction of X far from the input. On cubic cells we use the 19-point stencil
  Δ₁₉ = (⅓ Σ_axis + ⅙ Σ_face-diagonal) second differences, whose symbol is
  (⅓ S₁ + ⅙ S₂)/h² with S₁ = Σ_a (2 − 2 cos ω_a h), S₂ = Σ_{a<b} (4 − 4 cos ω_a h cos ω_b h): both terms are
  |ω|²h² to second order, and these weights also make the fourth-order error a multiple of |ω|⁴ (isotropic):
  the Taylor coefficients of Σ x_a⁴ and of Σ x_a² x_b² must be in the ratio 1 : 2, which fixes α = 2β for the
  weights α S₁ + β S₂ with α + 4β = 1. Non-cubic cells use the 7-point symbol.
* **the splat's blur taken out of t.** Trilinear splatting is a convolution with a hat of variance h²/6 per
  axis (its transform is sinc²(ωh/2) ≈ 1 − ω²h²/12); a screened kernel of time t, 1/(1 + tω²) ≈ 1 − tω², has
  variance 2t per axis, so the node field matches the continuous one to second order in h when the grid solve
  uses t − h²/12 (requires t > h²/12; :func:`screened_heat` refuses less).

The box is padded by ``pad`` cells for the transform (Neumann reflections of the sources at the box faces are
then ~e^{−2·pad} weaker) and cropped. Unlike the tree sum, the field comes back unscaled: at distance d from the
input it is ~e^{−d/√t} of the near value, and once that nears the transforms' rounding (~1e-16 of the largest
value) its direction is noise. :func:`screened_reach` is the guard the grid domain applies before choosing this
path (``step1="auto"``).

Example
-------
>>> import numpy as np
>>> from gsdf.heat.grid._screened import screened_heat
>>> B = np.array([[0.5, 0.5, 0.5]]); W = np.array([[0.0, 0.0, 1.0]])
>>> X = screened_heat(B, W, np.zeros(3), np.full(3, 0.1), (11, 11, 11), t=0.01).reshape(11, 11, 11, 3)
>>> bool(X[5, 5, 5, 2] > 0 and abs(X[5, 5, 5, 0]) < 1e-12 and X[5, 5, 5, 2] > X[5, 5, 9, 2] > 0)
True
"""

from __future__ import annotations

import numpy as np

from gsdf._checks import positive
from gsdf.heat.grid._poisson import dct3

__all__ = ["screened_heat", "screened_symbol", "screened_reach", "splat", "PAD", "MAX_DECAY"]

#: Cells of padding on every side of the box for the transform (reflections damped by ~e^{−2 PAD}).
PAD = 2
#: Largest d/√t (d the farthest node's distance to the sources) for which the unscaled field is trusted:
#: e^{−25} ≈ 1e-11 of the near value, five orders above the transforms' rounding.
MAX_DECAY = 25.0


def splat(B, W, lo, spacing, shape) -> np.ndarray:
    """Trilinear splat of vector charges ``W`` (m, 3) at points ``B`` (m, 3) onto the nodes of the grid
    (``lo``, ``spacing``, ``shape``), divided by the cell volume: (N, 3), C order. Points outside the box are
    clamped to it."""
    n = np.asarray(shape, np.int64)
    spacing = np.asarray(spacing, float)
    u = np.clip((np.asarray(B, float) - lo) / spacing, 0.0, n - 1.0)
    i0 = np.minimum(np.floor(u).astype(np.int64), n - 2)
    f = u - i0
    base = (i0[:, 0] * n[1] + i0[:, 1]) * n[2] + i0[:, 2]
    idx = np.empty((len(B), 8), np.int64)
    wt = np.empty((len(B), 8))
    k = 0
    for dx in (0, 1):
        fx = f[:, 0] if dx else 1.0 - f[:, 0]
        for dy in (0, 1):
            fy = fx * (f[:, 1] if dy else 1.0 - f[:, 1])
            for dz in (0, 1):
                wt[:, k] = fy * (f[:, 2] if dz else 1.0 - f[:, 2])
                idx[:, k] = base + (dx * n[1] + dy) * n[2] + dz
                k += 1
    N = int(np.prod(n))
    flat = idx.ravel()
    out = np.empty((N, 3))
    for c in range(3):
        out[:, c] = np.bincount(flat, weights=(wt * W[:, c:c + 1]).ravel(), minlength=N)
    out /= float(np.prod(spacing))
    return out


def _cubic(spacing) -> bool:
    spacing = np.asarray(spacing, float)
    return bool(np.ptp(spacing) <= 1e-9 * spacing.max())


def screened_symbol(shape, spacing, t: float) -> np.ndarray:
    """1 + t · (symbol of −Δ) on the DCT-II modes of ``shape``: the 19-point isotropic stencil on cubic cells,
    the 7-point one otherwise (module docs). Shape ``shape``."""
    cs = []
    lam = np.ones(tuple(shape))
    for a in range(3):
        n = shape[a]
        c = np.cos(np.pi * np.arange(n) / n).reshape([-1 if i == a else 1 for i in range(3)])
        cs.append(c)
        if not _cubic(spacing):
            lam = lam + t * (2.0 - 2.0 * c) / float(spacing[a]) ** 2
    if _cubic(spacing):
        s1 = (2.0 - 2.0 * cs[0]) + (2.0 - 2.0 * cs[1]) + (2.0 - 2.0 * cs[2])
        s2 = (4.0 - 4.0 * cs[0] * cs[1]) + (4.0 - 4.0 * cs[0] * cs[2]) + (4.0 - 4.0 * cs[1] * cs[2])
        lam = lam + (t / float(spacing[0]) ** 2) * (s1 / 3.0 + s2 / 6.0)
    return lam


def screened_heat(B, W, lo, spacing, shape, t: float, pad: int = PAD) -> np.ndarray:
    """X at the grid nodes: the sources (``B``, ``W``) splatted and diffused by one screened solve (module docs).

    Parameters
    ----------
    B, W : (m, 3) source points and vector charges.
    lo : (3,) the first node; spacing : (3,) cell sizes; shape : (3,) node counts.
    t : float
        Diffusion time of the continuous kernel; the grid solve uses t − h²/12 (h² the mean squared spacing),
        so t must exceed h²/12.
    pad : int
        Cells of padding per side for the transform.

    Returns
    -------
    (N, 3) float, nodes in C order.
    """
    spacing = np.asarray(spacing, float)
    t = positive(t, "t")
    teff = t - float(np.mean(spacing ** 2)) / 12.0
    if teff <= 0.0:
        raise ValueError(f"t: {t} is too short for the grid (must exceed h²/12 = {t - teff}); use the Yukawa "
                         "sum (step1=\"yukawa\")")
    shape = tuple(int(s) for s in shape)
    big = tuple(s + 2 * pad for s in shape)
    X0 = splat(B, W, np.asarray(lo, float) - pad * spacing, spacing, big)
    lam = screened_symbol(big, spacing, teff)
    out = np.empty(shape + (3,))
    crop = tuple(slice(pad, pad + s) for s in shape)
    for c in range(3):
        out[..., c] = dct3(dct3(X0[:, c].reshape(big)) / lam, inverse=True)[crop]
    return out.reshape(-1, 3)


def screened_reach(dmax: float, t: float, spacing) -> float:
    """d_max / √(t − h²/12): how many decay lengths of the grid kernel the farthest node lies from the sources
    (inf when t ≤ h²/12). :func:`screened_heat` is trusted while this is at most :data:`MAX_DECAY`."""
    teff = float(t) - float(np.mean(np.asarray(spacing, float) ** 2)) / 12.0
    return float(dmax) / np.sqrt(teff) if teff > 0 else np.inf
