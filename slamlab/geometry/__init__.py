"""Geometry helpers: angles, rotations, rigid transforms (one place for each)."""

from .angles import angle_mean, wrap_angle
from .ellipse import covariance_ellipse
from .odometry import Odometry, simulate_odometry
from .registration import RigidTransform, apply_transform, umeyama
from .se2 import check_pose, check_poses, se2_compose, se2_integrate, se2_inverse, se2_relative, se2_transform

__all__ = ["Odometry", "RigidTransform", "angle_mean", "apply_transform", "check_pose", "check_poses", "covariance_ellipse",
           "se2_compose", "se2_integrate", "se2_inverse", "se2_relative", "se2_transform", "simulate_odometry", "umeyama",
           "wrap_angle"]

# --- pinhole camera and projection, stereo rig, midpoint triangulation, RANSAC, SE(3) helpers (000 §3),
#     SO(3)/SE(3) hat, exp and log (003 §4.4, 002) ---
from .camera import (
    PinholeCamera,
    StereoRig,
    backproject_points,
    focal_from_hfov,
    fundamental_matrix,
    project_points,
    rotation_xyz,
)
from .homography import apply_homography
from .ransac import RansacResult, ransac, ransac_refit
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
from .so3 import hat, rotation_angle, se3_exp, se3_log, so3_exp, so3_log, vee
from .triangulation import Triangulation, triangulate_midpoint, triangulate_stereo

__all__ += [
    "PinholeCamera",
    "RansacResult",
    "StereoRig",
    "Triangulation",
    "apply_homography",
    "backproject_points",
    "focal_from_hfov",
    "fundamental_matrix",
    "hat",
    "planar_from_se3",
    "project_points",
    "ransac",
    "ransac_refit",
    "rotate_points",
    "rotation_angle",
    "rotation_xyz",
    "se3",
    "se3_compose",
    "se3_exp",
    "se3_from_planar",
    "se3_inverse",
    "se3_log",
    "so3_exp",
    "so3_log",
    "transform_points",
    "triangulate_midpoint",
    "triangulate_stereo",
    "vee",
    "yaw_from_R",
]
