"""Ch. 05 stereo SLAM (000 §3.2-3.7): the arena runs, KITTI, the drift and scale studies, their tables, plots and widget."""

from ..._lazy import lazy_exports
from .experiments import (
    COMPARISON,
    DISPARITY_PARAMS,
    EXPERIMENTS,
    SIZES,
    DriftStudy,
    StereoRunResult,
    comparison_table,
    disparity_errors,
    experiment_poses,
    record_stereo_stream,
    run_comparison,
    run_drift_study,
    run_experiment,
    run_stereo_slam,
    run_stereo_slam_variants,
)
from .heading import heading_frames
from .kitti_experiments import (
    KITTI_ABLATION,
    KITTI_GOAL,
    KITTI_PARAMS,
    KITTI_SETS,
    KittiRunResult,
    kitti_ablation,
    kitti_ablation_table,
    kitti_comparison,
    kitti_set_runs,
    kitti_sets,
    kitti_sets_table,
    ours_vs_source,
    run_kitti,
)
from .scale_ablation import (
    ABLATION_BASE,
    PROPOSED_FIX,
    PROPOSED_FIX_OFF,
    SCALE_ABLATION,
    ScaleAblation,
    run_scale_ablation,
)

_LAZY = {
    **dict.fromkeys(("plot_kitti", "plot_run_errors", "plot_run_map", "run_figure"), ".plot"),
    "explore_stereo_slam": ".widgets",
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)

__all__ = [
    "ABLATION_BASE",
    "COMPARISON",
    "DISPARITY_PARAMS",
    "EXPERIMENTS",
    "KITTI_ABLATION",
    "KITTI_GOAL",
    "KITTI_PARAMS",
    "KITTI_SETS",
    "PROPOSED_FIX",
    "PROPOSED_FIX_OFF",
    "SCALE_ABLATION",
    "SIZES",
    "DriftStudy",
    "KittiRunResult",
    "ScaleAblation",
    "StereoRunResult",
    "comparison_table",
    "disparity_errors",
    "experiment_poses",
    "heading_frames",
    "kitti_ablation",
    "kitti_ablation_table",
    "kitti_comparison",
    "kitti_set_runs",
    "kitti_sets",
    "kitti_sets_table",
    "ours_vs_source",
    "record_stereo_stream",
    "run_comparison",
    "run_drift_study",
    "run_experiment",
    "run_kitti",
    "run_scale_ablation",
    "run_stereo_slam",
    "run_stereo_slam_variants",
]
__all__ += list(_LAZY)
