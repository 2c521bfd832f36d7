"""SURF's orientation and descriptor (Bay 2008 §4.1-4.2; 000 §3.3), vectorised over chunks of keypoints.

Part of :mod:`slamlab.features.surf` (which re-exports the public names; its docstring describes the steps).
"""

from __future__ import annotations

import numpy as np

from .._compiled import numba_enabled
from .._validate import check_int
from ._padded_ii import PaddedIntegralImage, by_chunks

__all__ = ["surf_describe", "surf_orientation"]


_ORI_I, _ORI_J = np.meshgrid(np.arange(-6, 7), np.arange(-6, 7), indexing="ij")
_ORI_MASK = _ORI_I**2 + _ORI_J**2 < 36
_ORI_I, _ORI_J = _ORI_I[_ORI_MASK], _ORI_J[_ORI_MASK]  # 109 samples
_ORI_G = np.exp(-(_ORI_I**2 + _ORI_J**2) / (2 * 2.5**2))


def _window_edges(window_rad, step_rad):
    """Indices into the per-keypoint cumulative sums of :func:`_orientation_chunk` for every window.

    Windows start at ``s_j = j·step`` (``j < nW``) and hold the angles in ``[s_j, s_j + w)`` and, for the
    wrap, those below ``s_j + w - 2π``. Every edge lies at ``(j + t)·step`` with ``t`` in ``{0, f1, f2}``,
    the fractional parts of ``w/step`` and ``(w - 2π)/step``; a sample of bin ``b = ⌊a/step⌋`` and
    fraction ``f`` has the fine index ``3b + [f >= t0] + [f >= t1]`` (``t0 <= t1`` the sorted ``f1, f2``),
    so the sum over ``a < (j + t)·step`` is the cumulative sum up to fine index ``3j + k(t)``.
    """
    nW = np.arange(0.0, 2 * np.pi, step_rad).size
    x1, x2 = window_rad / step_rad, (window_rad - 2 * np.pi) / step_rad
    J1, J2 = np.floor(x1), np.floor(x2)
    f1, f2 = x1 - J1, x2 - J2
    t = (min(f1, f2), max(f1, f2))
    j = np.arange(nW)

    def edge(jb, k):
        return np.clip(3 * jb + k, 0, 3 * nW).astype(np.intp)

    e0 = edge(j, 0)
    e1 = edge(j + int(J1), 1 if f1 == t[0] else 2)
    e2 = edge(j + int(J2), 1 if f2 == t[0] else 2)
    return nW, t, e0, e1, e2


def _orientation_chunk(P, uv, s, step_rad, edges, fast, compiled=False):
    """Orientations of the keypoints ``uv`` of rounded scale ``s``, see :func:`surf_orientation`."""
    nW, (t0, t1), e0, e1, e2 = edges
    k = uv.shape[0]
    r0, c0 = np.rint(uv[:, 1]).astype(np.int64)[:, None], np.rint(uv[:, 0]).astype(np.int64)[:, None]
    if fast and compiled:  # the same responses and weights, fused per sample (_surf_kernels; issue 45)
        from ._surf_kernels import haar_samples

        dx, dy = np.empty((k, _ORI_G.size)), np.empty((k, _ORI_G.size))
        haar_samples(P.flat, P.Wp, P.index(r0, c0) + P.index(_ORI_J * s, _ORI_I * s) - P.index(0, 0), 2 * s,
                     _ORI_G, dx, dy)
    else:
        if fast:
            dx, dy = P.haar(P.index(r0, c0) + P.index(_ORI_J * s, _ORI_I * s) - P.index(0, 0), 2 * s)
        else:
            dx, dy = P.haar_clipped(r0 + _ORI_J * s, c0 + _ORI_I * s, 2 * s)
        dx *= _ORI_G
        dy *= _ORI_G
    ang = np.arctan2(dy, dx)
    if compiled:  # the same bins, sums and choice, one pass per keypoint (_surf_kernels; issue 45)
        from ._surf_kernels import orientation_best

        best = np.empty((2, k))
        orientation_best(ang, dx, dy, float(step_rad), nW, float(t0), float(t1), e0, e1, e2, best)
        return np.arctan2(best[1], best[0]) % (2 * np.pi)
    np.add(ang, 2 * np.pi, out=ang, where=ang < 0)  # = ang % 2π for ang in [-π, π]
    u = np.divide(ang, step_rad, out=ang)
    bins = np.minimum(np.floor(u), nW - 1)
    u -= bins  # fraction within the bin
    fine = bins * 3
    fine += u >= t0
    fine += u >= t1
    idx = fine.astype(np.intp)
    idx += (3 * nW) * np.arange(k)[:, None]
    # window sums: cumulative sums of the samples over (keypoint, fine index), differences at the edges
    C = np.zeros((2, k, 3 * nW + 1))
    C[0, :, 1:] = np.bincount(idx.ravel(), dx.ravel(), minlength=3 * nW * k).reshape(k, -1)
    C[1, :, 1:] = np.bincount(idx.ravel(), dy.ravel(), minlength=3 * nW * k).reshape(k, -1)
    np.cumsum(C, axis=2, out=C)
    S = C[:, :, e1] - C[:, :, e0] + C[:, :, e2]  # (2, k, nW): Σdx, Σdy per window
    # the longest sum; among windows within 1e-12 of it (ties, e.g. windows that differ only by
    # zero responses of a flat patch) the first, whatever the rounding of the sums (ours)
    n2 = S[0] * S[0] + S[1] * S[1]
    best = np.argmax(n2 >= (1 - 1e-12) * n2.max(axis=1, keepdims=True), axis=1)
    kk = np.arange(k)
    return np.arctan2(S[1, kk, best], S[0, kk, best]) % (2 * np.pi)


def surf_orientation(II, uv, scale_px, *, window_rad: float = np.pi / 3, step_rad: float = 0.15,
                     chunk: int | None = None, workers: int = 1, _padded=None) -> np.ndarray:
    """Dominant orientation from Haar responses in a sliding 60° window (Bay 2008 §4.1).

    Returns angles in [0, 2π), image axes (u right, v down). The window sums are differences of
    cumulative sums over the samples binned by angle (speed, issue 17: no per-keypoint sort; same
    sets of samples per window as the sorted sweep). Windows whose sums are within 1e-12 of the
    longest count as tied and the first wins (ours: the choice does not depend on rounding).
    ``chunk`` keypoints at a time, split over ``workers`` threads (ours, speed; the result does not
    depend on either).

    Parameters
    ----------
    II : (H+1, W+1) float
        Integral image (:func:`integral_image`).
    uv : (K, 2) float
        Keypoint positions (u, v) in pixels.
    scale_px : (K,) float
        Keypoint scales σ in pixels (rounded to whole pixels for the samples).
    window_rad : float
        Width of the sliding angular window (Bay: π/3).
    step_rad : float
        Step of the window's start angle.
    chunk : int, optional
        Keypoints per vectorised chunk (default 128; 512 with the compiled kernels, whose calls cost more than
        their temporaries).
    workers : int
        Threads.
    _padded : PaddedIntegralImage, optional
        Private: a padded integral image already built by :func:`surf_detect`.

    Returns
    -------
    (K,) float
        Orientations in radians.
    """
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    s = np.maximum(np.rint(np.asarray(scale_px, dtype=np.float64)), 1).astype(np.int64)
    compiled = numba_enabled()
    chunk = check_int((512 if compiled else 128) if chunk is None else chunk, "chunk", minimum=1)
    workers = check_int(workers, "workers", minimum=1)
    P = PaddedIntegralImage(II) if _padded is None else _padded
    edges = _window_edges(float(window_rad), float(step_rad))
    fast = P.fits(uv, 7 * s + 1)  # samples at up to 5s, boxes of half-side 2s

    def one(idx, f, si):
        return _orientation_chunk(P, uv[idx], si, step_rad, edges, f, compiled)

    return by_chunks(one, fast, s, chunk, workers, np.zeros(uv.shape[0]))


_D_OFF = (np.arange(20) - 9.5)  # sample centres in units of σ along each axis
_D_X, _D_Y = np.meshgrid(_D_OFF, _D_OFF, indexing="xy")  # (20, 20): rows = y, cols = x
_D_X, _D_Y = _D_X.ravel(), _D_Y.ravel()
_D_G = np.exp(-(_D_X**2 + _D_Y**2) / (2 * 3.3**2))


def _subregion_sums(R):
    """Gaussian-weighted sums ``(..., 16)`` over the 4×4 sub-regions of 5×5 samples of ``R (..., 400)``.

    Row-major sub-regions (4·row + column). Sums of strided slices, not a product with a
    0/1 matrix: a product of this size can start OpenBLAS's threads, which cost ~10x on a
    busy 2-core machine (issue 17). ``R`` is overwritten.
    """
    R *= _D_G
    V = R.reshape(*R.shape[:-1], 20, 4, 5)  # sample row, sub-region column, column within it
    t = V[..., 0] + V[..., 1]
    for j in range(2, 5):
        t += V[..., j]
    T = t.reshape(*R.shape[:-1], 4, 5, 4)  # sub-region row, row within it, sub-region column
    S = T[..., 0, :] + T[..., 1, :]
    for j in range(2, 5):
        S += T[..., j, :]
    return S.reshape(*R.shape[:-1], 16)


def _describe_chunk(P, uv, sigma, s, th, extended, fast, compiled=False):
    """Descriptors of the keypoints ``uv`` of rounded scale ``s``, see :func:`surf_describe`."""
    k = uv.shape[0]
    cs, sn = np.cos(th)[:, None], np.sin(th)[:, None]
    if compiled and fast and not extended:  # the same numbers, fused per keypoint (_surf_kernels; issue 45)
        from ._surf_kernels import describe_sums

        desc = np.empty((k, 64))
        describe_sums(P.flat, P.Wp, int(P.index(0, 0)), uv, sigma, cs[:, 0], sn[:, 0], int(s), _D_OFF, _D_G, desc)
        norm = np.linalg.norm(desc, axis=1, keepdims=True)
        return desc / np.where(norm > 0, norm, 1.0)
    sg = sigma[:, None]
    # sample positions: the 20×20 grid rotated by θ (u right, v down), rounded to pixels;
    # x = (X·c - Y·s)·σ + u with the products taken on the 20 grid values (the same numbers)
    x = np.subtract((_D_OFF * cs)[:, None, :], (_D_OFF * sn)[:, :, None]).reshape(k, -1)
    x *= sg
    x += uv[:, 0:1]
    y = np.add((_D_OFF * sn)[:, None, :], (_D_OFF * cs)[:, :, None]).reshape(k, -1)
    y *= sg
    y += uv[:, 1:2]
    np.rint(x, out=x)
    np.rint(y, out=y)
    R = np.empty((4, k, _D_X.size))  # dx, dy, |rx|, |ry| per sample, summed per sub-region together
    dx, dy, t = R[0], R[1], R[2]
    if fast:
        y *= P.Wp
        y += x
        A = P.corners(y.astype(np.intp) + P.index(0, 0), s)
        # dx = right - left = (A22 - A00) + (A20 - A02) - 2(A21 - A01); dy likewise with A12, A10
        d1, d2 = A[2][2] - A[0][0], A[2][0] - A[0][2]
        np.add(d1, d2, out=dx)
        np.subtract(A[2][1], A[0][1], out=t)
        t += t
        dx -= t
        np.subtract(d1, d2, out=dy)
        np.subtract(A[1][2], A[1][0], out=t)
        t += t
        dy -= t
    else:
        dx[...], dy[...] = P.haar_clipped(y.astype(np.int64), x.astype(np.int64), s)
    # responses in the keypoint frame (the Gaussian weight is applied in _subregion_sums)
    rx, ry = R[2], R[3]
    np.multiply(dx, cs, out=rx)
    rx += sn * dy
    np.multiply(dy, cs, out=ry)
    ry -= sn * dx
    if not extended:
        # Σ(c·dx + s·dy)·g = c·Σdx·g + s·Σdy·g: the signed sums are rotated after summing
        np.abs(rx, out=rx)
        np.abs(ry, out=ry)
        S = _subregion_sums(R)
        feats = (cs * S[0] + sn * S[1], cs * S[1] - sn * S[0], S[2], S[3])
    else:
        neg_y, neg_x = ry < 0, rx < 0
        arx, ary = np.abs(rx), np.abs(ry)
        feats = _subregion_sums(np.stack([np.where(neg_y, rx, 0), np.where(neg_y, arx, 0),
                                          np.where(neg_y, 0, rx), np.where(neg_y, 0, arx),
                                          np.where(neg_x, ry, 0), np.where(neg_x, ary, 0),
                                          np.where(neg_x, 0, ry), np.where(neg_x, 0, ary)]))
    desc = np.stack(feats, axis=-1).reshape(k, -1)  # (k, 16, nf): per sub-region
    norm = np.linalg.norm(desc, axis=1, keepdims=True)
    return desc / np.where(norm > 0, norm, 1.0)


def surf_describe(II, uv, scale_px, orientation_rad, *, extended: bool = False, chunk: int | None = None,
                  workers: int = 1, _padded=None):
    """64-d (or extended 128-d) SURF descriptors, unit length (Bay 2008 §4.2).

    Returns float32 ``(K, 64)`` or ``(K, 128)``. The Gaussian-weighted sums over the 16
    sub-regions are taken for all features of a chunk together (:func:`_subregion_sums`); the
    signed sums of the rotated responses are the rotated sums (Σ(c·dx + s·dy)·g = c·Σdx·g +
    s·Σdy·g), so only the absolute values need the rotated responses per sample (speed, issue 17;
    same values to rounding). ``chunk`` keypoints at a time, split over ``workers`` threads (the
    result does not depend on either).

    Parameters
    ----------
    II : (H+1, W+1) float
        Integral image (:func:`integral_image`).
    uv : (K, 2) float
        Keypoint positions (u, v) in pixels.
    scale_px : (K,) float
        Keypoint scales σ in pixels.
    orientation_rad : (K,) float
        Keypoint orientations (0 for U-SURF).
    extended : bool
        128-d descriptor (sums split by the sign of the other response).
    chunk : int, optional
        Keypoints per vectorised chunk (default 32; 512 with the compiled kernels, whose calls cost more than
        their temporaries).
    workers : int
        Threads.
    _padded : PaddedIntegralImage, optional
        Private: a padded integral image already built by :func:`surf_detect`.

    Returns
    -------
    (K, 64) or (K, 128) float32
        Unit-length descriptors.
    """
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    sigma = np.asarray(scale_px, dtype=np.float64)
    s_int = np.maximum(np.rint(sigma), 1).astype(np.int64)
    th = np.asarray(orientation_rad, dtype=np.float64)
    K = uv.shape[0]
    dim = 128 if extended else 64
    out = np.zeros((K, dim), dtype=np.float32)
    compiled = numba_enabled()
    chunk = check_int((512 if compiled else 32) if chunk is None else chunk, "chunk", minimum=1)
    workers = check_int(workers, "workers", minimum=1)
    P = PaddedIntegralImage(II) if _padded is None else _padded
    fast = P.fits(uv, np.ceil(13.44 * sigma) + s_int + 1)  # samples within 9.5·√2·σ, boxes of half-side s

    def one(idx, f, si):
        return _describe_chunk(P, uv[idx], sigma[idx], si, th[idx], extended, f, compiled)

    return by_chunks(one, fast, s_int, chunk, workers, out)
