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


def _local_maxima(Ht, H_min):
    """Cells with at least ``H_min`` votes and no fewer than their 8 neighbours (``_peak_groups`` step 1, compiled).

    As the numpy path: rho is clipped at the axis ends (edge cells compare with themselves), θ wraps to
    ``(-rho, θ ± π)``. ``Ht`` is scanned in its memory order (θ-major); a counting sort by rho row then
    gives the numpy path's candidate order, (rho, θ) row-major.

    Parameters
    ----------
    Ht : numpy.ndarray, shape (n_theta, n_rho)
        Votes, θ-major (``acc.H.T``).
    H_min : int
        Smallest vote count.

    Returns
    -------
    numpy.ndarray of int64
        Flat indices ``i·n_theta + k`` of the local maxima, ascending.
    """
    n_theta, n_rho = Ht.shape
    found = np.empty(n_theta * n_rho, dtype=np.int64)  # θ-major flat indices k·n_rho + i
    per_row = np.zeros(n_rho + 1, dtype=np.int64)
    m = 0
    for k in range(n_theta):
        for i in range(n_rho):
            value = Ht[k, i]
            if value < H_min:
                continue
            is_max = True
            for dk in (-1, 0, 1):
                for di in (-1, 0, 1):
                    ii = min(max(i + di, 0), n_rho - 1)
                    kk = k + dk
                    if kk < 0 or kk >= n_theta:  # across the θ wrap: rho flips
                        ii, kk = n_rho - 1 - ii, kk % n_theta
                    is_max = is_max and value >= Ht[kk, ii]
            if is_max:
                found[m] = k * n_rho + i
                per_row[i + 1] += 1
                m += 1
    start = np.cumsum(per_row)  # counting sort by rho row; within a row θ stays ascending
    flat = np.empty(m, dtype=np.int64)
    for j in range(m):
        k, i = found[j] // n_rho, found[j] % n_rho
        flat[start[i]] = i * n_theta + k
        start[i] += 1
    return flat


def _group_peaks(i, k, value, n_rho, n_theta):
    """Flat tops: groups of adjacent candidates and their centres (``_peak_groups`` step 2, compiled).

    As the numpy path: candidates adjacent in (rho, θ), or across the θ wrap where ``(rho, -90°)``
    continues as ``(-rho, 90°)``, form one group; a group's centre is the mean of its cells, the cells
    of a group that spans the wrap moved to the side of θ = -90°.

    Parameters
    ----------
    i, k : numpy.ndarray of int64, shape (M,)
        Rows and columns of the candidates, in (rho, θ) row-major order.
    value : numpy.ndarray of int64, shape (M,)
        Their votes.
    n_rho, n_theta : int
        Accumulator shape.

    Returns
    -------
    sum_i, sum_k : numpy.ndarray of float, shape (G,)
        Sums of the (moved) row and column indices of each group's cells, added in cell order.
    count, votes, first : numpy.ndarray of int64, shape (G,)
        Cells, votes and smallest flat index ``i·n_theta + k`` of each group; groups in the order of
        their first cell.
    """
    m_c = i.size
    parent = np.arange(m_c)  # union-find; a root is its group's first cell
    for a in range(m_c):
        for b in range(a + 1, m_c):
            near = abs(i[a] - i[b]) <= 1 and abs(k[a] - k[b]) <= 1
            near = near or (k[a] == 0 and k[b] == n_theta - 1 and abs(i[a] - (n_rho - 1 - i[b])) <= 1)
            near = near or (k[b] == 0 and k[a] == n_theta - 1 and abs(i[b] - (n_rho - 1 - i[a])) <= 1)
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
    count = np.zeros(n_groups, dtype=np.int64)
    votes = np.zeros(n_groups, dtype=np.int64)
    first = np.full(n_groups, n_theta * n_rho, dtype=np.int64)
    at_start = np.zeros(n_groups, dtype=np.bool_)
    at_end = np.zeros(n_groups, dtype=np.bool_)
    for a in range(m_c):
        g = label[a]
        count[g] += 1
        votes[g] = value[a]
        first[g] = min(first[g], i[a] * n_theta + k[a])
        at_start[g] |= k[a] == 0
        at_end[g] |= k[a] == n_theta - 1
    sum_i = np.zeros(n_groups)
    sum_k = np.zeros(n_groups)
    for a in range(m_c):
        g = label[a]
        if at_start[g] and at_end[g] and k[a] >= n_theta / 2:  # across the wrap: to the -90° side
            sum_i[g] += float(n_rho - 1 - i[a])
            sum_k[g] += float(k[a] - n_theta)
        else:
            sum_i[g] += float(i[a])
            sum_k[g] += float(k[a])
    return sum_i, sum_k, count, votes, first


def peak_groups(H, H_min, max_candidates):
    """``lines._peak_groups`` with its two loops compiled: the same centres, votes and first cells.

    Parameters
    ----------
    H : numpy.ndarray of intp, shape (n_rho, n_theta)
        Votes.
    H_min : int
        Smallest vote count.
    max_candidates : int
        Cap on the candidates grouped (``lines._MAX_CANDIDATES``).

    Returns
    -------
    centre : numpy.ndarray, shape (G, 2)
        Mean (rho index, θ index) of each group of adjacent local maxima.
    votes, first : numpy.ndarray of int64, shape (G,)
        Its votes and smallest flat index ``i·n_theta + k``.
    """
    n_rho, n_theta = H.shape
    flat = local_maxima(H.T, H_min)
    i, k = flat // n_theta, flat % n_theta
    value = H[i, k]
    if i.size > max_candidates:  # the most votes, ties by position (as lines._peak_groups)
        top = np.sort(np.argsort(-value, kind="stable")[:max_candidates])
        i, k, value = i[top], k[top], value[top]
    sum_i, sum_k, count, votes, first = group_peaks(i, k, value, n_rho, n_theta)
    return np.column_stack([sum_i / count, sum_k / count]), votes, first


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
local_maxima = kernel(_local_maxima)
group_peaks = kernel(_group_peaks)
greedy_keep = kernel(_greedy_keep)
