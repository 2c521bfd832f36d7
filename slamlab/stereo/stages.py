"""The per-frame stages of the stereo SLAM pipeline (000 §3.3-3.6), callable one at a time.

:func:`slamlab.features.detect` (with :meth:`StereoParams.detect_kwargs`) → ``stereo_match``
→ ``triangulate_local`` → ``match_to_map`` → ``estimate_pose``;
:class:`~slamlab.stereo.slam.StereoSLAM` runs them in a loop and refines / adds landmarks.
Each public stage takes ``params=`` (:class:`~slamlab.stereo.params.StereoParams`) plus
overrides and checks its arguments once; the loop calls the unchecked cores (``_stereo_match``,
...) with arguments it checked once.

Stages 1-2 (features, stereo matching, local cloud) live in :mod:`slamlab.stereo.local_stages`, stage 3 (map
matching) in :mod:`slamlab.stereo.map_stages`, stage 4 (pose) in :mod:`slamlab.stereo.pose_stages`; this module
gathers their public names.
"""

from __future__ import annotations

from .local_stages import (
    LocalCloud,
    StereoMatches,
    detect_features,
    epipolar_pairs,
    is_rectified,
    stereo_match,
    stereo_point_cov,
    subpixel_disparity,
    triangulate_local,
)
from .map_stages import MapMatches, match_to_map
from .pose_stages import PoseEstimate, estimate_pose, pose_std, refine_pose_stereo, select_oldest

__all__ = [
    "LocalCloud",
    "MapMatches",
    "PoseEstimate",
    "StereoMatches",
    "detect_features",
    "epipolar_pairs",
    "estimate_pose",
    "is_rectified",
    "match_to_map",
    "pose_std",
    "refine_pose_stereo",
    "select_oldest",
    "stereo_match",
    "stereo_point_cov",
    "subpixel_disparity",
    "triangulate_local",
]
