"""Two shared worker threads for numpy work that releases the GIL (our addition, speed; issue 17).

One pool per process, shared by every caller (SURF's response maps, orientations and descriptors;
the exact k-NN's numpy selection passes, and the second worker of its two-worker path), so that concurrent callers — e.g. the stereo pipeline's two images — still run at most two
threads of such work. Tasks never submit tasks (no nesting). Where two workers each call BLAS (the
exact k-NN's two-worker path), :func:`blas_one_thread` holds numpy's OpenBLAS to one thread meanwhile.
"""

from __future__ import annotations

import contextlib
import threading

_POOL = None


def shared_pool():
    """The process's two worker threads, created on first use."""
    global _POOL
    if _POOL is None:
        from concurrent.futures import ThreadPoolExecutor

        _POOL = ThreadPoolExecutor(max_workers=2, thread_name_prefix="slamlab-worker")
    return _POOL


def run_tasks(tasks, workers: int):
    """Results of the zero-argument callables ``tasks``, in order; in the shared pool when ``workers > 1``.

    >>> run_tasks([lambda: 1, lambda: 2], 2)
    [1, 2]
    """
    if workers <= 1 or len(tasks) <= 1:
        return [t() for t in tasks]
    return [f.result() for f in [shared_pool().submit(t) for t in tasks]]


# numpy's OpenBLAS thread count (issue 25): two workers that each call BLAS must call it on one thread each,
# or the two threaded products fight for the two cores (measured: 10-18x slower than one threaded caller).
# OpenBLAS's count is process-wide (its "_local" setter too, in pthreads builds), so it is lowered while any
# caller needs it and restored when the last one leaves.
_BLAS = None  # (get, set) of numpy's OpenBLAS thread count once looked up; () where it cannot be set
_BLAS_LOCK = threading.Lock()
_BLAS_USERS = [0, None]  # callers inside blas_one_thread(), the count to restore


def _openblas_threads():
    """``(get, set)`` of the thread count of the OpenBLAS that numpy loaded, or ``()`` where not found.

    Looks for the library numpy's wheels ship (``numpy.libs`` on Linux and Windows, ``numpy/.dylibs`` on
    macOS) and its setter under the names its builds use; accepts only a pthreads or sequential build
    (an OpenMP build counts threads per caller already).

    Returns
    -------
    tuple
        ``(get, set)`` ctypes functions, or ``()``.
    """
    global _BLAS
    if _BLAS is None:
        _BLAS = ()
        import ctypes
        import glob
        import os

        import numpy

        here = os.path.dirname(numpy.__file__)
        for path in sorted(glob.glob(os.path.join(here, os.pardir, "numpy.libs", "*openblas*"))
                           + glob.glob(os.path.join(here, ".dylibs", "*openblas*"))):
            try:
                lib = ctypes.CDLL(path)
            except OSError:  # pragma: no cover - a library of another platform
                continue
            for pre, post in (("scipy_openblas_", "64_"), ("openblas_", "64_"), ("openblas_", "")):
                try:
                    get, put, par = (getattr(lib, f"{pre}{f}{post}") for f in
                                     ("get_num_threads", "set_num_threads", "get_parallel"))
                except AttributeError:
                    continue
                if par() in (0, 1):  # sequential or pthreads: one process-wide count
                    _BLAS = (get, put)
                break
            if _BLAS:
                break
    return _BLAS


def blas_threads_settable() -> bool:
    """Whether :func:`blas_one_thread` can hold numpy's BLAS to one thread here.

    Returns
    -------
    bool
        True where numpy's OpenBLAS (pthreads or sequential build) was found.
    """
    return bool(_openblas_threads())


@contextlib.contextmanager
def blas_one_thread():
    """Hold numpy's OpenBLAS to one thread inside the block (process-wide), so that two workers can each
    call BLAS at once; the count before the first of nested or concurrent callers is restored after the last.

    Does nothing where :func:`blas_threads_settable` is false.

    Yields
    ------
    None
    """
    fns = _openblas_threads()
    if not fns:
        yield
        return
    get, put = fns
    with _BLAS_LOCK:
        if _BLAS_USERS[0] == 0:
            _BLAS_USERS[1] = get()
            put(1)
        _BLAS_USERS[0] += 1
    try:
        yield
    finally:
        with _BLAS_LOCK:
            _BLAS_USERS[0] -= 1
            if _BLAS_USERS[0] == 0:
                put(_BLAS_USERS[1])
