"""Geometry helpers: angles, rotations, rigid transforms (one place for each)."""

from .angles import angle_mean, wrap_angle
from .ellipse import covariance_ellipse
from .odometry import Odometry, simulate_odometry
from .registration import RigidTransform, apply_transform, umeyama
from .se2 import check_pose, check_poses, se2_compose, se2_integrate, se2_inverse, se2_relative, se2_transform

__all__ = ["Odometry", "RigidTransform", "angle_mean", "apply_transform", "check_pose", "check_poses", "covariance_ellipse",
           "se2_compose", "se2_integrate", "se2_inverse", "se2_relative", "se2_transform", "simulate_odometry", "umeyama",
           "wrap_angle"]

# --- pinhole camera, stereo rig, midpoint triangulation, RANSAC, SE(3) helpers (000 §3) ---
from .camera import PinholeCamera, StereoRig, focal_from_hfov, fundamental_matrix, rotation_xyz
from .ransac import RansacResult, ransac
from .se3 import (
    planar_from_se3,
    rotate_points,
    se3,
    se3_compose,
    se3_from_planar,
    se3_inverse,
    transform_points,
    yaw_from_R,
)
from .triangulation import Triangulation, triangulate_midpoint, triangulate_stereo

__all__ += [
    "PinholeCamera",
    "RansacResult",
    "StereoRig",
    "Triangulation",
    "focal_from_hfov",
    "fundamental_matrix",
    "planar_from_se3",
    "ransac",
    "rotate_points",
    "rotation_xyz",
    "se3",
    "se3_compose",
    "se3_from_planar",
    "se3_inverse",
    "transform_points",
    "triangulate_midpoint",
    "triangulate_stereo",
    "yaw_from_R",
]
