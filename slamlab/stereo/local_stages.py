"""Stereo SLAM stages 1-2: stereo matching by the ratio rule and the epipolar check, sub-pixel disparities, and the
local landmark cloud (000 §3.3). The features of both images (stage 1's detection) live in
:mod:`slamlab.stereo.detection`; this module re-exports ``detect_features`` and ``detect_pair``.

Part of :mod:`slamlab.stereo.stages` (which re-exports every name; its docstring gives the pipeline's order).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._compiled import numba_enabled
from .._validate import as_finite_array, check_int, check_positive, check_real
from ..features.base import Features
from ..features.matching import best_per_target, ratio_rule
from ..geometry.camera import StereoRig
from ..geometry.triangulation import triangulate_stereo
from ._pairs import pairs_two_nearest
from ._sad_kernel import MAX_SAD_TERMS, sad_costs
from .detection import detect_features, detect_pair
from .params import StereoParams
from .window_kernel import epipolar_hamming_2nn

__all__ = [
    "LocalCloud",
    "StereoMatches",
    "check_features",
    "detect_features",
    "detect_pair",
    "epipolar_pairs",
    "is_rectified",
    "stereo_match",
    "stereo_point_cov",
    "subpixel_disparity",
    "triangulate_local",
]


# --- stereo matching: ratio rule + epipolar check (000 §3.3) ---------------------------------------


class StereoMatches(NamedTuple):
    """Indices ``left (M,)`` / ``right (M,)`` into the two keypoint sets and descriptor ``distance (M,)``.

    Attributes
    ----------
    left, right : numpy.ndarray of int, shape (M,)
        Indices into the left and right keypoints.
    distance : numpy.ndarray, shape (M,)
        Descriptor distances.
    """

    left: np.ndarray
    right: np.ndarray
    distance: np.ndarray


def check_features(features, name: str = "features") -> Features:
    """Check that ``features`` are keypoints with descriptors, what every matching stage needs (000 §3.3-3.4).

    Parameters
    ----------
    features : Features
        Keypoints and descriptors (from :func:`slamlab.features.detect`).
    name : str, default "features"
        The argument's name in the messages.

    Returns
    -------
    Features
        ``features`` itself.

    Raises
    ------
    TypeError
        When ``features`` is not a :class:`~slamlab.features.Features`.
    ValueError
        When it has no descriptors.
    """
    if not isinstance(features, Features):
        raise TypeError(f"`{name}` must be slamlab.features.Features (from `slamlab.features.detect`); "
                        f"got {type(features).__name__}")
    if features.descriptors is None:
        raise ValueError(f"`{name}` must have descriptors (detect with descriptors=True)")
    return features


def stereo_match(left: Features, right: Features, rig: StereoRig, *, params: StereoParams | None = None,
                 max_distance: float | None = None, **overrides) -> StereoMatches:
    """Left-right correspondences by descriptor, ratio rule and epipolar check (000 §3.3).

    Candidates of a left keypoint are the right keypoints within ``epi_tol_px`` of its
    epipolar line (from the calibrated ``rig``); the nearest candidate is kept when its
    distance is below ``ratio`` × the second nearest (Lowe's rule; 000 does not say how it
    matched — our choice) and when no other left keypoint claims it with a smaller distance.
    ``params`` / ``overrides``: :class:`StereoParams` (``ratio``, ``epi_tol_px``).

    Parameters
    ----------
    left, right : Features
        Keypoints of the two images.
    rig : StereoRig
        Calibration giving the epipolar lines.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    max_distance : float, optional
        Largest descriptor distance accepted (None: no limit).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    StereoMatches
    """
    p = StereoParams.resolve(params, **overrides)
    check_features(left, "left")
    check_features(right, "right")
    if not isinstance(rig, StereoRig):
        raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
    if len(left.uv) and len(right.uv) and (left.descriptors.dtype != right.descriptors.dtype
                                           or left.descriptors.shape[1] != right.descriptors.shape[1]):
        raise ValueError("`left` and `right` descriptors must have the same type and length")
    max_distance = None if max_distance is None else check_positive(max_distance, "max_distance")
    empty = StereoMatches(np.empty(0, np.intp), np.empty(0, np.intp), np.empty(0))
    if len(left.uv) == 0 or len(right.uv) == 0:
        return empty
    li, ri, d1, d2, _ = _epipolar_two_nearest(left.descriptors, right.descriptors, left.uv, right.uv, rig.F,
                                              p.epi_tol_px)
    if li.size == 0:
        return empty
    keep = ratio_rule(d1, d2, p.ratio)
    if max_distance is not None:
        keep &= d1 <= max_distance
    li, ri, d1 = li[keep], ri[keep], d1[keep]
    sel = best_per_target(ri, d1)  # each right keypoint goes to its best left keypoint only
    return StereoMatches(li[sel], ri[sel], d1[sel])


def epipolar_pairs(uv_left, uv_right, F, tol_px):
    """All (left, right) keypoint pairs with the right point within ``tol_px`` of the left one's
    epipolar line ``l = F x_l``, grouped by left index (ascending) (000 §3.3: the epipolar check of stereo matching).

    When every epipolar line is nearly horizontal (a rectified or nearly rectified rig), the
    candidates come from a row-sorted list by binary search (a few per keypoint); otherwise every
    pair is tested.

    Parameters
    ----------
    uv_left, uv_right : ndarray, shape (N, 2) and (M, 2)
        Keypoint pixels of the left and right images.
    F : ndarray, shape (3, 3)
        Fundamental matrix with ``x_r^T F x_l = 0``.
    tol_px : float
        Largest distance of a right keypoint from the left one's epipolar line, pixels.

    Returns
    -------
    left, right : ndarray of int
        Indices of the pairs, grouped by left index (ascending).
    """
    a, b, c, order, lo, hi = _epipolar_ranges(uv_left, uv_right, F, tol_px)
    n = len(uv_left)
    if order is not None:
        cnt = hi - lo
        li = np.repeat(np.arange(n), cnt)
        ri = order[np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt - lo, cnt)]
    else:
        li, ri = np.divmod(np.arange(n * len(uv_right)), len(uv_right))
    dist = np.abs(a[li] * uv_right[ri, 0] + b[li] * uv_right[ri, 1] + c[li])
    keep = dist <= tol_px
    return li[keep], ri[keep]


def _epipolar_ranges(uv_left, uv_right, F, tol_px):
    """The left keypoints' epipolar lines ``l = F x_l`` scaled to a unit normal, ``(a, b, c)``, and when every
    line is nearly horizontal their candidates for :func:`epipolar_pairs` before the distance test: left
    keypoint ``i``'s are ``order[lo[i]:hi[i]]`` (right keypoints sorted by row). ``(a, b, c, order, lo, hi)``,
    the last three None when some line is steep (then every pair is a candidate)."""
    xl = np.column_stack([uv_left, np.ones(len(uv_left))])
    lines = xl @ F.T
    lines /= np.hypot(lines[:, 0], lines[:, 1])[:, None]
    a, b, c = lines.T
    if not np.all(np.abs(b) > 0.5):
        return a, b, c, None, None, None
    order = np.argsort(uv_right[:, 1], kind="stable")
    ys = uv_right[order, 1]
    x_lo, x_hi = uv_right[:, 0].min(), uv_right[:, 0].max()
    y_lo, y_hi = -(a * x_lo + c) / b, -(a * x_hi + c) / b
    pad = tol_px / np.abs(b) + 1e-9  # |a x + b y + c| <= tol  <=>  |y - y_line(x)| <= tol / |b|
    lo = np.searchsorted(ys, np.minimum(y_lo, y_hi) - pad, side="left")
    hi = np.searchsorted(ys, np.maximum(y_lo, y_hi) + pad, side="right")
    return a, b, c, order, lo, hi


def _epipolar_two_nearest(A, B, uv_left, uv_right, F, tol_px):
    """:func:`epipolar_pairs` and then ``pairs_two_nearest`` on them: ``(query, nearest, d1, d2, second)``.
    Binary descriptors on a nearly rectified rig take one compiled kernel for both when numba is enabled (the
    same pairs in the same order, the same distance test; same result, tested), otherwise numpy."""
    if A.dtype == np.uint8 and A.shape[1] % 8 == 0 and len(uv_right) and numba_enabled():
        a, b, c, order, lo, hi = _epipolar_ranges(uv_left, uv_right, F, tol_px)
        if order is not None:
            r1, d1, d2, r2 = epipolar_hamming_2nn(A.view(np.uint64), B.view(np.uint64), a, b, c,
                                                  np.ascontiguousarray(uv_right, dtype=np.float64), order, lo, hi,
                                                  float(tol_px))
            q = np.flatnonzero(r1 >= 0)
            return q, r1[q], d1[q], d2[q], r2[q]
    li, ri = epipolar_pairs(uv_left, uv_right, F, tol_px)
    if li.size == 0:
        return li, ri, np.empty(0), np.empty(0), ri
    return pairs_two_nearest(A, B, li, ri)


# --- sub-pixel disparity along the rows of a rectified pair (our addition) -------------------------


def is_rectified(rig: StereoRig, tol: float = 1e-9) -> bool:
    """True when ``rig``'s epipolar lines are image rows: parallel axes, a baseline along ``x`` and
    equal ``fy``, ``cy`` (then a left pixel's match lies on the same row of the right image).

    Parameters
    ----------
    rig : StereoRig
        The calibrated pair.
    tol : float, default 1e-9
        Tolerance on the rotation and the baseline's y, z [m].

    Returns
    -------
    bool
    """
    return bool(np.allclose(rig.R_rl, np.eye(3), atol=tol) and abs(rig.t_rl[1]) <= tol and abs(rig.t_rl[2]) <= tol
                and np.isclose(rig.left.fy, rig.right.fy) and np.isclose(rig.left.cy, rig.right.cy))


def subpixel_disparity(left_image, right_image, uv_left, uv_right, *, half_px: int = 5, search_px: int = 4):
    """Refine stereo matches of a rectified pair by patch search along the row (our addition to 000 §3.3).

    The ``(2 half_px + 1)²`` patch at the left keypoint's nearest pixel ``(c, r)`` is compared (sum of absolute differences of mean-free patches) with right patches on row ``r``
    within ``search_px`` columns of the matched right keypoint; a V (equiangular line fit, suited to
    absolute differences) through the best cost and its two neighbours gives the sub-pixel column.
    Returns ``(uv_left, uv_right, ok)``: the left keypoints unchanged, the right ones on the same row
    at the refined disparity (measured at ``c``, applied at the keypoint's sub-pixel column), and the mask of matches that were refined — False near a border or when
    the best cost lies at the end of the search window (a match the patches do not confirm).

    Why: ORB finds keypoints on a scale pyramid (factor 1.2, 8 levels), so a keypoint of level L
    sits on a grid of ``1.2^L`` pixels; the disparity of two such keypoints carries that error
    into the depth (``z² δd / (f b)``). The patch search measures the disparity at full resolution.

    Parameters
    ----------
    left_image, right_image : array_like, shape (H, W)
        The rectified pair.
    uv_left, uv_right : array_like, shape (M, 2)
        Matched keypoints ``(u, v)`` [px].
    half_px : int, default 5
        Patch half-size [px].
    search_px : int, default 4
        Search half-width along the row [px].

    Returns
    -------
    uv_left, uv_right : numpy.ndarray, shape (M, 2)
    ok : numpy.ndarray of bool, shape (M,)

    Examples
    --------
    >>> rng = np.random.default_rng(0); L = rng.integers(0, 256, (40, 60)).astype(np.uint8)
    >>> R = np.roll(L, -7, axis=1)  # disparity 7 px everywhere
    >>> _, uvr, ok = subpixel_disparity(L, R, [[30.2, 20.0]], [[21.0, 20.0]])
    >>> bool(ok[0]), round(float(uvr[0, 0]), 1)
    (True, 23.2)
    """
    from ..features.base import to_gray_uint8

    h = check_int(half_px, "half_px", minimum=1)
    s = check_int(search_px, "search_px", minimum=1)
    IL = to_gray_uint8(left_image, "left_image")
    IR = to_gray_uint8(right_image, "right_image")
    if IL.shape != IR.shape:
        raise ValueError(f"`left_image` and `right_image` must have the same shape; got {IL.shape} and {IR.shape}")
    uvl = as_finite_array(uv_left, "uv_left", ndim=2)
    uvr = as_finite_array(uv_right, "uv_right", ndim=2)
    if uvl.shape != uvr.shape or uvl.shape[1:] != (2,):
        raise ValueError(f"`uv_left` and `uv_right` must both have shape (M, 2); got {uvl.shape} and {uvr.shape}")
    return _subpixel_disparity(IL, IR, uvl, uvr, h, s)


def _subpixel_disparity(IL, IR, uvl, uvr, h, s):
    """:func:`subpixel_disparity` on checked grey uint8 images (the per-frame core)."""
    from numpy.lib.stride_tricks import sliding_window_view

    H, W = IL.shape
    c = np.rint(uvl[:, 0]).astype(np.intp)
    r = np.rint(uvl[:, 1]).astype(np.intp)
    cr = np.rint(c - (uvl[:, 0] - uvr[:, 0])).astype(np.intp)  # right column of pixel c at the matched disparity
    ok = (r >= h) & (r < H - h) & (c >= h) & (c < W - h) & (cr - h - s >= 0) & (cr + h + s < W)
    out_r = np.column_stack([uvr[:, 0], uvl[:, 1]])
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return uvl.copy(), out_r, ok
    P = 2 * h + 1
    if P * P <= MAX_SAD_TERMS and numba_enabled():  # the same costs compiled (bit for bit, tested; issue 25)
        cost = sad_costs(IL, IR, r[idx], c[idx], cr[idx], h, s)
    else:
        lp = sliding_window_view(IL, (P, P))[r[idx] - h, c[idx] - h].astype(np.float32)
        strip = sliding_window_view(IR, (P, P + 2 * s))[r[idx] - h, cr[idx] - h - s].astype(np.float32)
        lp -= lp.mean(axis=(1, 2), keepdims=True)
        cost = np.empty((idx.size, 2 * s + 1), np.float32)
        for k in range(2 * s + 1):
            rp = strip[:, :, k:k + P]
            cost[:, k] = np.abs(lp - (rp - rp.mean(axis=(1, 2), keepdims=True))).sum(axis=(1, 2))
    k = np.argmin(cost, axis=1)
    inner = (k > 0) & (k < 2 * s)
    kk = np.clip(k, 1, 2 * s - 1)
    rows = np.arange(idx.size)
    cm, c0, cp = cost[rows, kk - 1], cost[rows, kk], cost[rows, kk + 1]
    den = 2.0 * (np.maximum(cm, cp) - c0)  # equiangular (V-shaped) fit: exact for a linear SAD slope
    delta = np.where(den > 0, (cm - cp) / np.where(den > 0, den, 1.0), 0.0)
    # the disparity measured at pixel c, applied at the keypoint's own sub-pixel position
    disparity = c[idx] - (cr[idx] - s + kk + np.clip(delta, -0.5, 0.5))
    out_r[idx, 0] = uvl[idx, 0] - disparity
    ok[idx] = inner
    return uvl.copy(), out_r, ok


# --- local landmark cloud (000 §3.3) ----------------------------------------------------------------


class LocalCloud(NamedTuple):
    """Landmarks of one frame in the left-camera frame.

    ``points (K, 3)``, their covariances ``cov (K, 3, 3)`` from the pixel error,
    ``left (K,)`` indices of their left keypoints, ``gap_m (K,)`` ray gaps.

    Attributes
    ----------
    points : numpy.ndarray, shape (K, 3)
        Points in the left-camera frame [m].
    cov : numpy.ndarray, shape (K, 3, 3)
        Their covariances [m²].
    left : numpy.ndarray of int, shape (K,)
        Indices of their left keypoints.
    gap_m : numpy.ndarray, shape (K,)
        Gap between the two rays at the midpoint [m].
    """

    points: np.ndarray
    cov: np.ndarray
    left: np.ndarray
    gap_m: np.ndarray


def triangulate_local(rig: StereoRig, left: Features, right: Features, matches: StereoMatches, *, images=None,
                      extra_offset_px: float = 0.0, params: StereoParams | None = None, **overrides) -> LocalCloud:
    """Midpoint triangulation of the stereo matches, with covariances (000 §3.3).

    Keeps points in front of both cameras with depth in ``[min_depth_m, max_depth_m]``.
    The covariance (our addition, used by the landmark filter) is that of a stereo
    point with ``pixel_std`` error per coordinate: lateral ``z σ / f``, depth
    ``z² √2 σ / (f b)``, rotated along the viewing ray. With ``images = (left_image,
    right_image)`` and a rectified ``rig`` (:func:`is_rectified`), the disparities are first
    refined by :func:`subpixel_disparity` when ``subpixel_stereo`` says so (default: ORB only), and
    the matches it does not confirm are dropped (what :class:`~slamlab.stereo.StereoSLAM` does). ``params`` /
    ``overrides``: :class:`StereoParams` (``min_depth_m``, ``max_depth_m``, ``pixel_std``,
    ``subpixel_*``).

    Parameters
    ----------
    rig : StereoRig
        The calibrated pair.
    left, right : Features
        Keypoints of the two images.
    matches : StereoMatches
        From :func:`stereo_match`.
    images : tuple of array_like, optional
        ``(left_image, right_image)`` for the sub-pixel refinement.
    extra_offset_px : float, default 0.0
        Added to every disparity beside ``disparity_offset_px`` (the online estimate of
        :class:`~slamlab.stereo.StereoSLAM`, ``disparity_offset_estimate``) [px].
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    LocalCloud
    """
    p = StereoParams.resolve(params, **overrides)
    if not isinstance(rig, StereoRig):
        raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
    check_features(left, "left")
    check_features(right, "right")
    if not isinstance(matches, StereoMatches):
        raise TypeError(f"`matches` must be StereoMatches; got {type(matches).__name__}")
    offset_px = p.disparity_offset_px + check_real(extra_offset_px, "extra_offset_px")
    if images is not None and (not isinstance(images, (tuple, list)) or len(images) != 2):
        raise TypeError("`images` must be a pair (left_image, right_image)")
    if images is None or not (p.refine_disparity and is_rectified(rig)):
        return _triangulate_local(rig, left, right, matches, p.min_depth_m, p.max_depth_m, p.pixel_std,
                                  offset_px=offset_px)
    from ..features.base import to_gray_uint8

    grey = [to_gray_uint8(im, name, channel_order=p.channel_order) for im, name in zip(images, ("left_image", "right_image"), strict=True)]
    return _triangulate_local(rig, left, right, matches, p.min_depth_m, p.max_depth_m, p.pixel_std,
                              refine=(*grey, p.subpixel_half_px, p.subpixel_search_px), offset_px=offset_px)


def _triangulate_local(rig, left, right, matches, min_depth_m, max_depth_m, pixel_std, refine=None,
                       offset_px=0.0) -> LocalCloud:
    """:func:`triangulate_local` on checked arguments (the per-frame core); ``refine`` =
    ``(grey_left, grey_right, half_px, search_px)`` refines the disparities first; ``offset_px`` is added to every
    disparity (the right keypoints move left by it: ``disparity_offset_px``)."""
    if len(matches.left) == 0:
        return LocalCloud(np.empty((0, 3)), np.empty((0, 3, 3)), np.empty(0, np.intp), np.empty(0))
    uvl, uvr, li = left.uv[matches.left], right.uv[matches.right], matches.left
    if refine is not None:
        uvl, uvr, ok = _subpixel_disparity(refine[0], refine[1], uvl, uvr, refine[2], refine[3])
        uvl, uvr, li = uvl[ok], uvr[ok], li[ok]
    if offset_px:
        uvr = uvr - np.array([offset_px, 0.0])
    tri = triangulate_stereo(rig, uvl, uvr)
    P = tri.points
    ok = tri.valid & (P[:, 2] >= min_depth_m) & (P[:, 2] <= max_depth_m)
    P = P[ok]
    return LocalCloud(P, stereo_point_cov(P, rig.left.fx, rig.baseline_m, pixel_std), li[ok], tri.gap_m[ok])


def stereo_point_cov(points, f_px: float, baseline_m: float, pixel_std: float) -> np.ndarray:
    """Covariances of stereo points in the left-camera frame from a pixel error (our addition to 000 §3.3).

    Lateral variance ``(z σ / f)²``, depth variance ``(z² √2 σ / (f b))²`` along the viewing ray.

    Parameters
    ----------
    points : numpy.ndarray, shape (K, 3)
        Points in the left-camera frame (``z`` > 0) [m].
    f_px : float
        Focal length [px].
    baseline_m : float
        Stereo baseline [m].
    pixel_std : float
        Pixel error per coordinate [px].

    Returns
    -------
    numpy.ndarray, shape (K, 3, 3)
        Covariances [m²].

    Examples
    --------
    >>> C = stereo_point_cov(np.array([[0.0, 0.0, 10.0]]), 500.0, 0.5, 0.5)
    >>> np.round(np.sqrt(np.diag(C[0])), 3).tolist()
    [0.01, 0.01, 0.283]
    """
    P = np.asarray(points, dtype=float)
    z = P[:, 2]
    lat = (z * pixel_std / f_px) ** 2
    dep = (z**2 * np.sqrt(2.0) * pixel_std / (f_px * baseline_m)) ** 2
    # covariance = lat I + (dep - lat) r r^T with r the unit viewing ray
    r = P / np.linalg.norm(P, axis=1, keepdims=True)
    return lat[:, None, None] * np.eye(3) + (dep - lat)[:, None, None] * (r[:, :, None] * r[:, None, :])
