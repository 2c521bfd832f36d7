"""Hough-transform SLAM from a scanning rangefinder (004): polar and classic Hough transforms,
peaks above H_min, line association and history, pose from two lines and an ICP baseline.
Scans are :class:`slamlab.scans.Scan` objects; maps come from :func:`slamlab.scans.occupancy_grid`.
"""

from .._lazy import lazy_exports
from .association import LineHistory, associate_lines, association_probability
from .icp import IcpResult, icp, icp_odometry, rigid_fit_2d
from .latency import LAGS_SCANS, line_rotation_steps, odometry_lag, retime_poses
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
from .mapping import map_agreement
from .pose import PoseChange, pose_from_lines, pose_from_two_lines, select_line_pair
from .slam import STEP_CAUSES, HoughSlamParams, HoughSlamResult, detect_lines, hough_slam, scan_lines
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

_PLOT = ("accumulator_figure", "plot_accumulator", "plot_built_map", "plot_scan_lines")
__getattr__, __dir__ = lazy_exports(__name__, dict.fromkeys(_PLOT, ".plot"))

__all__ = [
    "LAGS_SCANS",
    "STEP_CAUSES",
    "HoughAccumulator",
    "HoughSlamParams",
    "HoughSlamResult",
    "IcpResult",
    "LineHistory",
    "Lines",
    "PoseChange",
    "align_lines",
    "associate_lines",
    "association_probability",
    "canonical_lines",
    "detect_lines",
    "find_peaks",
    "hough_classic",
    "hough_cost",
    "hough_polar",
    "hough_slam",
    "icp",
    "icp_odometry",
    "line_difference",
    "line_rotation_steps",
    "line_scan",
    "lines_about_centre",
    "map_agreement",
    "merge_duplicates",
    "odometry_lag",
    "pose_from_lines",
    "pose_from_two_lines",
    "rasterise_scan",
    "refine_lines",
    "retime_poses",
    "rigid_fit_2d",
    "scan_lines",
    "select_line_pair",
    "theta_axis",
    "transform_lines",
]
__all__ += list(_PLOT)  # loaded on first use
