"""Stereo SLAM (000 §3): settings, per-frame stages, the SLAM loop, experiments.

Uses the features chapter (:func:`slamlab.features.detect`, the ratio rule) and the
landmark stores of :mod:`slamlab.kdtree`; nothing below imports this package. Plots and
widgets load on first use.
"""

from .._lazy import lazy_exports
from .experiments import (
    COMPARISON,
    SIZES,
    DriftStudy,
    StereoRunResult,
    comparison_table,
    disparity_errors,
    experiment_poses,
    record_stereo_stream,
    run_closed_loop,
    run_comparison,
    run_drift_study,
    run_stereo_slam,
    run_stereo_slam_variants,
    run_turn_in_place,
)
from .heading import heading_frames
from .kitti_experiments import KITTI_PARAMS, KittiRunResult, kitti_comparison, ours_vs_source, run_kitti
from .noise_estimate import disparity_noise_px, robust_pixel_std, stereo_residuals_px
from .params import STEREO_DETECTORS, RenderParams, StereoParams
from .scale_ablation import (
    ABLATION_BASE,
    PROPOSED_FIX,
    PROPOSED_FIX_OFF,
    SCALE_ABLATION,
    ScaleAblation,
    run_scale_ablation,
)
from .slam import STAGES, FrameRecord, StereoSLAM, default_store
from .stages import (
    LocalCloud,
    MapMatches,
    PoseEstimate,
    StereoMatches,
    detect_features,
    estimate_pose,
    is_rectified,
    match_to_map,
    pose_std,
    refine_pose_stereo,
    select_oldest,
    stereo_match,
    stereo_point_cov,
    subpixel_disparity,
    triangulate_local,
)

_LAZY = {
    **dict.fromkeys(("plot_frame_stages", "plot_kitti", "plot_run_errors", "plot_run_map", "plot_triangulation",
                     "run_figure"), ".plot"),
    "explore_stereo_slam": ".widgets",
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)

__all__ = [
    "ABLATION_BASE",
    "COMPARISON",
    "KITTI_PARAMS",
    "PROPOSED_FIX",
    "PROPOSED_FIX_OFF",
    "SCALE_ABLATION",
    "SIZES",
    "STAGES",
    "STEREO_DETECTORS",
    "DriftStudy",
    "FrameRecord",
    "KittiRunResult",
    "LocalCloud",
    "MapMatches",
    "PoseEstimate",
    "RenderParams",
    "ScaleAblation",
    "StereoMatches",
    "StereoParams",
    "StereoRunResult",
    "StereoSLAM",
    "comparison_table",
    "default_store",
    "detect_features",
    "disparity_errors",
    "disparity_noise_px",
    "estimate_pose",
    "experiment_poses",
    "heading_frames",
    "is_rectified",
    "kitti_comparison",
    "match_to_map",
    "ours_vs_source",
    "pose_std",
    "record_stereo_stream",
    "refine_pose_stereo",
    "robust_pixel_std",
    "run_closed_loop",
    "run_comparison",
    "run_drift_study",
    "run_kitti",
    "run_scale_ablation",
    "run_stereo_slam",
    "run_stereo_slam_variants",
    "run_turn_in_place",
    "select_oldest",
    "stereo_match",
    "stereo_point_cov",
    "stereo_residuals_px",
    "subpixel_disparity",
    "triangulate_local",
]
__all__ += list(_LAZY)
