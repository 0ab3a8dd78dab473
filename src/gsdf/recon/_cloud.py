"""The cloud stage of the reconstruction (seed 003 §3.3, the implementation notes' §2(b)): validation and
normalisation, the statistical outlier pre-filter, the rescues of dropped points on thin parts, and PCA normals.

Example
-------
>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> P = rng.normal(size=(800, 3)); P /= np.linalg.norm(P, axis=1)[:, None]
>>> X, N, keep, scale, centre = prepare_cloud(np.vstack([P, rng.uniform(-1, 1, (40, 3))]))
>>> inl = prefilter(X)
>>> bool(inl[:800].mean() > 0.95 and inl[800:].mean() < 0.5)
True
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from gsdf._checks import as_normals, as_points

__all__ = ["prepare_cloud", "prefilter", "dense_points", "on_surface", "on_side", "pca_normals"]


def prepare_cloud(P, N=None):
    """Validate and deduplicate a cloud; return ``(P, N, keep, scale, centre)``.

    ``keep`` (n_unique,) indexes the kept rows of the input; ``P`` is returned normalised to a bounding-box
    diagonal of 1 around ``centre``.  Raises ValueError for fewer than 4 distinct points, or points that are
    all coplanar / collinear (no volume to tetrahedralise).
    """
    P = as_points(P, "P")
    if N is not None:
        N = as_normals(N, len(P), "N")
    _, keep = np.unique(P, axis=0, return_index=True)
    keep = np.sort(keep)
    if len(keep) < 4:
        raise ValueError(f"P: needs at least 4 distinct points, got {len(keep)} (of {len(P)} rows)")
    Pk = P[keep]
    centre = 0.5 * (Pk.min(axis=0) + Pk.max(axis=0))
    scale = float(np.linalg.norm(Pk.max(axis=0) - Pk.min(axis=0)))
    X = (Pk - centre) / scale
    s = np.linalg.svd(X - X.mean(axis=0), compute_uv=False)
    if s[2] <= 1e-9 * s[0] * np.sqrt(len(X)) or s[2] < 1e-12:
        kind = "collinear" if s[1] <= 1e-9 * s[0] * np.sqrt(len(X)) else "coplanar"
        raise ValueError(f"P: all points are {kind}; a closed surface needs a cloud that spans 3-D")
    Nk = None
    if N is not None:
        Nk = N[keep]
        nn = np.linalg.norm(Nk, axis=1)
        Nk = np.where(nn[:, None] > 0, Nk / np.maximum(nn, 1e-300)[:, None], 0.0)
    return X, Nk, keep, scale, centre


def prefilter(X: np.ndarray, k: int = 10, factor: float = 2.5, residual: float = 0.4, planarity: float = 0.1,
               rounds: int = 3, rescue: bool = True) -> np.ndarray:
    """(n,) bool inliers of the statistical pre-filter (§3.3's outlier removal, first pass).

    A point is kept when the mean distance to its ``k`` nearest kept neighbours is at most ``factor`` × the
    median, and its distance to the least-squares plane of those neighbours (itself excluded) is at most
    ``residual`` × their mean distance, and the neighbours are flat (smallest covariance eigenvalue ≤
    ``planarity`` × the trace; outliers among outliers have isotropic neighbourhoods): exact samples of a
    smooth surface lie on the plane of their neighbours, points moved off the surface do not.  Repeated ``rounds`` times on the kept points, so that
    inlier neighbourhoods get cleaner as outliers leave.
    """
    keep = np.ones(len(X), dtype=bool)
    for _ in range(rounds):
        idx = np.flatnonzero(keep)
        if len(idx) <= k + 1:
            break
        d, I = cKDTree(X[idx]).query(X, k=k + 1)
        # drop the point itself where it is in the kept set (first neighbour at distance 0)
        self_hit = d[:, 0] == 0
        d = np.where(self_hit[:, None], d[:, 1:], d[:, :-1])
        I = np.where(self_hit[:, None], I[:, 1:], I[:, :-1])
        Y = X[idx][I]
        mu = Y.mean(axis=1)
        Q = Y - mu[:, None]
        lam, vec = np.linalg.eigh(np.einsum("nki,nkj->nij", Q, Q))
        res = np.abs(np.einsum("ni,ni->n", vec[:, :, 0], X - mu))
        flat = lam[:, 0] / np.maximum(lam.sum(axis=1), 1e-300)
        dm = d.mean(axis=1)
        new = (dm <= factor * np.median(dm[keep])) & (res <= residual * dm) & (flat <= planarity)
        if np.array_equal(new, keep):
            break
        keep = new
    if rescue and keep.mean() >= 0.5:
        # thin parts (legs, ears) have curved, non-planar neighbourhoods: keep a dropped point anyway when it
        # is densely surrounded — its nearest point within 1.5 spacings and 3 points within 2 spacings, as on
        # a surface sampled at that spacing and rarely among outliers, which are sparse
        idx = np.flatnonzero(keep)
        dk, _ = cKDTree(X[idx]).query(X[idx], k=2)
        sp_ = float(np.median(dk[:, 1]))
        d4, _ = cKDTree(X).query(X, k=min(4, len(X)))
        dense = (d4[:, 1] <= 1.5 * sp_) & (d4[:, -1] <= 2.0 * sp_)
        keep = keep | dense
    return keep


def dense_points(X: np.ndarray, keep: np.ndarray, factor: float = 3.0, k: int = 5) -> np.ndarray:
    """(n,) bool: points whose ``k``-th nearest neighbour (in the whole cloud) lies within ``factor`` × the
    median nearest-neighbour spacing of the ``keep`` points.

    Samples of a surface are densely surrounded wherever they lie — on thin, curved parts too, where the
    planarity test of :func:`prefilter` fails (legs, ears, tails); outliers moved along the normal (seed 003,
    Table 2) are sparse unless they stayed close to the surface (and those the relocation puts back on it).
    """
    idx = np.flatnonzero(keep)
    if len(idx) < 2 or len(X) <= k:
        return np.zeros(len(X), dtype=bool)
    sp_ = float(np.median(cKDTree(X[idx]).query(X[idx], k=2)[0][:, 1]))
    dk, _ = cKDTree(X).query(X, k=k + 1)
    return dk[:, k] <= factor * sp_


def on_surface(X: np.ndarray, keep: np.ndarray, factor: float = 4.0, height: float = 1.0, k: int = 5,
                fit_k: int = 12, rounds: int = 3) -> np.ndarray:
    """(n,) bool: dropped points that lie on the surface of the kept ones — their ``k``-th nearest neighbour (in
    the whole cloud) within ``factor`` × the kept points' median spacing, and their height over the
    moving-least-squares quadric of their ``fit_k`` nearest kept points (:func:`gsdf.recon._relocate.local_surface`) at
    most ``height`` × that spacing; repeated up to ``rounds`` times with the points so kept added (a thin
    part's quadric improves as its samples come back).

    The samples the planar test and :func:`dense_points` drop lie on thin, curved parts (legs, horns, ears) in
    the gaps of a random sampling: their 5th neighbour is just beyond 3 spacings, but they sit on the quadric
    of their neighbours, which outliers moved along the normal do not.
    """
    from gsdf.recon._relocate import local_surface
    out = np.zeros(len(X), dtype=bool)
    kept = keep.copy()
    for _ in range(rounds):
        idx = np.flatnonzero(kept)
        cand = np.flatnonzero(~kept)
        if len(idx) <= fit_k or cand.size == 0 or len(X) <= k:
            break
        sp_ = float(np.median(cKDTree(X[idx]).query(X[idx], k=2)[0][:, 1]))
        dk, _ = cKDTree(X).query(X[cand], k=k + 1)
        near = dk[:, k] <= factor * sp_
        if not near.any():
            break
        _, _, h = local_surface(X[cand[near]], X[idx], sp_, k=fit_k)
        new = cand[near][np.abs(h) <= height * sp_]
        if new.size == 0:
            break
        out[new] = True
        kept[new] = True
    return out


def on_side(X: np.ndarray, keep: np.ndarray, N: np.ndarray, factor: float = 4.0, height: float = 2.5, k: int = 5,
             fit_k: int = 12, rounds: int = 3):
    """Dropped points on the surface of the kept ones, judged one side at a time: (add (n,) bool, normals (n, 3)).

    The second pass of the rescue, after the orientation: a dropped point whose ``k``-th nearest neighbour (in
    the whole cloud) lies within ``factor`` × the kept points' median spacing is kept when its height over the
    moving-least-squares quadric of the ``fit_k`` nearest kept points on the side of its nearest kept point —
    those whose oriented normal ``N`` (n, 3; rows of kept points) has a positive cosine with that point's
    (:func:`gsdf.recon._relocate.local_surface` with normals) — is at most ``height`` × that spacing.  An added point
    gets the quadric's normal, signed like its nearest kept point's.  Repeated up to ``rounds`` times with
    the added points kept.

    The points :func:`on_surface` leaves are at the tips of thin parts (hooves, ears, tails: 5th neighbour at
    3–4 spacings), 1–4 spacings off the quadric of their neighbours, which there extrapolates; outliers
    moved along the normal that are that dense are few.
    """
    from gsdf.recon._relocate import local_surface
    add = np.zeros(len(X), dtype=bool)
    Nout = np.zeros((len(X), 3))
    kept = keep.copy()
    Nall = N.copy()
    for _ in range(rounds):
        idx = np.flatnonzero(kept)
        cand = np.flatnonzero(~kept)
        if len(idx) <= fit_k or cand.size == 0 or len(X) <= k:
            break
        tk = cKDTree(X[idx])
        sp_ = float(np.median(tk.query(X[idx], k=2)[0][:, 1]))
        dk, _ = cKDTree(X).query(X[cand], k=k + 1)
        c = cand[dk[:, k] <= factor * sp_]
        if c.size == 0:
            break
        _, j = tk.query(X[c])
        n0 = Nall[idx[j]]
        _, n, h = local_surface(X[c], X[idx], sp_, k=fit_k, tree=tk, normals=Nall[idx], query_normals=n0)
        ok = np.abs(h) <= height * sp_
        if not ok.any():
            break
        new = c[ok]
        nn = n[ok] * np.sign(np.einsum("ij,ij->i", n[ok], n0[ok]) + 1e-300)[:, None]
        add[new] = kept[new] = True
        Nout[new] = Nall[new] = nn
    return add, Nout


def pca_normals(X: np.ndarray, k: int = 16) -> np.ndarray:
    """(n, 3) unit normals of the points ``X``, unsigned: the smallest principal axis of each point's ``k`` + 1
    nearest points (itself included)."""
    k = min(k, len(X) - 1)
    _, I = cKDTree(X).query(X, k=k + 1)
    Q = X[I] - X[I].mean(axis=1, keepdims=True)
    _, vec = np.linalg.eigh(np.einsum("nki,nkj->nij", Q, Q))
    return vec[:, :, 0]
