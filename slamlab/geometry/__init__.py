"""Geometry helpers: angles, rotations, rigid transforms (one place for each)."""

from .angles import angle_mean, wrap_angle
from .ellipse import covariance_ellipse

__all__ = ["angle_mean", "covariance_ellipse", "wrap_angle"]
