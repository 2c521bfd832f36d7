"""Readers for real sensor logs and data sets: CARMEN and URG-04LX laser logs, KITTI stereo odometry folders."""

from .carmen import CarmenLog, flaser_angles, open_text, read_carmen
from .kitti import kitti_rig, read_kitti_calib, read_kitti_image
from .urg04lx import UrgLog, read_urg04lx_log, urg04lx_bearings, urg04lx_odometry, urg04lx_sensor_increments

__all__ = [
    "CarmenLog",
    "UrgLog",
    "flaser_angles",
    "kitti_rig",
    "open_text",
    "read_carmen",
    "read_kitti_calib",
    "read_kitti_image",
    "read_urg04lx_log",
    "urg04lx_bearings",
    "urg04lx_odometry",
    "urg04lx_sensor_increments",
]
