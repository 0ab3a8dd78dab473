"""Points as Tori, learned estimator (thesis §5.1.2): shipped weights, numpy inference, accuracy."""

import os
import subprocess
import sys

import numpy as np

from gsdf.data import _shapes as S
from gsdf.tori._learned import WEIGHTS, LearnedEstimator, neighbourhood_features, scaled_jet, unscale
from gsdf.tori._pat import PointsAsTori


def _fib_sphere(n=2000, radius=0.5):
    i = np.arange(n) + 0.5
    ph, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    N = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    return radius * N, N


def test_weights_ship_small_and_numpy_inference_matches_torch_reference():
    assert os.path.getsize(WEIGHTS) <= 10 * 2 ** 20
    est = LearnedEstimator()
    z = np.load(WEIGHTS)
    # reference batch evaluated by the torch model (float64) at the end of scripts/train_pat.py
    got = est.forward(z["ref_F"].astype(np.float64), z["ref_J"].astype(np.float64))
    np.testing.assert_allclose(got, z["ref_out"], atol=1e-6, rtol=0)


def test_feature_scaling_roundtrip_and_invariance():
    P, N = _fib_sphere(500)
    from scipy.spatial import cKDTree

    d, i = cKDTree(P).query(P, 64)
    F, h = neighbourhood_features(P, N, i, d)
    F2, h2 = neighbourhood_features(3.0 * P + 1.0, N, i, 3.0 * d)  # scaled + translated cloud
    np.testing.assert_allclose(F, F2, atol=1e-9)
    np.testing.assert_allclose(h2, 3 * h)
    A = np.random.default_rng(0).normal(size=(500, 6)) * 0.1
    np.testing.assert_allclose(unscale(scaled_jet(A * [h[0], 1, 1, 1 / h[0], 1 / h[0], 1 / h[0]], h), h),
                               A * [h[0], 1, 1, 1 / h[0], 1 / h[0], 1 / h[0]], atol=1e-12)


def test_learned_sphere_and_cylinder_are_accurate(tmp_path):
    P, N = _fib_sphere()
    X = S.grid(16)
    pat = PointsAsTori(P, N, estimator="learned")
    err = np.abs(pat(X) - S.sphere_sdf(X, 0.5))
    assert np.isfinite(err).all() and err.mean() < 5e-3
    f = tmp_path / "learned.npz"
    pat.save(f)
    again = PointsAsTori.load(f)
    assert again.estimator == "learned"
    np.testing.assert_array_equal(again(X), pat(X))
    rng = np.random.default_rng(1)
    P, N = S.sample_cylinder(2048, 0.3, rng)
    pat = PointsAsTori(P, N, estimator="learned")
    X = S.grid(16)
    tr = S.cylinder_sdf(X, 0.3)
    phi = pat(X)
    assert np.isfinite(phi).all()
    assert np.abs(phi - tr).mean() < 0.1  # over [-1, 1]³; PAT (jet) has 0.08 here (far-field corners)
    assert np.abs(phi - tr)[np.abs(tr) < 0.2].mean() < 0.02
    assert (np.sign(phi) == np.sign(tr))[np.abs(tr) > 0.05].mean() > 0.99


def test_runtime_never_imports_torch():
    code = ("import sys, numpy as np, gsdf; from gsdf.tori._pat import PointsAsTori; P = np.random.default_rng(0)"
            ".normal(size=(300, 3)); N = P / np.linalg.norm(P, axis=1)[:, None]; P = N.copy(); "
            "PointsAsTori(P, N, estimator='learned')([[0, 0, 0.0]]); assert 'torch' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)
