"""The per-frame stages of the stereo SLAM pipeline (000 §3.3-3.6), callable one at a time.

:func:`slamlab.features.detect` (with :meth:`StereoParams.detect_kwargs`) → ``stereo_match``
→ ``triangulate_local`` → ``match_to_map`` → ``estimate_pose``;
:class:`~slamlab.stereo.slam.StereoSLAM` runs them in a loop and refines / adds landmarks.
Each public stage takes ``params=`` (:class:`~slamlab.stereo.params.StereoParams`) plus
overrides and checks its arguments once; the loop calls the unchecked cores (``_stereo_match``,
...) with arguments it checked once.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import _validate as v
from ..features.base import Features
from ..features.detect import detect
from ..features.matching import best_per_target, ratio_rule
from ..geometry.camera import StereoRig
from ..geometry.ransac import ransac
from ..geometry.registration import RigidTransform, umeyama
from ..geometry.so3 import hat
from ..geometry.triangulation import triangulate_stereo
from ..kdtree.stores import LandmarkStore
from .params import StereoParams

__all__ = [
    "LocalCloud",
    "MapMatches",
    "PoseEstimate",
    "StereoMatches",
    "detect_features",
    "estimate_pose",
    "is_rectified",
    "match_to_map",
    "pose_std",
    "select_oldest",
    "stereo_match",
    "subpixel_disparity",
    "triangulate_local",
]


# --- stereo matching: ratio rule + epipolar check (000 §3.3) ---------------------------------------


def detect_features(image, *, params: StereoParams | None = None, **overrides) -> Features:
    """Keypoints and descriptors of one image with the pipeline's settings (000 §3.3).

    :func:`slamlab.features.detect` with :meth:`StereoParams.detect_kwargs`: 000 uses SURF with
    about 2000 points per 768×576 image; SURF is absent from our OpenCV, so ``"surf"`` (the default)
    is the features chapter's own SURF (its threshold, not ``n_features``, limits it to about 600
    points on the arena); ``"orb"`` and ``"sift"`` are OpenCV's (ORB is the fast one).

    >>> img = (np.indices((64, 64)).sum(0) % 16 < 8).astype(np.uint8) * 255
    >>> f = detect_features(img, detector="orb", n_features=50); f.uv.shape[1], f.descriptors.dtype
    (2, dtype('uint8'))
    """
    p = StereoParams.resolve(params, **overrides)
    return detect(image, p.detector, **p.detect_kwargs())


class StereoMatches(NamedTuple):
    """Indices ``left (M,)`` / ``right (M,)`` into the two keypoint sets and descriptor ``distance (M,)``."""

    left: np.ndarray
    right: np.ndarray
    distance: np.ndarray


def _check_features(f, name):
    if not isinstance(f, Features):
        raise TypeError(f"`{name}` must be slamlab.features.Features (from `slamlab.features.detect`); "
                        f"got {type(f).__name__}")
    if f.descriptors is None:
        raise ValueError(f"`{name}` must have descriptors (detect with descriptors=True)")
    return f


def stereo_match(left: Features, right: Features, rig: StereoRig, *, params: StereoParams | None = None,
                 max_distance: float | None = None, **overrides) -> StereoMatches:
    """Left-right correspondences by descriptor, ratio rule and epipolar check (000 §3.3).

    Candidates of a left keypoint are the right keypoints within ``epi_tol_px`` of its
    epipolar line (from the calibrated ``rig``); the nearest candidate is kept when its
    distance is below ``ratio`` × the second nearest (Lowe's rule; 000 does not say how it
    matched — our choice) and when no other left keypoint claims it with a smaller distance.
    ``params`` / ``overrides``: :class:`StereoParams` (``ratio``, ``epi_tol_px``).
    """
    p = StereoParams.resolve(params, **overrides)
    _check_features(left, "left")
    _check_features(right, "right")
    if not isinstance(rig, StereoRig):
        raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
    if len(left.uv) and len(right.uv) and (left.descriptors.dtype != right.descriptors.dtype
                                           or left.descriptors.shape[1] != right.descriptors.shape[1]):
        raise ValueError("`left` and `right` descriptors must have the same type and length")
    max_distance = None if max_distance is None else v.check_positive(max_distance, "max_distance")
    return _stereo_match(left, right, rig.F, p.ratio, p.epi_tol_px, max_distance)


def _stereo_match(left, right, F, ratio, epi_tol_px, max_distance=None) -> StereoMatches:
    """:func:`stereo_match` on checked arguments (the per-frame core)."""
    empty = StereoMatches(np.empty(0, np.intp), np.empty(0, np.intp), np.empty(0))
    if len(left.uv) == 0 or len(right.uv) == 0:
        return empty
    li, ri = _epipolar_pairs(left.uv, right.uv, F, epi_tol_px)
    if li.size == 0:
        return empty
    d = _pair_distances(left.descriptors, right.descriptors, li, ri)
    li, ri, d1, d2, _ = _two_nearest(li, ri, d)
    keep = ratio_rule(d1, d2, ratio)
    if max_distance is not None:
        keep &= d1 <= max_distance
    li, ri, d1 = li[keep], ri[keep], d1[keep]
    sel = best_per_target(ri, d1)  # each right keypoint goes to its best left keypoint only
    return StereoMatches(li[sel], ri[sel], d1[sel])


def _two_nearest(qi, ti, d):
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


def _epipolar_pairs(uv_left, uv_right, F, tol_px):
    """All (left, right) keypoint pairs with the right point within ``tol_px`` of the left one's
    epipolar line ``l = F x_l``, grouped by left index (ascending).

    When every epipolar line is nearly horizontal (a rectified or nearly rectified rig), the
    candidates come from a row-sorted list by binary search (a few per keypoint); otherwise every
    pair is tested.
    """
    xl = np.column_stack([uv_left, np.ones(len(uv_left))])
    lines = xl @ F.T
    lines /= np.hypot(lines[:, 0], lines[:, 1])[:, None]
    a, b, c = lines.T
    n = len(uv_left)
    if np.all(np.abs(b) > 0.5):
        order = np.argsort(uv_right[:, 1], kind="stable")
        ys = uv_right[order, 1]
        x_lo, x_hi = uv_right[:, 0].min(), uv_right[:, 0].max()
        y_lo, y_hi = -(a * x_lo + c) / b, -(a * x_hi + c) / b
        pad = tol_px / np.abs(b) + 1e-9  # |a x + b y + c| <= tol  <=>  |y - y_line(x)| <= tol / |b|
        lo = np.searchsorted(ys, np.minimum(y_lo, y_hi) - pad, side="left")
        hi = np.searchsorted(ys, np.maximum(y_lo, y_hi) + pad, side="right")
        cnt = hi - lo
        li = np.repeat(np.arange(n), cnt)
        ri = order[np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt - lo, cnt)]
    else:
        li, ri = np.divmod(np.arange(n * len(uv_right)), len(uv_right))
    dist = np.abs(a[li] * uv_right[ri, 0] + b[li] * uv_right[ri, 1] + c[li])
    keep = dist <= tol_px
    return li[keep], ri[keep]


def _pair_distances(A, B, ia, ib, block: int = 1 << 16) -> np.ndarray:
    """Descriptor distance of each pair ``(A[ia], B[ib])``: Hamming for uint8, Euclidean otherwise."""
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


# --- sub-pixel disparity along the rows of a rectified pair (our addition) -------------------------


def is_rectified(rig: StereoRig, tol: float = 1e-9) -> bool:
    """True when ``rig``'s epipolar lines are image rows: parallel axes, a baseline along ``x`` and
    equal ``fy``, ``cy`` (then a left pixel's match lies on the same row of the right image)."""
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

    >>> rng = np.random.default_rng(0); L = rng.integers(0, 256, (40, 60)).astype(np.uint8)
    >>> R = np.roll(L, -7, axis=1)  # disparity 7 px everywhere
    >>> _, uvr, ok = subpixel_disparity(L, R, [[30.2, 20.0]], [[21.0, 20.0]])
    >>> bool(ok[0]), round(float(uvr[0, 0]), 1)
    (True, 23.2)
    """
    from ..features.base import to_gray_uint8

    h = v.check_int(half_px, "half_px", minimum=1)
    s = v.check_int(search_px, "search_px", minimum=1)
    IL = to_gray_uint8(left_image, "left_image")
    IR = to_gray_uint8(right_image, "right_image")
    if IL.shape != IR.shape:
        raise ValueError(f"`left_image` and `right_image` must have the same shape; got {IL.shape} and {IR.shape}")
    uvl = v.as_finite_array(uv_left, "uv_left", ndim=2)
    uvr = v.as_finite_array(uv_right, "uv_right", ndim=2)
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
    """

    points: np.ndarray
    cov: np.ndarray
    left: np.ndarray
    gap_m: np.ndarray


def triangulate_local(rig: StereoRig, left: Features, right: Features, matches: StereoMatches, *, images=None,
                      params: StereoParams | None = None, **overrides) -> LocalCloud:
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
    """
    p = StereoParams.resolve(params, **overrides)
    if not isinstance(rig, StereoRig):
        raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
    _check_features(left, "left")
    _check_features(right, "right")
    if not isinstance(matches, StereoMatches):
        raise TypeError(f"`matches` must be StereoMatches; got {type(matches).__name__}")
    if images is not None and (not isinstance(images, (tuple, list)) or len(images) != 2):
        raise TypeError("`images` must be a pair (left_image, right_image)")
    if images is None or not (p.refine_disparity and is_rectified(rig)):
        return _triangulate_local(rig, left, right, matches, p.min_depth_m, p.max_depth_m, p.pixel_std)
    from ..features.base import to_gray_uint8

    grey = [to_gray_uint8(im, name, channel_order=p.channel_order) for im, name in zip(images, ("left_image", "right_image"), strict=True)]
    return _triangulate_local(rig, left, right, matches, p.min_depth_m, p.max_depth_m, p.pixel_std,
                              refine=(*grey, p.subpixel_half_px, p.subpixel_search_px))


def _triangulate_local(rig, left, right, matches, min_depth_m, max_depth_m, pixel_std, refine=None) -> LocalCloud:
    """:func:`triangulate_local` on checked arguments (the per-frame core); ``refine`` =
    ``(grey_left, grey_right, half_px, search_px)`` refines the disparities first."""
    if len(matches.left) == 0:
        return LocalCloud(np.empty((0, 3)), np.empty((0, 3, 3)), np.empty(0, np.intp), np.empty(0))
    uvl, uvr, li = left.uv[matches.left], right.uv[matches.right], matches.left
    if refine is not None:
        uvl, uvr, ok = _subpixel_disparity(refine[0], refine[1], uvl, uvr, refine[2], refine[3])
        uvl, uvr, li = uvl[ok], uvr[ok], li[ok]
    tri = triangulate_stereo(rig, uvl, uvr)
    P = tri.points
    ok = tri.valid & (P[:, 2] >= min_depth_m) & (P[:, 2] <= max_depth_m)
    P = P[ok]
    f = rig.left.fx
    z = P[:, 2]
    lat = (z * pixel_std / f) ** 2
    dep = (z**2 * np.sqrt(2.0) * pixel_std / (f * rig.baseline_m)) ** 2
    # covariance = lat I + (dep - lat) r r^T with r the unit viewing ray
    r = P / np.linalg.norm(P, axis=1, keepdims=True)
    cov = lat[:, None, None] * np.eye(3) + (dep - lat)[:, None, None] * (r[:, :, None] * r[:, None, :])
    return LocalCloud(P, cov, li[ok], tri.gap_m[ok])


# --- local landmarks to map landmarks through a store (000 §3.4) -----------------------------------


class MapMatches(NamedTuple):
    """``local (M,)`` indices into the local cloud, ``ids (M,)`` landmark ids, ``distance (M,)``,
    ``unmatched (K - M,)`` local indices that found no landmark (candidates for new landmarks), and
    ``nearest (K,)``: every local point's nearest landmark by descriptor (-1: none), matched or not."""

    local: np.ndarray
    ids: np.ndarray
    distance: np.ndarray
    unmatched: np.ndarray
    nearest: np.ndarray | None = None


def match_to_map(descriptors, store: LandmarkStore, *, params: StereoParams | None = None, positions=None,
                 candidates=None, max_distance: float | None = None, **overrides) -> MapMatches:
    """Match local descriptors to the stored landmarks: 2-NN query + ratio rule, one local per landmark (000 §3.4).

    The ratio is ``map_ratio`` of ``params`` / ``overrides`` (:class:`StereoParams`). With
    ``positions`` ((n, 3) landmark positions indexed by id) and ``same_point_m``, two nearest
    landmarks closer than ``same_point_m`` to each other count as one physical point (a duplicate
    added when a sighting was missed), so the ratio rule does not reject them (our addition:
    without it, duplicates make every later sighting of a place ambiguous and the map stops
    closing loops).

    With ``candidates`` (landmark ids), only those landmarks are searched
    (:meth:`~slamlab.kdtree.LandmarkStore.query_among`, exact for every store).

    >>> from slamlab.kdtree import ExactStore
    >>> s = ExactStore(); s.add(np.array([[0.0, 0.0], [5.0, 0.0]]), [7, 8])
    >>> m = match_to_map(np.array([[0.1, 0.0], [2.4, 0.0]]), s)
    >>> m.local.tolist(), m.ids.tolist(), m.unmatched.tolist()
    ([0], [7], [1])
    """
    p = StereoParams.resolve(params, **overrides)
    D = np.asarray(descriptors)
    if D.ndim != 2:
        raise ValueError(f"`descriptors` must be 2-D (K, D); got shape {D.shape}")
    if not isinstance(store, LandmarkStore):
        raise TypeError(f"`store` must be a slamlab.kdtree.LandmarkStore; got {type(store).__name__}")
    X = None if positions is None else v.as_finite_array(positions, "positions", ndim=2)
    cand = None if candidates is None else np.asarray(candidates, dtype=np.int64).ravel()
    max_distance = None if max_distance is None else v.check_positive(max_distance, "max_distance")
    return _match_to_map(D, store, p.map_ratio, X, p.same_point_m or None, cand, max_distance)


def _match_to_map(D, store, ratio, positions=None, same_point_m=None, candidates=None, max_distance=None):
    """:func:`match_to_map` on checked arguments (the per-frame core)."""
    k = D.shape[0]
    if k == 0 or len(store) == 0:
        return MapMatches(np.empty(0, np.intp), np.empty(0, np.int64), np.empty(0), np.arange(k), np.full(k, -1))
    if candidates is not None:
        dist, ids = store.query_among(D, candidates, k=2)
    else:
        dist, ids = store.query(D, k=2)
    return _matches_from_knn(dist, ids, ratio, positions, same_point_m, max_distance)


def _accept_twins(ok, first, second, positions, same_point_m):
    """Set ``ok`` (in place) where the ratio rule failed only because the nearest and second-nearest
    landmarks (ids ``first``, ``second``; -1: none) lie within ``same_point_m`` of each other: one point."""
    if positions is None or same_point_m is None:
        return
    both = ~ok & (first >= 0) & (second >= 0)
    if both.any():
        gap = np.linalg.norm(positions[first[both]] - positions[second[both]], axis=1)
        ok[np.flatnonzero(both)[gap < same_point_m]] = True


def _matches_from_knn(dist, ids, ratio, positions=None, same_point_m=None, max_distance=None) -> MapMatches:
    """:class:`MapMatches` from the 2-NN ``(dist, ids)`` of every local point (the rules of :func:`match_to_map`)."""
    k = dist.shape[0]
    ok = (ids[:, 0] >= 0) & ratio_rule(dist[:, 0], dist[:, 1], ratio)
    _accept_twins(ok, ids[:, 0], ids[:, 1], positions, same_point_m)
    if max_distance is not None:
        ok &= dist[:, 0] <= max_distance
    loc = np.flatnonzero(ok)
    lid, d = ids[ok, 0], dist[ok, 0]
    sel = best_per_target(lid, d)  # one local point per landmark: the closest descriptor wins
    claimed = np.zeros(k, dtype=bool)
    claimed[loc] = True  # ratio-passing points that lost a duplicate are neither matches nor new
    return MapMatches(loc[sel], lid[sel], d[sel], np.flatnonzero(~claimed), ids[:, 0])


def _radius_pairs(uv_q, uv_t, radius):
    """All pairs ``(query, target)`` of 2-D points at most ``radius`` apart, grouped by ascending query
    index: targets bucketed in a grid of ``radius`` cells, each query looks in its 3 x 3 cells."""
    lo_xy = np.minimum(uv_q.min(axis=0), uv_t.min(axis=0))
    cq = np.floor((uv_q - lo_xy) / radius).astype(np.int64)
    ct = np.floor((uv_t - lo_xy) / radius).astype(np.int64)
    ny = int(max(cq[:, 1].max(), ct[:, 1].max())) + 3
    key_t = (ct[:, 0] + 1) * ny + ct[:, 1] + 1
    order = np.argsort(key_t, kind="stable")
    keys = key_t[order]
    # the 3 cells of a column are consecutive keys: one range per column offset
    base = (cq[:, 0:1] + 1 + np.arange(-1, 2)) * ny + cq[:, 1:2] + 1  # (k, 3) middle cell of each column
    lo = np.searchsorted(keys, base - 1, side="left")
    hi = np.searchsorted(keys, base + 1, side="right")
    cnt = (hi - lo).ravel()
    qi = np.repeat(np.arange(len(uv_q)), 3)
    qi = np.repeat(qi, cnt)
    ti = order[np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt - lo.ravel(), cnt)]
    d = uv_q[qi] - uv_t[ti]
    keep = np.einsum("ij,ij->i", d, d) <= radius * radius
    return qi[keep], ti[keep]


def _window_match(D, uv, desc_lm, uv_lm, ids_lm, radius_px, ratio, max_distance, positions=None,
                  same_point_m=None) -> tuple[MapMatches, int]:
    """Map matching by projection (our addition to 000 §3.4): each local point (left keypoint ``uv``,
    descriptor ``D``) is compared only with the landmarks ``ids_lm`` that a predicted pose projects within
    ``radius_px`` of it (pixels ``uv_lm``, descriptors ``desc_lm``); nearest and second nearest of those
    decide by the ratio rule (two neighbours closer than ``same_point_m`` count as one), the nearest
    must be within ``max_distance``, one local point per landmark. Returns the matches and the number of
    descriptor distances computed."""
    k = D.shape[0]
    none = MapMatches(np.empty(0, np.intp), np.empty(0, np.int64), np.empty(0), np.arange(k), np.full(k, -1))
    if k == 0 or len(ids_lm) == 0:
        return none, 0
    qi, rows = _radius_pairs(uv, uv_lm, radius_px)
    if qi.size == 0:
        return none, 0
    d = _pair_distances(D, desc_lm, qi, rows)
    q, r1, d1, d2, r2 = _two_nearest(qi, rows, d)
    ok = ratio_rule(d1, d2, ratio)
    _accept_twins(ok, ids_lm[r1], np.where(r2 >= 0, ids_lm[r2], -1), positions, same_point_m)
    ok &= d1 <= max_distance
    nearest = np.full(k, -1, dtype=np.int64)
    nearest[q] = ids_lm[r1]
    loc, lid, dd = q[ok], ids_lm[r1[ok]], d1[ok]
    sel = best_per_target(lid, dd)
    claimed = np.zeros(k, dtype=bool)
    claimed[loc] = True
    return MapMatches(loc[sel], lid[sel], dd[sel], np.flatnonzero(~claimed), nearest), int(qi.size)


# --- pose: absolute orientation inside RANSAC, oldest landmarks first (000 §3.5) -----------------


def select_oldest(first_seen, n_min: int) -> np.ndarray:
    """Indices of the matches whose landmarks were first seen longest ago (000 §3.5).

    Sort by the frame of the first sighting and take the earliest ones until at
    least ``n_min`` are gathered, with every landmark of the last frame included
    ("seen as long ago as possible and at about the same time").

    >>> select_oldest([5, 0, 3, 0, 9, 3], 3).tolist()
    [1, 2, 3, 5]
    """
    fs = np.asarray(first_seen)
    if fs.ndim != 1:
        raise ValueError(f"`first_seen` must be 1-D; got shape {fs.shape}")
    n_min = v.check_int(n_min, "n_min", minimum=1)
    if fs.size <= n_min:
        return np.arange(fs.size)
    cut = np.sort(fs)[n_min - 1]
    return np.flatnonzero(fs <= cut)


def pose_std(points_map, cov_map, center=None) -> np.ndarray:
    """Standard deviations of the 6 pose parameters (3 rotations, rad; 3 translations, m)
    determined by matched points with covariances ``cov_map`` (Gauss-Newton information
    ``Σ Jᵢᵀ Σᵢ⁻¹ Jᵢ``, ``Jᵢ = [-[pᵢ - c]ₓ, I]``; translations about ``center``, default the
    points' mean). Our addition: it tells whether a set of landmarks is "sufficiently large
    for computing the position" (000 §3.5). A wall of points straight ahead, with stereo depth
    error much larger than the lateral error, leaves yaw and sideways translation nearly
    interchangeable; this shows as large standard deviations.

    >>> P = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    >>> bool(np.all(np.isfinite(pose_std(P, np.tile(np.eye(3) * 1e-4, (4, 1, 1))))))
    True
    """
    P = v.as_finite_array(points_map, "points_map", ndim=2)
    C = np.asarray(cov_map, dtype=float)
    if C.shape != (len(P), 3, 3):
        raise ValueError(f"`cov_map` must have shape ({len(P)}, 3, 3); got {C.shape}")
    c = P.mean(axis=0) if center is None else np.asarray(center, dtype=float)
    return _std_from_information(_point_information(P, C, c).sum(axis=0))


def _point_information(P, C, center) -> np.ndarray:
    """(N, 6, 6) Gauss-Newton information ``Jᵢᵀ Cᵢ⁻¹ Jᵢ`` of each point about ``center``."""
    q = P - center
    J = np.zeros((len(P), 3, 6))
    J[:, :, :3] = hat(-q)  # d(R p)/d(rotation vector) = -[p]x = [-p]x
    J[:, :, 3:] = np.eye(3)
    CiJ = np.linalg.solve(C, J)
    return np.einsum("nki,nkj->nij", J, CiJ)


def _std_from_information(info) -> np.ndarray:
    """Standard deviations from (..., 6, 6) information matrices; inf where one is singular."""
    info = np.asarray(info)
    out = np.full(info.shape[:-1], np.inf)
    ok = np.linalg.cond(info) < 1e12
    if ok.any():
        out[ok] = np.sqrt(np.diagonal(np.linalg.inv(info[ok]), axis1=-2, axis2=-1))
    return out


class PoseEstimate(NamedTuple):
    """Pose ``T`` (4, 4) mapping local points to the map, ``inliers (M,)`` over all matches,
    ``converged``, ``n_used`` matches the final fit used, ``n_iters`` hypotheses."""

    T: np.ndarray
    inliers: np.ndarray
    converged: bool
    n_used: int
    n_iters: int


def _fit(src, dst, w):
    return umeyama(src, dst, weights=w)


def _residuals(T: RigidTransform, src, dst, w):
    # residual in units of the per-point scale: sqrt(w) = 1 / scale
    return np.linalg.norm(src @ T.R.T + T.t - dst, axis=1) * np.sqrt(w)


def estimate_pose(local_points, map_points, first_seen=None, *, depth_m=None, cov=None,
                  params: StereoParams | None = None, rng=None, **overrides) -> PoseEstimate:
    """Rotation + translation mapping the local cloud onto the map landmarks, by RANSAC + Umeyama (000 §3.5).

    Parameters
    ----------
    local_points, map_points : (M, 3) matched points in the body frame and in the map frame.
    first_seen : (M,) frame at which each matched landmark was first seen (for ``policy="oldest"``).
    params, overrides : :class:`StereoParams` (``policy``, ``ransac_iters``, ``threshold_m``,
        ``depth_ref_m``, ``min_inliers``, ``n_oldest``, ``oldest_fraction``, ``keep_fraction``,
        ``loose_factor``, ``still_fraction``, ``max_std_factor``, ``max_correction_*``).
    depth_m : (M,) depths of the local points: the inlier threshold grows as
        ``threshold_m · max(1, (depth / depth_ref_m)²)`` (stereo depth error ∝ depth²; our choice),
        and the final fit weights points by the inverse square of that scale.
    policy : ``"oldest"`` — RANSAC on all matches gives a consensus pose; the matches within
        ``loose_factor`` thresholds of it are candidates; the landmarks among them first seen
        longest ago (:func:`select_oldest`: at least ``n_oldest`` and ``oldest_fraction`` of the
        candidates — fewer, all from one edge of the view, leave yaw and sideways translation
        nearly ambiguous) — extended by the next-oldest until, with ``cov`` given, no pose parameter is
        more than ``max_std_factor`` times as uncertain as with all candidates (:func:`pose_std`;
        "sufficiently large for computing the position") — get a RANSAC of their own, whose pose wins when at least
        ``keep_fraction`` of them agree, it keeps ``still_fraction`` (80 %) of the candidates within the loose band and
        it differs from the consensus pose by at most ``max_correction_rad`` / ``max_correction_m``
        (None = unbounded; a bound of 5° / 0.3 m also blocks the loop-closing correction)
        (our reading of 000 §3.5: old landmarks correct the drift of the recent ones when a place
        is revisited);
        ``"all"`` — the pose is the least-squares fit on all RANSAC inliers.
    cov : (M, 3, 3) covariances of the local points (body frame), for the conditioning test of
        ``policy="oldest"``; None skips the test.
    ransac_iters : RANSAC hypotheses (000: about 200), minimal samples of 3, early exit at 99.9 % confidence.
    min_inliers : inliers needed for a valid pose.

    Raises
    ------
    ValueError if fewer than 3 matches are given.

    Examples
    --------
    >>> rng = np.random.default_rng(0); P = rng.uniform(-2, 2, (30, 3))
    >>> from slamlab.geometry import se3_from_planar
    >>> T = se3_from_planar(0.5, -0.2, 0.3)
    >>> est = estimate_pose(P, P @ T[:3, :3].T + T[:3, 3], rng=0)
    >>> bool(np.allclose(est.T, T)), int(est.inliers.sum())
    (True, 30)
    """
    p = StereoParams.resolve(params, **overrides)
    src = v.as_finite_array(local_points, "local_points", ndim=2)
    dst = v.as_finite_array(map_points, "map_points", ndim=2)
    if src.shape != dst.shape or src.shape[1:] != (3,):
        raise ValueError(f"`local_points` and `map_points` must both have shape (M, 3); got {src.shape} and {dst.shape}")
    m = src.shape[0]
    if m < 3:
        raise ValueError(f"`local_points` must hold at least 3 matches for a 3-D pose; got {m}")
    if cov is not None:
        cov = np.asarray(cov, dtype=float)
        if cov.shape != (m, 3, 3) or not np.all(np.isfinite(cov)):
            raise ValueError(f"`cov` must be a finite ({m}, 3, 3) array; got shape {cov.shape}")
    depth = np.linalg.norm(src, axis=1) if depth_m is None else v.as_vector(depth_m, "depth_m", m)
    first_seen = np.zeros(m, dtype=np.int64) if first_seen is None else np.asarray(first_seen)
    if first_seen.shape != (m,):
        raise ValueError(f"`first_seen` must have shape ({m},); got {first_seen.shape}")
    return _estimate_pose(src, dst, first_seen, depth, cov, p, v.as_rng(rng))


def _estimate_pose(src, dst, first_seen, depth, cov, p: StereoParams, rng) -> PoseEstimate:
    """:func:`estimate_pose` on checked arguments (the per-frame core)."""
    m = src.shape[0]
    threshold_m, min_inliers, max_iters = p.threshold_m, p.min_inliers, p.ransac_iters
    loose_factor, max_std_factor = p.loose_factor, p.max_std_factor
    scale = np.maximum(1.0, (depth / p.depth_ref_m) ** 2)
    w = 1.0 / scale**2

    r = ransac((src, dst, w), _fit, _residuals, 3, threshold_m, max_iters=max_iters, min_inliers=min_inliers, rng=rng)
    if not r.converged:
        return PoseEstimate(np.eye(4), np.zeros(m, dtype=bool), False, 0, r.n_iters)
    Tm = r.model
    used = np.flatnonzero(r.inliers)
    if p.policy == "oldest":
        # 000 §3.5: the pose from the landmarks first seen longest ago and at about the same time.
        # Candidates: matches within `loose_factor` thresholds of the consensus pose (true matches to
        # old landmarks that drifted apart from the recent map stay, random false matches go);
        # then RANSAC again on the oldest of them, kept if most of them agree.
        loose = np.flatnonzero(_residuals(Tm, src, dst, w) <= loose_factor * threshold_m)
        n_min = max(p.n_oldest, int(np.ceil(p.oldest_fraction * loose.size)))
        old = loose[select_oldest(first_seen[loose], n_min)]
        if cov is not None and max_std_factor is not None and old.size < loose.size:
            # grow the set by first-sighting time until it determines the pose nearly as well as all candidates
            # (cumulative information over the loose candidates sorted by first sighting)
            pts_map = dst[loose]
            info = _point_information(pts_map, Tm.R @ cov[loose] @ Tm.R.T, pts_map.mean(axis=0))
            order = np.argsort(first_seen[loose], kind="stable")
            fs = first_seen[loose][order]
            cum = np.cumsum(info[order], axis=0)
            ends = np.flatnonzero(np.r_[fs[1:] != fs[:-1], True])  # last candidate of each sighting time
            ends = ends[fs[ends] >= first_seen[old].max()]
            std = _std_from_information(cum[ends])
            good = np.all(std <= max_std_factor * _std_from_information(cum[-1]), axis=1)
            cut = ends[np.argmax(good)] if good.any() else len(order) - 1
            old = loose[np.sort(order[: cut + 1])]
        if old.size >= 3:
            r_old = ransac((src[old], dst[old], w[old]), _fit, _residuals, 3, threshold_m, max_iters=max_iters, rng=rng)
            n_old = int(r_old.inliers.sum())
            if r_old.converged and n_old >= max(min(min_inliers, old.size), p.keep_fraction * old.size):
                # and it must still explain the candidates loosely: a wedge of old landmarks at one
                # edge of the view can otherwise trade yaw for sideways translation
                T_old = r_old.model
                still = _residuals(T_old, src[loose], dst[loose], w[loose]) <= loose_factor * threshold_m
                # the old landmarks may correct the consensus pose by a bounded amount only
                d_rot = np.arccos(np.clip((np.trace(T_old.R @ Tm.R.T) - 1.0) / 2.0, -1.0, 1.0))
                d_pos = np.linalg.norm(T_old.t - Tm.t)
                bounded = (p.max_correction_rad is None or d_rot <= p.max_correction_rad) and (
                    p.max_correction_m is None or d_pos <= p.max_correction_m
                )
                if still.mean() >= p.still_fraction and bounded:
                    Tm, used = T_old, old[r_old.inliers]
    inl = _residuals(Tm, src, dst, w) <= threshold_m
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = Tm.R, Tm.t
    return PoseEstimate(T, inl, bool(inl.sum() >= min_inliers), int(used.size), r.n_iters)
