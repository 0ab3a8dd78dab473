"""Points as Tori (thesis ch. 5) and the convolutional baselines (ch. 3, Eqs. 5.8–5.9).

Modules: ``_torus`` (torus geometry from six height-field coefficients, Eqs. 5.2–5.4), ``_fit`` (jet fitting),
``_learned`` (the trained coefficient regressor of §5.1.2, numpy inference, weights in ``pat_weights.npz``),
``_blend`` (σ_x, λ_x and neighbour selection of Eq. 5.7), ``_pat`` (PointsAsTori, Eq. 5.6), ``_baselines``
(signed Hopf–Cole, smoothed signed planar distance, LogSumExp, winding-number pipeline), ``_ops`` (booleans and
offsets of pointwise SDFs, §5.2).
"""

from gsdf.tori._baselines import (
    LogSumExpDistance,
    SignedHopfCole,
    SmoothedSignedPlanarDistance,
    WindingNumberPipeline,
)
from gsdf.tori._pat import PointsAsTori, PointsAsToriOptions
from gsdf.tori._ops import contour, difference, intersection, offset, union
from gsdf.tori._torus import coefficients_to_tori, torus_sdf

__all__ = ["PointsAsTori", "PointsAsToriOptions", "SignedHopfCole", "SmoothedSignedPlanarDistance", "LogSumExpDistance",
           "WindingNumberPipeline", "coefficients_to_tori", "torus_sdf", "union", "intersection", "difference",
           "offset", "contour"]
