"""The C heap of a notebook's kernel: large arrays go back to the system when freed (our addition; issue 45).

A student's JupyterHub kernel commonly gets 512 MiB. numpy allocates its arrays with ``malloc``; glibc keeps freed
blocks below its mmap threshold in the heap for reuse, and that threshold grows (up to 32 MiB) every time a larger
mapped block is freed, so after the first large temporaries every later one of up to 32 MiB stays in the heap, and
each thread that allocates gets its own arena (up to 8 per core). Measured with ``tools/kernel_memory.py`` on
notebook 04 (environment.md): the kernel peaked at 595 MiB as glibc sets it, 520 MiB with two arenas and 498 MiB
with two arenas and a fixed 256 KiB threshold (the same outputs). :func:`limit_heap_growth` sets the latter with
``mallopt``, at run time; :func:`slamlab.notebook_setup` calls it. Other C libraries: nothing is changed.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import sys

#: glibc's mallopt parameter numbers (malloc.h)
_M_MMAP_THRESHOLD = -3
_M_ARENA_MAX = -8

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
    return bool(mallopt(_M_ARENA_MAX, arena_max) == 1) & bool(mallopt(_M_MMAP_THRESHOLD, mmap_threshold_bytes) == 1)
