"""Two shared worker threads for numpy work that releases the GIL (our addition, speed; issue 17).

One pool per process, shared by every caller (SURF's response maps, orientations and descriptors;
the exact k-NN's numpy selection passes, and its compiled selection when ``knn._POOL_SELECTION`` is
on), so that concurrent callers — e.g. the stereo pipeline's two images — still run at most two
threads of such work. Tasks never submit tasks (no nesting).
"""

from __future__ import annotations

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
