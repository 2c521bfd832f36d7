"""Angles: the one ``wrap_angle`` of slamlab and a circular mean."""

from __future__ import annotations

import numpy as np

__all__ = ["angle_mean", "wrap_angle"]


def wrap_angle(angle_rad):
    """Wrap angles to ``[-pi, pi)``; works element-wise on arrays.

    >>> float(wrap_angle(3 * np.pi / 2))
    -1.5707963267948966
    """
    return np.mod(np.asarray(angle_rad, dtype=float) + np.pi, 2.0 * np.pi) - np.pi


def angle_mean(angles_rad, weights=None, axis: int = 0):
    """Weighted circular mean: ``atan2(sum w sin a, sum w cos a)``.

    Weights may be negative (unscented transforms): the result is still the
    direction of the weighted resultant vector.

    >>> float(angle_mean(np.array([np.pi - 0.1, -np.pi + 0.1])))
    3.141592653589793
    """
    a = np.asarray(angles_rad, dtype=float)
    if weights is None:
        s, c = np.sin(a).sum(axis=axis), np.cos(a).sum(axis=axis)
    else:
        w = np.asarray(weights, dtype=float)
        s = np.tensordot(w, np.sin(a), axes=(0, axis))
        c = np.tensordot(w, np.cos(a), axes=(0, axis))
    return np.arctan2(s, c)
