"""Points as Tori: pointwise generalized signed distance of an oriented point cloud (thesis ch. 5, §5.1).

Precomputation: one torus per point from six height-field coefficients (§5.1.1, Eqs. 5.2–5.4) estimated on its
k = 64 nearest neighbours (``estimator="jet"``: weighted least squares, :mod:`gsdf.tori._fit`;
``estimator="learned"``: the trained network of §5.1.2, :mod:`gsdf.tori._learned`).
Evaluation (§5.1.3, Eqs. 5.6–5.7):

    φ(x) = Σ_i g_i(x) exp(−λ_x (‖x − p_i‖ − σ_x)) / Σ_i exp(−λ_x (‖x − p_i‖ − σ_x)),
    σ_x = ½ max_i ‖x − p_i‖,  λ_x = C / σ_x,  C = 64,

summed over the points within R_eval of x (at least the 32 nearest). The gradient is analytic: with
w_i the weights and ℓ_i = −λ_x ‖x − p_i‖ their log (terms common to all i cancel in the ratio),

    ∇φ = Σ w_i ∇g_i / W + Σ w_i (g_i − φ) ∇ℓ_i / W,   ∇ℓ_i = −λ_x (x − p_i)/‖x − p_i‖ − ‖x − p_i‖ ∇λ_x,
    ∇λ_x = −(C/σ_x²) ∇σ_x,  ∇σ_x = ½ (x − p_far)/‖x − p_far‖.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numba import njit, prange

from gsdf._checks import as_points, choice, finite, integer, neighbours, nonnegative, positive, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf._normalize import Frame
from gsdf.grid import PAD, Grid, padded_box
from gsdf.threads import apply_env
from gsdf.tori._blend import NeighbourBlend
from gsdf.tori._fit import jet_coefficients
from gsdf.tori._torus import TORUS_WIDTH, coefficients_to_tori, torus_eval

__all__ = ["PointsAsTori", "PointsAsToriOptions", "level_grid"]


@njit(cache=True, inline="always")
def _sigma(H, x0, x1, x2):
    best, bj = -1.0, 0
    for j in range(H.shape[0]):
        a, b, c = x0 - H[j, 0], x1 - H[j, 1], x2 - H[j, 2]
        d2 = a * a + b * b + c * c
        if d2 > best:
            best, bj = d2, j
    return 0.5 * np.sqrt(best), bj


@njit(parallel=True, cache=True)
def _pat_kernel(Q, D, I, T, P, H, C, r_eval, k_fb, want_grad, out, grad):
    q, k = I.shape
    for j in prange(q):
        x0, x1, x2 = Q[j, 0], Q[j, 1], Q[j, 2]
        sig, jf = _sigma(H, x0, x1, x2)
        if sig <= 0.0:
            sig = 1e-300
        lam = C / sig
        dmin = D[j, 0]
        W = 0.0
        Sg = 0.0
        G0 = G1 = G2 = 0.0  # Σ w ∇g
        L0 = L1 = L2 = 0.0  # Σ w ∇ℓ
        M0 = M1 = M2 = 0.0  # Σ w g ∇ℓ
        # ∇λ
        f0, f1, f2 = x0 - H[jf, 0], x1 - H[jf, 1], x2 - H[jf, 2]
        fn = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        if fn > 0.0:
            c = -(C / (sig * sig)) * 0.5 / fn
            l0, l1, l2 = c * f0, c * f1, c * f2
        else:
            l0 = l1 = l2 = 0.0
        for m in range(k):
            d = D[j, m]
            if m >= k_fb and d > r_eval:
                break
            i = I[j, m]
            w = np.exp(-lam * (d - dmin))
            g, g0, g1, g2 = torus_eval(T, i, x0, x1, x2)
            W += w
            Sg += w * g
            if want_grad:
                G0 += w * g0
                G1 += w * g1
                G2 += w * g2
                if d > 0.0:
                    e0 = -lam * (x0 - P[i, 0]) / d - d * l0
                    e1 = -lam * (x1 - P[i, 1]) / d - d * l1
                    e2 = -lam * (x2 - P[i, 2]) / d - d * l2
                else:
                    e0, e1, e2 = -d * l0, -d * l1, -d * l2
                L0 += w * e0
                L1 += w * e1
                L2 += w * e2
                M0 += w * g * e0
                M1 += w * g * e1
                M2 += w * g * e2
        phi = Sg / W
        out[j] = phi
        if want_grad:
            grad[j, 0] = (G0 + M0 - phi * L0) / W
            grad[j, 1] = (G1 + M1 - phi * L1) / W
            grad[j, 2] = (G2 + M2 - phi * L2) / W


def _clean_cloud(P, N, k):
    """Validate a cloud; drop zero normals, merge exact duplicates; returns (P, N unit)."""
    P = as_points(P, "P")
    if N is None:
        raise ValueError("N: PointsAsTori needs oriented normals (got None); estimate them first, "
                         "e.g. with gsdf.estimate_normals(P, orient_towards=...)")
    N = as_points(N, "N")
    if N.shape[0] != P.shape[0]:
        raise ValueError(f"N: has {N.shape[0]} rows but there are {P.shape[0]} points")
    L = np.linalg.norm(N, axis=1)
    keep = L > 1e-12 * max(1.0, float(L.max()))
    if not keep.any():
        raise ValueError("N: all normals are zero")
    P, N = P[keep], N[keep] / L[keep, None]
    # exact duplicates: merge, averaging their normals (a pair with opposite normals cancels and is dropped)
    U, first, inv = np.unique(P, axis=0, return_index=True, return_inverse=True)
    if len(U) < len(P):
        inv = inv.ravel()
        Nm = np.zeros_like(U)
        np.add.at(Nm, inv, N)
        Ln = np.linalg.norm(Nm, axis=1)
        ok = Ln > 1e-9
        order = np.argsort(first)  # keep the original order of first occurrences
        ok_o = ok[order]
        P, N = U[order][ok_o], (Nm[order] / np.maximum(Ln[order], 1e-300)[:, None])[ok_o]
    if len(P) < k:
        raise ValueError(f"P: PointsAsTori needs at least k={k} distinct points with nonzero normals "
                         f"(got {len(P)}); pass a smaller k (>= 6)")
    return np.ascontiguousarray(P), np.ascontiguousarray(N)


@dataclasses.dataclass(frozen=True)
class PointsAsToriOptions:
    """Neighbour-selection and jet-fitting options of :class:`PointsAsTori` (thesis §5.1).

    Attributes
    ----------
    k_eval : int, default 64
        Most points summed per query (neighbour query size); above both the cloud's n - 1 and 64 it is refused
        by :class:`PointsAsTori`.
    k_fallback : int, default 32
        Points always summed per query, even beyond R_eval (the 32 nearest of §5.1.3); above both n - 1 and 32
        it is refused.
    normal_weight : float, default 1.0
        Jet fitting: weight of the normal (slope) rows.
    ridge : float, default 1e-3
        Jet fitting: ridge on the curvature terms.
    curvature_cap : float, default 4.0
        Jet fitting: largest curvature in units of 1/h_i (h_i: median distance to the k-th neighbour).
    kd_eps : float, default 0.0
        Approximate neighbour search for queries far from the cloud: every neighbour distance used is within a
        factor (1 + kd_eps) of the true one (0 = exact).

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> P = np.random.default_rng(0).normal(size=(500, 3))
    >>> P /= np.linalg.norm(P, axis=1, keepdims=True)
    >>> pat = gsdf.PointsAsTori(P, P, k=32, options=gsdf.PointsAsToriOptions(kd_eps=0.3))
    >>> bool(pat.signed_distance([[0, 0, 0]])[0] < 0)
    True
    """

    k_eval: int = 64
    k_fallback: int = 32
    normal_weight: float = 1.0
    ridge: float = 1e-3
    curvature_cap: float = 4.0
    kd_eps: float = 0.0

    def __post_init__(self):  # a ValueError naming the attribute, at construction (as PointsAsTori checks them)
        integer(self.k_eval, "k_eval", lo=1)
        integer(self.k_fallback, "k_fallback", lo=1)
        nonnegative(self.normal_weight, "normal_weight")
        nonnegative(self.ridge, "ridge")
        positive(self.curvature_cap, "curvature_cap")
        nonnegative(self.kd_eps, "kd_eps", most=1e3)


class PointsAsTori:
    """Generalized signed distance of an oriented point cloud, evaluated pointwise (thesis ch. 5).

    Parameters
    ----------
    P : (n, 3) float
        Points.
    N : (n, 3) float
        Outward normals (normalized internally). Rows with zero normals are dropped and exact duplicate
        points are merged (their normals averaged); ``None`` raises ``ValueError``.
    estimator : {"jet", "learned"}, default "jet"
        Coefficient estimator: weighted least-squares jet fitting (:func:`gsdf.tori._fit.jet_coefficients`), or
        the learned regressor of §5.1.2 (:mod:`gsdf.tori._learned`; a small network, weights shipped in
        ``gsdf/tori/pat_weights.npz``, evaluated in numpy; it corrects the jet coefficients, so
        ``normal_weight``/``ridge`` do not apply to it).
    k : int, default 64
        Neighbours per fit (64 in the thesis, >= 6); the cloud needs at least ``k`` distinct points. More
        neighbours fit smoother tori.
    C : float, default 64.0
        Screening constant of Eq. 5.7 (λ_x = C/σ_x); larger blends fewer tori per query (sharper, noisier).
    r_eval : float, optional
        Summation radius R_eval, model units; default twice the median distance of a point to its 32nd
        neighbour.
    options : PointsAsToriOptions, optional
        Neighbour selection and jet-fitting options.

    Attributes
    ----------
    P, N : (n, 3) float64
        The cleaned cloud (duplicates merged, zero normals dropped) and its unit normals.
    tori : (n, 13) float64
        The fitted tori (thesis Fig. 5.4), model units: per point its position, normal, principal direction,
        curvatures k1 >= k2 >= 0, s = sign of the larger curvature and e = +1 (same signs) or -1 (saddle)
        (columns 0-2, 3-5, 6-8, 9, 10, 11, 12).
    coefficients : (n, 6) float64
        Height-field coefficients (a00, a10, a01, a20, a11, a02) per point, model units.
    r_eval : float
        The summation radius used, model units.

    Raises
    ------
    ValueError
        Bad shapes, NaN or infinite values, normals missing, fewer than ``k`` distinct points, bad options.

    Notes
    -----
    Calling the object, ``pat(Q)``, is the same as :meth:`signed_distance`.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> i = np.arange(2000) + 0.5
    >>> ph, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
    >>> P = 0.5 * np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    >>> pat = PointsAsTori(P, P)
    >>> pat.signed_distance([[0, 0, 0.3], [0, 0, 1.0]]).round(2)
    array([-0.2,  0.5])
    """

    def __init__(self, P, N, estimator: str = "jet", k: int = 64, C: float = 64.0, r_eval=None,
                 options: PointsAsToriOptions | None = None):
        self._setup(P, N, estimator, k, C, r_eval, options, None)

    @classmethod
    def _from_state(cls, state, estimator, k, C, r_eval, options):
        self = cls.__new__(cls)
        self._setup(None, None, estimator, k, C, r_eval, options, state)
        return self

    def _setup(self, P, N, estimator, k, C, r_eval, options, _state):
        apply_env()  # GSDF_NUM_THREADS
        if options is None:
            options = PointsAsToriOptions()
        if not isinstance(options, PointsAsToriOptions):
            raise ValueError(f"options: expected a gsdf.PointsAsToriOptions, got {type(options).__name__}")
        self.estimator = choice(estimator, "estimator", {"jet", "learned"})
        self.k = integer(k, "k", lo=6)
        self.C = positive(C, "C", most=1e300)
        self.k_eval = integer(options.k_eval, "k_eval", lo=1)
        self.k_fallback = integer(options.k_fallback, "k_fallback", lo=1)
        self.options = dict(normal_weight=nonnegative(options.normal_weight, "normal_weight"),
                            ridge=nonnegative(options.ridge, "ridge"),
                            curvature_cap=positive(options.curvature_cap, "curvature_cap"))
        if r_eval is not None:
            r_eval = positive(r_eval, "r_eval")
        # (1 + kd_eps)² scales squared box distances in the neighbour walk: keep it a modest finite factor
        kd_eps = nonnegative(options.kd_eps, "kd_eps", most=1e3)
        if _state is not None:
            self.P, self.N, coefficients, tori, framed = _state
        else:
            self.P, self.N = _clean_cloud(P, N, self.k)
        # the baselines' rule: above both n - 1 and the default is refused, up to the default is clamped
        self.k_eval = neighbours(self.k_eval, len(self.P), "k_eval", default=64)
        self.k_fallback = neighbours(self.k_fallback, len(self.P), "k_fallback", default=32)
        # scale invariance: tori, neighbour search and kernel work in the cloud's normalised frame
        self._frame = fr = Frame.of(self.P)
        self._Pf = fr.geometry(self.P, "P")
        if r_eval is not None:
            r_eval = float(fr.inverse_length(r_eval))
            if not r_eval > 0:
                raise ValueError("r_eval: too small to represent relative to the cloud's size")
            r_eval = min(r_eval, 1e150)  # the cloud spans ~2 frame units: any radius beyond covers all of it
        self._blend = NeighbourBlend(self._Pf, self.C, r_eval, self.k_eval, self.k_fallback, kd_eps=kd_eps)
        if _state is not None:
            if framed is not None:
                self._coefficients, self._tori = framed
            else:  # format 1: tori in input units only
                self._coefficients = _coefficients_units(coefficients, -fr.exponent)
                self._tori = _tori_to_frame(tori, fr)
            return
        d, idx = self._blend.knn.query(self._Pf, self.k)
        if self.estimator == "learned":
            from gsdf.tori._learned import learned_coefficients

            self._coefficients = learned_coefficients(self._Pf, self.N, idx, d)
        else:
            self._coefficients = jet_coefficients(self._Pf, self.N, idx, d, self.options["normal_weight"],
                                                 self.options["ridge"])
        scale = float(np.linalg.norm(self._Pf.max(0) - self._Pf.min(0))) or 1.0
        h = np.median(d[:, -1])
        self._tori = coefficients_to_tori(self._Pf, self.N, self._coefficients, k_floor=1e-6 / scale,
                                          k_cap=self.options["curvature_cap"] / max(h, 1e-300))

    @property
    def tori(self) -> np.ndarray:
        """Fitted tori (n, TORUS_WIDTH) in input units (the kernels use a copy in the normalised frame)."""
        return _tori_from_frame(self._tori, self._frame)

    @property
    def coefficients(self) -> np.ndarray:
        """Height-field coefficients (a00, a10, a01, a20, a11, a02) per point (n, 6), in input units."""
        return _coefficients_units(self._coefficients, self._frame.exponent)

    @property
    def r_eval(self) -> float:
        """Summation radius R_eval in input units."""
        return float(self._frame.length(self._blend.r_eval))

    def _eval(self, Q, want_grad):
        b = self._blend
        fr = self._frame
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        Qf, excess = fr.queries(Q, want_excess=True)

        def fn(q, d, i, out):
            g = np.empty((len(q), 3)) if want_grad else np.empty((1, 3))
            o = np.empty(len(q))
            _pat_kernel(q, d, i, self._tori, self._Pf, b.hull, self.C, b.r_eval, b.k_fallback, want_grad, o, g)
            if want_grad:
                out[:] = g
            else:
                out[:] = o

        out = b.map(Qf, fn, width=3 if want_grad else 0)
        if want_grad:
            return out
        # a clamped far query (gsdf._normalize.FAR) is farther by ``excess``; there φ grows like the distance
        return fr.length(out + excess)

    @query_shaped()
    def signed_distance(self, Q) -> np.ndarray:
        """Generalized signed distance φ of Eq. 5.6 at the query points; negative inside.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units (anywhere: no grid is needed).

        Returns
        -------
        (q,) float64
            φ(Q), model units.

        Raises
        ------
        ValueError
            ``Q`` of the wrong shape or with NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> i = np.arange(2000) + 0.5
        >>> ph, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
        >>> P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
        >>> gsdf.PointsAsTori(P, P).signed_distance([[0, 0, 0.5], [0, 0, 2.0]]).round(2).tolist()
        [-0.5, 1.0]
        """
        return self._eval(Q, False)

    __call__ = signed_distance

    @query_shaped()
    def gradient(self, Q) -> np.ndarray:
        """Analytic gradient ∇φ of Eq. 5.6 at the query points (about unit length, pointing outward).

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        (q, 3) float64

        Raises
        ------
        ValueError
            ``Q`` of the wrong shape or with NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> i = np.arange(2000) + 0.5
        >>> ph, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
        >>> P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
        >>> gsdf.PointsAsTori(P, P).gradient([[0, 0, 2.0]]).round(2).tolist()
        [[0.0, 0.0, 1.0]]
        """
        return self._eval(Q, True)

    def isosurface(self, level: float = 0.0, resolution=64, pad: float = PAD):
        """Mesh of the level set φ = ``level`` (marching cubes + bisection, :func:`gsdf.extract_isosurface`).

        Parameters
        ----------
        level : float, default 0.0
            The level, model units (0: the surface; an offset distance for an offset surface).
        resolution : int or gsdf.Grid, default 64
            Grid nodes along the longest side of the cloud's bounding box grown by ``pad`` times its diagonal
            and by ``|level|``; or the :class:`gsdf.Grid` to sample. Time grows with its cube.
        pad : float, default 0.1
            Growth of the box on every side, as a fraction of the cloud's bounding-box diagonal.

        Returns
        -------
        V : (nv, 3) float64
        F : (nf, 3) int64
            Outward oriented (φ < level inside).

        Raises
        ------
        ValueError
            A non-finite level, a bad resolution or pad.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> i = np.arange(2000) + 0.5
        >>> ph, th = np.arccos(1 - 2 * i / 2000), np.pi * (1 + 5 ** 0.5) * i
        >>> P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
        >>> V, F = gsdf.PointsAsTori(P, P).isosurface(0.0, resolution=24)
        >>> bool(np.abs(np.linalg.norm(V, axis=1) - 1).max() < 0.05)
        True
        """
        from gsdf.contour import extract_isosurface

        grid = resolution if isinstance(resolution, Grid) else level_grid(self.P, resolution, level, pad)
        return extract_isosurface(self.signed_distance, resolution=grid, level=level, inside="below")

    def save(self, path) -> None:
        """Write the fitted tori (and the cloud) to an ``.npz`` file; reload with :meth:`load`.

        Parameters
        ----------
        path : str or os.PathLike
            The file, written atomically; it must end in ``.npz`` (numpy would silently append the extension).

        Raises
        ------
        ValueError
            Another extension, or a failed write.

        Examples
        --------
        >>> import numpy as np, os, tempfile, gsdf
        >>> i = np.arange(500) + 0.5
        >>> ph, th = np.arccos(1 - 2 * i / 500), np.pi * (1 + 5 ** 0.5) * i
        >>> P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
        >>> p = os.path.join(tempfile.mkdtemp(), "tori.npz")
        >>> gsdf.PointsAsTori(P, P).save(p)
        >>> gsdf.PointsAsTori.load(p).tori.shape
        (500, 13)
        """
        from gsdf.io._safe_write import atomic_output

        # coefficients and tori in input units (the normalised frame is recomputed from P on load)
        # and, for a bitwise round trip, the frame copies the kernels use (format 2)
        with atomic_output(path, extensions=(".npz",)) as tmp:
            np.savez_compressed(tmp, P=self.P, N=self.N, coefficients=self.coefficients, tori=self.tori,
                                coefficients_frame=self._coefficients, tori_frame=self._tori,
                                estimator=self.estimator, k=self.k, C=self.C, r_eval=self.r_eval,
                                k_eval=self.k_eval, k_fallback=self.k_fallback, format=np.int64(2))

    @classmethod
    def load(cls, path) -> "PointsAsTori":
        """Read a file written by :meth:`save`.

        Every array is checked against the points (shape, length, finiteness) before any kernel reads it.

        Parameters
        ----------
        path : str or os.PathLike
            An ``.npz`` file written by :meth:`save`.

        Returns
        -------
        PointsAsTori
            Evaluates exactly as the object that was saved.

        Raises
        ------
        ValueError
            Not a saved PointsAsTori file, missing or malformed arrays.

        Examples
        --------
        >>> pat = gsdf.PointsAsTori.load("tori.npz")          # doctest: +SKIP
        """
        from gsdf._checks import numpy_file

        try:
            p = numpy_file(path, "path")
        except FileNotFoundError as exc:
            raise ValueError(f"{path}: not a saved PointsAsTori file (FileNotFoundError: {exc})") from exc
        try:
            z = np.load(p, allow_pickle=False)
            files = set(z.files)
        except Exception as exc:
            raise ValueError(f"{path}: not a saved PointsAsTori file ({type(exc).__name__}: {exc})") from exc
        need = {"P", "N", "coefficients", "tori", "C", "r_eval", "k_eval", "k_fallback", "k", "estimator"}
        if not need <= files:
            raise ValueError(f"{path}: missing arrays {sorted(need - files)}")
        try:
            fmt = 1 if "format" not in files else _scalar(z["format"], path, "format")
        except ValueError:
            raise
        except Exception as exc:
            raise ValueError(f"{path}: unreadable array ({type(exc).__name__}: {exc})") from exc
        if fmt not in (1, 2):
            raise ValueError(f"{path}: unknown PointsAsTori file format {fmt!r}")
        try:
            arrays = {name: z[name] for name in need | ({"format", "tori_frame", "coefficients_frame"} & files)}
        except Exception as exc:
            raise ValueError(f"{path}: unreadable array ({type(exc).__name__}: {exc})") from exc
        P = as_points(arrays["P"], f"{path}: P")
        n = P.shape[0]
        N = as_points(arrays["N"], f"{path}: N")
        if N.shape[0] != n:
            raise ValueError(f"{path}: N has {N.shape[0]} rows but P has {n}")
        for name, width in (("coefficients", 6), ("tori", TORUS_WIDTH), ("coefficients_frame", 6),
                            ("tori_frame", TORUS_WIDTH)):
            if name not in arrays:
                continue
            A = arrays[name]
            if A.dtype.kind not in "fiu" or A.shape != (n, width):
                raise ValueError(f"{path}: {name} must be a ({n}, {width}) numeric array, got {A.shape} {A.dtype}")
            if not np.isfinite(A).all():
                raise ValueError(f"{path}: {name} contains NaN or infinite values")

        frame_copies = "tori_frame" in arrays and "coefficients_frame" in arrays and fmt == 2
        state = (P, N, np.ascontiguousarray(arrays["coefficients"], dtype=np.float64),
                 np.ascontiguousarray(arrays["tori"], dtype=np.float64),
                 (np.ascontiguousarray(arrays["coefficients_frame"], dtype=np.float64),
                  np.ascontiguousarray(arrays["tori_frame"], dtype=np.float64)) if frame_copies else None)
        if n < 1:
            raise ValueError(f"{path}: no points")
        options = PointsAsToriOptions(k_eval=_scalar(arrays["k_eval"], path, "k_eval"),
                                      k_fallback=_scalar(arrays["k_fallback"], path, "k_fallback"))
        return cls._from_state(state, estimator=str(_scalar(arrays["estimator"], path, "estimator")),
                               k=_scalar(arrays["k"], path, "k"), C=_scalar(arrays["C"], path, "C"),
                               r_eval=_scalar(arrays["r_eval"], path, "r_eval"), options=options)


def level_grid(X, resolution, level: float = 0.0, pad: float = PAD) -> Grid:
    """The grid for the level set φ = ``level`` of a cloud ``X``: :meth:`gsdf.Grid.fit` of its bounding box grown
    by ``pad`` × its diagonal (:func:`gsdf.grid.padded_box`) and by ``|level|`` (an offset surface lies up to
    ``|level|`` outside the cloud)."""
    lo, hi = padded_box(X, pad)
    m = abs(finite(level, "level"))
    return Grid.fit((lo - m, hi + m), resolution)


def _coefficients_units(A, exponent):
    """Coefficients scaled by 2**exponent lengths: a00 is a length, a10/a01 slopes, a20/a11/a02 curvatures."""
    if exponent == 0:
        return A
    A = np.array(A, dtype=np.float64, copy=True)
    A[:, 0] = np.ldexp(A[:, 0], exponent)
    A[:, 3:6] = np.ldexp(A[:, 3:6], -exponent)
    return A


def _tori_from_frame(T, frame):
    """Tori of the normalised frame in input units: positions mapped back, curvatures k1, k2 divided by s."""
    if frame.identity:
        return T
    from gsdf.tori._torus import T_K1, T_K2, T_P

    T = np.array(T, copy=True)
    T[:, T_P:T_P + 3] = frame.point(T[:, T_P:T_P + 3])
    with np.errstate(over="ignore"):
        T[:, T_K1:T_K2 + 1] = np.ldexp(T[:, T_K1:T_K2 + 1], -frame.exponent)
    return T


def _tori_to_frame(T, frame):
    if frame.identity:
        return np.ascontiguousarray(T)
    from gsdf.tori._torus import T_K1, T_K2, T_P

    T = np.array(T, dtype=np.float64, copy=True)
    T[:, T_P:T_P + 3] = frame.geometry(T[:, T_P:T_P + 3], "tori")
    T[:, T_K1:T_K2 + 1] = np.ldexp(T[:, T_K1:T_K2 + 1], frame.exponent)
    if not np.isfinite(T).all():
        raise ValueError("tori: not representable at the cloud's scale")
    return np.ascontiguousarray(T)


def _scalar(a, path, name):
    """The Python scalar stored in a 0-d array of a saved file, or ValueError."""
    a = np.asarray(a)
    if a.shape != () or a.dtype.kind not in "biufU":
        raise ValueError(f"{path}: {name} must be a scalar, got shape {a.shape} dtype {a.dtype}")
    return a.item()
