"""Memory guard: estimate the bytes of a large allocation before making it, refuse with numbers.

Every allocation proportional to a grid (voxel and winding grids, sampled signed-distance grids,
isosurface extraction) or to queries × neighbours calls :func:`check_bytes` first. The limit is what the
machine can give now: ``MemAvailable`` of ``/proc/meminfo`` (Linux), else ``os.sysconf`` physical pages;
the environment variable ``GSDF_MEMORY_LIMIT`` (bytes, or with a K/M/G/T suffix, e.g. ``2G``) overrides it.
A refused request is a ``ValueError`` naming what was asked, its estimated size and the limit, instead of a
numpy ``MemoryError`` traceback (or the machine swapping).

Example
-------
>>> import os
>>> os.environ["GSDF_MEMORY_LIMIT"] = "1M"
>>> try:
...     check_bytes(grid_bytes((1000, 1000, 1000), 8), "resolution=1000 grid")
... except ValueError as e:
...     print(str(e).split(";")[0])
resolution=1000 grid: needs about 7.5 GB, more than the 1.0 MB allowed
>>> del os.environ["GSDF_MEMORY_LIMIT"]
"""

from __future__ import annotations

import math
import os

ENV = "GSDF_MEMORY_LIMIT"
_SUFFIX = {"": 1, "B": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def _parse(text: str) -> int:
    t = text.strip().upper().removesuffix("IB").removesuffix("B")
    unit = t[-1:] if t[-1:] in _SUFFIX else ""
    num = t[: len(t) - len(unit)] if unit else t
    try:
        v = float(num) * _SUFFIX[unit]
    except ValueError:
        raise ValueError(f"{ENV}: expected bytes like 2000000000 or 2G, got {text!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise ValueError(f"{ENV}: expected a positive size, got {text!r}")
    return int(v)


#: Share of the available memory one request may take when GSDF_MEMORY_LIMIT is not set.
SHARE = 0.8


def available_bytes() -> int:
    """Bytes a new allocation may use: ``GSDF_MEMORY_LIMIT`` if set, else 80 % of ``MemAvailable`` (Linux),
    else of physical memory; 2**62 when none can be read."""
    env = os.environ.get(ENV)
    if env:
        return _parse(env)
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(SHARE * int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(SHARE * int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES")))
    except (ValueError, OSError, AttributeError):
        return 1 << 62


def human(n: float) -> str:
    """``8.0 GB`` style size (powers of 1024)."""
    for unit in ("B", "KB", "MB", "GB", "TB", "PB"):
        if abs(n) < 1024 or unit == "PB":
            return f"{n:.1f} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024.0
    return f"{n:.1f} PB"  # pragma: no cover


def grid_bytes(shape, bytes_per_node: float) -> int:
    """Bytes of a grid of ``shape`` nodes (Python integers: no overflow) at ``bytes_per_node``."""
    n = 1
    for s in shape:
        n *= int(s)
    return int(n * bytes_per_node)


def check_bytes(nbytes: float, what: str, limit: int | None = None) -> None:
    """Raise ``ValueError`` when ``nbytes`` exceeds ``limit`` (default :func:`available_bytes`).

    ``what`` names the request (e.g. ``"voxelize: resolution=4000 grid (4000×4000×4000 cells)"``) and should
    say what to lower.
    """
    limit = available_bytes() if limit is None else int(limit)
    if nbytes > limit:
        raise ValueError(f"{what}: needs about {human(nbytes)}, more than the {human(limit)} allowed; "
                         f"lower the resolution/size, or set {ENV} (bytes) to change the limit")


def chunk_rows(bytes_per_row: float, total: int, budget: float | None = None) -> int:
    """Rows per chunk so one chunk uses at most ``budget`` bytes (default: 1/8 of the available memory,
    capped at 256 MB); at least 1 and at most ``total``."""
    if budget is None:
        budget = min(available_bytes() / 8, 256 << 20)
    return int(max(1, min(max(total, 1), budget // max(bytes_per_row, 1))))
