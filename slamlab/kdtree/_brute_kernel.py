"""Compiled running top-``c`` selection for the blocked brute force (our addition, speed; issue 25).

:func:`slamlab.kdtree.knn.exact_knn` ranks the database in blocks: one BLAS product per block writes the
ranking keys ``|x|²/2 - q·x`` of every query against the block (queries × block rows, row-major). The
numpy path then selects from that matrix with a ``min`` pass and ``argmin`` passes (the teaching
version, :func:`slamlab.kdtree.knn._exact_knn_float`). The kernel here does the selection in one pass
over each row of the block while the row is in cache: it keeps, per query, the ``c`` smallest keys seen
so far, sorted, and compares every key with the ``c``-th smallest (a branch-free test over chunks of
64 keys, compiled to SIMD compares; the rare chunks with a smaller key are walked once more to insert them).

Ties keep the lowest database index first (a key equal to the ``c``-th best does not enter; an entering
key goes behind the equal ones already kept), as the numpy path's ``argmin`` does.

:func:`top_c_blocks` drives it over the blocks: in the calling thread (each product split over two
threads by BLAS, the selection on one), or, for large problems, on two workers that each take the next
free block, multiply it (BLAS on one thread) and select from it while its keys are still in L2, so that
both cores multiply and select; the two workers' lists are then merged by (key, index).
"""

from __future__ import annotations

import threading

import numpy as np

from slamlab._compiled import kernel
from slamlab._threads import blas_one_thread, shared_pool

__all__ = ["top_c_blocks", "update_top_c"]

_CHUNK = 64  # keys per vectorised test (256 bytes of one row; 32: slower, 128: about the same)


@kernel
def update_top_c(G, s0, best_key, best_idx, r0, r1):
    """Merge the keys of one block into the running ``c`` best of rows ``r0:r1`` (one pass per row).

    Parameters
    ----------
    G : (M, b) float32, C-contiguous
        Ranking keys of the block (row ``i``: query ``i``; column ``j``: database row ``s0 + j``).
    s0 : int
        Database index of the block's first column.
    best_key : (M, c) float32
        The ``c`` smallest keys seen so far per query, ascending (``inf`` where none yet); updated in place.
    best_idx : (M, c) int64
        Their database indices (``-1`` where none yet); updated in place.
    r0, r1 : int
        The rows (queries) to update (a slice, so that two threads can share a block).

    Returns
    -------
    None
    """
    b = G.shape[1]
    c = best_key.shape[1]
    for i in range(r0, r1):
        row = G[i]
        worst = best_key[i, c - 1]  # the c-th smallest key so far: a key must beat it to enter
        for j0 in range(0, b, _CHUNK):
            j1 = min(j0 + _CHUNK, b)
            beats = False
            # does any key of the chunk beat it? Branch-free, so it compiles to SIMD compares; the index is
            # unsigned because a signed one may be negative, which numba wraps around (row[-1] is the last key),
            # and that per-key check made LLVM gather the keys one by one instead of loading 16 at a time
            for j in range(np.uint64(j0), np.uint64(j1)):
                beats |= row[j] < worst
            if not beats:
                continue
            for j in range(j0, j1):  # insertion of the few that do, keeping the list sorted
                g = row[j]
                if g < worst:
                    p = c - 1
                    while p > 0 and best_key[i, p - 1] > g:  # strictly greater: ties keep the earlier index
                        best_key[i, p] = best_key[i, p - 1]
                        best_idx[i, p] = best_idx[i, p - 1]
                        p -= 1
                    best_key[i, p] = g
                    best_idx[i, p] = s0 + j
                    worst = best_key[i, c - 1]


def top_c_blocks(Qa, Xa, c, block, workers=1):
    """Indices of the ``c`` smallest ranking keys ``Qa @ Xa.T`` of every query, block by block (ties: lowest index).

    Parameters
    ----------
    Qa : (M, d + 1) float32
        Query rows ``[-q, 1]``.
    Xa : (N, d + 1) float32
        Database rows ``[x, |x|²/2]``.
    c : int
        Candidates kept per query (``c <= N``).
    block : int
        Database rows per product.
    workers : int
        1: every block in the calling thread; 2: the calling thread and a worker of
        :mod:`slamlab._threads`' pool each take the next free block, BLAS held to one thread meanwhile
        (:func:`slamlab._threads.blas_one_thread`).

    Returns
    -------
    (M, c) int64
        Database rows by ascending key, ties by index; ``-1`` where no finite key was seen.
    """
    M, N = Qa.shape[0], Xa.shape[0]
    starts, lock = iter(range(0, N, block)), threading.Lock()  # the blocks not taken yet

    def worker():  # products and selection of the next free block (in increasing order) until none is left
        best_key, best_idx = np.full((M, c), np.inf, dtype=np.float32), np.full((M, c), -1, dtype=np.int64)
        buf = np.empty(M * min(block, N), dtype=np.float32)
        while True:
            with lock:
                s0 = next(starts, None)
            if s0 is None:
                return best_key, best_idx
            s1 = min(s0 + block, N)
            G = buf[: M * (s1 - s0)].reshape(M, s1 - s0)  # contiguous rows, also for the last block
            np.matmul(Qa, Xa[s0:s1].T, out=G)  # (M, b) ranking keys |x|²/2 - q·x
            update_top_c(G, s0, best_key, best_idx, 0, M)

    if workers <= 1:
        return worker()[1]
    with blas_one_thread():
        other = shared_pool().submit(worker)
        try:
            parts = [worker()]
        finally:  # not started (the pool busy with other work): no block left for it; else wait for it
            if not other.cancel():
                parts.append(other.result())
    key, idx = (np.concatenate([p[j] for p in parts], axis=1) for j in (0, 1))
    o = np.lexsort((idx, key), axis=1)[:, :c]  # the c best of both lists by key, ties by the lower index
    return np.take_along_axis(idx, o, axis=1)
