"""Feature detectors, descriptors and matching (000 §1.4; 003 §3.1).

Ours: SURF from the paper (:func:`surf_detect`, :class:`SURF`), FAST
(:func:`fast_detect`) and Moravec (:func:`moravec_detect`) for teaching; OpenCV:
SIFT, ORB, MSER and FAST as the reference. Every detector returns
:class:`Features`; :func:`detect` calls any of them by name. Matching rules
(000's 2× rule, ratio, mutual check, Hamming) are in :mod:`.matching`,
evaluation on the Oxford affine pairs in :mod:`.evaluation`.
"""

from .._lazy import lazy_exports
from .base import CHANNEL_ORDERS, Features, to_gray_float, to_gray_uint8
from .detect import DETECTORS, describe_surf, detect
from .evaluation import (
    OXFORD_SEQUENCES,
    PairScores,
    common_region,
    correct_matches,
    load_oxford_image,
    load_oxford_pair,
    oxford_folder,
    oxford_label,
    project,
    repeatability,
)
from .fast import fast_corner_mask, fast_detect, fast_score
from .matching import (
    KNN_METHODS,
    Matches,
    accept_000,
    accept_ratio,
    best_per_target,
    hamming_distances,
    knn2,
    match_descriptors,
    mutual_mask,
    ratio_rule,
)
from .moravec import moravec_detect, moravec_response
from .opencv import fast_cv, features_from_keypoints, mser_cv, orb_cv, sift_cv
from .surf import (
    SURF,
    filter_sizes,
    haar_xy,
    hessian_maxima,
    hessian_response,
    integral_image,
    surf_describe,
    surf_detect,
    surf_orientation,
    threshold_sweep,
)

__all__ = [
    "CHANNEL_ORDERS",
    "DETECTORS",
    "KNN_METHODS",
    "OXFORD_SEQUENCES",
    "SURF",
    "Features",
    "Matches",
    "PairScores",
    "accept_000",
    "accept_ratio",
    "best_per_target",
    "common_region",
    "correct_matches",
    "describe_surf",
    "detect",
    "fast_corner_mask",
    "fast_cv",
    "fast_detect",
    "fast_score",
    "features_from_keypoints",
    "filter_sizes",
    "haar_xy",
    "hamming_distances",
    "hessian_maxima",
    "hessian_response",
    "integral_image",
    "knn2",
    "load_oxford_image",
    "load_oxford_pair",
    "match_descriptors",
    "moravec_detect",
    "moravec_response",
    "mser_cv",
    "mutual_mask",
    "orb_cv",
    "oxford_folder",
    "oxford_label",
    "project",
    "ratio_rule",
    "repeatability",
    "sift_cv",
    "surf_describe",
    "surf_detect",
    "surf_orientation",
    "threshold_sweep",
    "to_gray_float",
    "to_gray_uint8",
]

#: plotting (pyplot) names load on first use
_LAZY = dict.fromkeys(("DETECTOR_GALLERY", "plot_box_filters", "plot_detector_gallery", "plot_fast_circle",
                       "plot_keypoint_pair", "plot_keypoints", "plot_matches"), ".plot")
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
__all__ += list(_LAZY)
