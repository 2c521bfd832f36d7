"""``detect(image, method=..., **params)``: every detector behind one call (000 §1.4)."""

from __future__ import annotations

import numpy as np

from .._validate import check_choice, check_int, check_positive
from .base import Features, to_gray_float, to_gray_uint8
from .fast import fast_detect
from .moravec import moravec_detect
from .opencv import fast_cv, mser_cv, orb_cv, sift_cv
from .surf import integral_image, surf_describe, surf_detect

__all__ = ["DETECTORS", "describe_surf", "detect"]

#: Detector names accepted by :func:`detect`.
DETECTORS = ("surf", "sift", "orb", "fast", "fast-cv", "moravec", "mser")


def describe_surf(image, features: Features, *, scale_px: float | None = None, upright: bool = True,
                  extended: bool = False) -> Features:
    """Attach SURF descriptors to any keypoints (e.g. FAST corners, which have none).

    ``scale_px`` overrides the keypoints' scale (FAST: our choice σ = 2 px);
    ``upright`` uses orientation 0 (U-SURF), otherwise the keypoints' orientation.

    Parameters
    ----------
    image : (H, W) or (H, W, 3) array
        The image the keypoints were found in (converted to grey float in [0, 1]).
    features : Features
        Keypoints to describe (their ``uv``, ``scale_px`` and ``orientation_rad`` are used).
    scale_px : float, optional
        Scale σ in pixels for every keypoint; None uses each keypoint's ``scale_px``.
    upright : bool
        Orientation 0 for every keypoint (U-SURF) instead of ``orientation_rad``.
    extended : bool
        128-d descriptors (SURF-128) instead of 64-d.

    Returns
    -------
    Features
        The same keypoints with float SURF ``descriptors`` attached.
    """
    if not isinstance(features, Features):
        raise TypeError(f"`features` must be slamlab.features.Features; got {type(features).__name__}")
    II = integral_image(to_gray_float(image))
    sigma = features.scale_px if scale_px is None else np.full(len(features), check_positive(scale_px, "scale_px"))
    ori = np.zeros(len(features)) if upright else features.orientation_rad
    desc = surf_describe(II, features.uv, sigma, ori, extended=extended)
    return Features(features.uv, features.scale_px, features.orientation_rad, features.response, features.octave,
                    desc, features.method)


def detect(image, method: str = "surf", *, descriptors: bool = True, max_points: int | None = None,
           channel_order: str = "rgb", **params) -> Features:
    """Keypoints (and descriptors) of ``image`` by ``method`` (000 §1.4).

    Parameters
    ----------
    image : (H, W) grey image (uint8 or float in [0, 1]), or (H, W, 3) colour, converted once
        to grey here (float for our SURF and Moravec, uint8 for the others).
    method : {'surf', 'sift', 'orb', 'fast', 'fast-cv', 'moravec', 'mser'}
        Ours: surf, fast, moravec. OpenCV: sift, orb, fast-cv, mser.
    descriptors : bool
        Compute descriptors where the method has them; our FAST gets upright SURF
        descriptors at σ = 2 px (our choice, so that FAST can be matched).
    channel_order : {'rgb', 'bgr'}
        Channel order of a colour image: ``"rgb"`` (default: numpy, matplotlib, imageio) or
        ``"bgr"`` (``cv2.imread``); a BGR image then gives exactly ``cv2.cvtColor(img,
        cv2.COLOR_BGR2GRAY)`` for the uint8 detectors.
    max_points : int, optional
        Keep the strongest ``max_points`` keypoints (by response).
    **params
        Passed to the method's function (``threshold`` for surf/fast/moravec, ...).

    Examples
    --------
    >>> img = np.zeros((40, 40), np.uint8); img[20, 20] = 200
    >>> f = detect(img, "fast", threshold=50)
    >>> f.uv.tolist(), f.descriptors.shape
    ([[20.0, 20.0]], (1, 64))

    Returns
    -------
    Features
        Keypoints with descriptors (None where the method has none or ``descriptors=False``).
    """
    method = check_choice(method, "method", DETECTORS)
    if np.ndim(image) == 3:  # colour: one conversion, in the stated channel order
        gray = to_gray_float if method in ("surf", "moravec") else to_gray_uint8
        image = gray(image, channel_order=channel_order)
    if method == "surf":
        f = surf_detect(image, descriptors=descriptors, **params)
    elif method == "sift":
        f = sift_cv(image, descriptors=descriptors, **params)
    elif method == "orb":
        f = orb_cv(image, descriptors=descriptors, **params)
    elif method == "fast":
        f = fast_detect(image, **params)
    elif method == "fast-cv":
        f = fast_cv(image, **params)
    elif method == "moravec":
        f = moravec_detect(image, **params)
    else:
        f = mser_cv(image, **params)
    if max_points is not None and len(f) > check_int(max_points, "max_points", minimum=1):
        f = f.strongest(max_points)  # (fewer points: strongest() would keep them all, in order)
    if descriptors and method == "fast":
        f = describe_surf(image, f, scale_px=2.0, upright=True)
    return f
