"""Tree–cotree homology bases (gsdf.dec._cycles): generators, periods of closed 1-forms, closed forms with given
periods, on meshes of genus 0–2 with and without boundary."""

import numpy as np
import pytest

from gsdf.dec._cycles import TreeCotree
from gsdf.dec._hodge import HodgeDecomposition
from gsdf.dec._triangle import TriangleDEC
from tests.shapes import annulus, double_torus, torus


@pytest.mark.parametrize("shape, b1", [("torus", 2), ("annulus", 1), ("double_torus", 4), ("disk", 0)])
def test_tree_cotree_generators_and_periods(shape, b1):
    if shape == "torus":
        V, F, _ = torus(16, 8)
    elif shape == "annulus":
        V, F, _ = annulus(4, 24)
    elif shape == "double_torus":
        V, F = double_torus(24)
    else:                                                      # an annulus cut open: a disk
        V, F, _ = annulus(4, 24)
        F = F[(F % 24).max(1) - (F % 24).min(1) < 2]
    dec = TriangleDEC(V, F)
    tc = TreeCotree(dec)
    assert tc.n_generators == b1 == dec.topology.betti_1()
    assert not (tc.tree & tc.cotree).any()
    rng = np.random.default_rng(1)
    p = rng.integers(-3, 4, b1).astype(float)
    w = tc.closed_form(p)
    assert np.abs(dec.d1 @ w).max() < 1e-9                     # closed
    assert np.allclose(tc.periods(w), p)                       # with the asked periods
    # exact forms have no periods; the harmonic basis has full period rank (the loops span H1)
    assert np.all(np.abs(tc.periods(dec.d0 @ rng.standard_normal(dec.n_vertices))) < 1e-9)
    if b1:
        H = HodgeDecomposition(dec.d0, dec.d1, dec.star1).harmonic_basis()
        P = np.array([tc.periods(H[:, i]) for i in range(H.shape[1])])
        assert np.linalg.matrix_rank(P, tol=1e-6) == b1
    with pytest.raises(ValueError, match="periods"):
        tc.closed_form(np.zeros(b1 + 1))


def test_tree_cotree_annulus_period_is_the_circulation():
    V, F, idx = annulus(4, 24)
    dec = TriangleDEC(V, F)
    th = np.arctan2(V[:, 1], V[:, 0])
    E = dec.edges
    dth = np.angle(np.exp(1j * (th[E[:, 1]] - th[E[:, 0]])))   # dθ, closed, period 2π around the hole
    assert np.allclose(np.abs(TreeCotree(dec).periods(dth)), 2 * np.pi)
