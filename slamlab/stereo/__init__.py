"""Stereo SLAM (000 §3): settings, per-frame stages, the SLAM loop and its plots.

Uses the features chapter (:func:`slamlab.features.detect`, the ratio rule) and the
landmark stores of :mod:`slamlab.kdtree`; nothing below imports this package. The chapter's
runs (the arena experiments, KITTI, the ablations) live in :mod:`slamlab.studies.stereo`.
Plots load on first use.
"""

from .._lazy import lazy_exports
from .noise_estimate import disparity_noise_px, disparity_residuals_px, robust_pixel_std, stereo_residuals_px
from .params import STEREO_DETECTORS, RenderParams, StereoParams
from .slam import STAGES, FrameRecord, StereoSLAM, default_store
from .stages import (
    LocalCloud,
    MapMatches,
    PoseEstimate,
    StereoMatches,
    detect_features,
    detect_pair,
    estimate_pose,
    is_rectified,
    match_in_window,
    match_to_landmarks,
    match_to_map,
    pose_std,
    refine_pose_stereo,
    select_oldest,
    stereo_match,
    stereo_point_cov,
    subpixel_disparity,
    triangulate_local,
)

_LAZY = dict.fromkeys(("plot_frame_stages", "plot_triangulation"), ".plot")
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)

__all__ = [
    "STAGES",
    "STEREO_DETECTORS",
    "FrameRecord",
    "LocalCloud",
    "MapMatches",
    "PoseEstimate",
    "RenderParams",
    "StereoMatches",
    "StereoParams",
    "StereoSLAM",
    "default_store",
    "detect_features",
    "detect_pair",
    "disparity_noise_px",
    "disparity_residuals_px",
    "estimate_pose",
    "is_rectified",
    "match_in_window",
    "match_to_landmarks",
    "match_to_map",
    "pose_std",
    "refine_pose_stereo",
    "robust_pixel_std",
    "select_oldest",
    "stereo_match",
    "stereo_point_cov",
    "stereo_residuals_px",
    "subpixel_disparity",
    "triangulate_local",
]
__all__ += list(_LAZY)
