"""The stereo pipeline's settings: one frozen :class:`StereoParams` (000 §3.3-3.6), and the renderer's.

Every knob of :class:`~slamlab.stereo.slam.StereoSLAM` and of the stage functions is a
field here, marked with its source section or "ours", and checked once, when the object
is made (:meth:`StereoParams.check`). ``StereoSLAM(rig, params=...)``, the stage
functions and every ``run_*`` take ``params=`` plus keyword overrides; the defaults
live here only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._params import Params, param
from .._validate import check_choice, check_int, check_positive, check_probability, check_real

__all__ = ["STEREO_DETECTORS", "RenderParams", "StereoParams"]

#: detectors the pipeline accepts (names of :func:`slamlab.features.detect`); ORB's descriptors
#: are binary (Hamming), so its landmarks go to an exact store
STEREO_DETECTORS = ("surf", "sift", "orb")
POLICIES = ("oldest", "all")
MAP_SEARCHES = ("global", "window")
DEPTH_SOURCES = ("measured", "map", "true")  # "true": an ablation oracle (run_scale_ablation only)


def _fraction(value, name):
    """A share in [0, 1]."""
    value = check_positive(value, name, allow_zero=True)
    if value > 1:
        raise ValueError(f"`{name}` must be in [0, 1]; got {value}")
    return value


def _optional_positive(value, name, allow_zero=False):
    return None if value is None else check_positive(value, name, allow_zero=allow_zero)


@dataclass(frozen=True)
class StereoParams(Params):
    """Settings of the stereo SLAM pipeline (000 §3.3-3.6); ``print(p.table())`` lists them with sources.

    Attributes
    ----------
    detector : str
        000 §3.3: SURF (ours, the features chapter's; 'orb' is the fast one)
    n_features : int
        000 §3.3: about 2000 points per 768x576 image
    orb_fast_threshold : int
        ours: ORB's FAST threshold (OpenCV: 20); 12 finds 2000 points on the arena
    orb_levels : int
        ours: ORB's pyramid levels, 1.2x apart (OpenCV's 8; KITTI: 1, see run_kitti)
    channel_order : str
        ours: channel order of colour images ('bgr' for cv2.imread)
    parallel_detect : bool
        ours: the two images in two threads (same result)
    ratio : float
        ours: Lowe's ratio for left-right matches (000 does not say how it matched)
    epi_tol_px : float
        ours: distance from the epipolar line
    min_depth_m : float
        ours: nearest depth a stereo point may have, m
    max_depth_m : float
        ours: the 6x8 m arena (KITTI: 40, see run_kitti)
    pixel_std : float
        ours: pixel error behind a stereo point's covariance
    pixel_std_estimate : bool
        ours: raise pixel_std to the keypoint noise estimated online from the pose refinement's disparity residuals (per frame, given the landmarks' covariances; smoothed; pixel_std its floor; needs pose_refine; issue 25)
    pixel_std_smoothing : float
        ours: weight of a frame's noise estimate in the running one
    disparity_offset_px : float
        ours: added to every measured disparity, px (a rig whose right principal point is off measures every disparity too small or too large; KITTI 01: about 0.8 px)
    disparity_offset_estimate : bool
        ours: add to every disparity, beside disparity_offset_px, an offset estimated online from the motion of the points two located frames share (:mod:`slamlab.stereo.disparity_offset`; needs a rectified rig)
    subpixel_stereo : bool or None
        ours: refine each match's disparity by a patch search along the row (rectified rigs); None: for ORB only, whose pyramid keypoints are off by up to 1.2^L / 2 px
    subpixel_half_px : int
        ours: half size of the patch of the disparity refinement (11x11 px)
    subpixel_search_px : int
        ours: columns searched on each side of the matched right keypoint
    map_ratio : float
        ours: ratio rule against the landmark store
    same_point_m : float or None
        ours: two nearest landmarks this close count as one for the ratio rule (0: off; None: 0.03 m with the window search, off with the global one)
    duplicate_gap_m : float or None
        ours: an unmatched point whose nearest landmark by descriptor lies this close to it (after the pose) is that landmark again, not a new one (None: off)
    map_search : str or None
        ours: 'global' (000: every stored landmark by descriptor) or 'window' (a pose from the last frame's landmarks, then the landmarks it projects near each point); None: 'window' for ORB, 'global' otherwise
    window_px : float
        ours: radius of the window search around each keypoint, px
    window_max_hamming : int
        ours: largest Hamming distance (of 256 bits) a window match may have; binary only
    window_min_share : float
        ours: fewer window matches than this share of the points: search globally (a first pose from repeated texture is confirmed by few windows)
    view_margin_deg : float or None
        ours: match only landmarks in view (None: the whole map, as 000)
    reobserve_depth_factor : float
        ours: a point up to this times max_depth_m deep may match a landmark (pose, filter) but becomes a new one only within max_depth_m (1: one cut; issue 25)
    view_depth_factor : float
        ours: the view gate keeps landmarks up to this times max_depth_m away
    base_seen_times : int
        000 §3.4: BaseSeenTimes = 3
    max_non_base_time : int
        000 §3.4: MaxNonBaseTime = 7
    policy : str
        000 §3.5: the oldest landmarks ('all': every RANSAC inlier)
    ransac_iters : int
        000 §3.5: about 200 hypotheses
    threshold_m : float
        ours: RANSAC inlier distance at depth_ref_m
    depth_ref_m : float
        ours: the threshold grows as (depth / depth_ref_m)^2 beyond it
    min_inliers : int
        ours: RANSAC inliers needed for a valid pose
    weight_depth : str
        ours: depth behind a match's RANSAC threshold and weight: 'measured' (this frame's point) or 'map' (the landmark seen from the last pose; issue 25); 'true': the simulator's true depth, an ablation oracle (needs ``StereoSLAM.truth_hook``)
    n_oldest : int
        ours: 000 §3.5 says 'sufficiently large'
    oldest_fraction : float
        ours: the oldest set holds at least this share of the candidates
    keep_fraction : float
        ours: share of the oldest set that must agree
    loose_factor : float
        ours: candidates within this many thresholds of the consensus pose
    still_fraction : float
        ours: share of the candidates the oldest set's pose must still explain
    max_std_factor : float or None
        ours: grow the oldest set until the pose is this well determined
    max_correction_rad : float or None
        ours: bound on the oldest set's correction (None: none)
    max_correction_m : float or None
        ours: bound on the oldest set's correction (None: none)
    max_rot_std_rad : float or None
        ours: reject a pose whose rotation std exceeds this (None: off)
    pose_refine : str
        ours: after RANSAC, 'none' or 'reprojection': Gauss-Newton on the inliers' stereo reprojection error with one pixel noise (motion-only bundle adjustment; issue 25)
    refine_iters : int
        ours: most Gauss-Newton steps of pose_refine
    refine_huber_px : float
        ours: Huber threshold of pose_refine on a point's pixel residual norm
    refine_min_seen : int
        ours: pose_refine uses the inliers whose landmark was seen at least this often (a landmark seen once was selected by the depth cut on its own noisy depth; 1: all)
    drop_first_sighting : bool
        ours: a landmark's second sighting replaces its first triangulation (which the depth cut selected on its own noisy depth) instead of being fused with it (issue 25)
    degenerate_pose : str
        ours: pose of a frame that gives none: 'constant_velocity' (the last frame's motion once more: a turn in place goes on) or 'last' (keep the last pose; on the ~80 m run's turns in place its heading error reaches 29.5 deg with ORB, 44.7 deg with SURF)
    state_var : float
        000 §3.6: static landmarks; ours: a small process variance, m^2
    pose_std_m : float
        ours: pose uncertainty added to an observation
    pose_std_rad : float
        ours: pose uncertainty added to an observation
    update_gate : float or None
        ours: chi^2_3 at 99.9 % (None: always update)
    update_cov_depth : str
        ours: depth behind an observation's covariance in the landmark filter: 'measured' or 'map' (the landmark seen from the new pose; issue 25); 'true': the oracle as for ``weight_depth``
    filter_space : str
        ours: the landmark filter's update in 'xyz' (000 §3.6) or in the stereo 'pixels' (u_l, v_l, u_r) of the current camera, one pixel noise for all (rectified rigs; issue 25)
    init_cov_depth : str
        ours: depth behind a new landmark's first covariance in the filter: 'measured' or 'true' (the oracle as for ``weight_depth``; issue 25)

    Examples
    --------
    >>> p = StereoParams(detector="orb")
    >>> p.detector, p.ransac_iters, StereoParams.sources()["ransac_iters"]
    ('orb', 200, '000 §3.5: about 200 hypotheses')
    >>> StereoParams(ratio=1.5)
    Traceback (most recent call last):
    ...
    ValueError: `ratio` must be in (0, 1); got 1.5
    """

    # -- detection (000 §3.3) ----------------------------------------------------------------------
    detector: str = param("surf", "000 §3.3: SURF (ours, the features chapter's; 'orb' is the fast one)")
    n_features: int = param(2000, "000 §3.3: about 2000 points per 768x576 image")
    orb_fast_threshold: int = param(12, "ours: ORB's FAST threshold (OpenCV: 20); 12 finds 2000 points on the arena")
    orb_levels: int = param(8, "ours: ORB's pyramid levels, 1.2x apart (OpenCV's 8; KITTI: 1, see run_kitti)")
    channel_order: str = param("rgb", "ours: channel order of colour images ('bgr' for cv2.imread)")
    parallel_detect: bool = param(True, "ours: the two images in two threads (same result)")
    # -- stereo matching and triangulation (000 §3.3) ------------------------------------------------
    ratio: float = param(0.8, "ours: Lowe's ratio for left-right matches (000 does not say how it matched)")
    epi_tol_px: float = param(2.0, "ours: distance from the epipolar line")
    min_depth_m: float = param(0.3, "ours")
    max_depth_m: float = param(10.0, "ours: the 6x8 m arena (KITTI: 40, see run_kitti)")
    pixel_std: float = param(0.5, "ours: pixel error behind a stereo point's covariance")
    pixel_std_estimate: bool = param(False, "ours: raise pixel_std to the keypoint noise estimated online from the "
                                            "pose refinement's disparity residuals (per frame, given the landmarks' "
                                            "covariances; smoothed; pixel_std its floor; needs pose_refine; issue 25)")
    pixel_std_smoothing: float = param(0.2, "ours: weight of a frame's noise estimate in the running one")
    disparity_offset_px: float = param(0.0, "ours: added to every measured disparity, px (a rig whose right principal "
                                            "point is off measures every disparity too small or too large; KITTI 01: "
                                            "about 0.8 px)")
    disparity_offset_estimate: bool = param(False, "ours: add to every disparity, beside disparity_offset_px, an offset "
                                                   "estimated online from the motion of the points two located frames "
                                                   "share (:mod:`slamlab.stereo.disparity_offset`; needs a rectified rig)")
    subpixel_stereo: bool | None = param(None, "ours: refine each match's disparity by a patch search along the row "
                                               "(rectified rigs); None: for ORB only, whose pyramid keypoints are off by "
                                               "up to 1.2^L / 2 px")
    subpixel_half_px: int = param(5, "ours: half size of the patch of the disparity refinement (11x11 px)")
    subpixel_search_px: int = param(4, "ours: columns searched on each side of the matched right keypoint")
    # -- matching to the map (000 §3.4) ----------------------------------------------------------------
    map_ratio: float = param(0.8, "ours: ratio rule against the landmark store")
    same_point_m: float | None = param(None, "ours: two nearest landmarks this close count as one for the ratio rule "
                                             "(0: off; None: 0.03 m with the window search, off with the global one)")
    duplicate_gap_m: float | None = param(None, "ours: an unmatched point whose nearest landmark by descriptor lies this "
                                                "close to it (after the pose) is that landmark again, not a new one (None: off)")
    map_search: str | None = param(None, "ours: 'global' (000: every stored landmark by descriptor) or 'window' (a pose "
                                         "from the last frame's landmarks, then the landmarks it projects near each "
                                         "point); None: 'window' for ORB, 'global' otherwise")
    window_px: float = param(15.0, "ours: radius of the window search around each keypoint, px")
    window_max_hamming: int = param(64, "ours: largest Hamming distance (of 256 bits) a window match may have; binary only")
    window_min_share: float = param(0.1, "ours: fewer window matches than this share of the points: search globally "
                                         "(a first pose from repeated texture is confirmed by few windows)")
    view_margin_deg: float | None = param(None, "ours: match only landmarks in view (None: the whole map, as 000)")
    reobserve_depth_factor: float = param(1.0, "ours: a point up to this times max_depth_m deep may match a landmark "
                                                 "(pose, filter) but becomes a new one only within max_depth_m (1: one "
                                                 "cut; issue 25)")
    view_depth_factor: float = param(1.5, "ours: the view gate keeps landmarks up to this times max_depth_m away")
    base_seen_times: int = param(3, "000 §3.4: BaseSeenTimes = 3")
    max_non_base_time: int = param(7, "000 §3.4: MaxNonBaseTime = 7")
    # -- pose (000 §3.5) ------------------------------------------------------------------------------
    policy: str = param("oldest", "000 §3.5: the oldest landmarks ('all': every RANSAC inlier)")
    ransac_iters: int = param(200, "000 §3.5: about 200 hypotheses")
    threshold_m: float = param(0.1, "ours: RANSAC inlier distance at depth_ref_m")
    depth_ref_m: float = param(3.0, "ours: the threshold grows as (depth / depth_ref_m)^2 beyond it")
    min_inliers: int = param(10, "ours")
    weight_depth: str = param("measured", "ours: depth behind a match's RANSAC threshold and weight: 'm"
                                          "easured' (this frame's point) or 'map' (the landmark seen from the last pose; issue 25)")
    n_oldest: int = param(40, "ours: 000 §3.5 says 'sufficiently large'")
    oldest_fraction: float = param(0.5, "ours")
    keep_fraction: float = param(0.5, "ours: share of the oldest set that must agree")
    loose_factor: float = param(4.0, "ours: candidates within this many thresholds of the consensus pose")
    still_fraction: float = param(0.8, "ours: share of the candidates the oldest set's pose must still explain")
    max_std_factor: float | None = param(2.0, "ours: grow the oldest set until the pose is this well determined")
    max_correction_rad: float | None = param(None, "ours: bound on the oldest set's correction (None: none)")
    max_correction_m: float | None = param(None, "ours: bound on the oldest set's correction (None: none)")
    max_rot_std_rad: float | None = param(0.01, "ours: reject a pose whose rotation std exceeds this (None: off)")
    pose_refine: str = param("none", "ours: after RANSAC, 'none' or 'reprojection': Gauss-Newton on the inliers' "
                                     "stereo reprojection error with one pixel noise (motion-only bundle adjustment; "
                                     "issue 25)")
    refine_iters: int = param(5, "ours: most Gauss-Newton steps of pose_refine")
    refine_huber_px: float = param(2.0, "ours: Huber threshold of pose_refine on a point's pixel residual norm")
    refine_min_seen: int = param(1, "ours: pose_refine uses the inliers whose landmark was seen at least this often "
                                    "(a landmark seen once was selected by the depth cut on its own noisy depth; 1: all)")
    drop_first_sighting: bool = param(False, "ours: a landmark's second sighting replaces its first triangulation "
                                             "(which the depth cut selected on its own noisy depth) instead of being "
                                             "fused with it (issue 25)")
    degenerate_pose: str = param("constant_velocity", "ours: pose of a frame that gives none: 'constant_velocity' "
                                                      "(the last frame's motion once more: a turn in place goes on) or "
                                                      "'last' (keep the last pose; on the ~80 m run's turns in place its "
                                                      "heading error reaches 29.5 deg with ORB, 44.7 deg with SURF)")
    # -- landmark filter (000 §3.6) --------------------------------------------------------------------
    state_var: float = param(1e-6, "000 §3.6: static landmarks; ours: a small process variance, m^2")
    pose_std_m: float = param(0.02, "ours: pose uncertainty added to an observation")
    pose_std_rad: float = param(float(np.deg2rad(0.5)), "ours: pose uncertainty added to an observation")
    update_gate: float | None = param(16.27, "ours: chi^2_3 at 99.9 % (None: always update)")
    update_cov_depth: str = param("measured", "ours: depth behind an observation's covariance in the landma"
                                              "rk filter: 'measured' or 'map' (the landmark seen from the new pose; issue 25)")
    filter_space: str = param("xyz", "ours: the landmark filter's update in 'xyz' (000 §3.6) or in the stereo 'pixels' "
                                     "(u_l, v_l, u_r) of the current camera, one pixel noise for all (rectified rigs; "
                                     "issue 25)")
    init_cov_depth: str = param("measured", "ours: depth behind a new landmark's first covariance: 'measured' ('true': "
                                            "an ablation oracle; issue 25)")

    def check(self) -> None:
        check_choice(self.detector, "detector", STEREO_DETECTORS)
        check_int(self.n_features, "n_features", minimum=10)
        check_int(self.orb_fast_threshold, "orb_fast_threshold", minimum=0, maximum=255)
        check_int(self.orb_levels, "orb_levels", minimum=1)
        check_choice(self.channel_order, "channel_order", ("rgb", "bgr"))
        if not isinstance(self.parallel_detect, bool):
            raise TypeError(f"`parallel_detect` must be a bool; got {type(self.parallel_detect).__name__}")
        check_probability(self.ratio, "ratio")
        check_positive(self.epi_tol_px, "epi_tol_px")
        check_positive(self.min_depth_m, "min_depth_m")
        if check_positive(self.max_depth_m, "max_depth_m") <= self.min_depth_m:
            raise ValueError(f"`max_depth_m` must exceed `min_depth_m` = {self.min_depth_m}; got {self.max_depth_m}")
        check_positive(self.pixel_std, "pixel_std")
        if not isinstance(self.pixel_std_estimate, bool):
            raise TypeError(f"`pixel_std_estimate` must be a bool; got {type(self.pixel_std_estimate).__name__}")
        if not 0 < check_positive(self.pixel_std_smoothing, "pixel_std_smoothing") <= 1:
            raise ValueError(f"`pixel_std_smoothing` must be in (0, 1]; got {self.pixel_std_smoothing}")
        check_real(self.disparity_offset_px, "disparity_offset_px")
        if not isinstance(self.disparity_offset_estimate, bool):
            raise TypeError(f"`disparity_offset_estimate` must be a bool; got {type(self.disparity_offset_estimate).__name__}")
        if self.pixel_std_estimate and self.pose_refine != "reprojection":
            raise ValueError("`pixel_std_estimate` needs `pose_refine='reprojection'` (its residuals give the estimate)")
        if check_positive(self.reobserve_depth_factor, "reobserve_depth_factor") < 1:
            raise ValueError(f"`reobserve_depth_factor` must be at least 1; got {self.reobserve_depth_factor}")
        if self.subpixel_stereo is not None and not isinstance(self.subpixel_stereo, bool):
            raise TypeError(f"`subpixel_stereo` must be a bool or None; got {type(self.subpixel_stereo).__name__}")
        check_int(self.subpixel_half_px, "subpixel_half_px", minimum=1)
        check_int(self.subpixel_search_px, "subpixel_search_px", minimum=1)
        check_probability(self.map_ratio, "map_ratio")
        _optional_positive(self.same_point_m, "same_point_m", allow_zero=True)
        _optional_positive(self.duplicate_gap_m, "duplicate_gap_m")
        if self.map_search is not None:
            check_choice(self.map_search, "map_search", MAP_SEARCHES)
        check_positive(self.window_px, "window_px")
        check_int(self.window_max_hamming, "window_max_hamming", minimum=0)
        _fraction(self.window_min_share, "window_min_share")
        _optional_positive(self.view_margin_deg, "view_margin_deg", allow_zero=True)
        check_positive(self.view_depth_factor, "view_depth_factor")
        check_int(self.base_seen_times, "base_seen_times", minimum=1)
        check_int(self.max_non_base_time, "max_non_base_time", minimum=1)
        check_choice(self.policy, "policy", POLICIES)
        check_int(self.ransac_iters, "ransac_iters", minimum=1)
        check_positive(self.threshold_m, "threshold_m")
        check_positive(self.depth_ref_m, "depth_ref_m")
        check_int(self.min_inliers, "min_inliers", minimum=3)
        check_choice(self.weight_depth, "weight_depth", DEPTH_SOURCES)
        check_choice(self.update_cov_depth, "update_cov_depth", DEPTH_SOURCES)
        check_choice(self.init_cov_depth, "init_cov_depth", ("measured", "true"))
        check_choice(self.filter_space, "filter_space", ("xyz", "pixels"))
        check_choice(self.pose_refine, "pose_refine", ("none", "reprojection"))
        check_int(self.refine_iters, "refine_iters", minimum=1)
        check_positive(self.refine_huber_px, "refine_huber_px")
        check_int(self.refine_min_seen, "refine_min_seen", minimum=1)
        if not isinstance(self.drop_first_sighting, bool):
            raise TypeError(f"`drop_first_sighting` must be a bool; got {type(self.drop_first_sighting).__name__}")
        check_int(self.n_oldest, "n_oldest", minimum=3)
        if check_positive(self.oldest_fraction, "oldest_fraction") > 1:
            raise ValueError(f"`oldest_fraction` must be in (0, 1]; got {self.oldest_fraction}")
        _fraction(self.keep_fraction, "keep_fraction")
        check_positive(self.loose_factor, "loose_factor")
        _fraction(self.still_fraction, "still_fraction")
        _optional_positive(self.max_std_factor, "max_std_factor")
        _optional_positive(self.max_correction_rad, "max_correction_rad", allow_zero=True)
        _optional_positive(self.max_correction_m, "max_correction_m", allow_zero=True)
        _optional_positive(self.max_rot_std_rad, "max_rot_std_rad")
        check_choice(self.degenerate_pose, "degenerate_pose", ("last", "constant_velocity"))
        check_positive(self.state_var, "state_var", allow_zero=True)
        check_positive(self.pose_std_m, "pose_std_m", allow_zero=True)
        check_positive(self.pose_std_rad, "pose_std_rad", allow_zero=True)
        _optional_positive(self.update_gate, "update_gate")

    @property
    def refine_disparity(self) -> bool:
        """Whether stereo matches get :func:`~slamlab.stereo.subpixel_disparity` (``subpixel_stereo``; None: ORB only)."""
        return self.detector == "orb" if self.subpixel_stereo is None else self.subpixel_stereo

    @property
    def search(self) -> str:
        """The map search in use (``map_search``; None: 'window' for ORB, 'global' otherwise)."""
        return ("window" if self.binary else "global") if self.map_search is None else self.map_search

    @property
    def twin_gap_m(self) -> float | None:
        """The ``same_point_m`` in use (None: off)."""
        if self.same_point_m is None:
            return 0.03 if self.search == "window" else None
        return self.same_point_m or None

    @property
    def binary(self) -> bool:
        """True when the detector's descriptors are binary (ORB: Hamming distance)."""
        return self.detector == "orb"

    def detect_kwargs(self) -> dict:
        """Keyword arguments of :func:`slamlab.features.detect` for this pipeline's detector (000 §3.3).

        Returns
        -------
        dict
        """
        kw = {"max_points": self.n_features, "channel_order": self.channel_order}
        if self.detector == "orb":
            kw.update(n_features=self.n_features, fast_threshold=self.orb_fast_threshold, n_levels=self.orb_levels)
        elif self.detector == "sift":
            kw["n_features"] = self.n_features
        return kw


@dataclass(frozen=True)
class RenderParams(Params):
    """Settings of the rendered arena runs (the simulator's, not the pipeline's; 000 §3.7).

    Attributes
    ----------
    arena_seed : int
        ours: texture seed of the 6x8 m arena
    camera_height_m : float
        ours: height of the cameras above the floor, m
    noise_std : float
        ours: image noise, grey levels
    drift_std_rad : float
        ours: random-walk step of the right camera per frame (000 §3.2)
    """

    arena_seed: int = param(0, "ours: texture seed of the 6x8 m arena")
    camera_height_m: float = param(0.4, "ours")
    noise_std: float = param(0.0, "ours: image noise, grey levels")
    drift_std_rad: float = param(0.0, "ours: random-walk step of the right camera per frame (000 §3.2)")

    def check(self) -> None:
        check_int(self.arena_seed, "arena_seed", minimum=0)
        check_positive(self.camera_height_m, "camera_height_m")
        check_positive(self.noise_std, "noise_std", allow_zero=True)
        check_positive(self.drift_std_rad, "drift_std_rad", allow_zero=True)
