"""Discrete exterior calculus on triangle and tet meshes.

``_triangle``: diagonal Hodge stars (cotan, clamped), jump ("reduced") coordinates of an integer edge chain, the
jump Laplace solve, the Darboux derivative. ``_tet``: the same on tet complexes. Both build on the operator sets
of :mod:`gsdf.mesh` (geometry, connectivity, d0/d1/d2, cotan and P1 weights). ``_hodge``: Hodge
decomposition of a 1-form on any cell complex given d0, d1 and positive diagonal stars (exact, coexact, harmonic
parts) and a harmonic basis (dimension = first Betti number). ``_cycles``: tree–cotree homology bases.

Names are imported lazily (PEP 562).
"""


from __future__ import annotations

import importlib

_LAZY = {
    "TriangleDEC": "_triangle",
    "JumpCoordinates": "_triangle",
    "HodgeDecomposition": "_hodge",
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
