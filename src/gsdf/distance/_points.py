"""Unsigned distance to a point cloud (k-d tree, :class:`scipy.spatial.cKDTree`, all cores).

Cost: O(p log p) to build the tree, about O(log p) per query.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from gsdf._checks import as_points, flag, query_shaped
from gsdf._memory import SECONDS_PER_QUERY
from gsdf._normalize import Frame

__all__ = ["PointCloudDistance", "point_cloud_distance"]


class PointCloudDistance:
    """Nearest-point distance to the points ``P``, with the k-d tree (scipy's cKDTree, all cores) built once.

    Parameters
    ----------
    P : (p, 3) float
        The points, model units.

    Attributes
    ----------
    P : (p, 3) float64
        The points, as given.

    Raises
    ------
    ValueError
        ``P`` empty, of the wrong shape, or with NaN or infinite coordinates.

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
        """The nearest point of the cloud to each query point, and its distance.

        Parameters
        ----------
        Q : (q, 3) float
            Query points, model units.

        Returns
        -------
        d : (q,) float64
            Euclidean distance to the nearest point.
        index : (q,) int64
            Index into ``P`` of that point (ties broken arbitrarily).
        closest : (q, 3) float64
            ``P[index]``.

        Raises
        ------
        ValueError
            ``Q`` of the wrong shape or with NaN or infinite coordinates.

        Examples
        --------
        >>> import numpy as np, gsdf
        >>> d, i, c = gsdf.PointCloudDistance(np.eye(3)).query([[2.0, 0.0, 0.0]])
        >>> float(d[0]), int(i[0]), c[0].tolist()
        (1.0, 0, [1.0, 0.0, 0.0])
        """
        Q = as_points(Q, "Q", seconds_per_row=SECONDS_PER_QUERY)
        Qf, excess = self._frame.queries(Q, want_excess=True)
        d, idx = self.tree.query(Qf, k=1, workers=-1)
        idx = np.asarray(idx, dtype=np.int64)
        return self._frame.length(np.asarray(d, dtype=np.float64) + excess), idx, self.P[idx]


@query_shaped()
def point_cloud_distance(P, Q, return_closest: bool = False):
    """Distance from every query point to the nearest of the points ``P`` (one call of
    :class:`PointCloudDistance`; build that once to query the same points repeatedly).

    Parameters
    ----------
    P : (p, 3) float
        The points, model units.
    Q : (q, 3) float
        Query points.
    return_closest : bool, default False
        Also return which point is nearest and where it is.

    Returns
    -------
    d : (q,) float64
        Distance to the nearest point.
    index : (q,) int64
        Only with ``return_closest``: index into ``P`` of the nearest point.
    closest : (q, 3) float64
        Only with ``return_closest``: ``P[index]``.

    Raises
    ------
    ValueError
        Empty ``P``, wrong shapes, NaN or infinite coordinates.

    Examples
    --------
    >>> import numpy as np, gsdf
    >>> d = gsdf.point_cloud_distance(np.eye(3), [[0.0, 0.0, 0.0]])
    >>> np.round(d, 3).tolist()
    [1.0]
    """
    return_closest = flag(return_closest, "return_closest")
    d, idx, closest = PointCloudDistance(P).query(Q)
    if return_closest:
        return d, idx, closest
    return d
