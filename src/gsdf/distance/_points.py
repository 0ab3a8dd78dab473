"""Unsigned distance to a point cloud (k-d tree, :class:`scipy.spatial.cKDTree`, all cores).

Cost: O(p log p) to build the tree, about O(log p) per query.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from gsdf._checks import as_points, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf._normalize import Frame

__all__ = ["PointCloudDistance", "point_cloud_distance"]


class PointCloudDistance:
    """Nearest-point distance to the points ``P`` (p, 3), with the k-d tree built once.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> tree = gsdf.PointCloudDistance(np.eye(3))          # build once
    >>> d = tree.query([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])[0]   # query many times
    >>> np.round(d, 3).tolist()
    [1.0, 1.0]
    """

    def __init__(self, P):
        self.P = as_points(P, "P")
        self._frame = Frame.of(self.P)  # the tree lives in the normalised frame (gsdf._normalize)
        self.tree = cKDTree(self._frame.geometry(self.P, "P"))

    @query_shaped()
    def query(self, Q):
        """Returns ``(d (q,), index (q,) int64, closest (q, 3))`` for the query points ``Q`` (q, 3)."""
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        Qf, excess = self._frame.queries(Q, want_excess=True)
        d, idx = self.tree.query(Qf, k=1, workers=-1)
        idx = np.asarray(idx, dtype=np.int64)
        return self._frame.length(np.asarray(d, dtype=np.float64) + excess), idx, self.P[idx]


@query_shaped()
def point_cloud_distance(P, Q, return_closest: bool = False):
    """Distance from every query ``Q`` (q, 3) to the nearest of the points ``P`` (p, 3).

    Returns ``d`` (q,), or ``(d, index, closest)`` when ``return_closest`` is true.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> d = gsdf.point_cloud_distance(np.eye(3), [[0.0, 0.0, 0.0]])
    >>> np.round(d, 3).tolist()
    [1.0]
    """
    d, idx, closest = PointCloudDistance(P).query(Q)
    if return_closest:
        return d, idx, closest
    return d
