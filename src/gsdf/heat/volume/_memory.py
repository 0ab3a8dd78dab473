"""Memory estimates of the volume solvers: refuse a resolution before any work when it cannot fit."""

from __future__ import annotations

import os

__all__ = ["available_memory", "check_memory", "BYTES_PER_NODE"]

BYTES_PER_NODE = 400  # positions, X, Y, d*, DCT work arrays (≈ 250 B/node measured); the constrained CG more


def available_memory() -> int:
    """Bytes of available physical memory (MemAvailable), or 8 GiB when it cannot be read."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return 8 << 30


def check_memory(n_nodes: int, max_memory=None) -> int:
    """Estimate the memory of a grid solve with ``n_nodes`` nodes and refuse (ValueError) when too large."""
    need = int(n_nodes) * BYTES_PER_NODE
    limit = int(0.8 * available_memory()) if max_memory is None else int(max_memory)
    if need > limit:
        raise ValueError(f"resolution too large: a grid of {n_nodes:,} nodes needs about {need / 2**30:.1f} GiB, "
                         f"more than the {limit / 2**30:.1f} GiB allowed; lower the resolution")
    return need
