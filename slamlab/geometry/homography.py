"""Homographies of the image plane (000 §2 repeatability; 003 §4.3.1 initialisation).

One mapping ``(u, v) ↦ π(H [u, v, 1]ᵀ)`` for the feature evaluation (a point of image 1 in
image 2) and the monocular initialisation (the transfer error of a plane's homography), written
element-wise: a matrix product goes to BLAS, whose rounding (FMA or not) depends on the machine.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, as_matrix

__all__ = ["apply_homography"]


def apply_homography(H, uv) -> np.ndarray:
    """Map pixels by a homography: ``(u', v') = ((h11 u + h12 v + h13) / w, (h21 u + h22 v + h23) / w)``,
    ``w = h31 u + h32 v + h33`` (Hartley & Zisserman §2.3).

    Parameters
    ----------
    H : array_like, shape (3, 3)
        Homography (any scale).
    uv : array_like, shape (N, 2) or (2,)
        Pixel coordinates ``(u, v)`` (column, row).

    Returns
    -------
    ndarray, shape (N, 2)
        The mapped pixels.

    Examples
    --------
    >>> apply_homography(np.diag([2.0, 2.0, 1.0]), [[1.0, 2.0]]).tolist()
    [[2.0, 4.0]]
    """
    H = as_matrix(H, "H", (3, 3))
    uv = as_finite_array(uv, "uv")
    if uv.shape == (2,):
        uv = uv.reshape(1, 2)
    if uv.ndim != 2 or uv.shape[1] != 2:
        raise ValueError(f"`uv` must have shape (N, 2) or (2,); got {uv.shape}")
    x, y = uv[:, 0], uv[:, 1]
    w = H[2, 0] * x + H[2, 1] * y + H[2, 2]
    return np.column_stack([(H[0, 0] * x + H[0, 1] * y + H[0, 2]) / w, (H[1, 0] * x + H[1, 1] * y + H[1, 2]) / w])
