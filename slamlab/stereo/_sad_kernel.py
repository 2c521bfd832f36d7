"""Compiled patch costs of the sub-pixel disparity refinement (speed, issue 25).

The teaching version is numpy (``_subpixel_disparity`` in :mod:`slamlab.stereo.local_stages`): for every
match it cuts the mean-free left patch and, at each of the ``2 s + 1`` column offsets, the mean-free right
patch, and sums the absolute differences. The kernel computes the same float32 numbers bit for bit
(tested against the numpy version): each patch mean is numpy's (the exact integer sum, divided in
float64, rounded to float32), and each sum of absolute differences adds the ``P²`` terms in numpy's
order for a contiguous float32 reduction of at most 128 terms (eight running sums over the terms
in steps of eight, combined pairwise, then the remaining terms one by one; ``P ≤ 11``). Larger patches
take the numpy version.
"""

from __future__ import annotations

import numpy as np

from .._compiled import kernel

__all__ = ["MAX_SAD_TERMS", "sad_costs"]

#: largest patch (terms of one sum) whose summation order the kernel reproduces
MAX_SAD_TERMS = 128


def _sad_costs(IL, IR, r, c, cr, h, s):  # pragma: no cover - compiled
    """Cost ``[m, k]``: sum of |mean-free left patch - mean-free right patch| for match ``m``, left patch centred
    at ``(c[m], r[m])``, right patch centred at ``(cr[m] - s + k, r[m])``; patches ``(2h + 1)²``, float32."""
    n = r.size
    P = 2 * h + 1
    NP = P * P
    Q = P + 2 * s  # columns of the right strip
    cost = np.empty((n, 2 * s + 1), np.float32)
    lp = np.empty(NP, np.float32)
    strip = np.empty((P, Q), np.float32)
    colsum = np.empty(Q, np.int64)
    v = np.empty(NP, np.float32)
    for m in range(n):
        r0, c0, q0 = r[m] - h, c[m] - h, cr[m] - h - s
        # the left patch, mean-free (numpy's mean of uint8 values as float32: exact sum / NP in float64)
        tot = 0
        for y in range(P):
            for x in range(P):
                tot += np.int64(IL[r0 + y, c0 + x])
        mean = np.float32(tot / float(NP))
        for y in range(P):
            for x in range(P):
                lp[y * P + x] = np.float32(IL[r0 + y, c0 + x]) - mean
        # the right strip and its column sums (each offset's patch sum from P of them)
        for x in range(Q):
            colsum[x] = 0
        for y in range(P):
            for x in range(Q):
                px = IR[r0 + y, q0 + x]
                strip[y, x] = np.float32(px)
                colsum[x] += np.int64(px)
        for k in range(2 * s + 1):
            tot = 0
            for x in range(P):
                tot += colsum[k + x]
            mean = np.float32(tot / float(NP))
            for y in range(P):
                for x in range(P):
                    v[y * P + x] = np.abs(lp[y * P + x] - (strip[y, k + x] - mean))
            # numpy's float32 sum of NP <= 128 contiguous terms
            if NP < 8:
                acc = np.float32(0.0)
                for i in range(NP):
                    acc += v[i]
            else:
                a0, a1, a2, a3, a4, a5, a6, a7 = v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]
                i = 8
                while i < NP - NP % 8:
                    a0 += v[i]
                    a1 += v[i + 1]
                    a2 += v[i + 2]
                    a3 += v[i + 3]
                    a4 += v[i + 4]
                    a5 += v[i + 5]
                    a6 += v[i + 6]
                    a7 += v[i + 7]
                    i += 8
                acc = ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7))
                while i < NP:
                    acc += v[i]
                    i += 1
            cost[m, k] = acc
    return cost


sad_costs = kernel(_sad_costs)
sad_costs.__doc__ = """Sums of absolute differences of mean-free patches along the row, per match and column offset (compiled).

Parameters
----------
IL, IR : numpy.ndarray of uint8, shape (H, W)
    The rectified grey pair.
r, c, cr : numpy.ndarray of int, shape (M,)
    Each match's row, left column and right column (patches and strips inside the images).
h : int
    Patch half-size [px]; ``(2h + 1)² <= MAX_SAD_TERMS``.
s : int
    Search half-width [px].

Returns
-------
numpy.ndarray of float32, shape (M, 2s + 1)
    The numpy version's costs, bit for bit.
"""
