"""Compiled kernels of the two-nearest search for binary descriptors (speed, issue 25).

The teaching versions are numpy: they build every candidate pair as arrays, then their Hamming
distances (``_pair_distances``), then the two nearest per query (``_two_nearest``). The kernels walk
the same pairs in the same order and keep only the two nearest, so nothing of size "pairs" is
allocated; the results are the same, bit for bit (tested against the numpy versions):

- :func:`window_hamming_2nn`: the window search of the map matching (our addition to 000 §3.4), the
  pairs of ``_radius_pairs`` in :mod:`slamlab.stereo.map_stages`;
- :func:`ranges_hamming_2nn`: candidates given as a range of an index list per query — the
  epipolar pairs of the stereo matching (000 §3.3, :func:`slamlab.stereo.epipolar_pairs`), and the
  brute-force search of the last frame's landmarks (every landmark a candidate; numpy:
  :func:`slamlab.kdtree.knn.exact_knn`, OpenCV's ``batchDistance``, whose order and ties it keeps).
"""

from __future__ import annotations

import numpy as np

from .._compiled import kernel

__all__ = ["ranges_hamming_2nn", "window_hamming_2nn"]


def _window_hamming_2nn(Dq, Dt, uv_q, uv_t, order, lo, hi, radius):  # pragma: no cover - compiled
    """For each query ``i``: the targets ``order[lo[i, c]:hi[i, c]]`` (c = 0, 1, 2: its 3 x 3 grid cells, in
    the numpy version's order) within ``radius`` px, their Hamming distances (descriptors as uint64 words)
    and the nearest / second nearest, each the first in that order among equals."""
    k = Dq.shape[0]
    r1 = np.full(k, -1, np.int64)
    r2 = np.full(k, -1, np.int64)
    d1 = np.full(k, np.inf)
    d2 = np.full(k, np.inf)
    r2_lim = radius * radius
    n_pairs = 0
    for i in range(k):
        for c in range(3):
            for j in range(lo[i, c], hi[i, c]):
                t = order[j]
                dx, dy = uv_q[i, 0] - uv_t[t, 0], uv_q[i, 1] - uv_t[t, 1]
                if dx * dx + dy * dy > r2_lim:  # outside the window
                    continue
                n_pairs += 1
                bits = np.uint64(0)
                for w in range(Dq.shape[1]):
                    # bits set in a 64-bit word: the "SWAR" count (Hacker's Delight §5-1)
                    x = Dq[i, w] ^ Dt[t, w]
                    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
                    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
                    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
                    bits += (x * np.uint64(0x0101010101010101)) >> np.uint64(56)
                d = float(bits)
                if d < d1[i]:  # a new nearest: the old one becomes the second
                    d2[i], r2[i] = d1[i], r1[i]
                    d1[i], r1[i] = d, t
                elif d < d2[i]:
                    d2[i], r2[i] = d, t
    return r1, d1, d2, r2, n_pairs


window_hamming_2nn = kernel(_window_hamming_2nn)
window_hamming_2nn.__doc__ = """Two nearest landmarks by Hamming distance within the window of each keypoint (compiled).

Parameters
----------
Dq : numpy.ndarray of uint64, shape (K, W)
    Keypoint descriptors as 64-bit words.
Dt : numpy.ndarray of uint64, shape (L, W)
    Landmark descriptors as 64-bit words.
uv_q : numpy.ndarray, shape (K, 2)
    Keypoint pixels.
uv_t : numpy.ndarray, shape (L, 2)
    Projected landmark pixels.
order, lo, hi : numpy.ndarray of int
    The grid of ``_radius_cells`` (targets sorted by cell; per query and column, a range of ``order``).
radius : float
    Window radius [px].

Returns
-------
tuple
    ``r1, d1, d2, r2`` per keypoint (``r1 = -1``: no landmark in the window; ``r2 = -1``, ``d2 = inf``: one)
    and the number of pairs within the windows.
"""


def _ranges_hamming_2nn(Dq, Dt, order, lo, hi):  # pragma: no cover - compiled
    """For each query ``i``: the targets ``order[lo[i]:hi[i]]`` in that order, their Hamming distances
    (descriptors as uint64 words) and the nearest / second nearest, each the first in that order among equals."""
    k = Dq.shape[0]
    r1 = np.full(k, -1, np.int64)
    r2 = np.full(k, -1, np.int64)
    d1 = np.full(k, np.inf)
    d2 = np.full(k, np.inf)
    n_max = 0
    for i in range(k):
        n_max = max(n_max, hi[i] - lo[i])
    bits = np.empty(max(n_max, 1), np.int64)  # the distances of one query's candidates
    for i in range(k):
        n = hi[i] - lo[i]
        # first the distances, in a loop without branches (the compiler vectorises it) ...
        for j in range(n):
            t = order[lo[i] + j]
            b = np.uint64(0)
            for w in range(Dq.shape[1]):
                # bits set in a 64-bit word: the "SWAR" count (Hacker's Delight §5-1)
                x = Dq[i, w] ^ Dt[t, w]
                x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
                x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
                x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
                b += (x * np.uint64(0x0101010101010101)) >> np.uint64(56)
            bits[j] = b
        # ... then the two smallest, as in the window kernel
        for j in range(n):
            d = float(bits[j])
            if d < d1[i]:  # a new nearest: the old one becomes the second
                d2[i], r2[i] = d1[i], r1[i]
                d1[i], r1[i] = d, order[lo[i] + j]
            elif d < d2[i]:
                d2[i], r2[i] = d, order[lo[i] + j]
    return r1, d1, d2, r2


ranges_hamming_2nn = kernel(_ranges_hamming_2nn)
ranges_hamming_2nn.__doc__ = """Two nearest targets by Hamming distance among each query's candidate range (compiled).

Parameters
----------
Dq : numpy.ndarray of uint64, shape (K, W)
    Query descriptors as 64-bit words.
Dt : numpy.ndarray of uint64, shape (N, W)
    Target descriptors as 64-bit words.
order : numpy.ndarray of int, shape (P,)
    Target indices; query ``i``'s candidates are ``order[lo[i]:hi[i]]``, in that order.
lo, hi : numpy.ndarray of int, shape (K,)
    Each query's range of ``order``.

Returns
-------
tuple
    ``r1, d1, d2, r2`` per query (``r1 = -1``, ``d1 = inf``: no candidate; ``r2 = -1``, ``d2 = inf``: one);
    among equal distances the first in ``order`` wins.
"""
