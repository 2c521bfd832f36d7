"""Map initialisation from two views (003 §4.3.1, §5.1.1).

FAST corners in a first frame (≥ 50 needed), tracked with pyramidal Lucas-Kanade
(``cv2.calcOpticalFlowPyrLK``) until their mean displacement passes a threshold (003:
10-20 px); restart from the current frame when too many are lost. The relative pose then
comes from a RANSAC homography (``cv2.findHomography``) and its decomposition
(``cv2.decomposeHomographyMat``, the solution chosen by points in front of both cameras),
or, as 003 also names the 5-point algorithm, from ``cv2.findEssentialMat`` +
``cv2.recoverPose``. Bad input is reported by a status string, never an exception or a NaN.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from ..geometry.homography import apply_homography

__all__ = [
    "INIT_STATUSES",
    "InitResult",
    "Initialiser",
    "TwoViewPose",
    "relative_pose_essential",
    "relative_pose_homography",
    "track_lk",
    "triangulate_two_view",
]

#: what :meth:`Initialiser.add_frame` can report
INIT_STATUSES = ("first_frame", "too_few_corners", "tracking", "restart", "no_parallax",
                 "degenerate_homography", "done")


def _check_uv_pair(uv0, uv1):
    uv0 = v.as_finite_array(uv0, "uv0", ndim=2)
    uv1 = v.as_finite_array(uv1, "uv1", ndim=2)
    if uv0.shape[1] != 2 or uv1.shape != uv0.shape:
        raise ValueError(f"`uv0` and `uv1` must both have shape (N, 2); got {uv0.shape} and {uv1.shape}")
    return uv0, uv1


def track_lk(img0, img1, uv0, *, win_px: int = 21, levels: int = 3, uv1_guess=None, max_err: float | None = None,
             fb_max_px: float | None = None):
    """Lucas-Kanade tracks of ``uv0`` from ``img0`` to ``img1`` (003 §4.3.1): ``(uv1, ok)``.

    ``cv2.calcOpticalFlowPyrLK`` with a ``win_px`` window on ``levels`` pyramid levels;
    ``ok`` also drops tracks that leave the image. ``uv1_guess`` starts from a prediction.
    ``fb_max_px`` (ours): also track back and drop tracks that do not return within it.

    Parameters
    ----------
    img0, img1 : array_like, shape (H, W)
        Grey images tracked from and to.
    uv0 : array_like, shape (N, 2)
        Pixels in ``img0``.
    win_px : int
        Search window side [px] (default 21).
    levels : int
        Pyramid levels above the image (default 3).
    uv1_guess : array_like, shape (N, 2), optional
        Predicted pixels in ``img1`` to start from.
    max_err : float, optional
        Largest OpenCV tracking error of a kept track; ``None`` = no limit.
    fb_max_px : float, optional
        Largest forward-backward distance [px]; ``None`` = no backward check.

    Returns
    -------
    uv1 : ndarray, shape (N, 2)
        Tracked pixels in ``img1``.
    ok : ndarray of bool, shape (N,)
        Tracks found and kept.
    """
    import cv2

    img0 = v.as_image(img0, "img0")
    img1 = v.as_image(img1, "img1")
    uv0 = v.as_finite_array(uv0, "uv0", ndim=2)
    if uv0.shape[1] != 2:
        raise ValueError(f"`uv0` must have shape (N, 2); got {uv0.shape}")
    if uv0.shape[0] == 0:
        return np.zeros((0, 2)), np.zeros(0, bool)
    p0 = uv0.astype(np.float32).reshape(-1, 1, 2)
    flags = 0
    p1 = None
    if uv1_guess is not None:
        p1 = np.asarray(uv1_guess, np.float32).reshape(-1, 1, 2).copy()
        flags = cv2.OPTFLOW_USE_INITIAL_FLOW
    p1, st, err = cv2.calcOpticalFlowPyrLK(
        np.ascontiguousarray(img0, np.uint8), np.ascontiguousarray(img1, np.uint8), p0, p1,
        winSize=(win_px, win_px), maxLevel=levels - 1, flags=flags,
        criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01))
    uv1 = p1.reshape(-1, 2).astype(np.float64)
    h, w = img1.shape[:2]
    ok = (st.ravel() == 1) & np.all(np.isfinite(uv1), axis=1)
    ok &= (uv1[:, 0] >= 0) & (uv1[:, 0] <= w - 1) & (uv1[:, 1] >= 0) & (uv1[:, 1] <= h - 1)
    if max_err is not None:
        ok &= err.ravel() <= max_err
    if fb_max_px is not None:
        back, st2, _ = cv2.calcOpticalFlowPyrLK(
            np.ascontiguousarray(img1, np.uint8), np.ascontiguousarray(img0, np.uint8), p1, p0.copy(),
            winSize=(win_px, win_px), maxLevel=levels - 1, flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
            criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01))
        ok &= (st2.ravel() == 1) & (np.linalg.norm(back.reshape(-1, 2) - uv0, axis=1) <= fb_max_px)
    return uv1, ok


@dataclass(frozen=True)
class TwoViewPose:
    """Relative pose of view 1 in view 0: ``X_1 = R X_0 + t`` with ``|t| = 1`` (003 §4.3.1).

    ``inliers`` (N,) the RANSAC inliers; ``n_front`` points in front of both cameras for the
    chosen solution; ``normal`` the plane normal in view 0 (homography) or None; ``ok`` False
    when the input was degenerate (then ``R = I``, ``t = 0``); ``reason`` says why.

    Attributes
    ----------
    R : ndarray, shape (3, 3)
        Rotation of view 0 into view 1.
    t : ndarray, shape (3,)
        Unit translation (0 when not ``ok``).
    inliers : ndarray of bool, shape (N,)
        RANSAC inliers.
    n_front : int
        Points in front of both cameras for the chosen solution.
    normal : ndarray, shape (3,), or None
        Plane normal in view 0 (homography), else ``None``.
    ok : bool
        False when the input was degenerate.
    reason : str
        Why it failed (``""`` when ``ok``).
    """

    R: np.ndarray
    t: np.ndarray
    inliers: np.ndarray
    n_front: int
    normal: np.ndarray | None
    ok: bool
    reason: str = ""


def _fail(n, reason):
    return TwoViewPose(np.eye(3), np.zeros(3), np.zeros(n, bool), 0, None, False, reason)


def _norm3(x) -> float:
    """Length of a 3-vector in Python floats (``np.linalg.norm`` of a vector is a BLAS dot: its last bit varies)."""
    x = np.asarray(x, dtype=np.float64).ravel()
    return math.sqrt(float(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]))


def triangulate_two_view(K, R, t, uv0, uv1):
    """Points in view 0 from pixel pairs (linear DLT, ``cv2.triangulatePoints``): ``(X0 (N, 3), in_front)``.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    R : array_like, shape (3, 3)
        Rotation of view 0 into view 1.
    t : array_like, shape (3,)
        Translation of view 1 (``X_1 = R X_0 + t``).
    uv0, uv1 : array_like, shape (N, 2)
        Matched pixels in views 0 and 1.

    Returns
    -------
    X0 : ndarray, shape (N, 3)
        Points in the frame of view 0 (units of ``t``).
    in_front : ndarray of bool, shape (N,)
        Finite and in front of both cameras.
    """
    import cv2

    K = v.as_matrix(K, "K", (3, 3))
    P0 = np.einsum("ij,jk->ik", K, np.hstack([np.eye(3), np.zeros((3, 1))]))  # einsum: no BLAS, same bits anywhere
    P1 = np.einsum("ij,jk->ik", K, np.hstack([np.asarray(R, float), np.asarray(t, float).reshape(3, 1)]))
    if len(uv0) == 0:
        return np.zeros((0, 3)), np.zeros(0, bool)
    Xh = cv2.triangulatePoints(P0, P1, np.asarray(uv0, float).T, np.asarray(uv1, float).T)
    w = Xh[3]
    good = np.abs(w) > 1e-12
    X = np.where(good[:, None], (Xh[:3] / np.where(good, w, 1.0)).T, 0.0)
    z1 = np.einsum("nj,j->n", X, np.asarray(R, float)[2]) + float(np.asarray(t, float)[2])
    return X, good & (X[:, 2] > 0) & (z1 > 0)


def _hartley(uv):
    """Similarity ``T`` (3, 3) taking pixels to zero mean and RMS distance √2 (Hartley's normalisation)."""
    c = uv.mean(axis=0)
    d = uv - c
    rms = math.sqrt(float(np.mean(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])))
    s = math.sqrt(2.0) / max(rms, 1e-12)
    return np.array([[s, 0.0, -s * c[0]], [0.0, s, -s * c[1]], [0.0, 0.0, 1.0]])


def _transfer(Hn, x):
    """``(u, v, w)`` of ``π(Hn x)`` for points ``x (N, 2)``; ``w`` the homogeneous scale (for the Jacobian)."""
    uv = apply_homography(Hn, x)
    return uv[:, 0], uv[:, 1], Hn[2, 0] * x[:, 0] + Hn[2, 1] * x[:, 1] + Hn[2, 2]


def polish_homography(H, uv0, uv1, *, mantissa_bits: int = 14, max_iter: int = 50) -> np.ndarray:
    """The homography of inlier pairs, the same bits on every machine: snap OpenCV's ``H``, then re-fit it (ours).

    ``cv2.findHomography`` refines its RANSAC model by Levenberg-Marquardt on OpenCV's bundled
    OpenBLAS, and stops at a tolerance: its ``H`` differs between machines in the 7th digit, and the
    monocular map built on it (a tracker amplifies such differences into different inlier sets) came
    out different. Here ``H`` (in Hartley-normalised coordinates, ``h33 = 1``) is rounded to
    ``mantissa_bits`` significant bits (relative 6e-5 for 14: far coarser than the machine
    differences, so both machines round to the same start unless a value lies within 1e-8 of a
    rounding boundary), then refined by Levenberg-Marquardt on the one-sided transfer error
    ``|π(H x0) − x1|²`` written without BLAS/LAPACK (see :func:`slamlab.mono.align.solve_spd`),
    to convergence: the result depends on the inliers, not on the machine.

    Parameters
    ----------
    H : array_like, shape (3, 3)
        OpenCV's homography from view 0 to view 1.
    uv0, uv1 : array_like, shape (N, 2)
        Inlier pixel pairs.
    mantissa_bits : int
        Significant bits kept when snapping ``H`` (default 14).
    max_iter : int
        Levenberg-Marquardt steps at most (default 50).

    Returns
    -------
    H : ndarray, shape (3, 3)
        The re-fitted homography.
    """
    from .align import solve_spd

    uv0 = np.asarray(uv0, dtype=np.float64)
    uv1 = np.asarray(uv1, dtype=np.float64)
    T0, T1 = _hartley(uv0), _hartley(uv1)
    x0 = uv0 * T0[0, 0] + T0[:2, 2]
    x1 = uv1 * T1[0, 0] + T1[:2, 2]
    T0_inv = np.array([[1 / T0[0, 0], 0.0, -T0[0, 2] / T0[0, 0]], [0.0, 1 / T0[1, 1], -T0[1, 2] / T0[1, 1]],
                       [0.0, 0.0, 1.0]])
    Hn = np.einsum("ij,jk,kl->il", T1, np.asarray(H, dtype=np.float64), T0_inv)
    if not abs(Hn[2, 2]) > 1e-8:
        return np.asarray(H, dtype=np.float64)
    Hn = Hn / Hn[2, 2]
    m, e = np.frexp(Hn)
    Hn = np.ldexp(np.round(m * 2.0**mantissa_bits), e - mantissa_bits)
    Hn[2, 2] = 1.0

    def cost_of(Hc):
        u, v, _ = _transfer(Hc, x0)
        ru, rv = u - x1[:, 0], v - x1[:, 1]
        return ru, rv, float(np.sum(ru * ru + rv * rv))

    ru, rv, cost = cost_of(Hn)
    lam = 1e-3
    x, y = x0[:, 0], x0[:, 1]
    for _ in range(max_iter):
        u, v, w = _transfer(Hn, x0)
        zero = np.zeros_like(x)
        Ju = np.column_stack([x / w, y / w, 1 / w, zero, zero, zero, -u * x / w, -u * y / w])
        Jv = np.column_stack([zero, zero, zero, x / w, y / w, 1 / w, -v * x / w, -v * y / w])
        A = np.einsum("ni,nj->ij", Ju, Ju) + np.einsum("ni,nj->ij", Jv, Jv)
        g = np.einsum("ni,n->i", Ju, ru) + np.einsum("ni,n->i", Jv, rv)
        done = False
        while True:
            step = -solve_spd(A + lam * np.diag(np.diag(A)), g)
            if not np.all(np.isfinite(step)):
                done = True
                break
            H_new = Hn.copy()
            H_new.flat[:8] += step
            ru_n, rv_n, cost_n = cost_of(H_new)
            if cost_n <= cost:
                small = cost - cost_n <= 1e-15 * cost or float(np.sum(step * step)) < 1e-30
                Hn, ru, rv, cost = H_new, ru_n, rv_n, cost_n
                lam = max(lam / 10.0, 1e-12)
                done = small
                break
            lam *= 10.0
            if lam > 1e10:
                done = True
                break
        if done:
            break
    T1_inv = np.array([[1 / T1[0, 0], 0.0, -T1[0, 2] / T1[0, 0]], [0.0, 1 / T1[1, 1], -T1[1, 2] / T1[1, 1]],
                       [0.0, 0.0, 1.0]])
    return np.einsum("ij,jk,kl->il", T1_inv, Hn, T0)


def relative_pose_homography(uv0, uv1, K, *, ransac_px: float = 2.0, min_points: int = 8) -> TwoViewPose:
    """Pose from a RANSAC homography and its decomposition (003 §4.3.1).

    ``cv2.findHomography(RANSAC)`` then ``cv2.decomposeHomographyMat`` (up to four
    solutions); we keep the one with most inliers triangulated in front of both views and,
    on a tie, the plane normal most facing view 0 (our choice). ``t`` is normalised.

    Parameters
    ----------
    uv0, uv1 : array_like, shape (N, 2)
        Tracked pixel pairs in views 0 and 1.
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    ransac_px : float
        RANSAC reprojection threshold [px] (default 2).
    min_points : int
        Fewest pairs (at least 4) before failing with ``"too_few_points"`` (default 8).

    Returns
    -------
    TwoViewPose
        ``R``, ``t``, ``inliers``, ``normal``, ``ok``, ``reason``.
    """
    import cv2

    uv0, uv1 = _check_uv_pair(uv0, uv1)
    K = v.as_matrix(K, "K", (3, 3))
    n = uv0.shape[0]
    if n < max(4, min_points):
        return _fail(n, "too_few_points")
    cv2.setRNGSeed(0)  # OpenCV's RANSAC seeds itself today; this keeps it so if a release draws from the global RNG
    H, mask = cv2.findHomography(uv0, uv1, cv2.RANSAC, ransac_px)
    if H is None or not np.all(np.isfinite(H)) or abs(np.linalg.det(H)) < 1e-12:
        return _fail(n, "degenerate_homography")
    inl = mask.ravel().astype(bool)
    if inl.sum() < min_points:
        return _fail(n, "degenerate_homography")
    H = polish_homography(H, uv0[inl], uv1[inl])
    _, Rs, ts, normals = cv2.decomposeHomographyMat(H, K)
    best, best_key = None, None
    for R, tt, nn in zip(Rs, ts, normals, strict=True):
        tt = tt.ravel()
        tt_norm = _norm3(tt)
        if tt_norm < 1e-9:  # a pure rotation: no translation to recover
            continue
        tn = tt / tt_norm
        _, front = triangulate_two_view(K, R, tn, uv0[inl], uv1[inl])
        key = (int(front.sum()), float(-nn.ravel()[2]))
        if best_key is None or key > best_key:
            best, best_key = (R, tn, nn.ravel()), key
    if best is None:
        return _fail(n, "no_parallax")
    R, tn, nn = best
    return TwoViewPose(R, tn, inl, best_key[0], nn, best_key[0] >= min_points,
                       "" if best_key[0] >= min_points else "cheirality")


def relative_pose_essential(uv0, uv1, K, *, ransac_px: float = 1.0, prob: float = 0.999,
                            min_points: int = 8) -> TwoViewPose:
    """Pose by the 5-point algorithm: ``cv2.findEssentialMat`` (RANSAC) + ``cv2.recoverPose`` (003 §4.3.1).

    Parameters
    ----------
    uv0, uv1 : array_like, shape (N, 2)
        Tracked pixel pairs in views 0 and 1.
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    ransac_px : float
        RANSAC threshold [px] (default 1).
    prob : float
        RANSAC confidence (default 0.999).
    min_points : int
        Fewest pairs (at least 5) before failing with ``"too_few_points"`` (default 8).

    Returns
    -------
    TwoViewPose
        ``R``, ``t``, ``inliers``, ``n_front``, ``ok`` (``normal`` is ``None``).
    """
    import cv2

    uv0, uv1 = _check_uv_pair(uv0, uv1)
    K = v.as_matrix(K, "K", (3, 3))
    n = uv0.shape[0]
    if n < max(5, min_points):
        return _fail(n, "too_few_points")
    cv2.setRNGSeed(0)  # as in relative_pose_homography
    E, mask = cv2.findEssentialMat(uv0, uv1, K, method=cv2.RANSAC, prob=prob, threshold=ransac_px)
    if E is None or E.shape != (3, 3):
        return _fail(n, "degenerate_essential")
    n_front, R, t, mask2 = cv2.recoverPose(E, uv0, uv1, K, mask=mask.copy())
    inl = mask2.ravel().astype(bool)
    t = t.ravel()
    if n_front < min_points or not np.all(np.isfinite(t)):
        return _fail(n, "cheirality")
    return TwoViewPose(R, t / _norm3(t), inl, int(n_front), None, True)


@dataclass
class InitResult:
    """Output of a finished initialisation (003 §4.3.1).

    ``pose`` the relative pose of the second keyframe, ``uv0``/``uv1`` (M, 2) the inlier
    tracks, ``X0`` (M, 3) their points in the first keyframe's frame scaled to a median
    depth of ``median_depth_m`` (SVO's convention; the scale of a monocular map is free),
    ``frame0``/``frame1`` the indices of the two keyframes.

    Attributes
    ----------
    pose : TwoViewPose
        Relative pose of the second keyframe.
    uv0, uv1 : ndarray, shape (M, 2)
        Inlier tracks in the two keyframes.
    X0 : ndarray, shape (M, 3)
        Their points in the first keyframe's frame, scaled to a median depth of ``median_depth_m``.
    frame0, frame1 : int
        Indices of the two keyframes.
    scale : float
        Factor applied to the triangulated points.
    """

    pose: TwoViewPose
    uv0: np.ndarray
    uv1: np.ndarray
    X0: np.ndarray
    frame0: int
    frame1: int
    scale: float


@dataclass
class Initialiser:
    """The automatic two-keyframe initialiser of 003 §4.3.1 as a small state machine.

    Feed frames to :meth:`add_frame`; it returns a status in :data:`INIT_STATUSES` and, once
    ``"done"``, :attr:`result` holds the map. ``counts`` tallies every status.

    Attributes
    ----------
    K : ndarray, shape (3, 3)
        Intrinsic matrix.
    detect : callable
        ``detect(image) -> (N, 2)`` corners.
    min_corners : int
        Fewest corners of a first frame (default 50).
    min_disparity_px : float
        Mean track length [px] before a pose is tried (default 15).
    min_tracked_ratio : float
        Share of ``min_corners`` that must survive tracking, else restart (default 0.5).
    method : str
        ``"homography"`` (003), ``"essential"`` or ``"auto"`` (default ``"homography"``).
    ransac_px : float
        RANSAC threshold [px] (default 2).
    min_parallax_deg : float
        Median triangulation angle needed [deg] (default 1).
    min_point_parallax_deg : float
        Triangulation angle a point of the first map needs [deg] (default 0).
    plane_share : float
        ``"auto"``: the homography when its inliers are at least this share of the 5-point's (default 0.9).
    median_depth_m : float
        Median depth the first map is scaled to (default 1).
    lk_win_px : int
        Lucas-Kanade window [px] (default 21).
    fb_max_px : float
        Forward-backward tolerance of the tracks [px] (default 1).
    ref_image, ref_uv, cur_uv : ndarray or None
        State: first keyframe, its corners and their current tracks.
    ref_index, frame_index : int
        State: index of the first keyframe and of the last frame.
    result : InitResult or None
        The map once the status is ``"done"``.
    counts : dict
        Status → number of frames.
    """

    K: np.ndarray
    detect: object  # callable image -> (N, 2) corners
    min_corners: int = 50
    min_disparity_px: float = 15.0
    min_tracked_ratio: float = 0.5
    method: str = "homography"
    ransac_px: float = 2.0
    min_parallax_deg: float = 1.0
    min_point_parallax_deg: float = 0.0  # ours: points of the first map need at least this triangulation angle
    plane_share: float = 0.9  # "auto": the homography when its inliers are at least this share of the 5-point's
    median_depth_m: float = 1.0
    lk_win_px: int = 21
    fb_max_px: float = 1.0
    ref_image: np.ndarray | None = None
    ref_uv: np.ndarray | None = None
    cur_uv: np.ndarray | None = None
    ref_index: int = -1
    frame_index: int = -1
    result: InitResult | None = None
    counts: dict = field(default_factory=dict)

    def __post_init__(self):
        self.K = v.as_matrix(self.K, "K", (3, 3))
        v.check_int(self.min_corners, "min_corners", minimum=5)
        v.check_positive(self.min_disparity_px, "min_disparity_px", allow_zero=True)
        v.check_probability(self.min_tracked_ratio, "min_tracked_ratio")
        v.check_choice(self.method, "method", ("homography", "essential", "auto"))
        v.check_probability(self.plane_share, "plane_share")
        v.check_positive(self.min_parallax_deg, "min_parallax_deg", allow_zero=True)
        v.check_positive(self.min_point_parallax_deg, "min_point_parallax_deg", allow_zero=True)

    def _count(self, status):
        self.counts[status] = self.counts.get(status, 0) + 1
        return status

    def reset(self, image, index):
        """Start over with ``image`` as the first keyframe (003 §4.3.1); return the status.

        Parameters
        ----------
        image : ndarray, shape (H, W)
            Grey image.
        index : int
            Its frame index.

        Returns
        -------
        status : str
            ``"first_frame"`` or ``"too_few_corners"``.
        """
        uv = np.asarray(self.detect(image), float).reshape(-1, 2)
        if uv.shape[0] < self.min_corners:
            self.ref_image = None
            return self._count("too_few_corners")
        self.ref_image, self.ref_uv, self.cur_uv, self.ref_index = image, uv, uv.copy(), index
        self._prev = image
        return self._count("first_frame")

    def add_frame(self, image) -> str:
        """Process one grey image; return the status (003 §4.3.1).

        Parameters
        ----------
        image : array_like, shape (H, W)
            Next grey image.

        Returns
        -------
        status : str
            One of ``INIT_STATUSES``; ``"done"`` sets :attr:`result`.
        """
        image = v.as_image(image, "image")
        self.frame_index += 1
        if self.ref_image is None:
            return self.reset(image, self.frame_index)
        uv1, ok = track_lk(self._prev, image, self.cur_uv, win_px=self.lk_win_px, fb_max_px=self.fb_max_px)
        self.ref_uv, self.cur_uv = self.ref_uv[ok], uv1[ok]
        self._prev = image
        if self.cur_uv.shape[0] < max(self.min_corners * self.min_tracked_ratio, 8):
            self.reset(image, self.frame_index)
            return self._count("restart")
        disp = float(np.mean(np.linalg.norm(self.cur_uv - self.ref_uv, axis=1)))
        if disp < self.min_disparity_px:
            return self._count("tracking")
        if self.method == "homography":
            pose = relative_pose_homography(self.ref_uv, self.cur_uv, self.K, ransac_px=self.ransac_px)
        elif self.method == "essential":
            pose = relative_pose_essential(self.ref_uv, self.cur_uv, self.K, ransac_px=self.ransac_px)
        else:  # "auto" (ours): 003's homography when a dominant plane explains the matches, else the 5-point
            pose_h = relative_pose_homography(self.ref_uv, self.cur_uv, self.K, ransac_px=self.ransac_px)
            pose_e = relative_pose_essential(self.ref_uv, self.cur_uv, self.K, ransac_px=self.ransac_px)
            n_h = int(np.count_nonzero(pose_h.inliers)) if pose_h.ok else 0
            n_e = int(np.count_nonzero(pose_e.inliers)) if pose_e.ok else 0
            pose = pose_h if pose_h.ok and n_h >= self.plane_share * n_e else pose_e
            self.counts["auto_homography" if pose is pose_h else "auto_essential"] = \
                self.counts.get("auto_homography" if pose is pose_h else "auto_essential", 0) + 1
        if not pose.ok:
            status = "degenerate_homography" if "homography" in pose.reason or pose.reason == "cheirality" else "no_parallax"
            self.reset(image, self.frame_index)
            self.counts[status] = self.counts.get(status, 0) + 1
            return status
        u0, u1 = self.ref_uv[pose.inliers], self.cur_uv[pose.inliers]
        X0, front = triangulate_two_view(self.K, pose.R, pose.t, u0, u1)
        c1 = -np.einsum("ji,j->i", pose.R, pose.t)
        r0 = X0 / np.maximum(np.linalg.norm(X0, axis=1, keepdims=True), 1e-12)
        r1 = X0 - c1
        r1 /= np.maximum(np.linalg.norm(r1, axis=1, keepdims=True), 1e-12)
        parallax = np.degrees(np.arccos(np.clip(np.sum(r0 * r1, axis=1), -1, 1)))
        if front.sum() < 8 or np.median(parallax[front]) < self.min_parallax_deg:
            # pure rotation or too little baseline: 003 §5.3 — no usable depth yet; keep the first
            # frame and wait for more baseline (ours; 003 restarts only when the tracks are lost)
            self.counts["no_parallax"] = self.counts.get("no_parallax", 0) + 1
            return "no_parallax"
        front &= parallax >= self.min_point_parallax_deg  # ours: a point with too little parallax has no depth
        if front.sum() < 8:
            self.reset(image, self.frame_index)
            self.counts["no_parallax"] = self.counts.get("no_parallax", 0) + 1
            return "no_parallax"
        scale = self.median_depth_m / float(np.median(X0[front, 2]))
        self.result = InitResult(pose, u0[front], u1[front], X0[front] * scale,
                                 self.ref_index, self.frame_index, scale)
        return self._count("done")
