"""Thread limits around sparse direct solves.

SuperLU calls BLAS on many tiny blocks; with a multithreaded OpenBLAS every call wakes (and, on a busy
machine, waits for) the BLAS worker threads. Measured on the 2-core benchmark machine under load (a 6144-quad
polygon mesh, vector heat factorization + solve): 33.8 s with OpenBLAS's default 2 threads, 1.6 s with one.
:func:`single_blas_thread` limits BLAS to one thread for the duration of a block, through ``threadpoolctl``
when it is installed (the ``fast`` extra; a no-op otherwise).

Example
-------
>>> with single_blas_thread():
...     pass
"""

from __future__ import annotations

import contextlib

__all__ = ["single_blas_thread"]

_CONTROLLER = None


def _controller():
    global _CONTROLLER
    if _CONTROLLER is None:
        try:
            from threadpoolctl import ThreadpoolController

            _CONTROLLER = ThreadpoolController()
        except Exception:  # noqa: BLE001 - not installed, or no BLAS it can see: run unlimited
            _CONTROLLER = False
    return _CONTROLLER


def single_blas_thread():
    """A context manager limiting BLAS to one thread (no-op without threadpoolctl)."""
    c = _controller()
    if not c:
        return contextlib.nullcontext()
    return c.limit(limits=1, user_api="blas")
