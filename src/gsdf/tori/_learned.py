"""Learned coefficient estimator of Points as Tori (thesis §5.1.2), inference in numpy.

The network is trained by ``scripts/train_pat.py`` (torch, training only) and shipped as ``pat_weights.npz``
next to this module; gsdf never imports torch.

Input of point p_i: its k nearest neighbours p_j (k = 64, p_i itself included) in the local frame
(s_i, t_i, n_i) of Eq. 5.2, scale-normalized by h_i = distance to the k-th neighbour, as seven features per
neighbour

    (u, v, w) = ((p_j − p_i)·s_i, (p_j − p_i)·t_i, (p_j − p_i)·n_i) / h_i,   (n_j·s_i, n_j·t_i, n_j·n_i),   ‖p_j − p_i‖/h_i,

plus the scale-normalized jet-fit coefficients (a00/h, a10, a01, a20 h, a11 h, a02 h) of
:func:`gsdf.tori._fit.jet_coefficients` (clipped to ±8). Architecture (a PointNet-style stand-in for the
transformer of Fig. 5.6): a shared per-neighbour MLP 7 → 32 → 64 → 64
(ReLU), max and mean pooling over the neighbours (permutation invariant), concatenation with the jet
coefficients, and an MLP 134 → 64 → 64 → 6 whose output is a *correction* added to the scaled jet
coefficients (the last layer is zero-initialized, so training starts from the classical estimator — the
"good initialization" argued for in §5.5.1). The result is scaled back: a00 = b0 h, a10 = b1, a01 = b2,
a20 = b3/h, a11 = b4/h, a02 = b5/h.
"""

from __future__ import annotations

import os

import numpy as np
from numba import njit, prange

from gsdf.tori._fit import jet_coefficients
from gsdf.tori._torus import local_frames

WEIGHTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "pat_weights.npz")
N_FEAT = 7
JET_CLIP = 8.0
LAYERS_POINT = ("p0", "p1", "p2")
LAYERS_HEAD = ("h0", "h1", "h2")

__all__ = ["neighbourhood_features", "scaled_jet", "unscale", "LearnedEstimator", "learned_coefficients"]


@njit(parallel=True, cache=True)
def _feat_kernel(P, N, S, T, idx, dist, off, out, hs):
    n, k = idx.shape
    for r in prange(n):
        i = r + off  # centre point; rows r of idx/dist/out/hs
        h = dist[r, k - 1]
        if not h > 0.0:
            h = 1.0
        hs[r] = h
        for jj in range(k):
            j = idx[r, jj]
            d0, d1, d2 = P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2]
            out[r, jj, 0] = (d0 * S[i, 0] + d1 * S[i, 1] + d2 * S[i, 2]) / h
            out[r, jj, 1] = (d0 * T[i, 0] + d1 * T[i, 1] + d2 * T[i, 2]) / h
            out[r, jj, 2] = (d0 * N[i, 0] + d1 * N[i, 1] + d2 * N[i, 2]) / h
            out[r, jj, 3] = N[j, 0] * S[i, 0] + N[j, 1] * S[i, 1] + N[j, 2] * S[i, 2]
            out[r, jj, 4] = N[j, 0] * T[i, 0] + N[j, 1] * T[i, 1] + N[j, 2] * T[i, 2]
            out[r, jj, 5] = N[j, 0] * N[i, 0] + N[j, 1] * N[i, 1] + N[j, 2] * N[i, 2]
            out[r, jj, 6] = dist[r, jj] / h


def neighbourhood_features(P, N, idx, dist, start: int = 0, frames=None):
    """Per-neighbour features (m, k, 7) float64 and scales h (m,) of the points start .. start + m − 1, whose
    neighbour rows are ``idx``/``dist`` (m, k) (see the module notes)."""
    P = np.ascontiguousarray(P, dtype=np.float64)
    N = np.ascontiguousarray(N, dtype=np.float64)
    S, T = local_frames(N) if frames is None else frames
    idx = np.ascontiguousarray(idx, dtype=np.int64)
    dist = np.ascontiguousarray(dist, dtype=np.float64)
    out = np.empty((len(idx), idx.shape[1], N_FEAT), np.float64)
    hs = np.empty(len(idx))
    _feat_kernel(P, N, np.ascontiguousarray(S), np.ascontiguousarray(T), idx, dist, int(start), out, hs)
    return out, hs


def scaled_jet(A, h):
    """Jet coefficients in units of h (a00/h, a10, a01, a20 h, a11 h, a02 h), clipped to ±JET_CLIP."""
    A = np.asarray(A, dtype=np.float64)
    h = np.asarray(h, dtype=np.float64)[:, None]
    B = A * np.concatenate([1.0 / h, np.ones_like(h), np.ones_like(h), h, h, h], axis=1)
    return np.clip(B, -JET_CLIP, JET_CLIP)


def unscale(B, h):
    """Inverse of :func:`scaled_jet` (without the clip)."""
    h = np.asarray(h, dtype=np.float64)[:, None]
    return np.asarray(B, np.float64) * np.concatenate([h, np.ones_like(h), np.ones_like(h), 1 / h, 1 / h, 1 / h], axis=1)


class LearnedEstimator:
    """The trained network (weights from ``pat_weights.npz``), evaluated in numpy float64."""

    def __init__(self, path: str = WEIGHTS):
        if not os.path.exists(path):
            raise FileNotFoundError(f"{path}: learned PAT weights missing; run scripts/train_pat.py")
        z = np.load(path, allow_pickle=False)
        self.W = {k: np.asarray(z[k], np.float64) for k in z.files if k.startswith(("p", "h")) and "_" in k}
        self.meta = {k: z[k] for k in z.files if not (k.startswith(("p", "h")) and "_" in k)}

    def _lin(self, name, x):
        return x @ self.W[name + "_w"].T + self.W[name + "_b"]

    def forward(self, F, J):
        """Scaled coefficients (n, 6) from features F (n, k, 7) and scaled jet coefficients J (n, 6)."""
        n, k, _ = F.shape
        x = F.reshape(n * k, N_FEAT)
        for li, name in enumerate(LAYERS_POINT):
            x = self._lin(name, x)
            x = np.maximum(x, 0.0)
        x = x.reshape(n, k, -1)
        z = np.concatenate([x.max(axis=1), x.mean(axis=1), J], axis=1)
        for li, name in enumerate(LAYERS_HEAD):
            z = self._lin(name, z)
            if li < len(LAYERS_HEAD) - 1:
                z = np.maximum(z, 0.0)
        return J + z

    def __call__(self, P, N, idx, dist, chunk: int = 2048):
        A = jet_coefficients(P, N, idx, dist)
        N = np.asarray(N, np.float64)
        frames = tuple(np.ascontiguousarray(a) for a in local_frames(N))
        out = np.empty((len(P), 6))
        for s in range(0, len(P), chunk):
            F, h = neighbourhood_features(P, N, idx[s: s + chunk], dist[s: s + chunk], s, frames)
            out[s: s + chunk] = unscale(self.forward(F, scaled_jet(A[s: s + chunk], h)), h)
        return out


_CACHE = {}


def learned_coefficients(P, N, idx, dist, path: str = WEIGHTS):
    """Six height-field coefficients per point from the learned estimator (§5.1.2); (n, 6) float64."""
    if path not in _CACHE:
        _CACHE[path] = LearnedEstimator(path)
    return _CACHE[path](P, N, idx, dist)
