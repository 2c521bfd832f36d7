"""Readers for real sensor logs (CARMEN laser logs; 004's rangefinder chapters)."""

from .carmen import CarmenLog, flaser_angles, read_carmen
from .urg04lx import UrgLog, read_urg04lx_log, urg04lx_bearings, urg04lx_odometry, urg04lx_sensor_increments

__all__ = [
    "CarmenLog",
    "UrgLog",
    "flaser_angles",
    "read_carmen",
    "read_urg04lx_log",
    "urg04lx_bearings",
    "urg04lx_odometry",
    "urg04lx_sensor_increments",
]
