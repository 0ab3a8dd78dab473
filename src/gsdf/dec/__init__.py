"""Discrete exterior calculus: operators on triangle (and tet) meshes, Hodge decomposition, the dual-graph L1 LP.

Modules
-------
triangle : d0, d1, diagonal Hodge stars (cotan, clamped), jump ("reduced") coordinates of an integer edge chain,
           the jump Laplace solve, the Darboux derivative — on triangle meshes.
hodge    : Hodge decomposition of a 1-form on any cell complex given d0, d1 and positive diagonal stars
           (exact, coexact, harmonic parts) and a harmonic basis (dimension = first Betti number).
lp       : the L1 linear program on a dual graph (per-cell shifts, least weighted L1 jump), solved by HiGHS.
netflow  : network simplex for min-cost circulations; the L1 program through its dual circulation.
band_lp  : the L1 program on a band of cells, proven optimal on all cells by a max-flow certificate.

Names are imported lazily (PEP 562) so ``import gsdf.dec.lp`` does not pay for the others.
"""

from __future__ import annotations

import importlib

_LAZY = {
    "TriangleDEC": "triangle",
    "JumpCoordinates": "triangle",
    "HodgeDecomposition": "hodge",
    "dual_graph_l1": "lp",
    "DualL1Result": "lp",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'gsdf.dec' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{mod}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
