"""Compiled kernels of the two-nearest search for binary descriptors (speed, issue 25).

The teaching versions are numpy: they build every candidate pair as arrays, then their Hamming
distances (``pair_distances`` of the stereo package's private ``_pairs`` module), then the two nearest
per query (``two_nearest``). The kernels walk the same pairs in the same order and keep only the two
nearest, so nothing of size "pairs" is allocated; the results are the same, bit for bit (tested against
the numpy versions):

- :func:`window_hamming_2nn`: the window search of the map matching (our addition to 000 §3.4), the
  pairs of ``_radius_pairs`` in :mod:`slamlab.stereo.map_stages`;
- ``ranges_hamming_2nn`` (in :mod:`slamlab.kdtree`, re-exported here): candidates given as a range of an
  index list per query — the epipolar pairs of the stereo matching (000 §3.3,
  ``slamlab.stereo.local_stages.epipolar_pairs``);
- :func:`epipolar_hamming_2nn`: the stereo matching in one pass when the epipolar lines are nearly rows
  (the rendered and KITTI rigs): each left keypoint's rows of right keypoints, the distance test of
  ``epipolar_pairs`` (the same arithmetic) and the two nearest, without the arrays of pairs. The brute-force search of the last frame's landmarks
  (:func:`slamlab.kdtree.knn.exact_knn`, binary 2-NN) has its own kernel beside it, keeping OpenCV's
  ``batchDistance`` order and ties.
"""

from __future__ import annotations

import numpy as np

from .._compiled import kernel
from ..kdtree._hamming_kernel import (  # ranges_hamming_2nn re-exported: the stereo matching's user
    hamming_words,
    no_two_nearest,
    ranges_hamming_2nn,
)

__all__ = ["epipolar_hamming_2nn", "ranges_hamming_2nn", "window_hamming_2nn"]


def _window_hamming_2nn(Dq, Dt, uv_q, uv_t, order, lo, hi, radius):  # pragma: no cover - compiled
    """For each query ``i``: the targets ``order[lo[i, c]:hi[i, c]]`` (c = 0, 1, 2: its 3 x 3 grid cells, in
    the numpy version's order) within ``radius`` px, their Hamming distances (descriptors as uint64 words)
    and the nearest / second nearest, each the first in that order among equals."""
    k = Dq.shape[0]
    r1, d1, d2, r2 = no_two_nearest(k)
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
                d = float(hamming_words(Dq, i, Dt, t))
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




def _epipolar_hamming_2nn(Dq, Dt, a, b, c, uv_t, order, lo, hi, tol):  # pragma: no cover - compiled
    """For each query ``i``: the targets ``t = order[j]``, ``j`` in ``lo[i]:hi[i]``, whose distance
    ``|a[i] u_t + b[i] v_t + c[i]|`` (``epipolar_pairs``' expression, evaluated in the same order) is at most
    ``tol``, their Hamming distances and the nearest / second nearest, each the first in that order among equals."""
    k = Dq.shape[0]
    r1, d1, d2, r2 = no_two_nearest(k)
    for i in range(k):
        for j in range(lo[i], hi[i]):
            t = order[j]
            if not np.abs(a[i] * uv_t[t, 0] + b[i] * uv_t[t, 1] + c[i]) <= tol:  # off the epipolar line
                continue
            d = float(hamming_words(Dq, i, Dt, t))
            if d < d1[i]:  # a new nearest: the old one becomes the second
                d2[i], r2[i] = d1[i], r1[i]
                d1[i], r1[i] = d, t
            elif d < d2[i]:
                d2[i], r2[i] = d, t
    return r1, d1, d2, r2


epipolar_hamming_2nn = kernel(_epipolar_hamming_2nn)
epipolar_hamming_2nn.__doc__ = """Two nearest right keypoints by Hamming distance near each left keypoint's epipolar line (compiled).

Parameters
----------
Dq : numpy.ndarray of uint64, shape (K, W)
    Left descriptors as 64-bit words.
Dt : numpy.ndarray of uint64, shape (N, W)
    Right descriptors as 64-bit words.
a, b, c : numpy.ndarray, shape (K,)
    Each left keypoint's epipolar line ``a u + b v + c = 0`` with ``a² + b² = 1``.
uv_t : numpy.ndarray, shape (N, 2)
    Right keypoint pixels.
order, lo, hi : numpy.ndarray of int
    Right keypoints sorted by row; left keypoint ``i``'s candidate rows are ``order[lo[i]:hi[i]]``.
tol : float
    Largest distance from the line [px].

Returns
-------
tuple
    ``r1, d1, d2, r2`` per left keypoint (``r1 = -1``: no candidate; ``r2 = -1``, ``d2 = inf``: one).
"""
