"""Hough-transform SLAM from a scanning rangefinder (004): polar and classic Hough transforms,
peaks above H_min, line association and history, pose from two lines, an ICP baseline and the
experiments of notebook 07. Scans are :class:`slamlab.scans.Scan` objects; maps come from
:func:`slamlab.scans.occupancy_grid`.
"""

from .._lazy import lazy_exports
from .association import LineHistory, associate, association_probability
from .experiments import (
    LOG_PARAMS,
    ODOMETRY_NOISE,
    SHARED_LOGS,
    ExampleLineResult,
    NoiseStudyResult,
    RealLogResult,
    SimSlamResult,
    check_pose_from_two_lines,
    log_format,
    ours_vs_source,
    pose_errors,
    run_example_line,
    run_noise_study,
    run_real_log,
    run_sim_slam,
    time_polar_vs_opencv,
)
from .icp import IcpResult, icp, icp_odometry, rigid_fit_2d
from .lines import (
    Lines,
    align_lines,
    canonical_lines,
    find_peaks,
    line_difference,
    merge_duplicates,
    refine_lines,
    transform_lines,
)
from .logs import REAL_LOG_PARAMS, real_log_cause_table
from .mapping import map_agreement
from .pose import PoseChange, pose_from_lines, pose_from_two_lines, select_line_pair
from .slam import STEP_CAUSES, HoughSlamParams, HoughSlamResult, detect_lines, hough_slam
from .transform import (
    HoughAccumulator,
    hough_classic,
    hough_cost,
    hough_polar,
    line_scan,
    lines_about_centre,
    rasterise_scan,
    theta_axis,
)

_PLOT = (
    "accumulator_figure",
    "example_figure",
    "plot_accumulator",
    "plot_built_map",
    "plot_pose_errors",
    "plot_scan_lines",
    "real_log_figure",
    "sim_figure",
)
_WIDGETS = ("explore_accumulator", "explore_hough_slam", "explore_real_log")
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"), **dict.fromkeys(_WIDGETS, ".widgets")})

__all__ = [
    "LOG_PARAMS",
    "ODOMETRY_NOISE",
    "REAL_LOG_PARAMS",
    "SHARED_LOGS",
    "STEP_CAUSES",
    "ExampleLineResult",
    "HoughAccumulator",
    "HoughSlamParams",
    "HoughSlamResult",
    "IcpResult",
    "LineHistory",
    "Lines",
    "NoiseStudyResult",
    "PoseChange",
    "RealLogResult",
    "SimSlamResult",
    "align_lines",
    "associate",
    "association_probability",
    "canonical_lines",
    "check_pose_from_two_lines",
    "detect_lines",
    "find_peaks",
    "hough_classic",
    "hough_cost",
    "hough_polar",
    "hough_slam",
    "icp",
    "icp_odometry",
    "line_difference",
    "line_scan",
    "lines_about_centre",
    "log_format",
    "map_agreement",
    "merge_duplicates",
    "ours_vs_source",
    "pose_errors",
    "pose_from_lines",
    "pose_from_two_lines",
    "rasterise_scan",
    "real_log_cause_table",
    "refine_lines",
    "rigid_fit_2d",
    "run_example_line",
    "run_noise_study",
    "run_real_log",
    "run_sim_slam",
    "select_line_pair",
    "theta_axis",
    "time_polar_vs_opencv",
    "transform_lines",
]
__all__ += list(_PLOT + _WIDGETS)  # loaded on first use
