"""Monocular mapping (003 §2.1, §4, §5): SDVL/SVO-style depth filter, initialisation, tracking.

Uses :mod:`slamlab.features` (FAST) and :mod:`slamlab.geometry`; nothing below imports this package.
cv2 loads inside the functions that need it. The chapter's runs, studies, tables and widgets are in
:mod:`slamlab.studies.mono`.
"""

from .._lazy import lazy_exports
from .align import refine_pose, se3_exp, sparse_align
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
from .epipolar import epipolar_segments, search_epipolar
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
from .params import MonoParams
from .slam import STAGES, Keyframe, MonoSLAM

__all__ = [
    "INIT_STATUSES",
    "STAGES",
    "InitResult",
    "Initialiser",
    "Keyframe",
    "MonoParams",
    "MonoSLAM",
    "Seeds",
    "TwoViewPose",
    "compute_tau",
    "converged_linearity",
    "converged_sigma",
    "depth_interval",
    "epipolar_segments",
    "init_seeds",
    "inlier_ratio",
    "linearity_index",
    "refine_pose",
    "relative_pose_essential",
    "relative_pose_homography",
    "se3_exp",
    "search_epipolar",
    "seed_points",
    "sparse_align",
    "track_lk",
    "triangulate_two_view",
    "update_seeds",
]

__getattr__, __dir__ = lazy_exports(__name__, {
    "plot_epipolar_pair": ".plot", "plot_seed_histograms": ".plot", "score_run": ".evaluate",
})
