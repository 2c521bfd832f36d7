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

from dataclasses import dataclass, field

import numpy as np

from .._validate import (
    as_finite_array,
    as_image,
    as_matrix,
    check_choice,
    check_int,
    check_positive,
    check_probability,
)
from .twoview import (
    TwoViewPose,
    polish_homography,
    relative_pose_essential,
    relative_pose_homography,
    triangulate_two_view,
)

__all__ = [
    "INIT_STATUSES",
    "InitResult",
    "Initialiser",
    "TwoViewPose",
    "polish_homography",
    "relative_pose_essential",
    "relative_pose_homography",
    "track_lk",
    "triangulate_two_view",
]

#: what :meth:`Initialiser.add_frame` can report
INIT_STATUSES = ("first_frame", "too_few_corners", "tracking", "restart", "no_parallax",
                 "degenerate_homography", "done")


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

    img0 = as_image(img0, "img0")
    img1 = as_image(img1, "img1")
    uv0 = as_finite_array(uv0, "uv0", ndim=2)
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
    plane_share_of : str
        ``"auto"``: the 5-point method's count compared: ``"ransac"`` its RANSAC inliers (default, ours), or
        ``"front"`` those ``cv2.recoverPose`` keeps (in front, nearer than 50 baselines: on a road, the far
        points drop out and the road's homography wins with a wrong pose).
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
    plane_share_of: str = "ransac"  # "auto": the 5-point's RANSAC inliers ("ransac") or those in front ("front")
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
        self.K = as_matrix(self.K, "K", (3, 3))
        check_int(self.min_corners, "min_corners", minimum=5)
        check_positive(self.min_disparity_px, "min_disparity_px", allow_zero=True)
        check_probability(self.min_tracked_ratio, "min_tracked_ratio")
        check_choice(self.method, "method", ("homography", "essential", "auto"))
        check_probability(self.plane_share, "plane_share")
        check_choice(self.plane_share_of, "plane_share_of", ("ransac", "front"))
        check_positive(self.min_parallax_deg, "min_parallax_deg", allow_zero=True)
        check_positive(self.min_point_parallax_deg, "min_point_parallax_deg", allow_zero=True)

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
        image = as_image(image, "image")
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
        else:  # "auto" (ours): the homography when a dominant plane explains the matches, else the 5-point
            pose_h = relative_pose_homography(self.ref_uv, self.cur_uv, self.K, ransac_px=self.ransac_px)
            pose_e = relative_pose_essential(self.ref_uv, self.cur_uv, self.K, ransac_px=self.ransac_px)
            n_h = int(np.count_nonzero(pose_h.inliers)) if pose_h.ok else 0
            # the 5-point's RANSAC inliers, not only those recoverPose keeps (ours: see `plane_share_of`)
            n_e = (pose_e.n_ransac if self.plane_share_of == "ransac" else int(np.count_nonzero(pose_e.inliers))) \
                if pose_e.ok else 0
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
