"""The C heap of a notebook's kernel: large arrays go back to the system when freed (our addition; issue 45).

A student's JupyterHub kernel commonly gets 512 MiB. numpy allocates its arrays with ``malloc``; glibc keeps freed
blocks below its mmap threshold in the heap for reuse, and that threshold grows (up to 32 MiB) every time a larger
mapped block is freed, so after the first large temporaries every later one of up to 32 MiB stays in the heap, and
each thread that allocates gets its own arena (up to 8 per core). Measured with ``tools/kernel_memory.py``
(environment.md, 2026-12-08, quiet): notebook 04 peaked at 583 MiB and 07 at 675 MiB with two arenas alone, 506
and 505 MiB with two arenas and a fixed 256 KiB threshold (the same outputs). :func:`limit_heap_growth` sets the
latter with ``mallopt``, at run time; :func:`slamlab.notebook_setup` calls it. A loop that maps and frees arrays
of a few MiB on every pass pays page faults for it, so the correlation search runs inside
:func:`reuse_large_blocks`. Other C libraries: nothing is changed.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import sys
import threading

#: glibc's mallopt parameter numbers (malloc.h)
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
_M_ARENA_MAX = -8
_TRIM_DEFAULT = 128 * 1024  # glibc's M_TRIM_THRESHOLD once the mmap threshold is set by hand
_REUSE_BYTES = 32 * 1024 * 1024  # glibc's largest dynamic mmap threshold

_STATE = {"libc": None, "threshold": None, "depth": 0}
_LOCK = threading.Lock()

#: the settings :func:`slamlab.notebook_setup` applies
ARENA_MAX = 2
MMAP_THRESHOLD_BYTES = 256 * 1024


def limit_heap_growth(arena_max: int = ARENA_MAX, mmap_threshold_bytes: int = MMAP_THRESHOLD_BYTES) -> bool:
    """Cap glibc's malloc arenas and fix its mmap threshold, so that freed large arrays leave the process.

    Parameters
    ----------
    arena_max : int
        Most malloc arenas (glibc's default: 8 per core).
    mmap_threshold_bytes : int
        Blocks at least this large are mapped on their own and unmapped when freed (fixed: no longer raised
        by glibc's dynamic rule).

    Returns
    -------
    bool
        True when glibc accepted both settings; False elsewhere (not Linux, another C library), where nothing
        changes.
    """
    if not isinstance(arena_max, int) or isinstance(arena_max, bool) or arena_max < 1:
        raise ValueError(f"`arena_max` must be an integer >= 1; got {arena_max!r}")
    if (not isinstance(mmap_threshold_bytes, int) or isinstance(mmap_threshold_bytes, bool)
            or not 0 < mmap_threshold_bytes <= 32 * 1024 * 1024):
        raise ValueError(f"`mmap_threshold_bytes` must be an integer in (0, 32 MiB]; got {mmap_threshold_bytes!r}")
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    ok = bool(mallopt(_M_ARENA_MAX, arena_max) == 1) & bool(mallopt(_M_MMAP_THRESHOLD, mmap_threshold_bytes) == 1)
    if ok:
        with _LOCK:
            _STATE["libc"], _STATE["threshold"] = libc, mmap_threshold_bytes
    return ok


@contextlib.contextmanager
def reuse_large_blocks():
    """Inside: glibc reuses freed blocks up to 32 MiB from the heap again, as it does by default (our addition).

    A loop that allocates and frees arrays of a few MiB on every pass (the correlation search's FFT batches) pays
    a fresh mapping and its page faults for each of them under :func:`limit_heap_growth`'s fixed threshold:
    ``localise()`` took 2.5× the CPU time (0.26 → 0.68 s on this machine). Inside this block the threshold is
    32 MiB and the heap is not trimmed; on leaving, the threshold is set back and the heap's free top is
    returned (``malloc_trim``). Nothing happens when the limit is not set. Nested and concurrent uses are counted.

    Yields
    ------
    None
    """
    with _LOCK:
        libc = _STATE["libc"]
        if libc is not None:
            _STATE["depth"] += 1
            if _STATE["depth"] == 1:
                libc.mallopt(_M_TRIM_THRESHOLD, 2 * _REUSE_BYTES)
                libc.mallopt(_M_MMAP_THRESHOLD, _REUSE_BYTES)
    try:
        yield
    finally:
        if libc is not None:
            with _LOCK:
                _STATE["depth"] -= 1
                if _STATE["depth"] == 0:
                    libc.mallopt(_M_MMAP_THRESHOLD, _STATE["threshold"])
                    libc.mallopt(_M_TRIM_THRESHOLD, _TRIM_DEFAULT)
                    libc.malloc_trim(0)
