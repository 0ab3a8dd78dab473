"""One tree over the triangles of a mesh, built once and shared by the distance and the winding-number queries.

:func:`triangle_tree` maps the mesh into its normalised frame (:class:`gsdf._normalize.Frame`), builds the
volume-split tree of :func:`gsdf.spatial._bvh.build_volume_bvh` over the triangles' [centroid, box] rows and
returns it with its 4-wide view (:func:`gsdf.spatial._wide.widen`) as a :class:`TriangleTree`.
:class:`gsdf.TriangleDistance` and :class:`gsdf.FastWindingNumber` each accept one, so
:func:`gsdf.signed_distance` builds the tree once for both.

Cost: O(m log m) for m triangles (the tree), O(k) for the wide view.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import numba
import numpy as np
from numba import njit

from gsdf._memory import scratch
from gsdf._normalize import Frame
from gsdf.spatial._bvh import BVH, build_volume_bvh
from gsdf.spatial._wide import WideBVH, widen
from gsdf.threads import run_ranges

#: Children per node of the wide walks (a compile-time constant of the kernels: their lane loops are unrolled).
WIDTH = 4

#: Triangle builds use the threads from this size on (below it a parallel launch costs more than it saves: a
#: numba launch waits for its worker threads, 30-200 ms per launch measured on a loaded machine).
PARALLEL_BUILD_FACES = 20_000


@contextmanager
def single_thread(serial: bool):
    """numba kernels called inside run on one thread when ``serial`` (numba's setting is per calling thread)."""
    if not serial:
        yield
        return
    before = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)


@dataclass(frozen=True)
class TriangleTree:
    """The tree of :func:`triangle_tree`.

    Attributes
    ----------
    frame : gsdf._normalize.Frame
        The mesh's normalised frame; ``Vf`` are the vertices in it (the tree's coordinates).
    F : (m, 3) int64
        The triangles.
    bvh : BVH
        Volume-split binary tree (``bvh.order`` maps tree order to faces).
    wide : WideBVH
        Its :data:`WIDTH`-wide view.
    leaf_size : int
        Most triangles per leaf.
    """

    frame: Frame
    Vf: np.ndarray
    F: np.ndarray
    bvh: BVH
    wide: WideBVH
    leaf_size: int


def triangle_tree(V, F, leaf_size: int = 4, frame: Frame | None = None) -> TriangleTree:
    """The shared tree of the validated mesh ``(V, F)`` (see the module documentation)."""
    frame = Frame.of_mesh(V, F) if frame is None else frame
    Vf = np.ascontiguousarray(frame.geometry(V))
    with single_thread(F.shape[0] < PARALLEL_BUILD_FACES):
        E, root = triangle_elements_root(Vf, F, reuse=True)
        bvh = build_volume_bvh(E, leaf_size, root)
        wide = widen(bvh, WIDTH)
    return TriangleTree(frame, Vf, F, bvh, wide, int(leaf_size))


def triangle_elements(V, F):
    """(m, 9) rows [centroid, box lo, box hi] of the triangles F of V: the input of the tree build."""
    return triangle_elements_root(V, F)[0]


def triangle_elements_root(V, F, reuse: bool = False):
    """The rows of :func:`triangle_elements` and their bounds (box lo, hi, centroid lo, hi: the tree's root
    bounds, collected in the same pass instead of one more serial pass over the rows, ~0.4 ms at 89k faces).
    ~10 ns per face, most of it the first touch of E's pages: on the threads from PARALLEL_BUILD_FACES faces.
    ``reuse``: the rows go to the calling thread's scratch buffer (:func:`gsdf._memory.scratch`; for a build
    that is done with them before the next one starts)."""
    m = F.shape[0]
    E = scratch("tree.E", (m, 9)) if reuse else np.empty((m, 9))
    if m >= PARALLEL_BUILD_FACES and numba.get_num_threads() > 1:
        parts = []  # list.append is atomic: one bounds row per range
        run_ranges(lambda i0, i1: parts.append(_triangle_elements_range(V, F, E, i0, i1)), m, 8192, 1)
        B = np.array(parts)
        root = np.concatenate((B[:, 0:3].min(axis=0), B[:, 3:6].max(axis=0), B[:, 6:9].min(axis=0),
                               B[:, 9:12].max(axis=0)))
    else:
        root = _triangle_elements_range(V, F, E, 0, m)
    return E, root


@njit(cache=True, nogil=True)  # one serial, GIL-free kernel: faces i0..i1 (ranges on Python threads)
def _triangle_elements_range(V, F, E, i0, i1):
    """Rows i0..i1 of E; returns their bounds (box lo, hi, centroid lo, hi), running in scalars."""
    lx = ly = lz = cx0 = cy0 = cz0 = np.inf
    hx = hy = hz = cx1 = cy1 = cz1 = -np.inf
    for t in range(i0, i1):
        for d in range(3):
            a, b, c = V[F[t, 0], d], V[F[t, 1], d], V[F[t, 2], d]
            E[t, d] = (a + b + c) / 3.0
            E[t, 3 + d] = min(a, min(b, c))
            E[t, 6 + d] = max(a, max(b, c))
        lx, ly, lz = min(lx, E[t, 3]), min(ly, E[t, 4]), min(lz, E[t, 5])
        hx, hy, hz = max(hx, E[t, 6]), max(hy, E[t, 7]), max(hz, E[t, 8])
        cx0, cy0, cz0 = min(cx0, E[t, 0]), min(cy0, E[t, 1]), min(cz0, E[t, 2])
        cx1, cy1, cz1 = max(cx1, E[t, 0]), max(cy1, E[t, 1]), max(cz1, E[t, 2])
    root = np.empty(12)
    root[0], root[1], root[2], root[3], root[4], root[5] = lx, ly, lz, hx, hy, hz
    root[6], root[7], root[8], root[9], root[10], root[11] = cx0, cy0, cz0, cx1, cy1, cz1
    return root
