"""Ch. 4 experiments (000 §3.7): the stereo SLAM loop on rendered arena runs, against ground truth (KITTI and the
closing table: :mod:`.kitti_experiments`).

``run_turn_in_place`` (000 §3.7.1) and ``run_closed_loop`` (000 §3.7.2) return a
frozen :class:`StereoRunResult`; ``str(result)`` is a one-line summary and
``result.table()`` prints our figures beside 000's. Timings live in ``stage_time_s``
and ``fps`` only, never in the table.

Families (CONVENTIONS: experiments.py split by experiment family): ``runs`` (the runner, the turn in place,
the closed loop), ``comparison``, ``drift``, ``diagnostics``.
"""

from __future__ import annotations

from .comparison import COMPARISON, comparison_table, run_comparison
from .diagnostics import disparity_errors, record_stereo_stream
from .drift import DriftStudy, run_drift_study
from .runs import (
    SIZES,
    StereoRunResult,
    experiment_poses,
    run_closed_loop,
    run_stereo_slam,
    run_stereo_slam_variants,
    run_turn_in_place,
)

__all__ = [
    "COMPARISON",
    "SIZES",
    "DriftStudy",
    "StereoRunResult",
    "comparison_table",
    "disparity_errors",
    "experiment_poses",
    "record_stereo_stream",
    "run_closed_loop",
    "run_comparison",
    "run_drift_study",
    "run_stereo_slam",
    "run_stereo_slam_variants",
    "run_turn_in_place",
]

