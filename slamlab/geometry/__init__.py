"""Geometry helpers: angles, rotations, rigid transforms (one place for each)."""

from .angles import angle_mean, wrap_angle
from .ellipse import covariance_ellipse
from .registration import RigidTransform, apply_transform, umeyama

__all__ = ["RigidTransform", "angle_mean", "apply_transform", "covariance_ellipse", "umeyama", "wrap_angle"]
