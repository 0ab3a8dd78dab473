"""Shared helpers of the subcommands: loading inputs, progress bars, clean error reporting."""

from __future__ import annotations

import functools
import os

import click
import numpy as np

POINT_EXTENSIONS = {".xyz", ".pwn", ".pc", ".npy", ".npz"}


class Geometry:
    """A loaded input: a triangle mesh/soup ``(V, F)`` or an oriented point cloud ``(P, N)``."""

    def __init__(self, path, V=None, F=None, P=None, N=None):
        self.path, self.V, self.F, self.P, self.N = path, V, F, P, N

    @property
    def is_mesh(self) -> bool:
        return self.F is not None

    @property
    def positions(self) -> np.ndarray:
        return self.V if self.is_mesh else self.P

    def describe(self) -> str:
        if self.is_mesh:
            return f"{self.path}: mesh, {len(self.V)} vertices, {len(self.F)} triangles"
        return f"{self.path}: point cloud, {len(self.P)} oriented points"

    def winding(self, beta=None):
        """A reusable fast winding number object for this input."""
        from ..winding import FastWindingNumber, FastWindingNumberPoints

        if self.is_mesh:
            return FastWindingNumber(self.V, self.F, beta=2.0 if beta is None else beta)
        return FastWindingNumberPoints(self.P, self.N, beta=2.3 if beta is None else beta)


def load_geometry(path: str, estimate_normals: bool = False) -> Geometry:
    """Read a mesh, or a point cloud when the file has no faces (or has a point-cloud extension)."""
    from ..io import read_mesh, read_points

    ext = os.path.splitext(path)[1].lower()
    if ext not in POINT_EXTENSIONS:
        try:
            V, F = read_mesh(path)
            return Geometry(path, V=V, F=F)
        except ValueError as exc:
            if "no faces" not in str(exc):
                raise
    P, N = read_points(path)
    if N is None:
        if not estimate_normals:
            raise ValueError(f"{path}: the point cloud has no normals; winding numbers need oriented normals "
                             "(pass --estimate-normals to use PCA normals oriented away from the centroid)")
        from ..winding.point_areas import estimate_normals as pca

        N = pca(P, orient_towards=P.mean(axis=0))
    return Geometry(path, P=P, N=N)


def progress_bar(total: int, desc: str, enabled: bool = True):
    """A tqdm bar and an ``update(done, total)`` callback for the library's ``progress`` hooks."""
    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit="pt", unit_scale=True, disable=not enabled, leave=False)

    def update(done, _total):
        bar.update(done - bar.n)

    return bar, update


def counting(func, desc: str, enabled: bool = True):
    """Wrap a field ``func(Q)`` so that a progress bar counts the evaluated points (total unknown up front)."""
    from tqdm import tqdm

    bar = tqdm(desc=desc, unit="pt", unit_scale=True, disable=not enabled, leave=False)

    def wrapped(Q):
        out = func(Q)
        bar.update(len(Q))
        return out

    return bar, wrapped


def report_errors(fn):
    """Turn the library's ValueError / FileNotFoundError into a clean CLI error (exit code 1)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except (ValueError, FileNotFoundError) as exc:
            raise click.ClickException(str(exc)) from exc

    return wrapper


def bbox_of(X: np.ndarray, pad: float) -> tuple[np.ndarray, np.ndarray]:
    from ..mesh.geometry import bounding_box

    return bounding_box(X, pad)


def parse_floats(text: str | None, name: str) -> list[float] | None:
    if text is None:
        return None
    try:
        return [float(t) for t in text.split(",") if t.strip()]
    except ValueError as exc:
        raise click.BadParameter(f"expected comma-separated numbers, got {text!r}", param_hint=name) from exc


def ensure_parent(path: str) -> None:
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)


beta_option = click.option("--beta", type=float, default=None,
                           help="Accuracy β of the fast winding number (default 2 for meshes, 2.3 for points).")
quiet_option = click.option("-q", "--quiet", is_flag=True, help="No progress bars.")
normals_option = click.option("--estimate-normals", is_flag=True,
                              help="For clouds without normals: PCA normals oriented away from the centroid.")
