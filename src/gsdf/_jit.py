"""numba set-up for the whole package: where compiled kernels are cached, and saying so when they compile.

Every kernel is ``@njit(cache=True)``: the first call compiles it (seconds) and writes machine code next to
the source (``__pycache__``); later processes load it in milliseconds. Three things here:

- :func:`configure_cache` (run by ``import gsdf``, before numba is imported): numba itself falls back from
  a read-only install directory to the user cache dir (``~/.cache/numba``); when that is not writable
  either (read-only home in a container), ``NUMBA_CACHE_DIR`` is pointed at a per-user temp dir so that
  ``cache=True`` still works instead of failing. An explicit ``NUMBA_CACHE_DIR`` is never overridden.
- :func:`install_compile_notice`: the CLI prints one line on stderr the first time a gsdf kernel compiles
  in a process ("compiling kernels, once per install"), so a cold first run does not look like a hang.
- :func:`failed_kernel`: which gsdf kernel was being compiled when compilation raised, so the CLI can
  stop with a message naming it instead of a traceback from numba internals.

Example
-------
>>> from gsdf import _jit
>>> _jit.install_compile_notice()        # the CLI does this at start
"""

from __future__ import annotations

import os
import sys
import tempfile

NOTICE = ("gsdf: compiling kernels, once per install (later runs start in about a second; "
          "`gsdf warmup` compiles all of them at once)")

_listener = None
_first_compile_callbacks = []


def _writable(path: str) -> bool:
    while path and not os.path.isdir(path):  # the nearest existing ancestor decides
        parent = os.path.dirname(path)
        if parent == path:
            return False
        path = parent
    return os.access(path, os.W_OK | os.X_OK)


def configure_cache(package_dir: str | None = None) -> str | None:
    """Make ``cache=True`` work on read-only installs; returns the ``NUMBA_CACHE_DIR`` it set, else None.

    Parameters
    ----------
    package_dir : str, optional
        The installed package directory (default: this file's directory).
    """
    if "numba" in sys.modules or os.environ.get("NUMBA_CACHE_DIR"):
        return None  # numba has read its configuration already / the user chose
    package_dir = package_dir or os.path.dirname(os.path.abspath(__file__))
    if _writable(package_dir):
        return None  # in-tree __pycache__ (numba's first choice)
    user_cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    if _writable(os.path.join(user_cache, "numba")):
        return None  # numba's own fallback works
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    path = os.path.join(tempfile.gettempdir(), f"gsdf-numba-cache-{uid}")
    os.environ["NUMBA_CACHE_DIR"] = path
    return path


def _kernel_name(dispatcher) -> str:
    func = getattr(dispatcher, "py_func", None)
    if func is None:
        return repr(dispatcher)
    return f"{func.__module__}.{func.__qualname__}"


def install_compile_notice(stream=None, message: str = NOTICE):
    """Print ``message`` once (on ``stream``, default stderr) when a gsdf kernel first compiles.

    Only cache misses compile (numba's ``numba:compile`` event fires after the disk cache was checked), so a
    warm install prints nothing. Installing twice is a no-op. Returns the listener.
    """
    global _listener
    if _listener is not None:
        return _listener
    from numba.core import errors, event

    class _Notice(event.Listener):
        def __init__(self):
            self.printed = False
            self.failed = {}      # gsdf kernel -> exception of its last compilation, while unresolved

        def on_start(self, ev):
            name = _kernel_name(ev.data.get("dispatcher"))
            if not name.startswith("gsdf."):
                return
            if not self.printed:
                self.printed = True
                out = stream if stream is not None else sys.stderr
                print(message, file=out, flush=True)
                while _first_compile_callbacks:
                    _first_compile_callbacks.pop(0)()

        def on_end(self, ev):
            name = _kernel_name(ev.data.get("dispatcher"))
            if not name.startswith("gsdf."):
                return
            details = getattr(ev, "_exc_details", None)
            exc = details[1] if details else None
            if exc is None:
                self.failed.pop(name, None)
            elif not isinstance(exc, errors.ForceLiteralArg):  # numba's normal retry with literal types
                self.failed[name] = exc

    _listener = _Notice()
    event.register("numba:compile", _listener)
    return _listener


def on_first_compile(callback) -> None:
    """Call ``callback()`` when the first gsdf kernel compiles in this process (with the notice).

    Needs :func:`install_compile_notice`; nothing happens on a warm cache. Used by ``gsdf demo`` to compile
    the second half of its kernels in a background process while the first half compiles here.
    """
    _first_compile_callbacks.append(callback)


def cancel_first_compile(callback) -> None:
    """Withdraw a callback of :func:`on_first_compile` that has not run yet."""
    if callback in _first_compile_callbacks:
        _first_compile_callbacks.remove(callback)


def failed_kernel() -> str | None:
    """The first gsdf kernel whose compilation raised and was not retried successfully (None if none)."""
    if _listener is None or not _listener.failed:
        return None
    return next(iter(_listener.failed))


def compile_error_message(exc: BaseException) -> str | None:
    """A one-line explanation when ``exc`` came from compiling a gsdf kernel, else None."""
    name = failed_kernel()
    if name is None:
        return None
    first = (str(exc).strip().splitlines() or [""])[0][:300]
    return (f"compiling the numba kernel {name} failed on this platform ({type(exc).__name__}: {first}). "
            "Please report it with `python -c \"import numba; numba.sysinfo()\"` output; "
            "NUMBA_DISABLE_JIT=1 runs gsdf as plain Python (very slow).")
