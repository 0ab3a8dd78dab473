"""Comparison reconstructions on the API shape of ``reconstruct_simply_connected``, with their topology.

The level sets gsdf could already extract from a point cloud — the fast winding number ½ level set (Barill
2018), the zero set of the signed heat method in a volume (Feng & Crane 2024 §8) and the zero set of Points as
Tori (Feng 2026 ch. 5) — carry no topological promise: on outlier-ridden clouds they break into many components
or grow handles.  Each function returns ``(V, F)`` or ``(V, F, report)`` with ``report["components"]``,
``report["genus"]`` (per component, None when not closed-manifold), ``report["manifold"]`` and timings, so the
difference is measured, not asserted.  Unoriented input gets the same normals as the guaranteed method
(PCA, propagated by :func:`gsdf.recon._orient.orient_normals`); given normals are used as they are.

Example
-------
>>> import numpy as np
>>> from gsdf.recon._compare import reconstruct_winding
>>> P = np.random.default_rng(0).normal(size=(1500, 3)); P /= np.linalg.norm(P, axis=1)[:, None]
>>> V, F, rep = reconstruct_winding(P, resolution=32, return_report=True)
>>> rep["components"], rep["genus"]
(1, [0])
"""

from __future__ import annotations

import time

import numpy as np

from gsdf._checks import as_normals, as_points, integer
from gsdf.mesh._topology import mesh_topology

__all__ = ["reconstruct_winding", "reconstruct_heat", "reconstruct_pat", "oriented_normals"]


def oriented_normals(P, N=None) -> np.ndarray:
    """(n, 3) unit normals: ``N`` normalised if given, else PCA normals oriented by MST propagation."""
    P = as_points(P, "P")
    if len(P) < 4:
        raise ValueError(f"P: needs at least 4 points, got {len(P)}")
    if N is not None:
        N = as_normals(N, len(P), "N")
        return N / np.maximum(np.linalg.norm(N, axis=1), 1e-300)[:, None]
    from gsdf.recon._orient import orient_normals
    from gsdf.recon._cloud import pca_normals
    return orient_normals(P, pca_normals(P))


def _box(P, pad=0.1):
    lo, hi = P.min(axis=0), P.max(axis=0)
    d = float(np.linalg.norm(hi - lo))
    return lo - pad * d, hi + pad * d


def _finish(V, F, t0, return_report, extra=None):
    if not return_report:
        return V, F
    top = mesh_topology(V, F)
    rep = {"components": top["components"], "genus": top["genus"],
           "manifold": bool(top["closed"] and top["edge_manifold"] and top["vertex_manifold"]),
           "topology": top, "time": time.perf_counter() - t0}
    rep.update(extra or {})
    return V, F, rep


def reconstruct_winding(P, N=None, *, resolution: int = 128, return_report: bool = False):
    """The ½ level set of the fast winding number of the oriented cloud (Barill et al. 2018, §3.2, Fig. 9)."""
    from gsdf.contour import extract_isosurface
    from gsdf.winding import FastWindingNumberPoints
    t0 = time.perf_counter()
    resolution = integer(resolution, "resolution", lo=2)
    P = as_points(P, "P")
    Nn = oriented_normals(P, N)
    fwn = FastWindingNumberPoints(P, Nn)
    lo, hi = _box(P)
    V, F = extract_isosurface(fwn, lo, hi, resolution=resolution, level=0.5)
    return _finish(V, F, t0, return_report)


def reconstruct_heat(P, N=None, *, resolution: int = 96, return_report: bool = False, **kwargs):
    """The zero set of the signed heat method on a grid (Feng & Crane 2024, §8.2); kwargs go to
    :func:`gsdf.signed_heat_volume`."""
    from gsdf.heat.volume import signed_heat_volume
    t0 = time.perf_counter()
    P = as_points(P, "P")
    Nn = oriented_normals(P, N)
    field = signed_heat_volume(points=(P, Nn), domain="grid", resolution=resolution, **kwargs)
    V, F = field.isosurface(0.0)
    return _finish(V, F, t0, return_report)


def reconstruct_pat(P, N=None, *, resolution: int = 96, return_report: bool = False, **kwargs):
    """The zero set of Points as Tori (Feng 2026, Eq. 5.6); kwargs go to :class:`gsdf.PointsAsTori`."""
    from gsdf.contour import extract_isosurface
    from gsdf.tori import PointsAsTori
    t0 = time.perf_counter()
    resolution = integer(resolution, "resolution", lo=2)
    P = as_points(P, "P")
    Nn = oriented_normals(P, N)
    pat = PointsAsTori(P, Nn, **kwargs)
    lo, hi = _box(P)
    V, F = extract_isosurface(pat.signed_distance, lo, hi, resolution=resolution, level=0.0, inside="below")
    return _finish(V, F, t0, return_report)
