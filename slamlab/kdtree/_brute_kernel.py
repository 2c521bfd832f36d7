"""Compiled running top-``c`` selection for the blocked brute force (our addition, speed; issue 25).

:func:`slamlab.kdtree.knn.exact_knn` ranks the database in blocks: one BLAS product per block writes the
ranking keys ``|x|²/2 - q·x`` of every query against the block (queries × block rows, row-major). The
numpy path then selects from that matrix with a ``min`` pass and ``argmin`` passes (the teaching
version, :func:`slamlab.kdtree.knn._exact_knn_float`). The kernel here does the selection in one pass
over each row of the block while the row is in cache: it keeps, per query, the ``c`` smallest keys seen
so far, sorted, and compares every key with the ``c``-th smallest (a vectorisable count over chunks of
64 keys; the rare chunks with a smaller key are walked once more to insert them).

Ties keep the lowest database index first (a key equal to the ``c``-th best does not enter; an entering
key goes behind the equal ones already kept), as the numpy path's ``argmin`` does.
"""

from __future__ import annotations

from slamlab._compiled import kernel

__all__ = ["update_top_c"]

_CHUNK = 64  # keys per vectorised test (256 bytes of one row)


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
            n = 0
            for j in range(j0, j1):  # how many keys of the chunk beat it (a SIMD compare-and-count)
                n += row[j] < worst
            if n == 0:
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
