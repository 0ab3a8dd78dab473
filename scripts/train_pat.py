"""Train the learned coefficient estimator of Points as Tori (thesis §5.1.2, loss Eq. 5.5).

    pip install torch==2.13.0          # training only; gsdf never imports torch
    python scripts/train_pat.py --minutes 60 --seed 1   # writes src/gsdf/tori/pat_weights.npz

Data recipe (all procedural, analytic implicit functions, seed-determined): random shapes in [-0.9, 0.9]³ —
spheres, ellipsoids, tori, capped cylinders, rounded boxes, superquadrics and CSG (union / intersection /
difference) of two of these — randomly scaled, rotated and offset. Each shape's surface is sampled densely
(area-uniform: volume-uniform points of the thin band |f|/|∇f| < ε projected onto f = 0), the exact distance
to the surface is taken from that dense sample (nearest sample, point-to-plane within 3 spacings; sign from f).
Training clouds draw n ∈ {512, 1024, 2048, 4096} points from the surface; 30 % get Gaussian noise on positions
(σ ∈ [0.002, 0.01]) and normals (σ ∈ [0.02, 0.1]). Per cloud: k = 64 neighbourhoods, the features of
:mod:`gsdf.tori._learned`, and query points (half uniform in [-1, 1]³, half within ~0.1 of the surface) with
their 16 nearest cloud points and σ_x = ½ max_i ‖x − p_i‖.

Loss (Eq. 5.5): L = mean |φ(q) − φ_true(q)| + mean |1 − ‖∇φ(q)‖|, φ the blend of Eq. 5.6 (C = 64) over the
--m-blend (default 32, what evaluation blends far from the cloud) nearest tori of each query, each torus built from the predicted coefficients through a differentiable torch
port of :mod:`gsdf.tori._torus` (float64); ∇φ by autograd (λ_x held fixed).

The wall-time cap (--minutes, default 25) covers data generation and training; the thesis trained ~45 h on a
GPU on 40 M neighbourhoods. A full run would use --minutes 120 (the issue's budget): more clouds (--clouds),
more steps, and a larger network would then pay off.

Run that produced the shipped weights (2026-11-22, 2-core machine, torch 2.13.0 CPU, one torch thread):
``python scripts/train_pat.py --minutes 60 --seed 1 --m-blend 32`` — 7.3 min of data generation (120 training
clouds = 223k neighbourhoods, 8 validation clouds), 9835 Adam steps (192 queries of one cloud per step, cosine
learning rate from 1e-3), 59.5 min in all; validation loss (Eq. 5.5) 0.00734 against 0.01904 for the jet
estimator (distance term 0.00121 against 0.00434). (The previous weights, 22 min, --m-blend 16, seed 0, had
0.01184 against 0.03115 on their own validation set; on the 64³ landscape's clean configurations they gave
mean |error| 0.00180, these 0.00102.) The weights are stored in float32 (~100 kB); the
file also holds a 16-neighbourhood reference batch evaluated by the torch model in float64, which the tests
compare with the numpy inference. Data generation is seeded but wall-time bounded, so a rerun on a machine of
another speed gets a different number of clouds and steps.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "src"))

from scipy.spatial import cKDTree  # noqa: E402

from gsdf.tori._fit import jet_coefficients  # noqa: E402
from gsdf.tori._learned import JET_CLIP, WEIGHTS, neighbourhood_features, scaled_jet  # noqa: E402
from gsdf.tori._torus import local_frames  # noqa: E402

K = 64
M_BLEND = 32  # tori blended per training query; set from --m-blend
C = 64.0


# ------------------------------------------------------------------------------------------------ shapes


def _rot(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    a, b, c, d = q
    return np.array([[a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
                     [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
                     [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d]])


def primitive(rng, size):
    """A random primitive implicit function f (negative inside) of roughly ``size`` extent."""
    kind = rng.choice(["sphere", "ellipsoid", "torus", "cylinder", "box", "superquadric"])
    R, t = _rot(rng), rng.uniform(-0.15, 0.15, 3)
    s = size
    if kind == "sphere":
        r = s * rng.uniform(0.4, 1.0)
        f = lambda Y: np.linalg.norm(Y, axis=1) - r  # noqa: E731
    elif kind == "ellipsoid":
        ax = s * rng.uniform(0.3, 1.0, 3)
        f = lambda Y: (np.linalg.norm(Y / ax, axis=1) - 1) * ax.min()  # noqa: E731
    elif kind == "torus":
        Rr = s * rng.uniform(0.45, 0.75)
        rr = Rr * rng.uniform(0.2, 0.6)
        f = lambda Y: np.hypot(np.hypot(Y[:, 0], Y[:, 1]) - Rr, Y[:, 2]) - rr  # noqa: E731
    elif kind == "cylinder":
        r, hh = s * rng.uniform(0.2, 0.8), s * rng.uniform(0.3, 1.0)

        def f(Y):
            dx, dz = np.hypot(Y[:, 0], Y[:, 1]) - r, np.abs(Y[:, 2]) - hh
            return np.hypot(np.maximum(dx, 0), np.maximum(dz, 0)) + np.minimum(np.maximum(dx, dz), 0)
    elif kind == "box":
        b = s * rng.uniform(0.3, 0.9, 3)
        rad = rng.uniform(0.0, 0.6) * b.min()

        def f(Y):
            q = np.abs(Y) - (b - rad)
            return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(1), 0) - rad
    else:
        ax = s * rng.uniform(0.4, 1.0, 3)
        p = rng.uniform(2.5, 6.0)
        f = lambda Y: ((np.abs(Y / ax) ** p).sum(1) ** (1 / p) - 1) * ax.min()  # noqa: E731
    return lambda X: f((X - t) @ R)


def random_shape(rng):
    u = rng.uniform()
    if u < 0.6:
        return primitive(rng, rng.uniform(0.35, 0.85))
    a, b = primitive(rng, rng.uniform(0.35, 0.7)), primitive(rng, rng.uniform(0.25, 0.6))
    off = rng.uniform(-0.25, 0.25, 3)
    op = rng.choice(["union", "intersection", "difference"])
    if op == "union":
        return lambda X: np.minimum(a(X), b(X - off))
    if op == "intersection":
        return lambda X: np.maximum(a(X), b(X - off))
    return lambda X: np.maximum(a(X), -b(X - off))


def _grad(f, X, e=1e-5):
    G = np.empty_like(X)
    for c in range(3):
        d = np.zeros(3)
        d[c] = e
        G[:, c] = (f(X + d) - f(X - d)) / (2 * e)
    return G


def dense_surface(f, rng, n_target=25000, eps=0.03):
    """Area-uniform dense sample of {f = 0} with normals (band rejection + Newton projection)."""
    pts = []
    got = 0
    for _ in range(12):
        X = rng.uniform(-1, 1, (400000, 3))
        v = f(X)
        m = np.abs(v) < 3 * eps
        X, v = X[m], v[m]
        G = _grad(f, X)
        gn = np.linalg.norm(G, axis=1)
        m = np.abs(v) / np.maximum(gn, 1e-12) < eps
        X = X[m]
        pts.append(X)
        got += len(X)
        if got >= n_target:
            break
    X = np.concatenate(pts)[:n_target]
    for _ in range(4):
        G = _grad(f, X)
        g2 = np.maximum((G * G).sum(1), 1e-12)
        X = X - (f(X) / g2)[:, None] * G
    G = _grad(f, X)
    N = G / np.maximum(np.linalg.norm(G, axis=1, keepdims=True), 1e-12)
    ok = (np.abs(f(X)) < 1e-6) & (np.abs(X).max(1) < 0.98)
    return X[ok], N[ok]


def truth(f, D, DN, X):
    """Signed distance from the dense sample D (normals DN): nearest sample, point-to-plane when close."""
    tree = cKDTree(D)
    d, i = tree.query(X)
    spacing = np.sqrt(4.0 * np.pi / len(D))  # crude; only decides where the plane correction is used
    dp = np.abs(((X - D[i]) * DN[i]).sum(1))
    d = np.where(d < 3 * spacing, dp, d)
    return np.where(f(X) < 0, -d, d)


def make_cloud(rng):
    while True:
        f = random_shape(rng)
        D, DN = dense_surface(f, rng)
        if len(D) > 8000:
            break
    n = int(rng.choice([512, 1024, 2048, 2048, 4096]))
    sel = rng.choice(len(D), n, replace=False)
    P, N = D[sel].copy(), DN[sel].copy()
    noisy = rng.uniform() < 0.3
    if noisy:
        P += rng.normal(scale=rng.uniform(0.002, 0.01), size=P.shape)
        N += rng.normal(scale=rng.uniform(0.02, 0.1), size=N.shape)
        N /= np.linalg.norm(N, axis=1, keepdims=True)
    tree = cKDTree(P)
    dist, idx = tree.query(P, K)
    A = jet_coefficients(P, N, idx, dist)
    F, h = neighbourhood_features(P, N, idx, dist)
    J = scaled_jet(A, h)
    nq = 1024
    Qu = rng.uniform(-1, 1, (nq // 2, 3))
    j = rng.choice(len(D), nq // 2)
    Qn = D[j] + DN[j] * rng.normal(scale=0.05, size=(nq // 2, 1)) + rng.normal(scale=0.01, size=(nq // 2, 3))
    Q = np.vstack([Qu, Qn])
    phi = truth(f, D, DN, Q)
    qd, qi = tree.query(Q, M_BLEND)
    hull = P[np.unique(np.argsort(-np.linalg.norm(P - P.mean(0), axis=1))[:64])]
    sig = 0.5 * np.sqrt(((Q[:, None] - P[None]) ** 2).sum(-1)).max(1)
    S, T = local_frames(N)
    return dict(P=P, N=N, S=S, T=T, F=F.astype(np.float32), J=J, h=h, Q=Q, phi=phi, qi=qi, sig=sig, noisy=noisy,
                jet=A)


# ------------------------------------------------------------------------------------------------ torch


def build_model(torch):
    nn = torch.nn

    class Net(nn.Module):
        def __init__(self):
            super().__init__()
            self.p0, self.p1, self.p2 = nn.Linear(7, 32), nn.Linear(32, 64), nn.Linear(64, 64)
            self.h0, self.h1, self.h2 = nn.Linear(134, 64), nn.Linear(64, 64), nn.Linear(64, 6)
            nn.init.zeros_(self.h2.weight)
            nn.init.zeros_(self.h2.bias)

        def forward(self, F, J):
            x = torch.relu(self.p0(F))
            x = torch.relu(self.p1(x))
            x = torch.relu(self.p2(x))
            z = torch.cat([x.max(1).values, x.mean(1), J], 1)
            z = torch.relu(self.h0(z))
            z = torch.relu(self.h1(z))
            return J + self.h2(z)

    return Net()


def torus_phi(torch, A, p, n, sv, tv, X, kcap, kfloor):
    """Differentiable torch port of gsdf.tori._torus (coefficients -> torus -> signed distance at X).
    A, p, n, sv, tv: (..., 6/3); X: (..., 3); kcap, kfloor: (...) float64."""
    a00, a10, a01, a20, a11, a02 = A.unbind(-1)
    W = torch.sqrt(1 + a10 ** 2 + a01 ** 2)
    ns = (-a10 / W)[..., None] * sv + (-a01 / W)[..., None] * tv + (1 / W)[..., None] * n
    E, F, G = 1 + a10 ** 2, a10 * a01, 1 + a01 ** 2
    L, M, Nn = 2 * a20 / W, a11 / W, 2 * a02 / W
    detI = E * G - F * F
    H = (E * Nn - 2 * F * M + G * L) / (2 * detI)
    K = (L * Nn - M * M) / detI
    disc = torch.sqrt(torch.clamp(H * H - K, min=0) + 1e-18)
    ka, kb = H + disc, H - disc
    big = ka.abs() >= kb.abs()
    kmax, kmin = torch.where(big, ka, kb), torch.where(big, kb, ka)
    v0a, v1a = M - kmax * F, -(L - kmax * E)
    v0b, v1b = Nn - kmax * G, -(M - kmax * F)
    first = v0a ** 2 + v1a ** 2 >= v0b ** 2 + v1b ** 2
    v0, v1 = torch.where(first, v0a, v0b), torch.where(first, v1a, v1b)
    tiny = v0 ** 2 + v1 ** 2 < 1e-20 * (1 + L * L + M * M + Nn * Nn)
    v0, v1 = torch.where(tiny, torch.ones_like(v0), v0), torch.where(tiny, torch.zeros_like(v1), v1)
    l2 = v0 * a10 + v1 * a01
    u = v0[..., None] * sv + v1[..., None] * tv + l2[..., None] * n
    u = u - (u * ns).sum(-1, keepdim=True) * ns
    u = u / torch.sqrt((u * u).sum(-1, keepdim=True) + 1e-30)
    cmax, cmin = -kmax, -kmin
    k1 = torch.minimum(cmax.abs(), kcap)
    k2 = torch.minimum(cmin.abs(), k1)
    k1 = torch.maximum(k1, kfloor)  # near-planar: a very large tube instead of the exact plane
    s = torch.where(cmax >= 0, 1.0, -1.0).to(A)
    e = torch.where(cmax * cmin >= 0, 1.0, -1.0).to(A)
    ps = p + a00[..., None] * n
    z = X - ps
    b = torch.cross(u, ns, dim=-1)
    zn, zu, zb = (z * ns).sum(-1), (z * u).sum(-1), (z * b).sum(-1)
    r = 1 / k1
    tw = r + s * zn
    direct = k1 <= (4 + e) * k2
    k2d = torch.where(direct, k2, k1)
    R = (k1 - e * k2d) / (k1 * k2d)
    a = e * tw + R
    q_direct = torch.sqrt(a * a + zb * zb + 1e-30) - R
    k2c = torch.where(direct, torch.zeros_like(k2), k2)
    kap = k1 * k2c / (k1 - e * k2c)
    ac = 1 + e * kap * tw
    Sc = torch.sqrt(ac * ac + kap * kap * zb * zb)
    q_cyl = (2 * e * tw + kap * (tw * tw + zb * zb)) / (1 + Sc)
    q = torch.where(direct, q_direct, q_cyl)
    return s * (torch.sqrt(q * q + zu * zu + 1e-30) - r)


def cloud_loss(torch, model, c, sub=None):
    """Eq. 5.5 on the queries of cloud ``c`` (or the subset ``sub`` of them)."""
    t64 = torch.float64
    if sub is not None:
        c = dict(c, Q=c["Q"][sub], phi=c["phi"][sub], qi=c["qi"][sub], sig=c["sig"][sub])
    uniq, inv = np.unique(c["qi"], return_inverse=True)
    inv = inv.reshape(c["qi"].shape)
    F = torch.from_numpy(c["F"][uniq])
    J = torch.from_numpy(c["J"][uniq].astype(np.float32))
    B = model(F, J).to(t64)
    h = torch.from_numpy(c["h"][uniq])
    scale = torch.stack([h, torch.ones_like(h), torch.ones_like(h), 1 / h, 1 / h, 1 / h], 1)
    A = B * scale
    g = lambda key: torch.from_numpy(c[key][uniq])  # noqa: E731
    p, n, sv, tv = g("P"), g("N"), g("S"), g("T")
    invt = torch.from_numpy(inv)
    X = torch.from_numpy(c["Q"]).requires_grad_(True)
    hmed = float(np.median(c["h"]))
    Xe = X[:, None, :].expand(-1, M_BLEND, -1)
    kcap = torch.full(invt.shape, 4.0 / hmed, dtype=t64)
    kfloor = torch.full(invt.shape, 1e-4, dtype=t64)
    gi = torus_phi(torch, A[invt], p[invt], n[invt], sv[invt], tv[invt], Xe, kcap, kfloor)
    d = torch.sqrt(((Xe - p[invt]) ** 2).sum(-1) + 1e-30)
    lam = torch.from_numpy(C / c["sig"])[:, None]
    w = torch.softmax(-lam * d, dim=1)
    phi = (w * gi).sum(1)
    grad = torch.autograd.grad(phi.sum(), X, create_graph=True)[0]
    ld = (phi - torch.from_numpy(c["phi"])).abs().mean()
    le = (1 - torch.sqrt((grad * grad).sum(1) + 1e-20)).abs().mean()
    return ld, le


def jet_eval_loss(torch, c):
    """Loss of the classical jet estimator on the same cloud (reference)."""
    import types

    class Id:
        def __call__(self, F, J):
            return J

    ld, le = cloud_loss(torch, Id(), c)
    return float(ld.detach()), float(le.detach())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--minutes", type=float, default=25.0, help="wall-time cap for data generation + training")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--clouds", type=int, default=120, help="training clouds (data generation stops at 30 %% of the cap)")
    ap.add_argument("--val", type=int, default=8)
    ap.add_argument("--queries", type=int, default=192, help="queries per training step (one cloud per step)")
    ap.add_argument("--lr", type=float, default=1e-3)
    ap.add_argument("--m-blend", type=int, default=32, help="nearest tori blended per training query")
    ap.add_argument("--out", default=WEIGHTS)
    args = ap.parse_args()
    global M_BLEND
    M_BLEND = args.m_blend
    import torch

    torch.manual_seed(args.seed)
    torch.set_num_threads(1)  # one thread: 5x faster than two on the shared, oversubscribed 2-core machine
    rng = np.random.default_rng(args.seed)
    t0 = time.time()
    cap = 60 * args.minutes
    val = [make_cloud(rng) for _ in range(args.val)]
    train = []
    while len(train) < args.clouds and time.time() - t0 < 0.30 * cap:
        train.append(make_cloud(rng))
    tdata = time.time() - t0
    print(f"data: {len(train)} training clouds ({sum(len(c['P']) for c in train)} neighbourhoods), "
          f"{len(val)} validation clouds, {tdata:.0f} s", flush=True)
    jet_val = np.mean([sum(jet_eval_loss(torch, c)) for c in val])
    jet_val_d = np.mean([jet_eval_loss(torch, c)[0] for c in val])
    print(f"jet estimator on validation: loss {jet_val:.5f} (distance term {jet_val_d:.5f})", flush=True)
    model = build_model(torch)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr)
    step, hist = 0, []
    best = (np.inf, None)
    t_train = time.time()
    budget = cap - (t_train - t0) - 30
    while time.time() - t_train < budget:
        c = train[rng.integers(len(train))]
        frac = (time.time() - t_train) / budget
        for gparam in opt.param_groups:
            gparam["lr"] = args.lr * (0.5 * (1 + np.cos(np.pi * min(frac, 1.0))) * 0.95 + 0.05)
        ld, le = cloud_loss(torch, model, c, rng.choice(len(c['Q']), args.queries, replace=False))
        loss = ld + le
        opt.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        hist.append(float(loss.detach()))
        step += 1
        if step % 250 == 0:
            with torch.no_grad():
                pass
            vl = np.mean([sum(float(v) for v in cloud_loss(torch, model, c)) for c in val])
            if vl < best[0]:
                best = (vl, {k: v.detach().clone() for k, v in model.state_dict().items()})
            print(f"step {step} {time.time() - t0:.0f}s train {np.mean(hist[-250:]):.5f} val {vl:.5f} "
                  f"(jet {jet_val:.5f})", flush=True)
    if best[1] is not None:
        model.load_state_dict(best[1])
    vals = [cloud_loss(torch, model, c) for c in val]
    vl_d = np.mean([float(a) for a, b in vals])
    vl = np.mean([float(a) + float(b) for a, b in vals])
    # save weights and a reference batch evaluated by torch in float64 (checked by the tests in numpy)
    sd = {k: v.detach().double().numpy() for k, v in model.state_dict().items()}
    out = {k.replace(".weight", "_w").replace(".bias", "_b"): v.astype(np.float32) for k, v in sd.items()}
    ref_F = val[0]["F"][:16]
    ref_J = val[0]["J"][:16].astype(np.float32)
    m64 = build_model(torch).double()
    m64.load_state_dict({k: torch.from_numpy(v.astype(np.float32).astype(np.float64)) for k, v in sd.items()})
    with torch.no_grad():
        ref_out = m64(torch.from_numpy(ref_F.astype(np.float64)), torch.from_numpy(ref_J.astype(np.float64))).numpy()
    np.savez_compressed(args.out, **out, ref_F=ref_F, ref_J=ref_J, ref_out=ref_out, seed=np.int64(args.seed), m_blend=np.int64(M_BLEND),
                        steps=np.int64(step), minutes=np.float64((time.time() - t0) / 60),
                        train_clouds=np.int64(len(train)), val_loss=np.float64(vl), val_loss_jet=np.float64(jet_val),
                        val_dist=np.float64(vl_d), val_dist_jet=np.float64(jet_val_d), k=np.int64(K),
                        jet_clip=np.float64(JET_CLIP))
    print(f"done: {step} steps, {(time.time() - t0) / 60:.1f} min; validation loss {vl:.5f} (distance {vl_d:.5f}) "
          f"vs jet {jet_val:.5f} (distance {jet_val_d:.5f}); wrote {args.out}", flush=True)


if __name__ == "__main__":
    main()
