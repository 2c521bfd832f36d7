"""Ch. 07's studies, Hough SLAM (004 §Hough SLAM): the example line, the 121-pose run, noise, real logs."""

from ..._lazy import lazy_exports
from .ablation import REAL_LOG_ABLATION, RealLogAblation, ablate_real_logs
from .example import ExampleLineResult, check_pose_from_two_lines, run_example_line, time_polar_vs_opencv
from .experiments import (
    ODOMETRY_NOISE,
    NoiseStudyResult,
    SimSlamResult,
    ours_vs_source,
    pose_errors,
    run_noise_study,
    run_sim_slam,
)
from .logs import (
    LOG_PARAMS,
    REAL_LOG_PARAMS,
    SHARED_LOGS,
    RealLogResult,
    log_format,
    map_sharpness,
    real_log_cause_table,
    rerun_real_log,
    run_real_log,
)

_PLOT = ("example_figure", "plot_pose_errors", "real_log_figure", "sim_figure")
_WIDGETS = ("explore_accumulator", "explore_hough_slam", "explore_real_log")
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"), **dict.fromkeys(_WIDGETS, ".widgets")})

__all__ = [
    "LOG_PARAMS",
    "ODOMETRY_NOISE",
    "REAL_LOG_ABLATION",
    "REAL_LOG_PARAMS",
    "SHARED_LOGS",
    "ExampleLineResult",
    "NoiseStudyResult",
    "RealLogAblation",
    "RealLogResult",
    "SimSlamResult",
    "ablate_real_logs",
    "check_pose_from_two_lines",
    "log_format",
    "map_sharpness",
    "ours_vs_source",
    "pose_errors",
    "real_log_cause_table",
    "rerun_real_log",
    "run_example_line",
    "run_noise_study",
    "run_real_log",
    "run_sim_slam",
    "time_polar_vs_opencv",
]
__all__ += list(_PLOT + _WIDGETS)  # loaded on first use
