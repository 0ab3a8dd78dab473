"""Bundled example inputs (regenerate with scripts/make_demo_data.py)."""

import os

DATA_DIR = os.path.dirname(os.path.abspath(__file__))


def path(name: str) -> str:
    """Absolute path of a bundled file: ``broken_soup.obj`` or ``torus_cloud.xyz``."""
    p = os.path.join(DATA_DIR, name)
    if not os.path.exists(p):
        raise ValueError(f"no bundled file named {name!r}; available: {sorted(os.listdir(DATA_DIR))}")
    return p
