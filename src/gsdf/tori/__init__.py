"""Points as Tori (thesis ch. 5) and the convolutional baselines (ch. 3, Eqs. 5.8–5.9).

Modules: ``torus`` (torus geometry from six height-field coefficients, Eqs. 5.2–5.4), ``fit`` (jet fitting), ``learned`` (the trained
coefficient regressor of §5.1.2, numpy inference, weights in ``pat_weights.npz``),
``blend`` (σ_x, λ_x and neighbour selection of Eq. 5.7), ``pat`` (PointsAsTori, Eq. 5.6), ``baselines``
(signed Hopf–Cole, smoothed signed planar distance, LogSumExp, winding-number pipeline), ``render``
(sphere tracing), ``ops`` (booleans and offsets of pointwise SDFs, §5.2), ``shapes`` (analytic shapes and the
§7.2 corruptions).
"""

from .baselines import LogSumExpDistance, SignedHopfCole, SmoothedSignedPlanarDistance, WindingNumberPipeline
from .pat import PointsAsTori
from .ops import contour, difference, intersection, offset, union
from .render import render_png, sphere_trace
from .torus import coefficients_to_tori, torus_sdf

__all__ = ["PointsAsTori", "SignedHopfCole", "SmoothedSignedPlanarDistance", "LogSumExpDistance",
           "WindingNumberPipeline", "coefficients_to_tori", "torus_sdf", "sphere_trace", "render_png", "union", "intersection", "difference",
           "offset", "contour"]
