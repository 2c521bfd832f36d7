"""Trajectory evaluation (Ch. 9; 003 §5.2): TUM/KITTI files, ATE and RPE equal to evo's."""

from .metrics import ErrorStats, align_trajectory, associate, ate, rpe
from .trajectory import Trajectory, read_kitti, read_tum, write_kitti, write_tum

__all__ = [
    "ErrorStats",
    "Trajectory",
    "align_trajectory",
    "associate",
    "ate",
    "read_kitti",
    "read_tum",
    "rpe",
    "write_kitti",
    "write_tum",
]
