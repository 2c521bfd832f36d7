"""Hough-transform SLAM from a scanning rangefinder (004): polar and classic Hough transforms,
peaks above H_min, line association and history, pose from two lines, map building, an ICP
baseline and the experiments of notebook 07.
"""

from .association import LineHistory, associate, association_probability
from .experiments import (
    ExampleLineResult,
    RealLogResult,
    SimSlamResult,
    check_pose_from_two_lines,
    pose_errors,
    run_example_line,
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
from .mapping import BuiltMap, build_map, map_agreement, scan_points_world
from .plot import (
    accumulator_figure,
    example_figure,
    plot_accumulator,
    plot_built_map,
    plot_pose_errors,
    plot_scan_lines,
    real_log_figure,
    sim_figure,
)
from .pose import PoseChange, compose, pose_from_lines, pose_from_two_lines, select_line_pair
from .slam import HoughSlamParams, HoughSlamResult, detect_lines, hough_slam
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

__all__ = [
    "BuiltMap",
    "HoughAccumulator",
    "HoughSlamParams",
    "HoughSlamResult",
    "IcpResult",
    "LineHistory",
    "Lines",
    "PoseChange",
    "align_lines",
    "associate",
    "association_probability",
    "build_map",
    "canonical_lines",
    "check_pose_from_two_lines",
    "compose",
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
    "map_agreement",
    "merge_duplicates",
    "pose_from_lines",
    "pose_from_two_lines",
    "rasterise_scan",
    "refine_lines",
    "rigid_fit_2d",
    "scan_points_world",
    "select_line_pair",
    "theta_axis",
    "time_polar_vs_opencv",
    "transform_lines",
]

from .widgets import explore_accumulator, explore_hough_slam, explore_real_log

__all__ += [
    "ExampleLineResult",
    "RealLogResult",
    "SimSlamResult",
    "accumulator_figure",
    "example_figure",
    "explore_accumulator",
    "explore_hough_slam",
    "explore_real_log",
    "plot_accumulator",
    "plot_built_map",
    "plot_pose_errors",
    "plot_scan_lines",
    "pose_errors",
    "real_log_figure",
    "run_example_line",
    "run_real_log",
    "run_sim_slam",
    "sim_figure",
]
