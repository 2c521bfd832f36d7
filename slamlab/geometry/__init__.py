"""Geometry helpers: angles, rotations, rigid transforms (one place for each)."""

from .angles import angle_mean, wrap_angle

__all__ = ["angle_mean", "wrap_angle"]
