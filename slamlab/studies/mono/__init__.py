"""Ch. 9 monocular mapping's studies (003 §2.1, §4, §5): runs, failure cases, ablations, tables and widgets."""

from ..._lazy import lazy_exports
from .convergence import (
    ConvergenceStudy,
    ConvergenceTests,
    run_convergence_tests,
    run_depth_filter_convergence,
)
from .epipolar_subset import EpipolarSubset, run_epipolar_subset
from .experiments import (
    failure_table,
    run_failure_cases,
    run_mono_sequence,
    run_parameter_sweep,
    sequence_poses,
)
from .findings import StillStart, practice_findings_table, run_still_start
from .formulas import chapter_cameras, inverse_depth_point_table, pinhole_table, tau_table
from .kitti import epipolar_demo, load_kitti, run_kitti_ablation, run_kitti_mono
from .kitti_goal import KITTI_GOAL_ABLATIONS, goal_ablation_table, kitti_goal_table
from .repeats import RepeatedRuns, run_repeats
from .runs import MonoRunResult, run_mono
from .studies import (
    MonoVsStereo,
    ablation_table,
    compare_init_methods,
    ours_vs_source,
    run_ablation,
    run_mono_vs_stereo,
    source_findings_table,
)
from .timing import source_timing_table, stage_timing_table

__all__ = [
    "KITTI_GOAL_ABLATIONS",
    "ConvergenceStudy",
    "ConvergenceTests",
    "EpipolarSubset",
    "MonoRunResult",
    "MonoVsStereo",
    "RepeatedRuns",
    "StillStart",
    "ablation_table",
    "chapter_cameras",
    "compare_init_methods",
    "epipolar_demo",
    "explore_depth_filter",
    "explore_failure_cases",
    "explore_mono",
    "explore_motion_prior",
    "failure_table",
    "goal_ablation_table",
    "inverse_depth_point_table",
    "kitti_goal_table",
    "load_kitti",
    "ours_vs_source",
    "pinhole_table",
    "plot_convergence",
    "plot_map_top",
    "plot_pinhole",
    "practice_findings_table",
    "run_ablation",
    "run_convergence_tests",
    "run_depth_filter_convergence",
    "run_epipolar_subset",
    "run_failure_cases",
    "run_kitti_ablation",
    "run_kitti_mono",
    "run_mono",
    "run_mono_sequence",
    "run_mono_vs_stereo",
    "run_parameter_sweep",
    "run_repeats",
    "run_still_start",
    "sequence_poses",
    "source_findings_table",
    "source_timing_table",
    "stage_timing_table",
    "tau_table",
]

__getattr__, __dir__ = lazy_exports(__name__, {
    "plot_convergence": ".plot", "plot_map_top": ".plot", "plot_pinhole": ".plot",
    "explore_depth_filter": ".widgets", "explore_failure_cases": ".widgets", "explore_mono": ".widgets",
    "explore_motion_prior": ".widgets",
})
