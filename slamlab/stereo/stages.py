"""The per-frame stages of the stereo SLAM pipeline (000 §3.3-3.6), callable one at a time.

:func:`slamlab.features.detect` (with :meth:`StereoParams.detect_kwargs`; ``detect_pair`` for both images)
→ ``stereo_match`` → ``triangulate_local`` → ``match_to_map`` (or the window search: ``match_to_landmarks``,
then ``match_in_window``) → ``estimate_pose``; :class:`~slamlab.stereo.slam.StereoSLAM` runs the same functions in
a loop and refines / adds landmarks (:mod:`slamlab.stereo.landmark_filter`). Each stage takes ``params=``
(:class:`~slamlab.stereo.params.StereoParams`) plus overrides and checks its arguments.

Stages 1-2 (features, stereo matching, local cloud) live in :mod:`slamlab.stereo.local_stages`, stage 3 (map
matching) in :mod:`slamlab.stereo.map_stages`, stage 4 (pose) in :mod:`slamlab.stereo.pose_stages`; this module
gathers their public names.
"""

from __future__ import annotations

from .local_stages import (
    LocalCloud,
    StereoMatches,
    check_features,
    detect_features,
    detect_pair,
    epipolar_pairs,
    is_rectified,
    stereo_match,
    stereo_point_cov,
    subpixel_disparity,
    triangulate_local,
)
from .map_stages import MapMatches, match_in_window, match_to_landmarks, match_to_map
from .pose_stages import PoseEstimate, estimate_pose, pose_std, refine_pose_stereo, select_oldest

__all__ = [
    "LocalCloud",
    "MapMatches",
    "PoseEstimate",
    "StereoMatches",
    "check_features",
    "detect_features",
    "detect_pair",
    "epipolar_pairs",
    "estimate_pose",
    "is_rectified",
    "match_in_window",
    "match_to_landmarks",
    "match_to_map",
    "pose_std",
    "refine_pose_stereo",
    "select_oldest",
    "stereo_match",
    "stereo_point_cov",
    "subpixel_disparity",
    "triangulate_local",
]
