"""Bundled example inputs (regenerate with scripts/make_demo_data.py) and analytic test shapes (``_shapes``)."""

import os

from gsdf.data._shapes import (
    anisotropic_mesh,
    corrupt,
    cylinder_sdf,
    grid_mesh,
    sample_cylinder,
    sample_sphere,
    sphere_mesh,
    sphere_sdf,
)

__all__ = ["path", "grid_mesh", "sphere_mesh", "anisotropic_mesh", "sphere_sdf", "cylinder_sdf", "sample_sphere",
           "sample_cylinder", "corrupt"]

DATA_DIR = os.path.dirname(os.path.abspath(__file__))


def path(name: str) -> str:
    """Absolute path of a bundled file: ``broken_soup.obj`` or ``torus_cloud.xyz``."""
    p = os.path.join(DATA_DIR, name)
    if not os.path.exists(p):
        files = sorted(f for f in os.listdir(DATA_DIR) if not f.endswith((".py", "__pycache__")))
        raise ValueError(f"no bundled file named {name!r}; available: {files}")
    return p
