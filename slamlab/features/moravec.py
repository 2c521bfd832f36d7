"""Moravec corner detector (003 §3.1.2), written for teaching.

For each of the 8 one-pixel shifts (u, v) (2 horizontal, 2 vertical, 4 diagonal)
the intensity change is the sum of squared differences over a square window
(003 eq. 13-14): ``E_uv(x, y) = Σ_window (I(x+u, y+v) - I(x, y))²``. The corner
measure is the minimum over the shifts (eq. 15): a corner changes in every
direction. Keep pixels above a threshold that are local maxima (NMS). The measure
is not rotation invariant (only 8 directions) and responds to edges at angles
between the shift directions -- the reasons Harris replaced it.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from .._validate import check_int, check_positive
from .base import Features, to_gray_float

__all__ = ["SHIFTS", "moravec_detect", "moravec_response"]

#: The 8 shifts (du, dv).
SHIFTS = np.array([(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1), (1, -1), (-1, 1)])


def moravec_response(image, window: int = 3) -> np.ndarray:
    """min over the 8 shifts of the windowed SSD (003 eq. 13-15), image in [0, 1] grey levels.

    Border pixels (closer than ``window // 2 + 1`` to the edge) get 0.

    Parameters
    ----------
    image : (H, W) array
        Grey image (uint8 or float in [0, 1]) or colour (converted to grey).
    window : int
        Odd side of the square SSD window in pixels.

    Returns
    -------
    (H, W) float
        Corner measure (squared grey levels summed over the window).

    Examples
    --------
    >>> img = np.zeros((9, 9)); img[4:, 4:] = 1.0
    >>> r = moravec_response(img, 3)
    >>> tuple(int(i) for i in np.unravel_index(np.argmax(r), r.shape))
    (4, 4)
    """
    img = to_gray_float(image)
    window = check_int(window, "window", minimum=1)
    if window % 2 == 0:
        raise ValueError(f"`window` must be odd (3, 5, 9, ...); got {window}")
    H, W = img.shape
    h = window // 2
    E = np.full((H, W), np.inf)
    for du, dv in SHIFTS:
        shifted = np.roll(img, (-dv, -du), axis=(0, 1))  # shifted[y, x] = I(x+du, y+dv)
        ssd = ndimage.uniform_filter((shifted - img) ** 2, size=window, mode="constant") * window * window
        np.minimum(E, ssd, out=E)
    b = h + 1
    out = np.zeros((H, W))
    if 2 * b < H and 2 * b < W:
        out[b:H - b, b:W - b] = E[b:H - b, b:W - b]
    return out


def moravec_detect(image, threshold: float = 0.1, window: int = 3, *, nms_size: int = 3) -> Features:
    """Moravec corners: response above ``threshold`` and the maximum of its ``nms_size`` neighbourhood (003 §3.1.2).

    ``threshold`` is in squared grey levels of a [0, 1] image summed over the window.

    Parameters
    ----------
    image : (H, W) array
        Grey image (uint8 or float in [0, 1]).
    threshold : float
        Smallest response (exclusive) of a corner.
    window : int
        Odd SSD window side in pixels.
    nms_size : int
        Side of the non-maximum-suppression neighbourhood in pixels.

    Returns
    -------
    Features
        Corners (``scale_px`` = window / 2, ``response`` = the measure), no descriptors.
    """
    threshold = check_positive(threshold, "threshold")
    nms_size = check_int(nms_size, "nms_size", minimum=1)
    R = moravec_response(image, window)
    peak = (ndimage.maximum_filter(R, size=nms_size, mode="constant") == R) & (threshold < R)
    r, c = np.nonzero(peak)
    k = r.size
    return Features(np.column_stack([c, r]).astype(np.float64), np.full(k, window / 2.0), np.zeros(k),
                    R[r, c], np.zeros(k, dtype=np.int64), None, "Moravec")
