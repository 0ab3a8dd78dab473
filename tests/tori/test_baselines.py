"""The convolutional baselines are scale-safe (issue: at 1e-150 the signed Hopf–Cole gave ±inf / NaN and at 1e150
lost every sign; the smoothed signed planar distance gave 0 / ±inf; LogSumExp came out 6.4x too large or
negative): they run in the cloud's power-of-two frame, and LogSumExp measures its areas in units of the cloud's
half-extent."""

import numpy as np
import pytest

import gsdf
from tests.shapes import fibonacci_sphere

NAMES = ("SignedHopfCole", "SmoothedSignedPlanarDistance", "LogSumExpDistance")
Q = np.array([[0.1, 0.05, 0], [0.5, 0.1, 0], [2, 0, 0.3], [0, 0.2, 1.5]])

# the previous code (input units, before the frame) on fibonacci_sphere(300) at Q: the frame only scales by a
# power of two, so the signed baselines are bit-identical at ordinary scales
OLD = {"SignedHopfCole": [-0.8692581182673145, -0.48205521900435755, 1.0398442368488403, 0.5296758340685678],
       "SmoothedSignedPlanarDistance": [-0.8959267280970677, -0.49593179369442153, 0.9971907504456218,
                                        0.4964298327725898]}


@pytest.mark.parametrize("name", sorted(OLD))
def test_signed_baselines_unchanged_at_scale_one(name):
    P = fibonacci_sphere(300)
    assert np.asarray(getattr(gsdf, name)(P, P)(Q)).tolist() == OLD[name]


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("s", [1e-150, 1e150, 3.0, 2.0 ** -40])
def test_scale_covariant(name, s):
    rng = np.random.default_rng(1)
    P = rng.normal(size=(400, 3))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    P *= 1 + 0.1 * rng.random((400, 1))  # no exact ties among neighbour distances
    ref = np.asarray(getattr(gsdf, name)(P, P)(Q))
    d = np.asarray(getattr(gsdf, name)(P * s, P)(Q * s)) / s
    assert np.isfinite(d).all()
    np.testing.assert_allclose(d, ref, rtol=1e-9, atol=1e-12)
    assert (np.sign(d) == np.sign(ref)).all()


def test_given_areas_and_lambda_scale_too():
    P = fibonacci_sphere(300)
    a = np.full(300, 4 * np.pi / 300)
    ref = gsdf.SignedHopfCole(P, P, areas=a, lam=40.0, r_eval=1.5)(Q)
    s = 1e150
    d = gsdf.SignedHopfCole(P * s, P, areas=a * s * s, lam=40.0 / s, r_eval=1.5 * s)(Q * s) / s
    np.testing.assert_allclose(d, ref, rtol=1e-9)
    with pytest.raises(ValueError, match="areas: expected real numbers, got complex"):
        gsdf.SignedHopfCole(P, P, areas=a + 1j)
    with pytest.raises(ValueError, match="areas: contains NaN"):
        gsdf.SignedHopfCole(P, P, areas=a * np.nan)


@pytest.mark.parametrize("name", NAMES)
def test_neighbour_counts_beyond_the_cloud_are_refused(name):
    P = fibonacci_sphere(300)
    for key in ("k_eval", "k_fallback"):
        with pytest.raises(ValueError, match=f"{key}: 1000000000 neighbours asked for"):
            getattr(gsdf, name)(P, P, **{key: 10**9})


def test_winding_pipeline_checks_the_corner_it_is_given():
    P = fibonacci_sphere(300)
    for key, bad in (("bbox_min", []), ("bbox_max", [1.0, 2.0]), ("bbox_min", "abc")):
        with pytest.raises(ValueError, match=key):
            gsdf.WindingNumberPipeline(P, P, resolution=16, **{key: bad})
    W = gsdf.WindingNumberPipeline(P, P, resolution=16, bbox_min=[-1.5, -1.5, -1.5])
    assert W.V.min() > -1.5
