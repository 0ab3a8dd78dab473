"""Tests of gsdf.recon._relocate: the moving-least-squares local surface, the face-preserving vertex
relocation (with its flip damping), and its use as the last step of reconstruct_simply_connected."""

import numpy as np
import pytest

import gsdf
from gsdf.recon._relocate import _face_normals, local_surface, relocate_vertices
from gsdf.mesh._topology import is_sphere


def _fibonacci(n, r=1.0):
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    return r * np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])


def _icosphere(level=2):
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    V = list(V / np.linalg.norm(V, axis=1)[:, None])
    for _ in range(level):
        mid, F2 = {}, []
        for a, b, c in F:
            ids = []
            for u, v in ((a, b), (b, c), (c, a)):
                key = (min(u, v), max(u, v))
                if key not in mid:
                    m = V[u] + V[v]
                    V.append(m / np.linalg.norm(m))
                    mid[key] = len(V) - 1
                ids.append(mid[key])
            ab, bc, ca = ids
            F2 += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        F = np.array(F2)
    return np.array(V), np.asarray(F, dtype=np.int64)


# ---------------------------------------------------------------- local surface
def test_local_surface_projects_onto_a_sphere():
    S = _fibonacci(4000)
    rng = np.random.default_rng(1)
    Q = _fibonacci(300) * rng.uniform(0.95, 1.05, (300, 1))
    foot, n, h = local_surface(Q, S, spacing=0.056)
    # the quadric fit recovers the curved surface: feet within 1e-3 of the unit sphere (a plane fit would leave
    # the sagitta, ~ 2e-3 here), heights = radial offsets, normals radial
    assert np.abs(np.linalg.norm(foot, axis=1) - 1).max() < 1e-3
    np.testing.assert_allclose(np.abs(h), np.abs(np.linalg.norm(Q, axis=1) - 1), atol=1.5e-3)
    radial = Q / np.linalg.norm(Q, axis=1)[:, None]
    assert np.abs(np.einsum("qx,qx->q", n, radial)).min() > 0.99


def test_local_surface_leave_one_out_flags_off_surface_points():
    S = _fibonacci(3000)
    off = np.arange(5, 3000, 300)                 # 10 scattered points moved off the sphere by ~0.8 spacing
    S[off] *= 1.05
    _, _, h, rms = local_surface(S, S, spacing=0.065, exclude_self=True, return_fit=True)
    rest = np.setdiff1d(np.arange(3000), off)
    assert np.abs(h[off]).min() > 0.045 and np.abs(h[rest]).max() < 0.025   # neighbours see the moved points a little
    assert rms.shape == (3000,) and np.isfinite(rms).all()


# ---------------------------------------------------------------- relocation
def test_relocation_moves_free_vertices_onto_the_surface_and_keeps_the_rest():
    V, F = _icosphere(3)
    S = _fibonacci(5000)
    rng = np.random.default_rng(0)
    free = rng.random(len(V)) < 0.4
    Vp = V.copy()
    Vp[free] *= rng.uniform(0.97, 1.03, (free.sum(), 1))        # free vertices off the surface
    Vp[free] += rng.normal(scale=0.01, size=(free.sum(), 3))
    Vin = Vp.copy()
    W, rep = relocate_vertices(Vp, F, S, spacing=0.05, fixed=~free, return_report=True)
    assert np.array_equal(Vp, Vin)                               # input untouched
    assert np.array_equal(W[~free], Vp[~free])                   # fixed vertices exactly where they were
    before = np.abs(np.linalg.norm(Vp[free], axis=1) - 1)
    after = np.abs(np.linalg.norm(W[free], axis=1) - 1)
    assert after.mean() < 0.1 * before.mean() and after.max() < 3e-3
    assert rep["moved"] == free.sum() and rep["reverted"] == 0
    assert is_sphere(W, F)                                       # same faces: same topology


def test_relocation_damps_and_undoes_moves_that_would_flip_faces():
    # a fan: free centre vertex, fixed hexagon ring in z = 0; the samples lie on the plane z = x − 3, whose
    # foot of the centre is outside the ring — the raw move would turn the fan inside out
    ang = np.arange(6) * np.pi / 3
    V = np.vstack([[0.8, 0.0, 0.0], np.column_stack([np.cos(ang), np.sin(ang), np.zeros(6)])])
    F = np.array([[0, 1 + i, 1 + (i + 1) % 6] for i in range(6)])
    g = np.linspace(-3, 6, 40)
    S = np.array([[x, y, x - 3.0] for x in g for y in np.linspace(-4, 4, 36)])
    fixed = np.arange(7) > 0
    foot, _, _ = local_surface(V[:1], S, spacing=1.0)
    raw = V.copy()
    raw[0] = foot[0]
    n0 = _face_normals(V, F)
    assert (np.einsum("fx,fx->f", _face_normals(raw, F), n0) <= 0).any()      # the undamped move flips
    W, rep = relocate_vertices(V, F, S, spacing=1.0, fixed=fixed, smooth=0.0, rounds=3, return_report=True)
    assert (np.einsum("fx,fx->f", _face_normals(W, F), n0) > 0).all()
    assert rep["damped"] + rep["reverted"] >= 1
    # the centre still moved towards the samples' plane (damped, not frozen)
    d = lambda p: abs(p[0] - p[2] - 3.0) / 2 ** 0.5                            # noqa: E731
    assert d(W[0]) < d(V[0])


@pytest.mark.parametrize("kw, match", [
    (dict(V=np.full((4, 3), np.nan)), "V"),
    (dict(F=np.array([[0, 1, 9]])), "F"),
    (dict(spacing=0.0), "spacing"),
    (dict(spacing=True), "spacing"),
    (dict(S=np.zeros((2, 3))), "S"),
    (dict(fixed=np.zeros(4, dtype=int)), "fixed"),
    (dict(fixed=np.zeros(3, dtype=bool)), "fixed"),
    (dict(rounds=True), "rounds"),
    (dict(smooth=1.5), "smooth"),
    (dict(fit_tol=-1.0), "fit_tol"),
])
def test_relocation_bad_input(kw, match):
    args = dict(V=np.eye(4)[:, :3], F=np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
                S=np.random.default_rng(0).normal(size=(20, 3)), spacing=0.1)
    args.update(kw)
    V, F, S, spacing = args.pop("V"), args.pop("F"), args.pop("S"), args.pop("spacing")
    with pytest.raises(ValueError, match=match):
        relocate_vertices(V, F, S, spacing, **args)


# ---------------------------------------------------------------- in the pipeline
def test_reconstruction_relocation_keeps_input_points_and_the_sphere():
    rng = np.random.default_rng(3)
    P = _fibonacci(1500)
    P = P[P[:, 2] < 0.8]                                          # a gap: the surface crosses it on Steiner points
    out = _fibonacci(60) * rng.uniform(1.01, 1.03, (60, 1))      # near-surface outliers
    P = np.vstack([P, out])
    # without the global fit, input points on the surface keep their exact coordinates; the other vertices
    # (Steiner points, kept outliers) are relocated onto the samples' surface
    V, F, rep = gsdf.reconstruct_simply_connected(P, return_report=True,
                                                  options=gsdf.ReconstructionOptions(subdivide=0, fit=False))
    assert is_sphere(V, F)
    on = np.abs(np.linalg.norm(V, axis=1) - 1) < 1e-12
    assert on.sum() > 1000 and rep["relocation"]["moved"] > 0
    off = ~on                          # the others within the outliers' own distance (1-3 % of the radius)
    assert np.abs(np.linalg.norm(V[off], axis=1) - 1).mean() < 0.03


def _local_surface_numpy(Q, S, spacing, k, extra=0):
    """The straightforward numpy formulation of local_surface (its first implementation: einsum moments,
    batched eigh, batched 6 × 6 solve), an independent check of the numba kernels."""
    from scipy.spatial import cKDTree
    d, I = cKDTree(S).query(Q, k=k + extra)
    d, I = d[:, extra:], I[:, extra:]
    Y = S[I]
    h = np.maximum(1.5 * spacing, np.median(d, axis=1))
    w = np.exp(-(d / h[:, None]) ** 2)
    w /= w.sum(axis=1, keepdims=True)
    c = np.einsum("qk,qkx->qx", w, Y)
    R = Y - c[:, None, :]
    _, vec = np.linalg.eigh(np.einsum("qk,qki,qkj->qij", w, R, R))
    t1, t2, n = vec[:, :, 2], vec[:, :, 1], vec[:, :, 0]
    x, y, z = (np.einsum("qkx,qx->qk", R, t) / s for t, s in ((t1, h[:, None]), (t2, h[:, None]), (n, 1.0)))
    B = np.stack([np.ones_like(x), x, y, x * x, x * y, y * y], axis=2)
    A = np.einsum("qk,qka,qkb->qab", w, B, B) + np.diag([1e-9, 1e-9, 1e-9, 1e-2, 1e-2, 1e-2])[None]
    coef = np.linalg.solve(A, np.einsum("qk,qka,qk->qa", w, B, z)[:, :, None])[:, :, 0]
    Rq = Q - c
    xq, yq, zq = (np.einsum("qx,qx->q", Rq, t) for t in (t1, t2, n))
    xq, yq = xq / h, yq / h
    zf = coef @ np.array([1.0, 0, 0, 0, 0, 0]) + coef[:, 1] * xq + coef[:, 2] * yq + coef[:, 3] * xq ** 2 \
        + coef[:, 4] * xq * yq + coef[:, 5] * yq ** 2
    rms = np.sqrt(np.einsum("qk,qk->q", w, (z - np.einsum("qka,qa->qk", B, coef)) ** 2))
    return Q + (zf - zq)[:, None] * n, n, zq - zf, rms


@pytest.mark.parametrize("k, extra", [(8, 0), (12, 1), (7, 0)])
def test_local_surface_kernels_match_the_numpy_formulation(k, extra):
    rng = np.random.default_rng(k)
    S = _fibonacci(2000) * np.array([1.0, 0.7, 0.5]) + rng.normal(scale=0.004, size=(2000, 3))
    Q = S[:300] if extra else S[:300] * rng.uniform(0.95, 1.05, (300, 1))
    foot, n, hgt, rms = local_surface(Q, S, 0.05, k=k, exclude_self=bool(extra), return_fit=True)
    foot0, n0, hgt0, rms0 = _local_surface_numpy(Q, S, 0.05, k, extra)
    np.testing.assert_allclose(foot, foot0, atol=1e-12)
    np.testing.assert_allclose(np.abs(np.einsum("qx,qx->q", n, n0)), 1.0, atol=1e-12)   # n unoriented
    np.testing.assert_allclose(np.abs(hgt), np.abs(hgt0), atol=1e-12)
    np.testing.assert_allclose(rms, rms0, atol=1e-12)
