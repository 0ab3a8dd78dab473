"""Convolutional baselines of PAT (thesis ch. 3 and §5.3, Eqs. 5.8–5.9) and the winding-number pipeline.

* :class:`SignedHopfCole` — signed Hopf–Cole / screened winding number (Eq. 5.8, from Eqs. 3.7–3.13):
  w(x) = Σ A_i (λ‖x−p_i‖ + 1)⟨x − p_i, n_i⟩ / (2π‖x−p_i‖³) · exp(−λ(‖x−p_i‖ − σ_x)),
  φ = sign(w) (−log|w|/λ + σ_x).
* :class:`SmoothedSignedPlanarDistance` — Eq. 5.9, the self-normalized formula (Eq. 3.16) with the tangent
  plane g_i(x) = ⟨x − p_i, n_i⟩ and area weights.
* :class:`LogSumExpDistance` — unsigned LogSumExp distance (Eq. 3.15 with h = A_i, Madan & Levin 2022):
  d(x) = −(1/λ) log Σ A_i exp(−λ‖x − p_i‖), the areas A_i measured in units of the cloud's half-extent
  (the largest half side of its bounding box; the log of an area otherwise depends on the unit of length).
* :class:`WindingNumberPipeline` — fast winding number → marching cubes at 1/2 → signed distance to that mesh
  (the "GWN" column of §7.2).

All three kernels share σ_x, λ_x = C/σ_x and the neighbour selection of :mod:`gsdf.tori._blend` (sums over the
points within R_eval, at least the 32 nearest, at most ``k_eval``; exponents shifted by the nearest distance,
which is exact). Truncating the sums is how PAT is accelerated in §5.1.3; for the baselines it changes the
value only by weights below exp(−λ (R_eval − d_min)).

Like PAT, the kernels run in the cloud's normalised frame (:class:`gsdf._normalize.Frame`; here only its scale, a
power of two bringing the half-extent into [0.5, 1)): points, queries, areas, a fixed λ and R_eval are mapped into
it and distances mapped back, so a cloud at 1e-150 or 1e150 gives the unit cloud's answer times the scale (the
``(λd + 1)⟨x − p, n⟩/d³`` term of Eq. 5.8 and the areas would otherwise under- or overflow).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from gsdf._checks import as_points, as_values, as_weights, neighbours, positive, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf._normalize import Frame
from gsdf.tori._blend import NeighbourBlend
from gsdf.tori._pat import _clean_cloud, _sigma

__all__ = ["SignedHopfCole", "SmoothedSignedPlanarDistance", "LogSumExpDistance", "WindingNumberPipeline"]

_INV_2PI = 1.0 / (2.0 * np.pi)


@njit(parallel=True, cache=True)
def _conv_kernel(Q, D, I, P, N, A, H, C, lam_fixed, r_eval, k_fb, mode, out):
    q, k = I.shape
    for j in prange(q):
        x0, x1, x2 = Q[j, 0], Q[j, 1], Q[j, 2]
        if lam_fixed > 0.0:
            lam = lam_fixed
        else:
            sig, _ = _sigma(H, x0, x1, x2)
            lam = C / max(sig, 1e-300)
        dmin = D[j, 0]
        num = 0.0
        den = 0.0
        for m in range(k):
            d = D[j, m]
            if m >= k_fb and d > r_eval:
                break
            i = I[j, m]
            e = np.exp(-lam * (d - dmin)) * A[i]
            pn = (x0 - P[i, 0]) * N[i, 0] + (x1 - P[i, 1]) * N[i, 1] + (x2 - P[i, 2]) * N[i, 2]
            if mode == 0:  # signed Hopf–Cole, Eq. 5.8
                if d > 0.0:
                    num += (lam * d + 1.0) * pn * _INV_2PI / (d * d * d) * e
            elif mode == 1:  # smoothed signed planar distance, Eq. 5.9
                num += pn * e
                den += e
            else:  # LogSumExp, Eq. 3.15
                num += e
        if mode == 0:
            if num == 0.0:
                out[j] = dmin
            else:
                s = 1.0 if num > 0.0 else -1.0
                # φ = sign(w)(−log|w|/λ + σ) with the exponent shifted by d_min instead of σ (exact)
                out[j] = s * (-np.log(abs(num)) / lam + dmin)
        elif mode == 1:
            out[j] = num / den if den > 0.0 else 0.0
        else:
            out[j] = dmin - np.log(num) / lam if num > 0.0 else dmin


class _Convolution:
    _mode = 0

    def __init__(self, P, N, areas=None, C: float = 64.0, lam=None, r_eval=None, k_eval: int = 64,
                 k_fallback: int = 32):
        n_given = as_points(P, "P").shape[0]
        self.P, self.N = _clean_cloud(P, N, 1)
        self.C = positive(C, "C")
        self.lam = 0.0 if lam is None else positive(lam, "lam")
        r_eval = None if r_eval is None else positive(r_eval, "r_eval")
        k_eval = neighbours(k_eval, len(self.P), "k_eval", default=64)
        k_fallback = neighbours(k_fallback, len(self.P), "k_fallback", default=32)
        # scale invariance: points, areas, λ and R_eval scaled by the power of two of the cloud's normalised frame
        # (gsdf._normalize; not centred: scaling by 2^k is exact, so at ordinary scales the sums are bitwise
        # those of the input units, while a translation would move the truncated neighbour sums by ~1e-6)
        e = Frame.of(self.P).exponent
        self._frame = fr = Frame(np.zeros(3), e, e == 0)
        self._Pf = fr.geometry(self.P, "P")
        if areas is None:
            from gsdf.winding._point_areas import point_areas

            self._Af = point_areas(self._Pf, self.N) if len(self.P) > 20 else np.ones(len(self.P))
            self.areas = fr.area(self._Af)
        else:
            a = as_weights(areas, n_given, "areas")
            if len(a) != len(self.P):
                raise ValueError("areas: cannot be combined with duplicate points or zero normals; clean the cloud first")
            self.areas = a
            self._Af = fr.inverse_area(a)
            if not (np.isfinite(self._Af).all() and (self._Af > 0).any()):
                raise ValueError("areas: too small or too large to represent relative to the cloud's size")
        self._lam_f = 0.0 if lam is None else float(fr.length(self.lam))
        if r_eval is not None:
            r_eval = min(float(fr.inverse_length(r_eval)), 1e150)  # the cloud spans ~2 frame units
            if not r_eval > 0:
                raise ValueError("r_eval: too small to represent relative to the cloud's size")
        self._blend = NeighbourBlend(self._Pf, self.C, r_eval, k_eval, k_fallback)

    @query_shaped()
    def __call__(self, Q) -> np.ndarray:
        b = self._blend
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        Qf, excess = self._frame.queries(Q, want_excess=True)

        def fn(q, d, i, out):
            _conv_kernel(q, d, i, self._Pf, self.N, self._Af, b.hull, self.C, self._lam_f, b.r_eval, b.k_fallback,
                         self._mode, out)

        out = b.map(Qf, fn)
        # a clamped far query (gsdf._normalize.FAR) is farther by ``excess``: the distances grow by it
        return self._frame.length(out + np.copysign(excess, out))


class SignedHopfCole(_Convolution):
    """Signed Hopf–Cole distance (screened winding number), Eq. 5.8; negative inside.

    Parameters
    ----------
    P, N : (n, 3) float
        Oriented points (outward normals, any length), model units.
    areas : (n,) float, optional
        Point areas A_i (square model units); default :func:`gsdf.point_areas` (k = 20; ones below 21 points).
    C : float, default 64.0
        Screening constant of Eq. 5.7: λ_x = C / σ_x, σ_x the query's distance scale (thesis §5.1.3); larger is
        sharper. Ignored when ``lam`` is given.
    lam : float, optional
        A fixed screening λ (1 / model units) instead of the per-query C / σ_x.
    r_eval : float, optional
        Summation radius R_eval, model units: points within it are summed. Default: twice the median distance
        from a point to its 32nd neighbour.
    k_eval : int, default 64
        Most points summed per query.
    k_fallback : int, default 32
        Points summed (the nearest) when fewer than this many lie within R_eval (§5.1.3).

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite values, negative or all-zero areas, non-positive constants.

    Notes
    -----
    Calling the object, ``f(Q)``, is the same as :meth:`signed_distance`.

    Examples
    --------
    >>> import numpy as np
    >>> i = np.arange(2000) + 0.5
    >>> ph, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
    >>> P = 0.5 * np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    >>> np.sign(SignedHopfCole(P, P)([[0, 0, 0.3], [0, 0, 0.7]])).tolist()
    [-1.0, 1.0]
    """

    _mode = 0

    @query_shaped()
    def signed_distance(self, Q) -> np.ndarray:
        """φ_SHC (Eq. 5.8) at the query points.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        (q,) float64
            Signed distance estimate, negative inside.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> P = np.array([[x, y, 0.0] for x in range(-3, 4) for y in range(-3, 4)])
        >>> f = gsdf.SignedHopfCole(P, np.tile([0, 0, 1.0], (49, 1)), areas=np.ones(49))
        >>> bool(f.signed_distance([[0.0, 0.0, 0.5]])[0] > 0)
        True
        """
        return self(Q)


class SmoothedSignedPlanarDistance(_Convolution):
    """Smoothed signed planar distance, Eq. 5.9 (self-normalized tangent-plane blend); negative inside.

    Parameters
    ----------
    P, N : (n, 3) float
        Oriented points (outward normals, any length), model units.
    areas : (n,) float, optional
        Point areas A_i (square model units); default :func:`gsdf.point_areas` (k = 20; ones below 21 points).
    C : float, default 64.0
        Screening constant of Eq. 5.7: λ_x = C / σ_x, σ_x the query's distance scale (thesis §5.1.3); larger is
        sharper. Ignored when ``lam`` is given.
    lam : float, optional
        A fixed screening λ (1 / model units) instead of the per-query C / σ_x.
    r_eval : float, optional
        Summation radius R_eval, model units: points within it are summed. Default: twice the median distance
        from a point to its 32nd neighbour.
    k_eval : int, default 64
        Most points summed per query.
    k_fallback : int, default 32
        Points summed (the nearest) when fewer than this many lie within R_eval (§5.1.3).

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite values, negative or all-zero areas, non-positive constants.

    Notes
    -----
    Calling the object, ``f(Q)``, is the same as :meth:`signed_distance`.

    Examples
    --------
    >>> import numpy as np
    >>> P = np.array([[x, y, 0.0] for x in range(-3, 4) for y in range(-3, 4)])
    >>> SmoothedSignedPlanarDistance(P, np.tile([0, 0, 1.0], (49, 1)), areas=np.ones(49))([[0.2, 0.1, 0.5]]).tolist()
    [0.5]
    """

    _mode = 1

    @query_shaped()
    def signed_distance(self, Q) -> np.ndarray:
        """φ_SSPD (Eq. 5.9) at the query points.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        (q,) float64
            Signed distance estimate, negative inside.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> P = np.array([[x, y, 0.0] for x in range(-3, 4) for y in range(-3, 4)])
        >>> f = gsdf.SmoothedSignedPlanarDistance(P, np.tile([0, 0, 1.0], (49, 1)), areas=np.ones(49))
        >>> f.signed_distance([[0.2, 0.1, -0.5]]).tolist()
        [-0.5]
        """
        return self(Q)


class LogSumExpDistance(_Convolution):
    """Unsigned LogSumExp distance (Eq. 3.15 with h = A_i; Madan & Levin 2022). Normals are not used.

    Parameters
    ----------
    P : (n, 3) float
        Points, model units.
    N : (n, 3) float, optional
        Ignored (accepted for the same call as the signed baselines).
    areas : (n,) float, optional
        Point areas A_i (square model units); default :func:`gsdf.point_areas` (k = 20; ones below 21 points).
    C : float, default 64.0
        Screening constant of Eq. 5.7: λ_x = C / σ_x, σ_x the query's distance scale (thesis §5.1.3); larger is
        sharper. Ignored when ``lam`` is given.
    lam : float, optional
        A fixed screening λ (1 / model units) instead of the per-query C / σ_x.
    r_eval : float, optional
        Summation radius R_eval, model units: points within it are summed. Default: twice the median distance
        from a point to its 32nd neighbour.
    k_eval : int, default 64
        Most points summed per query.
    k_fallback : int, default 32
        Points summed (the nearest) when fewer than this many lie within R_eval (§5.1.3).
    **kw
        ``areas``, ``C``, ``lam``, ``r_eval``, ``k_eval``, ``k_fallback`` as above, by keyword.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite values, negative or all-zero areas, non-positive constants.

    Notes
    -----
    Calling the object, ``f(Q)``, is the same as :meth:`unsigned_distance`.

    Examples
    --------
    >>> import numpy as np
    >>> d = LogSumExpDistance([[0, 0, 0.0], [5, 0, 0.0]], None, areas=np.ones(2), lam=50.0)([[0, 0, 1.0]])
    >>> d.round(3).tolist()
    [1.0]
    """

    _mode = 2

    def __init__(self, P, N=None, **kw):
        P = as_points(P, "P")
        super().__init__(P, np.tile([0.0, 0.0, 1.0], (len(P), 1)) if N is None else N, **kw)
        # log Σ A_i e^{−λ d_i} depends on the unit of the areas: measure them in units of the cloud's half-extent
        # h (the largest half side of its bounding box), so that the distance scales with the cloud; a cloud with
        # h = 1 gets Eq. 3.15 with its areas as given
        half = float(np.max(0.5 * self._Pf.max(axis=0) - 0.5 * self._Pf.min(axis=0)))
        if half > 0:
            self._Af = self._Af / (half * half)

    @query_shaped()
    def unsigned_distance(self, Q) -> np.ndarray:
        """LogSumExp distance (Eq. 3.15) at the query points.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        (q,) float64
            Unsigned distance estimate (a smooth minimum of the distances to the points).

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> f = gsdf.LogSumExpDistance([[0, 0, 0.0], [5, 0, 0.0]], None, areas=np.ones(2), lam=50.0)
        >>> f.unsigned_distance([[0, 0, 2.0]]).round(3).tolist()
        [2.0]
        """
        return self(Q)


class WindingNumberPipeline:
    """Fast winding number → marching cubes at 1/2 → signed distance to that mesh (the §7.2 "GWN" pipeline).

    Parameters
    ----------
    P, N : (n, 3) float
        Oriented points (outward normals), model units.
    bbox_min, bbox_max : (3,) float, optional
        Box contoured (default: the cloud's bounding box grown by 0.1 of its diagonal on every side; a corner
        not given is that box's).
    resolution : int or gsdf.Grid, default 64
        Marching-cubes grid nodes along the longest side of the box (64 as in §7.2); or the
        :class:`gsdf.Grid` to contour on (then omit the box).
    areas : (n,) float, optional
        Point areas for the winding number (default: estimated, k = 20).

    Attributes
    ----------
    V, F
        The extracted mesh, (nv, 3) float64 and (nf, 3) int64.

    Raises
    ------
    ValueError
        Bad inputs, or a winding number that never crosses 1/2 in the box (no surface).

    Notes
    -----
    Calling the object, ``f(Q)``, is the same as :meth:`signed_distance`.

    Examples
    --------
    >>> import numpy as np
    >>> i = np.arange(2000) + 0.5
    >>> ph, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
    >>> P = 0.5 * np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    >>> WindingNumberPipeline(P, P, resolution=32)([[0, 0, 0], [0, 0, 1.0]]).round(1).tolist()
    [-0.5, 0.5]
    """

    def __init__(self, P, N, bbox_min=None, bbox_max=None, resolution: int = 64, areas=None):
        from gsdf.contour import extract_isosurface
        from gsdf.distance import TriangleDistance
        from gsdf.winding import FastWindingNumber, FastWindingNumberPoints

        from gsdf.grid import Grid, padded_box

        P = as_points(P, "P")
        fwn = FastWindingNumberPoints(P, N, areas=areas)
        if (bbox_min is None or bbox_max is None) and not isinstance(resolution, Grid):
            lo, hi = padded_box(P)  # the corner not given
            bbox_min = lo if bbox_min is None else as_values(bbox_min, "bbox_min", (3,))
            bbox_max = hi if bbox_max is None else as_values(bbox_max, "bbox_max", (3,))
        self.V, self.F = extract_isosurface(fwn, bbox_min, bbox_max, resolution, level=0.5, inside="above")
        if len(self.F) == 0:
            raise ValueError("the winding number of the cloud never crosses 1/2 in the box: no surface to measure")
        self._dist = TriangleDistance(self.V, self.F)
        self._fwn = FastWindingNumber(self.V, self.F)

    @query_shaped()
    def __call__(self, Q) -> np.ndarray:
        """Signed distance to the extracted mesh at the query points.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        (q,) float64
            Exact distance to the mesh, negative where its winding number exceeds 1/2.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> i = np.arange(2000) + 0.5
        >>> ph, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
        >>> P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
        >>> gsdf.WindingNumberPipeline(P, P, resolution=24).signed_distance([[0, 0, 0]]).round(1).tolist()
        [-1.0]
        """
        d = self._dist.query(Q)[0]
        w = self._fwn(Q)
        return np.where(w > 0.5, -d, d)

    signed_distance = __call__
