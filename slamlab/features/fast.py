"""FAST segment-test corners (003 §3.1.1), written for teaching and equal to OpenCV's FAST.

A pixel p with intensity I_p is a corner when n contiguous pixels of the
16-pixel Bresenham circle of radius 3 are all brighter than I_p + t or all darker
than I_p - t (003 eq. 12: brighter / darker / similar). The 1-5-9-13 high-speed
test (compass pixels first; at least 3 of the 4 must be brighter, or 3 darker) is
a valid pre-filter only for n >= 12: a run of 12 always covers three compass
pixels, a run of 9 may cover only two. 003 notes the plain test has no strength
score; like OpenCV we use the largest threshold at which the pixel is still a
corner, minus one: ``max over n-arcs of min |I_k - I_p|`` (signed consistently)
``- 1``. Non-maximum suppression keeps a corner whose score is strictly larger
than that of its 8 neighbours (non-corners score 0) -- OpenCV's rule.
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .._validate import check_int
from .base import Features, to_gray_uint8

__all__ = ["CIRCLE_OFFSETS", "fast_corner_mask", "fast_detect", "fast_score"]

#: (du, dv) of the 16 circle pixels, numbered 1..16 clockwise from the top in 003's figure
#: (here from "down" as OpenCV orders them; any cyclic order gives the same corners).
CIRCLE_OFFSETS = np.array([(0, 3), (1, 3), (2, 2), (3, 1), (3, 0), (3, -1), (2, -2), (1, -3),
                           (0, -3), (-1, -3), (-2, -2), (-3, -1), (-3, 0), (-3, 1), (-2, 2), (-1, 3)])


def _circle_stack(img: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centre pixels (H-6, W-6) and the 16 circle pixels (16, H-6, W-6) as int16."""
    H, W = img.shape
    I = img.astype(np.int16)
    C = I[3:H - 3, 3:W - 3]
    P = np.stack([I[3 + dv:H - 3 + dv, 3 + du:W - 3 + du] for du, dv in CIRCLE_OFFSETS])
    return C, P


def _has_run(bits: np.ndarray, n: int) -> np.ndarray:
    """True where the 16-bit cyclic mask has a run of ``n`` ones (bit-doubling trick)."""
    b = bits.astype(np.uint32)
    bb = b | (b << 16)
    r = bb.copy()
    for i in range(1, n):
        r &= bb >> i
    return (r & 0xFFFF) != 0


def fast_corner_mask(image, threshold: int = 20, n: int = 9, *, high_speed: bool | None = None) -> np.ndarray:
    """Boolean map of segment-test corners (003 §3.1.1); the 3-pixel border is never a corner.

    Parameters
    ----------
    image : (H, W) uint8 (or float in [0, 1]) image
    threshold : int
        Intensity threshold t (grey levels, 0..255).
    n : int
        Length of the contiguous arc, 9..12 (003: 12; "visually best" 9).
    high_speed : bool, optional
        Apply the 1-5-9-13 pre-test first; default True for n >= 12. Raises for n < 12.

    Examples
    --------
    >>> img = np.zeros((9, 9), np.uint8); img[4, 4] = 200
    >>> np.argwhere(fast_corner_mask(img, 20)).tolist()
    [[4, 4]]

    Returns
    -------
    (H, W) bool
        True at the corners.
    """
    img = to_gray_uint8(image)
    threshold = check_int(threshold, "threshold", minimum=0, maximum=255)
    n = check_int(n, "n", minimum=9, maximum=12)
    if high_speed is None:
        high_speed = n >= 12
    if high_speed and n < 12:
        raise ValueError(f"`high_speed` (the 1-5-9-13 test) is valid only for n >= 12; got n={n}")
    H, W = img.shape
    mask = np.zeros((H, W), dtype=bool)
    if H < 7 or W < 7:
        return mask
    C, P = _circle_stack(img)
    brighter = C + threshold < P
    darker = C - threshold > P
    inner = np.ones(C.shape, dtype=bool)
    if high_speed:
        compass = [0, 4, 8, 12]  # pixels 1, 5, 9, 13
        inner = (brighter[compass].sum(axis=0) >= 3) | (darker[compass].sum(axis=0) >= 3)
    weights = (1 << np.arange(16, dtype=np.uint32))[:, None, None]
    bits_b = (brighter * weights).sum(axis=0, dtype=np.uint32)
    bits_d = (darker * weights).sum(axis=0, dtype=np.uint32)
    mask[3:H - 3, 3:W - 3] = inner & (_has_run(bits_b, n) | _has_run(bits_d, n))
    return mask


def fast_score(image, rows, cols, n: int = 9) -> np.ndarray:
    """OpenCV's FAST score at the given pixels: max over n-arcs of the arc's min contrast, minus 1.

    For a corner at threshold t the score is >= t; it is the largest t' for which the
    pixel is still a corner, minus one (OpenCV ``cornerScore``).

    Parameters
    ----------
    image : (H, W) uint8 (or float in [0, 1]) image
    rows, cols : (K,) int
        Pixel rows and columns, at least 3 pixels from the border.
    n : int
        Arc length, 9..12.

    Returns
    -------
    score : (K,) int64
    """
    img = to_gray_uint8(image).astype(np.int16)
    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    n = check_int(n, "n", minimum=9, maximum=12)
    if rows.size == 0:
        return np.zeros(0, dtype=np.int64)
    ring = img[rows[:, None] + CIRCLE_OFFSETS[:, 1], cols[:, None] + CIRCLE_OFFSETS[:, 0]]  # (K, 16)
    d = img[rows, cols][:, None] - ring  # centre minus circle: > 0 for darker circle pixels
    d2 = np.concatenate([d, d[:, :n - 1]], axis=1)
    win = sliding_window_view(d2, n, axis=1)  # (K, 16, n)
    dark = win.min(axis=2).max(axis=1)
    bright = (-win).min(axis=2).max(axis=1)
    return np.maximum(dark, bright).astype(np.int64) - 1


def fast_detect(image, threshold: int = 20, n: int = 9, *, nonmax: bool = True,
                high_speed: bool | None = None) -> Features:
    """FAST corners with OpenCV's score and 3×3 non-maximum suppression (003 §3.1.1).

    Same corners as ``cv2.FastFeatureDetector_create(threshold, nonmax, TYPE_9_16)``
    for n = 9 (tested). Keypoints are in row-major order; ``scale_px`` = 3.5 (OpenCV's
    size 7 / 2), ``response`` = the score.

    Parameters
    ----------
    image : (H, W) uint8 (or float in [0, 1]) image
    threshold : int
        Intensity threshold t (grey levels, 0..255).
    n : int
        Arc length, 9..12.
    nonmax : bool
        Keep only corners whose score is strictly larger than their 8 neighbours'.
    high_speed : bool, optional
        The 1-5-9-13 pre-test (see :func:`fast_corner_mask`).

    Returns
    -------
    Features
        Corners with ``response`` = score, no descriptors, method ``"FAST-<n>"``.

    Examples
    --------
    >>> img = np.zeros((9, 9), np.uint8); img[4, 4] = 200
    >>> f = fast_detect(img, 20)
    >>> f.uv.tolist(), f.response.tolist()
    ([[4.0, 4.0]], [199.0])
    """
    img = to_gray_uint8(image)
    mask = fast_corner_mask(img, threshold, n, high_speed=high_speed)
    r, c = np.nonzero(mask)
    score = fast_score(img, r, c, n)
    if nonmax and r.size:
        S = np.zeros(img.shape, dtype=np.int64)
        S[r, c] = score
        Sp = np.pad(S, 1)
        keep = np.ones(r.size, dtype=bool)
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if dr or dc:
                    keep &= score > Sp[r + 1 + dr, c + 1 + dc]
        r, c, score = r[keep], c[keep], score[keep]
    k = r.size
    return Features(np.column_stack([c, r]).astype(np.float64), np.full(k, 3.5), np.zeros(k),
                    score.astype(np.float64), np.zeros(k, dtype=np.int64), None, f"FAST-{n}")
