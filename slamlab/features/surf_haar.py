"""SURF's Haar wavelet responses on the integral image (Bay 2008 §4.1).

:func:`haar_xy`, boxes clipped to the image; the SURF modules read the same responses from the edge-padded
integral image of the package-private ``_padded_ii`` module (the same values, faster). Part of
:mod:`slamlab.features.surf` (which re-exports :func:`haar_xy`).
"""

from __future__ import annotations

import numpy as np

from ._padded_ii import haar_from_corners

__all__ = ["haar_xy"]


def haar_xy(II, rows, cols, half):
    """Haar wavelet responses of side ``2·half`` centred on integer pixels (Bay 2008 §4.1).

    dx = right half minus left half, dy = lower half minus upper half (v down),
    boxes clipped to the image. ``rows``, ``cols``, ``half`` broadcast together.

    Parameters
    ----------
    II : (H+1, W+1) float
        Integral image (:func:`slamlab.features.surf.integral_image`).
    rows, cols : int arrays
        Centre pixels.
    half : int or int array
        Half the wavelet side in pixels.

    Returns
    -------
    dx, dy : float arrays
        The responses, shaped as the broadcast inputs.
    """
    H, W = II.shape[0] - 1, II.shape[1] - 1
    Wp = W + 1
    flat = II.ravel()
    r0 = np.clip(rows - half, 0, H) * Wp
    rm = np.clip(rows, 0, H) * Wp
    r1 = np.clip(rows + half, 0, H) * Wp
    c0 = np.clip(cols - half, 0, W)
    cm = np.clip(cols, 0, W)
    c1 = np.clip(cols + half, 0, W)
    return haar_from_corners(flat[r0 + c0], flat[r0 + cm], flat[r0 + c1], flat[rm + c0], flat[rm + c1],
                             flat[r1 + c0], flat[r1 + cm], flat[r1 + c1])
