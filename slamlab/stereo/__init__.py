"""Stereo SLAM (000 §3): per-frame stages, landmark store interface, the SLAM loop."""

from .experiments import (
    SIZES,
    DriftStudy,
    KittiRunResult,
    StereoRunResult,
    run_closed_loop,
    run_drift_study,
    run_kitti,
    run_stereo_slam,
    run_turn_in_place,
)
from .plot import plot_frame_stages, plot_run_errors, plot_run_map, plot_triangulation, run_figure
from .slam import STAGES, FrameRecord, StereoSLAM
from .stages import (
    DETECTORS,
    POLICIES,
    Features,
    LocalCloud,
    MapMatches,
    PoseEstimate,
    StereoMatches,
    detect,
    estimate_pose,
    match_to_map,
    select_oldest,
    stereo_match,
    triangulate_local,
)
from .store import ExactStore, check_store
from .widgets import explore_stereo_slam

__all__ = [
    "DETECTORS",
    "POLICIES",
    "SIZES",
    "STAGES",
    "DriftStudy",
    "ExactStore",
    "Features",
    "FrameRecord",
    "KittiRunResult",
    "LocalCloud",
    "MapMatches",
    "PoseEstimate",
    "StereoMatches",
    "StereoRunResult",
    "StereoSLAM",
    "check_store",
    "detect",
    "estimate_pose",
    "explore_stereo_slam",
    "match_to_map",
    "plot_frame_stages",
    "plot_run_errors",
    "plot_run_map",
    "plot_triangulation",
    "run_closed_loop",
    "run_drift_study",
    "run_figure",
    "run_kitti",
    "run_stereo_slam",
    "run_turn_in_place",
    "select_oldest",
    "stereo_match",
    "triangulate_local",
]
