"""The shared triangle tree (gsdf.spatial._triangle_tree) against fixed expectations: a change to the build's
speed must not change the tree (node ranges, element order, boxes, wide view), the distances or the fast winding
numbers. The expectations were recorded from the build as it was before its speed-ups (hashes of the integer
arrays and of the boxes, which are copies of input coordinates; distances and winding numbers at 12 points)."""

import hashlib

import numpy as np
import pytest

import gsdf
from gsdf._checks import as_mesh
from gsdf.data import path
from gsdf.distance import TriangleDistance
from gsdf.spatial._triangle_tree import triangle_tree
from gsdf.winding import FastWindingNumber


def _soup(m, seed):
    """Random triangles in the unit cube, some tiny, some duplicated and some zero-area (as tests/winding)."""
    rng = np.random.default_rng(seed)
    c = rng.random((m, 3))
    size = np.where(rng.random(m) < 0.2, 1e-3, 0.08)[:, None, None]
    T = c[:, None, :] + size * rng.normal(size=(m, 3, 3))
    T[:50] = T[50:100]
    T[100:110, 2] = T[100:110, 1]
    V = T.reshape(-1, 3)
    return V, np.arange(len(V)).reshape(-1, 3)


def _mesh(name):
    if name == "soup3000":
        return _soup(3000, 0)
    if name == "soup30000":  # above the size from which the build runs on the threads
        return _soup(30000, 1)
    return gsdf.read_mesh(path("broken_soup.obj"))


def _hash(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a, dtype=np.int64).tobytes())
    return h.hexdigest()[:16]


#: name: (tree hash, wide view hash, boxes hash, distances, winding numbers)
EXPECTED = {
    "soup3000": ("bc687d5691e221a3", "8244537450644e15", "c731db1dd4a46f96",
                 [0.12414075669545425, 0.31497202510765704, 0.5231795894436645, 0.34332492216555416, 0.4698914165885748, 0.09443185905874957, 0.1983072448533057, 0.414576920435185, 0.18721108819570817, 0.5088222022494876, 0.3622976652544511, 0.022750764651756825],
                 [-0.03425105293412364, 0.03372629837577703, 0.006854885147588273, 0.008763189367442269, 0.005016982574353417, 0.06799629029171146, 0.048448528194318524, -0.0273855218133148, -0.032522306212165515, -0.0044454466049416025, 0.03298527971210961, -0.007856619709203257]),
    "soup30000": ("e2c8e11fc3c72b71", "4e4355c50dc010e0", "666fe7c4c0ce8f18",
                 [0.08763684965863194, 0.3205700035478401, 0.5439283508705655, 0.43204002769365213, 0.42270618032663815, 0.0809825828742171, 0.26460050463754275, 0.41216272252898467, 0.2185479995143668, 0.5573542451486484, 0.3802978036570553, 0.04463001007658367],
                 [-0.02147177436727837, -0.032287788105362786, 0.024920039797362258, 0.10289339126508511, -0.07793650874072029, 0.15585241386075516, 0.020489717162487944, -0.05964287629079631, 0.0859612437937021, 0.03656280592609085, 0.01882980461237429, 0.14917882195806353]),
    "broken_soup": ("1a30bbc499934d86", "f340e0857becaa71", "de25ca48bba62c65",
                 [0.5266792405556948, 0.3812088816347582, 0.9107060087096174, 0.9404359004779956, 0.8439569634259004, 0.07945359372943478, 0.709341062944679, 0.9213283370459929, 0.8361882521017507, 1.485817891786853, 0.9040991017011278, 0.05361267864939633],
                 [0.01858529540848672, -0.003828604122988792, -0.001751390849958713, -0.002435910089238235, -0.0048844920827358545, -0.02446498755897232, -0.007464134775373942, 0.00010673596827883575, -0.0019697858557987807, -0.0007184086755886616, -0.0057792813257463065, -0.013587563210733608]),
}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_tree_distances_and_winding_numbers_match_fixed_expectations(name):
    tree_h, wide_h, box_h, d_exp, w_exp = EXPECTED[name]
    V, F = as_mesh(*_mesh(name))
    tt = triangle_tree(V, F)
    b, w = tt.bvh, tt.wide
    assert _hash(b.order, b.start, b.end, b.right) == tree_h
    assert _hash(w.kids, w.child) == wide_h
    assert hashlib.sha256(np.ascontiguousarray(np.hstack([b.lo, b.hi])).tobytes()).hexdigest()[:16] == box_h
    lo, hi = V.min(axis=0), V.max(axis=0)
    q = lo + np.random.default_rng(5).uniform(-0.2, 1.2, (12, 3)) * (hi - lo)
    d = TriangleDistance._of_tree(V, F, tt).query(q)
    d = d[0] if isinstance(d, tuple) else d
    np.testing.assert_allclose(d, d_exp, rtol=1e-12, atol=0)
    np.testing.assert_allclose(FastWindingNumber._of_tree(tt)(q), w_exp, rtol=0, atol=1e-12)
