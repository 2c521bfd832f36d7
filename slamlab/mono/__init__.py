"""Monocular mapping (003 §2.1, §4, §5): SDVL/SVO-style depth filter, initialisation, tracking.

Uses :mod:`slamlab.features` (FAST), :mod:`slamlab.geometry` and :mod:`slamlab.evaluation`;
nothing below imports this package. cv2 loads inside the functions that need it.
"""

from .._lazy import lazy_exports
from .align import refine_pose, se3_exp, sparse_align
from .depth_filter import (
    Seeds,
    compute_tau,
    converged_linearity,
    converged_sigma,
    depth_interval,
    init_seeds,
    inlier_ratio,
    linearity_index,
    seed_points,
    update_seeds,
)
from .epipolar import epipolar_segments, search_epipolar
from .initialise import (
    INIT_STATUSES,
    Initialiser,
    InitResult,
    TwoViewPose,
    relative_pose_essential,
    relative_pose_homography,
    track_lk,
    triangulate_two_view,
)
from .params import MonoParams
from .slam import STAGES, Keyframe, MonoSLAM

__all__ = [
    "INIT_STATUSES",
    "STAGES",
    "InitResult",
    "Initialiser",
    "Keyframe",
    "MonoParams",
    "MonoSLAM",
    "Seeds",
    "TwoViewPose",
    "compute_tau",
    "converged_linearity",
    "converged_sigma",
    "depth_interval",
    "epipolar_segments",
    "init_seeds",
    "inlier_ratio",
    "linearity_index",
    "refine_pose",
    "relative_pose_essential",
    "relative_pose_homography",
    "se3_exp",
    "search_epipolar",
    "seed_points",
    "sparse_align",
    "track_lk",
    "triangulate_two_view",
    "update_seeds",
]

__getattr__, __dir__ = lazy_exports(__name__, {
    "plot_convergence": ".plot", "plot_epipolar_pair": ".plot", "plot_map_top": ".plot",
    "plot_seed_histograms": ".plot", "explore_mono": ".widgets",
    "run_depth_filter_convergence": ".experiments", "run_failure_cases": ".experiments",
    "failure_table": ".experiments", "run_kitti_mono": ".kitti", "run_mono_vs_stereo": ".studies",
    "run_parameter_sweep": ".experiments", "run_mono_sequence": ".experiments", "run_mono": ".experiments",
    "ours_vs_source": ".studies", "epipolar_demo": ".kitti", "sequence_poses": ".experiments",
    "compare_init_methods": ".studies",
    "explore_failure_cases": ".widgets", "explore_motion_prior": ".widgets", "explore_depth_filter": ".widgets",
    "plot_pinhole": ".plot", "score_run": ".evaluate", "pinhole_table": ".studies",
    "inverse_depth_point_table": ".studies", "tau_table": ".studies", "run_convergence_tests": ".studies",
    "run_ablation": ".studies", "ablation_table": ".studies", "source_findings_table": ".studies",
    "chapter_cameras": ".studies", "run_kitti_ablation": ".kitti",
    "load_kitti": ".kitti",
})
