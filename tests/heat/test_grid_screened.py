"""Step I of the grid signed heat method as a screened solve on the grid (gsdf.heat.grid._screened)."""

import numpy as np
import pytest

from gsdf.heat.grid._domain import GridDomain
from gsdf.heat.grid._screened import screened_heat, screened_reach, screened_symbol, splat
from gsdf.heat.volume import signed_heat_volume

from tests.shapes import uv_sphere


def _sphere(n=1500):
    i = np.arange(n) + 0.5
    ph, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    return np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])


def test_splat_keeps_total_charge_and_its_centre():
    rng = np.random.default_rng(0)
    B = rng.uniform(0.05, 0.95, (200, 3))
    W = rng.normal(size=(200, 3))
    lo, h, shape = np.zeros(3), np.array([0.1, 0.125, 0.2]), (11, 9, 6)
    X = splat(B, W, lo, h, shape) * np.prod(h)                       # back to charges per node
    assert np.allclose(X.sum(axis=0), W.sum(axis=0), atol=1e-12)
    nodes = np.stack(np.meshgrid(*[lo[a] + h[a] * np.arange(shape[a]) for a in range(3)], indexing="ij"),
                     axis=-1).reshape(-1, 3)
    # trilinear weights reproduce linear functions: the first moments are kept exactly
    assert np.allclose(nodes.T @ X, B.T @ W, atol=1e-12)


def test_kernel_is_isotropic_and_decays_like_the_yukawa_potential():
    """One source: X / G_t(r) is the same along the axes, face and body diagonals (19-point symbol)."""
    n, h = 33, 0.1
    t = h * h
    X = screened_heat(np.full((1, 3), 16 * h), np.array([[1.0, 0, 0]]), np.zeros(3), np.full(3, h), (n,) * 3, t)
    X = X.reshape(n, n, n, 3)[..., 0]
    ratios = []
    for d in ((1, 0, 0), (1, 1, 0), (1, 1, 1), (2, 1, 0)):
        d = np.array(d)
        for k in range(1, 9):
            r = k * np.linalg.norm(d) * h
            if 3 * h <= r <= 7 * h and (16 + k * d).max() < n:
                ratios.append(X[tuple(16 + k * d)] / (np.exp(-r / np.sqrt(t)) / (4 * np.pi * r)))
    ratios = np.array(ratios)
    assert len(ratios) >= 8
    assert ratios.max() / ratios.min() < 1.06
    assert abs(X[16, 16, 16 + 3] / X[16, 16 + 3, 16] - 1) < 1e-12                # symmetric in the axes


def test_symbol_is_the_stencil_on_the_dct_modes():
    """screened_symbol (cubic cells) equals the 19-point operator applied to a cosine mode in the interior."""
    n, h, t = 12, 0.5, 0.3
    k = (2, 3, 5)
    j = np.arange(n)
    modes = [np.cos(np.pi * k[a] * (2 * j + 1) / (2 * n)) for a in range(3)]
    U = modes[0][:, None, None] * modes[1][None, :, None] * modes[2][None, None, :]
    lap = np.zeros((n - 2,) * 3)
    c = U[1:-1, 1:-1, 1:-1]
    for off in np.ndindex(3, 3, 3):
        o = np.array(off) - 1
        m = int(np.abs(o).sum())
        if m == 0 or m == 3:
            continue
        w = 1 / 3 if m == 1 else 1 / 6
        lap += w * (U[1 + o[0]:n - 1 + o[0], 1 + o[1]:n - 1 + o[1], 1 + o[2]:n - 1 + o[2]] - c)
    lhs = c - t * lap / h ** 2
    lam = screened_symbol((n, n, n), np.full(3, h), t)[k]
    assert np.allclose(lhs, lam * c, atol=1e-12)


def _sphere_errors(monkeypatch, **kw):
    """Mean |φ − (|x| − 1)| on a 9³ lattice in [-1.1, 1.1]³ of the default run (checked to take the grid Step I)
    and of the Yukawa tree run, at resolution 24."""
    import functools

    import gsdf.heat.volume._solve as solve

    g = signed_heat_volume(resolution=24, **kw)
    with monkeypatch.context() as m:
        m.setattr(solve, "GridDomain", functools.partial(GridDomain, step1="yukawa"))
        y = signed_heat_volume(resolution=24, **kw)
    assert g.meta["step1"] == "heat" and y.meta["step1"] == "yukawa"
    x = np.linspace(-1.1, 1.1, 9)
    Q = np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1).reshape(-1, 3)
    exact = np.linalg.norm(Q, axis=1) - 1
    return np.abs(g(Q) - exact).mean(), np.abs(y(Q) - exact).mean()


def test_cloud_uses_the_grid_solve_and_is_as_accurate_as_the_tree(monkeypatch):
    P = _sphere()
    eg, ey = _sphere_errors(monkeypatch, points=(P, P))
    assert eg < 0.03 and eg < 1.1 * ey
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    assert signed_heat_volume(mesh=(V, F), resolution=12).meta["step1"] == "heat"


def test_mesh_uses_the_grid_solve_and_is_as_accurate_as_the_tree(monkeypatch):
    """A sphere mesh with a hole: Step I on the grid by default, mean error within 5 % of the tree sum's."""
    from gsdf.heat.volume._sources import mesh_sources

    V, F = uv_sphere(24, 48)
    F = F[V[F][:, :, 0].mean(axis=1) < 0.7]                                           # cut a hole
    eg, ey = _sphere_errors(monkeypatch, mesh=(V, F))
    assert eg < 0.05 and eg < 1.05 * ey
    # sources beyond the box padded by PAD cells: the splat would clamp them, so the tree is used
    d = GridDomain(np.full(3, -0.5), np.full(3, 0.5), (12, 12, 12), t=0.01)
    d.diffuse(d.prepare(mesh_sources(V, F)))
    assert d.step1_used == "yukawa"


def test_bad_step1_and_too_short_t():
    from gsdf.heat.volume._sources import point_sources

    P = _sphere(300)
    lo, hi, shape = np.full(3, -1.5), np.full(3, 1.5), (10, 10, 10)
    for bad in ("walk", True):
        with pytest.raises(ValueError, match="step1"):
            GridDomain(lo, hi, shape, t=0.1, step1=bad)
    d = GridDomain(lo, hi, shape, t=0.05 * (3 / 9) ** 2, step1="heat")
    with pytest.raises(ValueError, match="t: .* too short"):
        d.diffuse(d.prepare(point_sources(P, P)))
    # the default falls back to the tree when t is short against the grid (t_scale="input" on a coarse grid)
    assert signed_heat_volume(points=(P, P), resolution=10, t_coef=0.05).meta["step1"] == "yukawa"
    with pytest.raises(ValueError, match="t"):
        screened_heat(P, P, np.full(3, -2.0), np.full(3, 0.4), (11, 11, 11), t=-1.0)
    assert screened_reach(1.0, 0.01, np.full(3, 1.0)) == np.inf
