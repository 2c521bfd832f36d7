"""Monocular mapping (003 §2.1, §4, §5): SDVL/SVO-style depth filter, initialisation, tracking.

Uses :mod:`slamlab.features` (FAST), :mod:`slamlab.geometry` and :mod:`slamlab.evaluation`;
nothing below imports this package. cv2 loads inside the functions that need it.
"""

from .depth_filter import (
    Seeds,
    compute_tau,
    converged_linearity,
    converged_sigma,
    depth_interval,
    init_seeds,
    inlier_ratio,
    linearity_index,
    seed_points,
    update_seeds,
)
from .initialise import (
    INIT_STATUSES,
    Initialiser,
    InitResult,
    TwoViewPose,
    relative_pose_essential,
    relative_pose_homography,
    track_lk,
    triangulate_two_view,
)

__all__ = [
    "INIT_STATUSES",
    "InitResult",
    "Initialiser",
    "Seeds",
    "TwoViewPose",
    "compute_tau",
    "converged_linearity",
    "converged_sigma",
    "depth_interval",
    "init_seeds",
    "inlier_ratio",
    "linearity_index",
    "relative_pose_essential",
    "relative_pose_homography",
    "seed_points",
    "track_lk",
    "triangulate_two_view",
    "update_seeds",
]
