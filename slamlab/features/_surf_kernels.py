"""Compiled kernels of SURF (our addition, speed; issue 45): the same arithmetic as the numpy code, fused.

Each kernel reproduces, operation for operation and in the same order, a part of the numpy implementation
(the teaching version) in :mod:`slamlab.features.surf_response` and :mod:`slamlab.features.surf_descriptor`,
so the results are equal bit for bit (``tests/features/test_surf_kernels.py`` compares them with the numpy
path under ``SLAMLAB_NO_NUMBA=1``, the response maps also with
:func:`~slamlab.features.surf_response.hessian_response` on strided views). The gain is memory traffic: the
numpy code makes a pass over a whole array for every operation, a kernel keeps one sample's numbers in
registers. Transcendental
functions (``arctan2``, ``cos``, ``sin``) stay in numpy: its SIMD versions need not round as a compiled
``libm`` call does. The kernels are compiled lazily by :func:`slamlab._compiled.kernel` (no numba at import).
"""

from __future__ import annotations

import numpy as np

from .._compiled import kernel

__all__ = ["describe_sums", "haar_samples", "hessian_det", "integral_body", "interior_maxima", "orientation_best"]


@kernel
def hessian_det(flat, Wp, base, step, nr, nc, L, out):
    """The determinant of ``surf_response.hessian_response`` (side ``L``, grid ``step``) into ``out``.

    Parameters
    ----------
    flat : (n,) float64
        The edge-padded integral image, flat (row length ``Wp``).
    Wp : int
        Row length of the padded image.
    base : int
        Flat index of pixel ``(0, 0)`` of the integral image.
    step : int
        Grid step.
    nr, nc : int
        Grid rows and columns.
    L : int
        Filter side.
    out : (nr, nc) float64
        The determinant.

    Returns
    -------
    None
    """
    lo = L // 3
    b = (L - 1) // 2
    h = lo // 2
    inv = 1.0 / (L * L)
    # the rows and columns of the eight boxes (r0, r1, c0, c1) of hessian_response, in its order
    xr0, xr1 = (-lo + 1) * Wp, lo * Wp  # Dxx: the whole box, then the middle lobe
    xc0, xc1, mc0, mc1 = -b, b + 1, -h, -h + lo
    yr0, yr1, mr0, mr1 = -b * Wp, (b + 1) * Wp, -h * Wp, (-h + lo) * Wp  # Dyy: the whole box, the middle lobe
    yc0, yc1 = -lo + 1, lo
    ua, ub, va, vb = -lo * Wp, 0, Wp, (lo + 1) * Wp  # Dxy: rows above / below, columns left / right
    la, lb, ra, rb = -lo, 0, 1, lo + 1
    for i in range(nr):
        for j in range(nc):
            p = base + i * step * Wp + j * step
            v0 = ((flat[p + xr1 + xc1] - flat[p + xr0 + xc1]) - flat[p + xr1 + xc0]) + flat[p + xr0 + xc0]
            v1 = ((flat[p + xr1 + mc1] - flat[p + xr0 + mc1]) - flat[p + xr1 + mc0]) + flat[p + xr0 + mc0]
            v2 = ((flat[p + yr1 + yc1] - flat[p + yr0 + yc1]) - flat[p + yr1 + yc0]) + flat[p + yr0 + yc0]
            v3 = ((flat[p + mr1 + yc1] - flat[p + mr0 + yc1]) - flat[p + mr1 + yc0]) + flat[p + mr0 + yc0]
            v4 = ((flat[p + ub + rb] - flat[p + ua + rb]) - flat[p + ub + ra]) + flat[p + ua + ra]
            v5 = ((flat[p + vb + lb] - flat[p + va + lb]) - flat[p + vb + la]) + flat[p + va + la]
            v6 = ((flat[p + ub + lb] - flat[p + ua + lb]) - flat[p + ub + la]) + flat[p + ua + la]
            v7 = ((flat[p + vb + rb] - flat[p + va + rb]) - flat[p + vb + ra]) + flat[p + va + ra]
            Dxx = (v0 - 3.0 * v1) * inv
            Dyy = (v2 - 3.0 * v3) * inv
            Dxy = (((v4 + v5) - v6) - v7) * inv
            out[i, j] = Dxx * Dyy - 0.81 * Dxy * Dxy


@kernel
def haar_samples(flat, Wp, idx, half, weight, dx, dy):
    """Weighted Haar responses at flat indices ``idx (k, n)`` (``PaddedIntegralImage.haar``, then ``*= weight``).

    Parameters
    ----------
    flat : (m,) float64
        The edge-padded integral image, flat.
    Wp : int
        Its row length.
    idx : (k, n) int64
        Flat indices of the sample centres.
    half : int
        Half the wavelet side.
    weight : (n,) float64
        Weight of each sample.
    dx, dy : (k, n) float64
        The responses (output).

    Returns
    -------
    None
    """
    k, n = idx.shape
    for a in range(k):
        for s in range(n):
            t = idx[a, s] - half * (Wp + 1)  # the top-left corner
            A00, A01, A02 = flat[t], flat[t + half], flat[t + 2 * half]
            A10, A12 = flat[t + half * Wp], flat[t + half * Wp + 2 * half]
            A20, A21, A22 = flat[t + 2 * half * Wp], flat[t + 2 * half * Wp + half], flat[t + 2 * half * Wp + 2 * half]
            right = ((A22 - A02) - A21) + A01
            left = ((A21 - A01) - A20) + A00
            lower = ((A22 - A12) - A20) + A10
            upper = ((A12 - A02) - A10) + A00
            dx[a, s] = (right - left) * weight[s]
            dy[a, s] = (lower - upper) * weight[s]


@kernel
def describe_sums(flat, Wp, base, uv, sigma, cs, sn, half, D_off, G, desc):
    """The 64-d descriptors before normalisation (the fast path of ``surf_descriptor._describe_chunk``).

    Parameters
    ----------
    flat : (m,) float64
        The edge-padded integral image, flat.
    Wp : int
        Its row length.
    base : int
        Flat index of pixel ``(0, 0)``.
    uv : (k, 2) float64
        Keypoints.
    sigma, cs, sn : (k,) float64
        Their scales and the cosine and sine of their orientations.
    half : int
        Half the Haar side (the rounded scale).
    D_off : (20,) float64
        Sample offsets in units of σ.
    G : (400,) float64
        Gaussian weight of each sample (row-major 20×20).
    desc : (k, 64) float64
        Per sub-region ``(Σdx', Σdy', Σ|dx'|, Σ|dy'|)`` in the keypoint frame (output).

    Returns
    -------
    None
    """
    k = uv.shape[0]
    R = np.empty((4, 20, 20))
    t = np.empty((4, 20, 4))
    S = np.empty(4)
    # unsigned offsets: numba wraps negative signed indices around (a test and a branch per load); the corners
    # of every sample lie inside the padded image (the caller's ``fits``), so the indices are never negative
    h1, h2, hw, hw2 = np.uint64(half), np.uint64(2 * half), np.uint64(half * Wp), np.uint64(2 * half * Wp)
    for a in range(k):
        c, s, sg, u, v = cs[a], sn[a], sigma[a], uv[a, 0], uv[a, 1]
        for iy in range(20):
            for ix in range(20):
                x = np.rint(((D_off[ix] * c) - (D_off[iy] * s)) * sg + u)
                y = np.rint(((D_off[ix] * s) + (D_off[iy] * c)) * sg + v)
                q = np.uint64(np.intp(y * Wp + x) + base - half * (Wp + 1))  # the top-left corner
                A00, A01, A02 = flat[q], flat[q + h1], flat[q + h2]
                A10, A12 = flat[q + hw], flat[q + hw + h2]
                A20, A21, A22 = flat[q + hw2], flat[q + hw2 + h1], flat[q + hw2 + h2]
                d1, d2 = A22 - A00, A20 - A02
                t1 = A21 - A01
                dx = (d1 + d2) - (t1 + t1)
                t2 = A12 - A10
                dy = (d1 - d2) - (t2 + t2)
                rx = dx * c + s * dy
                ry = dy * c - s * dx
                g = G[iy * 20 + ix]
                R[0, iy, ix] = dx * g
                R[1, iy, ix] = dy * g
                R[2, iy, ix] = abs(rx) * g
                R[3, iy, ix] = abs(ry) * g
        for f in range(4):  # sums over the 5 columns of each sub-region, then over its 5 rows
            for iy in range(20):
                for qc in range(4):
                    m = 5 * qc
                    t[f, iy, qc] = ((((R[f, iy, m] + R[f, iy, m + 1]) + R[f, iy, m + 2]) + R[f, iy, m + 3])
                                    + R[f, iy, m + 4])
        for p in range(4):
            for qc in range(4):
                r = 5 * p
                for f in range(4):
                    S[f] = (((t[f, r, qc] + t[f, r + 1, qc]) + t[f, r + 2, qc]) + t[f, r + 3, qc]) + t[f, r + 4, qc]
                S0, S1, S2, S3 = S[0], S[1], S[2], S[3]
                o = 4 * (4 * p + qc)
                desc[a, o] = c * S0 + s * S1
                desc[a, o + 1] = c * S1 - s * S0
                desc[a, o + 2] = S2
                desc[a, o + 3] = S3


@kernel
def orientation_best(ang, dx, dy, step_rad, nW, t0, t1, e0, e1, e2, best):
    """The longest window sum of ``surf_descriptor._orientation_chunk``, from the samples' angles (one pass each).

    Bins the angles as the numpy code does (fine index ``3·bin + [f >= t0] + [f >= t1]``), sums the
    responses per fine bin in sample order (as ``np.bincount``), takes the cumulative sums and the window
    sums ``C[e1] - C[e0] + C[e2]``, and keeps the first window within 1e-12 of the longest.

    Parameters
    ----------
    ang : (k, n) float64
        ``arctan2(dy, dx)`` of the samples, in [-π, π].
    dx, dy : (k, n) float64
        The weighted responses.
    step_rad : float
        Step of the window's start angle.
    nW : int
        Number of windows.
    t0, t1 : float
        Fractions of a bin at which the fine index steps (sorted).
    e0, e1, e2 : (nW,) int64
        The window edges into the cumulative sums (``_window_edges``).
    best : (2, k) float64
        ``Σdx`` and ``Σdy`` of the chosen window per keypoint (output; rows contiguous, as numpy's arctan2
        of the numpy code reads them).

    Returns
    -------
    None
    """
    k, n = ang.shape
    m = 3 * nW + 1
    C = np.empty((2, m))
    n2 = np.empty(nW)
    Sx = np.empty(nW)
    Sy = np.empty(nW)
    for a in range(k):
        C[:, :] = 0.0
        for s in range(n):
            u = ang[a, s]
            if u < 0:
                u = u + 2 * np.pi
            u = u / step_rad
            b = min(np.floor(u), nW - 1)
            u = u - b
            f = int(b) * 3 + (1 if u >= t0 else 0) + (1 if u >= t1 else 0)
            C[0, f + 1] += dx[a, s]
            C[1, f + 1] += dy[a, s]
        for j in range(1, m):
            C[0, j] = C[0, j - 1] + C[0, j]
            C[1, j] = C[1, j - 1] + C[1, j]
        top = -np.inf
        for w in range(nW):
            Sx[w] = (C[0, e1[w]] - C[0, e0[w]]) + C[0, e2[w]]
            Sy[w] = (C[1, e1[w]] - C[1, e0[w]]) + C[1, e2[w]]
            n2[w] = Sx[w] * Sx[w] + Sy[w] * Sy[w]
            top = max(top, n2[w])
        thr = (1 - 1e-12) * top
        w = 0
        while w < nW - 1 and not n2[w] >= thr:
            w += 1
        best[0, a] = Sx[w]
        best[1, a] = Sy[w]


@kernel
def interior_maxima(D, threshold, out):
    """Flat indices of the points of ``surf_response._interior_maxima`` (the same set, the same order).

    A point of the interior of the (interval, row, column) stack is kept when it is above ``threshold`` and
    at least each of its 26 neighbours (a conjunction of comparisons: the order of the tests does not change
    the set); points in row-major order, as ``np.nonzero`` gives them.

    Parameters
    ----------
    D : (nI, nr, nc) float64
        The response stack of one octave.
    threshold : float
        Minimum response.
    out : (nI·nr·nc,) int64
        The flat indices ``(i·nr + r)·nc + c`` of the maxima (output; the first ``n`` entries).

    Returns
    -------
    n : int
        Number of maxima.
    """
    nI, nr, nc = D.shape
    n = 0
    for i in range(1, nI - 1):
        for r in range(1, nr - 1):
            for c in range(1, nc - 1):
                v = D[i, r, c]
                if not (threshold < v and v >= D[i, r, c - 1] and v >= D[i, r, c + 1]):
                    continue
                keep = True
                for di in range(-1, 2):
                    for dr in range(-1, 2):
                        for dc in range(-1, 2):
                            if not v >= D[i + di, r + dr, c + dc]:
                                keep = False
                if keep:
                    out[n] = (i * nr + r) * nc + c
                    n += 1
    return n


@kernel
def integral_body(image, body):
    """``body = cumsum(cumsum(image, axis=0), axis=1)`` (float64), row by row (``PaddedIntegralImage``).

    The column sums are carried from row to row (``colsum[c] += image[r, c]``, from ``image[0, c]``: numpy's
    first cumulative sum), each row's running sum over them is numpy's second: the same additions in the same
    order, so the same values, in one pass over contiguous rows instead of numpy's column-wise pass.

    Parameters
    ----------
    image : (H, W) float64
        Grey image.
    body : (H, W) float64
        ``II[1:, 1:]`` of the padded integral image (output).

    Returns
    -------
    None
    """
    H, W = image.shape
    colsum = image[0].copy()
    for r in range(H):
        if r > 0:
            for c in range(W):
                colsum[c] = colsum[c] + image[r, c]
        acc = colsum[0]
        body[r, 0] = acc
        for c in range(1, W):
            acc = acc + colsum[c]
            body[r, c] = acc
