"""The assembled sources of one solve of the signed heat method on one domain (Feng & Crane 2024, §5.6, §8, App. A):
what a domain's ``assemble_sources`` returns and :mod:`gsdf.heat._core` consumes — the right-hand side of step I
(or point charges, in volumes), the interpolation rows of the source nodes for the level-set constraints (§7.1),
and the rows and weights of the final shift (Alg. 13).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

__all__ = ["Sources"]


@dataclass
class Sources:
    """The assembled sources of one solve on one domain (what :mod:`gsdf.heat._core` consumes).

    Attributes
    ----------
    X0 : ndarray or None
        Right-hand side of step I (Eq. 12): complex per step-I unknown (edges, vertices), or None for domains
        whose step I is a sum over point charges (volumes, see ``B``, ``W``, ``a``).
    node_rows : csr (k, n)
        Interpolation rows of the curve nodes (φ at node i is ``node_rows[i] @ φ``).
    node_curve : (k,) int
        The curve each node belongs to (curves sharing a vertex node form one component for "multiple").
    node_vertex : (k,) int
        The vertex a node sits on, or -1 (nodes inside faces / cells).
    point_rows, point_vertex : csr (p, n), (p,)
        The same for isolated point sources.
    shift_rows, shift_weights : csr (s, n), (s,)
        Alg. 13: φ is shifted by ``Σ w (R φ) / Σ w`` (the length-weighted mean along the curves); with no rows
        (or zero weight) by ``min φ``.
    B, W, a : (m, 3), (m, 3), (m,)
        Volume sources: points, vector charges ``a N`` and weights (areas); None on surfaces.
    kind : str
        "mesh", "points" or "curves".
    mean_spacing : float
        Typical spacing of the source geometry (volumes).
    components : (k,) int, optional
        Connected component of every node when the domain knows it better than vertex sharing (tets).
    """

    X0: np.ndarray | None = None
    node_rows: sp.csr_matrix | None = None
    node_curve: np.ndarray | None = None
    node_vertex: np.ndarray | None = None
    point_rows: sp.csr_matrix | None = None
    point_vertex: np.ndarray | None = None
    shift_rows: sp.csr_matrix | None = None
    shift_weights: np.ndarray | None = None
    B: np.ndarray | None = None
    W: np.ndarray | None = None
    a: np.ndarray | None = None
    kind: str = "curves"
    mean_spacing: float = 0.0
    components: np.ndarray | None = None
    extra: dict = field(default_factory=dict)

    @property
    def bbox(self):
        """(min, max) corners of the volume source points."""
        return self.B.min(axis=0), self.B.max(axis=0)

    def all_rows(self):
        """(rows (k + p, n), vertex (k + p,)) of curve nodes and point sources together (kept: a cached
        :class:`Sources` serves repeated solves)."""
        got = self.extra.get("all_rows")
        if got is not None:
            return got
        got = self._all_rows()
        got[1].flags.writeable = False                 # shared by later solves (gsdf.heat._core keys on it)
        self.extra["all_rows"] = got
        return got

    def _all_rows(self):
        mats = [m for m in (self.node_rows, self.point_rows) if m is not None and m.shape[0]]
        vs = [v for m, v in ((self.node_rows, self.node_vertex), (self.point_rows, self.point_vertex))
              if m is not None and m.shape[0]]
        if not mats:
            n = self.node_rows.shape[1] if self.node_rows is not None else 0
            return sp.csr_matrix((0, n)), np.zeros(0, np.int64)
        if len(mats) == 1:
            return mats[0].copy(), vs[0].copy()
        return sp.vstack(mats).tocsr(), np.concatenate(vs)
