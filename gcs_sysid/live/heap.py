"""Give the C heap's free pages back to the system after a learner step.

A learner step builds and drops tens of MiB of short-lived objects: the window's decode (up to
~17 MiB for a coalesced window four windows long), the smoother's arrays, the confidence map's and
the hyperparameter refresh's temporaries. CPython and NumPy take that memory
from glibc's ``malloc``, and glibc keeps freed chunks in its arenas for reuse: it returns memory to
the system only from the top of the main heap, so once long-lived objects (the row stores, the
k-d tree, compiled programs) are interleaved with the freed chunks, the resident size stays at the
step's high-water mark and climbs each time a longer window or a refresh sets a new one. Measured
in the one-hour soak (``benchmarks/bench_soak.py``, ``docs/benchmarks.md``): the main arena held
~135-165 MiB of *free* chunks beside ~130-170 MiB in use once the stores had filled.

``malloc_trim(0)`` (glibc >= 2.8) walks every arena and returns whole free pages anywhere in them to
the system (``madvise(MADV_DONTNEED)``), not just the top of the heap; the memory stays mapped and
is faulted back in when reused. It changes no value the learner computes. Other C libraries (musl,
macOS, Windows) have no ``malloc_trim``; there :func:`release_free_heap` does nothing.

References: glibc manual, "Memory Allocation Tunables" and ``malloc_trim(3)``.
"""

from __future__ import annotations

import ctypes
import ctypes.util

__all__ = ["release_free_heap", "trim_available"]

_trim = None
_looked = False


def _malloc_trim():
    global _trim, _looked
    if not _looked:
        _looked = True
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
            fn = libc.malloc_trim
            fn.argtypes, fn.restype = [ctypes.c_size_t], ctypes.c_int
            _trim = fn
        except (OSError, AttributeError):
            _trim = None
    return _trim


def trim_available() -> bool:
    """True where the C library has ``malloc_trim`` (glibc)."""
    return _malloc_trim() is not None


def release_free_heap() -> bool:
    """Return the free pages of every malloc arena to the system (``malloc_trim(0)``).

    Returns:
        True if memory was released, False if none could be or the C library has no
        ``malloc_trim``. Never raises.
    """
    fn = _malloc_trim()
    return bool(fn(0)) if fn is not None else False
