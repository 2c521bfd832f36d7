"""The two nearest targets of each query among candidate pairs, by descriptor distance (000 §3.3-3.4).

Package-private machinery of the stereo matching (:mod:`slamlab.stereo.local_stages`) and the map matching
(:mod:`slamlab.stereo.map_stages`): the numpy two-nearest selection, the descriptor distances of pairs, and the
dispatch of binary descriptors to the compiled kernel. The module's underscore marks its names private.
"""

from __future__ import annotations

import numpy as np

from .._compiled import numba_enabled
from .window_kernel import ranges_hamming_2nn

__all__ = ["pair_distances", "pairs_two_nearest", "two_nearest"]


def pairs_two_nearest(A, B, qi, ti):
    """Nearest and second-nearest target of each query among the candidate pairs ``(qi, ti)`` (grouped by
    ascending query index), by descriptor distance: ``(query, nearest, d1, d2, second)`` as :func:`two_nearest`.
    Binary descriptors take the compiled kernel when numba is enabled (same result, tested), otherwise numpy."""
    if A.dtype == np.uint8 and A.shape[1] % 8 == 0 and numba_enabled():
        cnt = np.bincount(qi, minlength=len(A))
        hi = np.cumsum(cnt)
        r1, d1, d2, r2 = ranges_hamming_2nn(A.view(np.uint64), B.view(np.uint64), ti, hi - cnt, hi)
        q = np.flatnonzero(r1 >= 0)
        return q, r1[q], d1[q], d2[q], r2[q]
    return two_nearest(qi, ti, pair_distances(A, B, qi, ti))


def two_nearest(qi, ti, d):
    """Nearest and second-nearest target of each query from candidate pairs ``(qi, ti)`` with distances
    ``d``, the pairs grouped by ascending query index: ``(query, nearest, d1, d2, second)``, one row per
    query with candidates (``d2 = inf`` and ``second = -1`` for a single candidate; with a tie, d2 = d1)."""
    start = np.flatnonzero(np.r_[True, qi[1:] != qi[:-1]])
    size = np.diff(np.r_[start, qi.size])
    d1 = np.minimum.reduceat(d, start)
    at_min = np.flatnonzero(d == np.repeat(d1, size))
    first_min = at_min[np.r_[True, qi[at_min][1:] != qi[at_min][:-1]]]
    d_rest = d.copy()
    d_rest[first_min] = np.inf
    d2 = np.minimum.reduceat(d_rest, start)
    at2 = np.flatnonzero((d_rest == np.repeat(d2, size)) & np.isfinite(d_rest))
    second = np.full(start.size, -1, dtype=np.int64)
    g2 = np.searchsorted(start, at2, side="right") - 1
    second[g2[::-1]] = ti[at2[::-1]]  # the first second-nearest of each group wins
    return qi[first_min], ti[first_min], d1, d2, second


#: bytes of one block's gathered descriptors (per side) in :func:`pair_distances` (ours, memory: a block of 2^16
#: SIFT pairs held 3 x 32 MiB of temporaries; each pair's distance does not depend on the block size)
PAIR_BLOCK_BYTES = 1 << 22


def _block_rows(A) -> int:
    """Pairs per block of :func:`pair_distances` for descriptors ``A``: ``PAIR_BLOCK_BYTES`` of rows, at most 2^16."""
    return max(1, min(1 << 16, PAIR_BLOCK_BYTES // max(1, A.shape[1] * A.itemsize)))


def pair_distances(A, B, ia, ib, block: int | None = None) -> np.ndarray:
    """Descriptor distance of each pair ``(A[ia], B[ib])``: Hamming for uint8, Euclidean otherwise; pairs taken
    ``block`` at a time (None: as many as fill ``PAIR_BLOCK_BYTES``, at most 2^16)."""
    block = _block_rows(A) if block is None else block
    out = np.empty(ia.size)
    for s0 in range(0, ia.size, block):
        x, y = A[ia[s0:s0 + block]], B[ib[s0:s0 + block]]
        if A.dtype == np.uint8:
            if A.shape[1] % 8 == 0:  # 8 bytes at a time
                x, y = x.view(np.uint64), y.view(np.uint64)
            bits = np.bitwise_count(x ^ y)
            acc = bits[:, 0].astype(np.uint16)
            for j in range(1, bits.shape[1]):  # column adds: ~2x faster than .sum(axis=1) on 4 columns
                acc += bits[:, j]
            out[s0:s0 + block] = acc
        else:
            dxy = x.astype(np.float32) - y
            out[s0:s0 + block] = np.sqrt(np.einsum("ij,ij->i", dxy, dxy))
    return out
