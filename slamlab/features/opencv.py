"""SIFT, ORB, MSER and FAST through OpenCV behind the slamlab interface (000 §1.4.1).

OpenCV's SURF lives in the non-free contrib build and is absent from the
headless wheel; our SURF is :mod:`slamlab.features.surf`. cv2 is imported inside the
functions, so ``import slamlab.features`` stays light.
"""

from __future__ import annotations

from operator import attrgetter

import numpy as np

from .._validate import check_int, check_positive
from .base import Features, to_gray_uint8

__all__ = ["fast_cv", "features_from_keypoints", "mser_cv", "orb_cv", "sift_cv"]


def features_from_keypoints(keypoints, descriptors, method: str) -> Features:
    """Convert a list of ``cv2.KeyPoint`` (+ descriptor array) to :class:`Features`.

    ``scale_px`` = ``size / 2``; OpenCV angles (degrees, -1 = none) become radians in
    [0, 2π) (0 when absent); SIFT's packed octave byte is unpacked to the octave index.

    Parameters
    ----------
    keypoints : sequence of cv2.KeyPoint
        OpenCV keypoints.
    descriptors : (N, d) array or None
        Their descriptors, row i for keypoint i.
    method : str
        Detector name ("SIFT" unpacks the octave; "ORB" gives uint8 empty descriptors).

    Returns
    -------
    Features
    """
    k = len(keypoints)
    if k == 0:
        dim = None if descriptors is None else descriptors.shape[1] if descriptors.ndim == 2 else None
        dt = np.uint8 if method == "ORB" else np.float32
        return Features.empty(method, dim if dim is not None else (32 if method == "ORB" else 128
                                                                    if method == "SIFT" else None), dt)
    import cv2  # the keypoints are cv2.KeyPoint: cv2 is loaded

    # positions in one call; each other field by one pass of its getter (about 3x faster than a list per field)
    uv = np.asarray(cv2.KeyPoint_convert(keypoints), dtype=np.float64).reshape(k, 2)
    size = np.fromiter(map(attrgetter("size"), keypoints), np.float64, k)
    ang = np.fromiter(map(attrgetter("angle"), keypoints), np.float64, k)
    ang = np.where(ang < 0, 0.0, np.deg2rad(ang) % (2 * np.pi))
    resp = np.fromiter(map(attrgetter("response"), keypoints), np.float64, k)
    octv = np.fromiter(map(attrgetter("octave"), keypoints), np.int64, k)
    if method == "SIFT":
        octv = octv & 255
        octv = np.where(octv >= 128, octv - 256, octv)
    return Features(uv, size / 2.0, ang, resp, octv, descriptors, method)


def sift_cv(image, *, n_features: int = 0, contrast_threshold: float = 0.04, edge_threshold: float = 10.0,
            sigma: float = 1.6, descriptors: bool = True) -> Features:
    """OpenCV SIFT (000 §1.4.1): 128-d float descriptors.

    Parameters
    ----------
    image : (H, W) array
        Grey image (converted to uint8).
    n_features : int
        Keep the best this many (0: all).
    contrast_threshold, edge_threshold, sigma : float
        OpenCV's ``contrastThreshold``, ``edgeThreshold`` and base blur σ in pixels.
    descriptors : bool
        Compute the descriptors.

    Returns
    -------
    Features
    """
    import cv2

    img = to_gray_uint8(image)
    det = cv2.SIFT_create(nfeatures=check_int(n_features, "n_features", minimum=0),
                          contrastThreshold=check_positive(contrast_threshold, "contrast_threshold"),
                          edgeThreshold=check_positive(edge_threshold, "edge_threshold"),
                          sigma=check_positive(sigma, "sigma"))
    if descriptors:
        kp, d = det.detectAndCompute(img, None)
    else:
        kp, d = det.detect(img, None), None
    return features_from_keypoints(kp, d if d is not None or not descriptors else np.zeros((0, 128), np.float32),
                                   "SIFT")


def orb_cv(image, *, n_features: int = 2000, scale_factor: float = 1.2, n_levels: int = 8,
           fast_threshold: int = 20, descriptors: bool = True) -> Features:
    """OpenCV ORB: oriented FAST + rotated BRIEF, 256-bit descriptors as 32 uint8 (Hamming distance).

    Parameters
    ----------
    image : (H, W) array
        Grey image (converted to uint8).
    n_features : int
        Most keypoints kept.
    scale_factor : float
        Pyramid scale ratio between levels.
    n_levels : int
        Pyramid levels.
    fast_threshold : int
        FAST threshold in grey levels.
    descriptors : bool
        Compute the descriptors.

    Returns
    -------
    Features
    """
    import cv2

    img = to_gray_uint8(image)
    det = cv2.ORB_create(nfeatures=check_int(n_features, "n_features", minimum=1),
                         scaleFactor=check_positive(scale_factor, "scale_factor"),
                         nlevels=check_int(n_levels, "n_levels", minimum=1),
                         fastThreshold=check_int(fast_threshold, "fast_threshold", minimum=0))
    if descriptors:
        kp, d = det.detectAndCompute(img, None)
        if d is None:
            d = np.zeros((0, 32), np.uint8)
    else:
        kp, d = det.detect(img, None), None
    return features_from_keypoints(kp, d, "ORB")


def fast_cv(image, *, threshold: int = 20, nonmax: bool = True) -> Features:
    """OpenCV FAST (type 9_16), the reference for :func:`slamlab.features.fast_detect`.

    Parameters
    ----------
    image : (H, W) array
        Grey image (converted to uint8).
    threshold : int
        Intensity threshold in grey levels (0..255).
    nonmax : bool
        Non-maximum suppression.

    Returns
    -------
    Features
        Corners without descriptors.
    """
    import cv2

    img = to_gray_uint8(image)
    det = cv2.FastFeatureDetector_create(check_int(threshold, "threshold", minimum=0, maximum=255),
                                         bool(nonmax), cv2.FAST_FEATURE_DETECTOR_TYPE_9_16)
    return features_from_keypoints(det.detect(img, None), None, "FAST-cv")


#: Every other MSER setting, fixed at the defaults of OpenCV 5.0.0.93 (the lock's ``opencv-python-headless``,
#: read from ``cv2.MSER_create()``'s getters): ``MSER_create``'s keywords, and ``pass2Only`` (set by its setter).
#: Set explicitly so that a default changed by a later OpenCV cannot change our regions unseen.
_MSER_FIXED = {"max_variation": 0.25, "min_diversity": 0.2, "max_evolution": 200, "area_threshold": 1.01,
               "min_margin": 0.003, "edge_blur_size": 5}
_MSER_PASS2_ONLY = False


def _mser_detector(delta: int, min_area: int, max_area: int):
    """``cv2.MSER`` with every parameter set: ours, and ``_MSER_FIXED`` (OpenCV 5.0.0.93's defaults)."""
    import cv2

    det = cv2.MSER_create(delta=check_int(delta, "delta", minimum=1),
                          min_area=check_int(min_area, "min_area", minimum=1),
                          max_area=check_int(max_area, "max_area", minimum=1), **_MSER_FIXED)
    det.setPass2Only(_MSER_PASS2_ONLY)
    return det


def mser_cv(image, *, delta: int = 5, min_area: int = 60, max_area: int = 14400) -> Features:
    """OpenCV MSER regions as keypoints: centroid, σ = sqrt(area / π), no descriptor.

    Every MSER parameter is passed explicitly: ``delta``, ``min_area`` and ``max_area`` below,
    the others fixed at OpenCV 5.0.0.93's defaults (``max_variation`` 0.25, ``min_diversity`` 0.2,
    ``max_evolution`` 200, ``area_threshold`` 1.01, ``min_margin`` 0.003, ``edge_blur_size`` 5,
    ``pass2Only`` off; ours: the choice to pin them).

    Parameters
    ----------
    image : (H, W) array
        Grey image (converted to uint8).
    delta : int
        MSER's intensity step Δ.
    min_area, max_area : int
        Region size limits in pixels.

    Returns
    -------
    Features
        One keypoint per region, ``response`` = area in pixels.

    Notes
    -----
    The regions depend on the OpenCV version, not only on these parameters (measured by us):
    ``opencv-python-headless`` 5.1.0.95 reports the same defaults but no longer applies
    ``min_diversity`` to grey images (its documentation describes the parameter as "for color
    image"). On Oxford graf/img1 resized to 768×576 (notebook 02, section 4) it finds 1798
    regions, exactly the regions 5.0.0.93 finds with ``min_diversity=0``, where 5.0.0.93 (the
    lock, ``constraints.txt``) finds 137. No parameter restores the pruning under 5.1.0.95;
    the lock keeps 5.0.0.93.
    """
    img = to_gray_uint8(image)
    regions, _ = _mser_detector(delta, min_area, max_area).detectRegions(img)
    k = len(regions)
    if k == 0:
        return Features.empty("MSER")
    uv = np.array([r.mean(axis=0) for r in regions], dtype=np.float64)
    area = np.array([len(r) for r in regions], dtype=np.float64)
    return Features(uv, np.sqrt(area / np.pi), np.zeros(k), area, np.zeros(k, dtype=np.int64), None, "MSER")
