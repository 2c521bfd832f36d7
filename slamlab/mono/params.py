"""Settings of the monocular pipeline (003 §4, §5.1.1): one frozen dataclass, each field sourced."""

from __future__ import annotations

from dataclasses import dataclass

from .._params import Params, param
from .._validate import check_choice, check_int, check_positive, check_probability

__all__ = ["MonoParams"]


@dataclass(frozen=True)
class MonoParams(Params):
    """Every knob of :class:`~slamlab.mono.MonoSLAM` with the source of its default.

    Attributes
    ----------
    fast_threshold : int
        ours: FAST threshold (003 §5.3 notes its effect on the initial map)
    min_corners : int
        003 §4.3.1: at least 50 FAST points
    init_disparity_px : float
        003 §5.1.1: 10-20 px ('initial displacement')
    init_min_tracked : float
        ours: restart when fewer than this share of corners is still tracked
    init_method : str
        ours: the homography when a dominant plane explains the matches, else the 5-point algorithm
        (003 §4.3.1 names both; 'homography', 'essential')
    init_plane_share : float
        ours ('auto'): the homography when its RANSAC inliers are at least this share of the 5-point
        method's
    init_plane_share_of : str
        ours ('auto'): the 5-point method's inliers counted: its RANSAC inliers ('ransac') or those
        cv2.recoverPose keeps in front within 50 baselines ('front')
    init_ransac_px : float
        ours
    init_min_parallax_deg : float
        ours: median triangulation angle needed (KITTI 01's forward motion: 1 deg kept a re-initialisation
        waiting)
    init_min_point_parallax_deg : float
        ours: triangulation angle each point of the first map needs
    convergence : str
        003 §4.3.2: 'linearity' (L < 0.1) or SVO's 'sigma'
    L_max : float
        003 §4.3.2
    sigma_fraction : float
        SVO: sigma < rho_range / 200
    n_sigma : float
        003 §4.2: search over rho +- 2 sigma
    epi_tol_px : float
        ours: 003 §4.2 says the band around the epipolar line is tunable
    patch_px : int
        ours: patch side for the seed score (ZNCC; SVO scores 8x8 patches)
    zncc_min : float
        ours: minimum ZNCC of a seed match
    warp_patches : bool
        SVO: the seed's patch warped affinely to the current view at its mean depth
    px_noise : float
        SVO: one pixel of measurement error
    max_seed_fail : int
        ours: 003 §4.3.2 drops a seed not found 'for several frames'
    min_inlier_ratio : float
        SVO: drop seeds with a/(a+b) < 0.1
    max_seeds_per_kf : int
        ours
    kf_min_frames : int
        003 §4.3: 30 iterations between keyframes
    kf_lost_ratio : float
        003 §4.3: at least 10 % of points lost
    kf_max_lost_ratio : float
        003 §4.3 / §5.1.1 ('lost-point ratio'): > 30 % lost forces one
    max_keyframes : int
        003 §5.1.1: 'number of keyframes', value not given
    motion_model : str
        003 §4.4 step 1 ('constant_position': SVO's)
    align_patch_px : int
        003 §4.4.1: 4x4 patches
    align_max_level : int
        ours: coarsest pyramid level
    align_min_level : int
        003 §4.4.1: the finest levels can be skipped
    align_iters : int
        ours
    align_max_points : int
        ours: map points used by the direct alignment
    max_matches : int
        003 §5.1.1: 'number of matches', value not given
    match_win_px : int
        ours: LK window refining a projected point
    refine_iters : int
        ours: Levenberg-Marquardt steps of the motion-only refinement
    reproj_inlier_deg : float
        ours: inlier angle of a reprojection (4 px at KITTI's 707 px focal length, 1.5 px at the
        rendered 264 px)
    min_inliers : int
        ours: fewer inliers = lost
    max_coast : int
        ours: lost frames over which the constant-velocity prior keeps moving the pose before a re-
        initialisation (0: re-initialise at once)
    reinit_when_lost : bool
        ours: after coasting, a new two-view map placed at the predicted pose, scaled by the velocity
        (constant-velocity prior only)
    reinit_velocity_frames : int
        ours: a re-initialisation is checked against, and moves with, the mean one-frame motion of this many
        last tracked frames (1: the last frame's velocity)
    reinit_scale : str
        ours: a re-initialisation's scale: 'map' the median depth ratio of the old map's points to the new
        map's at the same pixels of the last tracked frame (the steps when fewer than 10 pixels agree),
        'steps' the median of the last tracked frames' steps
    prefer_seen : bool
        ours: among the map points in view, those matched in the previous frame first
    init_velocity : bool
        ours: the first map's two-view motion, per frame, is the constant-velocity prior of the first tracked
        frame (off: that frame starts at the last pose)
    min_inlier_share : float
        ours: lost when fewer than this share of the matched points are inliers
    max_align_rms : float
        ours: lost when the alignment's photometric RMS (grey levels) exceeds this
    outlier_rejection : bool
        003 §5.1.1 item 5 (RdE); our form: a second refinement without points over 3 px and dropping
        points that keep failing
    refine : bool
        003 §4.4 step 4: motion-only refinement of the reprojection error (off: the alignment's pose is
        final)
    """

    # initialisation (003 §4.3.1, §5.1.1)
    fast_threshold: int = param(20, "ours: FAST threshold (003 §5.3 notes its effect on the initial map)")
    min_corners: int = param(50, "003 §4.3.1: at least 50 FAST points")
    init_disparity_px: float = param(15.0, "003 §5.1.1: 10-20 px ('initial displacement')")
    init_min_tracked: float = param(0.5, "ours: restart when fewer than this share of corners is still tracked")
    init_method: str = param("auto", "ours: the homography when a dominant plane explains the matches, else the "
                                     "5-point algorithm (003 §4.3.1 names both; 'homography', 'essential')")
    init_plane_share: float = param(0.7, "ours ('auto'): the homography when its RANSAC inliers are at least this "
                                         "share of the 5-point method's")
    init_plane_share_of: str = param("ransac", "ours ('auto'): the 5-point method's inliers counted: its RANSAC "
                                               "inliers ('ransac') or those cv2.recoverPose keeps in front within "
                                               "50 baselines ('front')")
    init_ransac_px: float = param(2.0, "ours")
    init_min_parallax_deg: float = param(0.5, "ours: median triangulation angle needed (KITTI 01's forward motion: "
                                              "1 deg kept a re-initialisation waiting)")
    init_min_point_parallax_deg: float = param(0.0, "ours: triangulation angle each point of the first map needs")
    # depth filter (003 §4.1.1, §4.2, §4.3.2; SVO)
    convergence: str = param("linearity", "003 §4.3.2: 'linearity' (L < 0.1) or SVO's 'sigma'")
    L_max: float = param(0.1, "003 §4.3.2")
    sigma_fraction: float = param(1.0 / 200.0, "SVO: sigma < rho_range / 200")
    n_sigma: float = param(2.0, "003 §4.2: search over rho +- 2 sigma")
    epi_tol_px: float = param(2.0, "ours: 003 §4.2 says the band around the epipolar line is tunable")
    patch_px: int = param(9, "ours: patch side for the seed score (ZNCC; SVO scores 8x8 patches)")
    zncc_min: float = param(0.8, "ours: minimum ZNCC of a seed match")
    warp_patches: bool = param(True, "SVO: the seed's patch warped affinely to the current view at its mean depth")
    px_noise: float = param(1.0, "SVO: one pixel of measurement error")
    max_seed_fail: int = param(10, "ours: 003 §4.3.2 drops a seed not found 'for several frames'")
    min_inlier_ratio: float = param(0.1, "SVO: drop seeds with a/(a+b) < 0.1")
    max_seeds_per_kf: int = param(400, "ours")
    # keyframes (003 §4.3)
    kf_min_frames: int = param(30, "003 §4.3: 30 iterations between keyframes")
    kf_lost_ratio: float = param(0.10, "003 §4.3: at least 10 % of points lost")
    kf_max_lost_ratio: float = param(0.30, "003 §4.3 / §5.1.1 ('lost-point ratio'): > 30 % lost forces one")
    max_keyframes: int = param(10, "003 §5.1.1: 'number of keyframes', value not given")
    # tracking (003 §4.4)
    motion_model: str = param("constant_velocity", "003 §4.4 step 1 ('constant_position': SVO's)")
    align_patch_px: int = param(4, "003 §4.4.1: 4x4 patches")
    align_max_level: int = param(3, "ours: coarsest pyramid level")
    align_min_level: int = param(1, "003 §4.4.1: the finest levels can be skipped")
    align_iters: int = param(30, "ours")
    align_max_points: int = param(400, "ours: map points used by the direct alignment")
    max_matches: int = param(120, "003 §5.1.1: 'number of matches', value not given")
    match_win_px: int = param(11, "ours: LK window refining a projected point")
    refine_iters: int = param(200, "ours: Levenberg-Marquardt steps of the motion-only refinement")
    reproj_inlier_deg: float = param(0.33, "ours: inlier angle of a reprojection (4 px at KITTI's 707 px focal "
                                           "length, 1.5 px at the rendered 264 px)")
    min_inliers: int = param(20, "ours: fewer inliers = lost")
    max_coast: int = param(0, "ours: lost frames over which the constant-velocity prior keeps moving the pose "
                                  "before a re-initialisation (0: re-initialise at once)")
    reinit_when_lost: bool = param(True, "ours: after coasting, a new two-view map placed at the predicted pose, "
                                         "scaled by the velocity (constant-velocity prior only)")
    reinit_velocity_frames: int = param(5, "ours: a re-initialisation is checked against, and moves with, the mean "
                                           "one-frame motion of this many last tracked frames (1: the last frame's "
                                           "velocity)")
    reinit_scale: str = param("map", "ours: a re-initialisation's scale: 'map' the median depth ratio of the old "
                                     "map's points to the new map's at the same pixels of the last tracked frame "
                                     "(the steps when fewer than 10 pixels agree), 'steps' the median of the last "
                                     "tracked frames' steps")
    prefer_seen: bool = param(True, "ours: among the map points in view, those matched in the previous frame first")
    init_velocity: bool = param(True, "ours: the first map's two-view motion, per frame, is the constant-velocity "
                                      "prior of the first tracked frame (off: that frame starts at the last pose)")
    # failure detection and the switches of 003 §5.1.1 / §5.4 (ours unless stated)
    min_inlier_share: float = param(0.35, "ours: lost when fewer than this share of the matched points are inliers")
    max_align_rms: float = param(40.0, "ours: lost when the alignment's photometric RMS (grey levels) exceeds this")
    outlier_rejection: bool = param(True, "003 §5.1.1 item 5 (RdE); our form: a second refinement without points "
                                          "over 3 px and dropping points that keep failing")
    refine: bool = param(True, "003 §4.4 step 4: motion-only refinement of the reprojection error (off: the "
                               "alignment's pose is final)")

    def check(self) -> None:
        check_int(self.fast_threshold, "fast_threshold", minimum=1, maximum=254)
        check_int(self.min_corners, "min_corners", minimum=8)
        check_positive(self.init_disparity_px, "init_disparity_px")
        check_probability(self.init_min_tracked, "init_min_tracked")
        check_choice(self.init_method, "init_method", ("homography", "essential", "auto"))
        check_probability(self.init_plane_share, "init_plane_share")
        check_choice(self.init_plane_share_of, "init_plane_share_of", ("ransac", "front"))
        check_positive(self.init_ransac_px, "init_ransac_px")
        check_positive(self.init_min_parallax_deg, "init_min_parallax_deg", allow_zero=True)
        check_positive(self.init_min_point_parallax_deg, "init_min_point_parallax_deg", allow_zero=True)
        check_choice(self.convergence, "convergence", ("linearity", "sigma"))
        check_positive(self.L_max, "L_max")
        check_positive(self.sigma_fraction, "sigma_fraction")
        check_positive(self.n_sigma, "n_sigma")
        check_positive(self.epi_tol_px, "epi_tol_px")
        check_int(self.patch_px, "patch_px", minimum=3, maximum=31)
        if not -1.0 <= float(self.zncc_min) <= 1.0:
            raise ValueError(f"`zncc_min` must be in [-1, 1]; got {self.zncc_min}")
        check_positive(self.px_noise, "px_noise")
        check_int(self.max_seed_fail, "max_seed_fail", minimum=1)
        check_probability(self.min_inlier_ratio, "min_inlier_ratio")
        check_int(self.max_seeds_per_kf, "max_seeds_per_kf", minimum=1)
        check_int(self.kf_min_frames, "kf_min_frames", minimum=1)
        check_probability(self.kf_lost_ratio, "kf_lost_ratio")
        check_probability(self.kf_max_lost_ratio, "kf_max_lost_ratio")
        check_int(self.max_keyframes, "max_keyframes", minimum=2)
        check_choice(self.motion_model, "motion_model", ("constant_position", "constant_velocity"))
        check_int(self.align_patch_px, "align_patch_px", minimum=2, maximum=16)
        check_int(self.align_max_level, "align_max_level", minimum=0, maximum=6)
        check_int(self.align_min_level, "align_min_level", minimum=0, maximum=6)
        if self.align_min_level > self.align_max_level:
            raise ValueError(f"`align_min_level` must be <= `align_max_level`; got {self.align_min_level} > "
                             f"{self.align_max_level}")
        check_int(self.align_iters, "align_iters", minimum=1)
        check_int(self.align_max_points, "align_max_points", minimum=10)
        check_int(self.max_matches, "max_matches", minimum=6)
        check_int(self.match_win_px, "match_win_px", minimum=5, maximum=51)
        check_positive(self.reproj_inlier_deg, "reproj_inlier_deg")
        check_int(self.min_inliers, "min_inliers", minimum=6)
        check_int(self.max_coast, "max_coast", minimum=0)
        check_int(self.reinit_velocity_frames, "reinit_velocity_frames", minimum=1, maximum=10)
        check_choice(self.reinit_scale, "reinit_scale", ("map", "steps"))
        check_int(self.refine_iters, "refine_iters", minimum=1)
        if not 0.0 <= check_positive(self.min_inlier_share, "min_inlier_share", allow_zero=True) <= 1.0:
            raise ValueError(f"`min_inlier_share` must be in [0, 1]; got {self.min_inlier_share}")
        check_positive(self.max_align_rms, "max_align_rms")
        for name in ("outlier_rejection", "refine", "prefer_seen", "warp_patches", "reinit_when_lost",
                     "init_velocity"):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"`{name}` must be True or False; got {getattr(self, name)!r}")
