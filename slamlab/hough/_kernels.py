"""Compiled kernels of the Hough chapter (our addition, speed; issue 25).

Each kernel reproduces one numpy function of :mod:`slamlab.hough.transform` / :mod:`slamlab.hough.lines`
(the teaching versions) with the same arithmetic, so the results are equal bit for bit; the tests in
``tests/hough/test_kernels.py`` check it. This module imports numba and is imported only when
:func:`slamlab._compiled.numba_enabled` is true, so ``import slamlab`` stays light.
"""

from __future__ import annotations

import math

import numpy as np
from numba.core import types
from numba.extending import intrinsic

from .._compiled import kernel


@intrinsic
def _fma(typingctx, a, b, c):
    """``a·b + c`` rounded once (LLVM's ``llvm.fma.f64``), as OpenBLAS's dgemm kernels compute it.

    Parameters
    ----------
    typingctx : numba typing context
        Supplied by numba.
    a, b, c : float64
        Operands.

    Returns
    -------
    signature, codegen
        numba's intrinsic pair (the call returns a float64).
    """
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


def _vote_polar(x, y, w, rows, n_rho):
    """Votes of 004 eq. (7) per θ row: ``counts[k, bin] += 1`` (the loop of ``_hough_polar``, compiled).

    The bin of point i at θ_k is ``int(w[k]·(x_i, y_i, 1))``, with the dot product evaluated as the numpy
    path's ``np.matmul`` does (OpenBLAS: ``fma(sin θ, y, cos θ·x) + offset``), then truncated; ``w[k, 2]``
    holds the numpy path's offset ``n_half + 0.5 + n_rho·(k mod rows)`` (its θ row within a block of
    ``rows``), which is taken off again after the truncation. Same float, same bin.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (N,)
        Points in units of Δrho.
    w : numpy.ndarray, shape (n_theta, 3)
        ``cos θ_k``, ``sin θ_k`` and the offset, as built by ``_hough_polar``.
    rows : int
        θ rows per block of the numpy path.
    n_rho : int
        rho bins.

    Returns
    -------
    numpy.ndarray of intp, shape (n_theta, n_rho)
        Votes, θ-major.
    """
    n_theta = w.shape[0]
    counts = np.zeros((n_theta, n_rho), dtype=np.intp)
    for k in range(n_theta):
        c, s, offset = w[k, 0], w[k, 1], w[k, 2]
        shift = n_rho * (k % rows)
        row = counts[k]
        for i in range(x.shape[0]):
            b = int(_fma(s, y[i], c * x[i]) + offset) - shift  # rho_i(θ_k)/Δrho + n_half, rounded
            if 0 <= b < n_rho:  # always (|rho| <= r_max); a guard, as numba does not check bounds
                row[b] += 1
    return counts


def _peak_groups(Ht, H_min, max_candidates):
    """Local maxima ≥ ``H_min`` and their flat tops (steps 1 of ``_find_peaks``, compiled; 004 §Hough SLAM).

    Same rules as the numpy path: a candidate is ≥ its 8 neighbours (rho clipped at the axis ends, θ
    wrapping to ``(-rho, θ ± π)``); at most ``max_candidates`` (the most votes, ties by position); adjacent
    candidates (also across the θ wrap) form one group, whose centre is the mean of its cells, the cells
    of a group across the wrap moved to one side.

    Parameters
    ----------
    Ht : numpy.ndarray, shape (n_theta, n_rho)
        Votes, θ-major (``acc.H.T``).
    H_min : int
        Smallest vote count.
    max_candidates : int
        Cap on the candidates grouped.

    Returns
    -------
    sum_i, sum_k : numpy.ndarray of float, shape (G,)
        Sums of the (moved) row and column indices of each group's cells, in cell order.
    count, votes, first : numpy.ndarray of int64, shape (G,)
        Cells, votes and smallest flat index ``i·n_theta + k`` of each group; groups in the order of
        their first cell.
    """
    n_theta, n_rho = Ht.shape
    # 1. candidates: cells >= H_min that are >= their 8 neighbours
    flat = np.empty(0, dtype=np.int64)
    found = []
    for k in range(n_theta):
        for i in range(n_rho):
            value = Ht[k, i]
            if value < H_min:
                continue
            is_max = True
            for dk in (-1, 0, 1):
                for di in (-1, 0, 1):
                    if di == 0 and dk == 0:
                        continue
                    ii = min(max(i + di, 0), n_rho - 1)
                    kk = k + dk
                    if kk < 0 or kk >= n_theta:  # across the θ wrap: rho flips
                        ii, kk = n_rho - 1 - ii, kk % n_theta
                    if value < Ht[kk, ii]:
                        is_max = False
            if is_max:
                found.append(i * n_theta + k)
    flat = np.sort(np.array(found, dtype=np.int64)) if found else flat
    i_c, k_c = flat // n_theta, flat % n_theta
    value = np.empty(flat.size, dtype=np.int64)
    for m in range(flat.size):
        value[m] = Ht[k_c[m], i_c[m]]
    if flat.size > max_candidates:  # the most votes, ties by position (a stable sort)
        top = np.sort(np.argsort(-value, kind="mergesort")[:max_candidates])
        i_c, k_c, value = i_c[top], k_c[top], value[top]
    # 2. groups of adjacent candidates (union-find; labels = smallest member)
    m_c = i_c.size
    parent = np.arange(m_c)
    for a in range(m_c):
        for b in range(a + 1, m_c):
            near = abs(i_c[a] - i_c[b]) <= 1 and abs(k_c[a] - k_c[b]) <= 1
            near = near or (k_c[a] == 0 and k_c[b] == n_theta - 1 and abs(i_c[a] - (n_rho - 1 - i_c[b])) <= 1)
            near = near or (k_c[b] == 0 and k_c[a] == n_theta - 1 and abs(i_c[b] - (n_rho - 1 - i_c[a])) <= 1)
            if near:
                ra, rb = a, b
                while parent[ra] != ra:
                    ra = parent[ra]
                while parent[rb] != rb:
                    rb = parent[rb]
                parent[max(ra, rb)] = min(ra, rb)
    label = np.empty(m_c, dtype=np.int64)
    n_groups = 0
    for a in range(m_c):
        root = a
        while parent[root] != root:
            root = parent[root]
        if root == a:
            label[a] = n_groups
            n_groups += 1
        else:
            label[a] = label[root]
    # 3. per group: cells, votes, first cell, and the index sums (cells across the wrap moved to one side)
    count = np.zeros(n_groups, dtype=np.int64)
    votes = np.zeros(n_groups, dtype=np.int64)
    first = np.full(n_groups, n_theta * n_rho, dtype=np.int64)
    at_start = np.zeros(n_groups, dtype=np.bool_)
    at_end = np.zeros(n_groups, dtype=np.bool_)
    for a in range(m_c):
        g = label[a]
        count[g] += 1
        votes[g] = value[a]
        first[g] = min(first[g], i_c[a] * n_theta + k_c[a])
        at_start[g] |= k_c[a] == 0
        at_end[g] |= k_c[a] == n_theta - 1
    sum_i = np.zeros(n_groups)
    sum_k = np.zeros(n_groups)
    for a in range(m_c):
        g = label[a]
        if at_start[g] and at_end[g] and k_c[a] >= n_theta / 2:
            sum_i[g] += float(n_rho - 1 - i_c[a])
            sum_k[g] += float(k_c[a] - n_theta)
        else:
            sum_i[g] += float(i_c[a])
            sum_k[g] += float(k_c[a])
    return sum_i, sum_k, count, votes, first


def _greedy_keep(rho, theta, s_rho, s_theta):
    """Indices kept going down the sorted lines, dropping those close to a kept one (``_greedy_keep``, compiled).

    Closeness as ``line_difference`` computes it: line j is taken in the representation nearest in θ to
    line m (``k = round((θ_j - θ_m)/π)``), then ``|Δrho| <= s_rho + 1e-9`` and ``|Δθ| <= s_theta + 1e-9``.

    Parameters
    ----------
    rho, theta : numpy.ndarray, shape (L,)
        Lines, strongest first.
    s_rho, s_theta : float
        Suppression windows.

    Returns
    -------
    numpy.ndarray of intp
        Indices of the lines kept, ascending.
    """
    n = rho.size
    keep = np.ones(n, dtype=np.bool_)
    for m in range(n):
        if not keep[m]:
            continue
        for j in range(m + 1, n):
            k = np.rint((theta[j] - theta[m]) / math.pi)
            rho_j = rho[j] if k % 2 == 0 else -rho[j]
            d_theta = theta[m] - (theta[j] - k * math.pi)
            if abs(rho[m] - rho_j) <= s_rho + 1e-9 and abs(d_theta) <= s_theta + 1e-9:
                keep[j] = False
    return np.flatnonzero(keep)


vote_polar = kernel(_vote_polar)
peak_groups = kernel(_peak_groups)
greedy_keep = kernel(_greedy_keep)
